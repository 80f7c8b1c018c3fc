//! Stipple drawings from point sets: dots of a chosen size ([`DotSize`]),
//! written as SVG for plotters and browsers ([`svg`]) or as an anti-aliased
//! PNG ([`raster`]), optionally in a pen-plotter order ([`tsp`]).
//!
//! All coordinates are in the sampling domain's pixels, origin top left, as
//! in [`crate::sampler`].

pub mod raster;
pub mod svg;
pub mod tsp;

use crate::sampler::Point;

/// What can go wrong while drawing.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter out of range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// Writing the output failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Encoding the PNG failed.
    #[error("cannot encode PNG: {0}")]
    Encode(String),
}

/// The result type of this module.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// The default fixed dot radius as a fraction of the smallest sample radius:
/// dots of 0.7 × r_min cover about 87% of a black area's paper (a maximal set
/// of radius r_min covers 53% with dots of r_min/2). With the tone mapping
/// the ink then follows the darkness within ±0.08 from 15% to 85% grey
/// (`tests/stipple.rs`, `tone_mapping_with_default_dots_reproduces_a_ramp`).
pub const FIXED_DOT_FACTOR: f32 = 0.7;

/// One dot of the drawing: centre and drawn radius in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dot {
    /// Centre x.
    pub x: f32,
    /// Centre y.
    pub y: f32,
    /// Drawn radius.
    pub radius: f32,
}

/// How big each dot is drawn.
///
/// With [`crate::importance::Mapping::Tone`], equal dots make the ink
/// coverage follow the dot density, hence the tone; dots proportional to
/// the sample radius would cover the same fraction everywhere.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DotSize {
    /// Drawn radius = factor × the sample's radius (0.5 draws touching disks
    /// at the minimum distance).
    Proportional(f32),
    /// The same drawn radius, in pixels, for every dot.
    Fixed(f32),
}

impl DotSize {
    /// Checks that the factor or radius is a positive number.
    pub fn validate(self) -> Result<()> {
        let (Self::Proportional(v) | Self::Fixed(v)) = self;
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidParameter(format!(
                "dot size {v} must be a positive number"
            )))
        }
    }

    /// The dots of `points`, in their order.
    ///
    /// ```
    /// use pixelpie::sampler::Point;
    /// use pixelpie::stipple::DotSize;
    /// let p = [Point { x: 1.0, y: 2.0, radius: 4.0 }];
    /// assert_eq!(DotSize::Proportional(0.5).dots(&p)[0].radius, 2.0);
    /// assert_eq!(DotSize::Fixed(1.5).dots(&p)[0].radius, 1.5);
    /// ```
    #[must_use]
    pub fn dots(self, points: &[Point]) -> Vec<Dot> {
        points
            .iter()
            .map(|p| Dot {
                x: p.x,
                y: p.y,
                radius: match self {
                    Self::Proportional(f) => f * p.radius,
                    Self::Fixed(r) => r,
                },
            })
            .collect()
    }
}
