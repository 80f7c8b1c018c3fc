//! Stipple drawings from point sets: dots of a chosen size ([`DotSize`]),
//! written as SVG for plotters and browsers ([`svg`]) or as an anti-aliased
//! PNG ([`raster`]), optionally in a pen-plotter order ([`tsp`]).
//!
//! All coordinates are in the sampling domain's pixels, origin top left, as
//! in [`crate::sampler`].

pub mod calibrate;
pub mod paper;
pub mod plot;
pub mod raster;
pub mod read;
pub mod relax;
pub mod svg;
pub mod tsp;

pub use paper::{Paper, Placement};

use crate::importance::{Prepared, RadiusRange};
use crate::sampler::Point;

/// What can go wrong while drawing.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter out of range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// A setting of a job file, or the file itself, that cannot be used:
    /// the message names the file or the key, the value and what is
    /// accepted ("relax = \"tsp\": expected a whole number, at least 0").
    #[error("{0}")]
    Setting(String),
    /// Writing the output failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// Encoding the PNG failed.
    #[error("cannot encode PNG: {0}")]
    Encode(String),
}

/// The result type of this module.
pub type Result<T, E = Error> = std::result::Result<T, E>;

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
/// The calibrated tone mappings ([`crate::importance::Mapping::Tone`] and
/// `ToneSized`) give each tone its dot radius
/// ([`crate::importance::Mapping::dot_radius`]); [`DotSize::Calibrated`]
/// draws those, and the ink then equals the darkness. Dots proportional to
/// the sample radius cover the same fraction everywhere: they do not
/// reproduce tones.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DotSize {
    /// Drawn radius = factor × the sample's radius (0.5 draws touching disks
    /// at the minimum distance).
    Proportional(f32),
    /// Drawn radius = factor × the dot's calibrated radius (1 reproduces the
    /// tones; above darkens, below lightens).
    Calibrated(f32),
}

impl DotSize {
    /// Checks that the factor or radius is a positive number.
    pub fn validate(self) -> Result<()> {
        let (Self::Proportional(v) | Self::Calibrated(v)) = self;
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidParameter(format!(
                "dot size {v} must be a positive number"
            )))
        }
    }

    /// The dots of `points`, in their order; `calibrated` gives a point's
    /// calibrated dot radius (used by [`DotSize::Calibrated`] only).
    ///
    /// ```
    /// use pixelpie::sampler::Point;
    /// use pixelpie::stipple::DotSize;
    /// let p = [Point { x: 1.0, y: 2.0, radius: 4.0, class: 0 }];
    /// let cal = |_: &Point| 3.0;
    /// assert_eq!(DotSize::Proportional(0.5).dots(&p, cal)[0].radius, 2.0);
    /// assert_eq!(DotSize::Calibrated(0.5).dots(&p, cal)[0].radius, 1.5);
    /// ```
    #[must_use]
    pub fn dots(self, points: &[Point], calibrated: impl Fn(&Point) -> f32) -> Vec<Dot> {
        points
            .iter()
            .map(|p| Dot {
                x: p.x,
                y: p.y,
                radius: self.radius(p.radius, calibrated(p), 1.0),
            })
            .collect()
    }

    /// The drawn radius of a dot of sample radius `sample` and calibrated
    /// radius `calibrated`, drawn by a pen whose dots spread by `gain` (the
    /// calibrated dot is the one on paper: drawn smaller by the gain). The
    /// one rule every drawing's dots follow.
    #[must_use]
    pub fn radius(self, sample: f32, calibrated: f32, gain: f32) -> f32 {
        match self {
            Self::Proportional(f) => f * sample,
            Self::Calibrated(f) => f * calibrated / gain,
        }
    }
}

/// The points of a stipple of `maps` (one per pen; the grey drawing has
/// one) after `iterations` weighted Lloyd steps ([`relax`]). With one map a
/// pixel weighs 1/r⁴ for its sample radius r (zero where the white cutoff
/// removes dots): a centroidal Voronoi tessellation puts points at a
/// density of √weight (Gersho's conjecture, which Lloyd's method follows),
/// so the relaxation evens the spacing while it keeps the calibrated
/// density, hence the tones. With several pens all points relax together
/// toward the union's density, (Σ_k 1/r_k²)² over the pens that have
/// samples at the pixel ([`crate::importance::Classes`]): the pens keep
/// their interleaving and each point its pen. Each point's radius becomes
/// its pen's sample radius at its new pixel. `progress` as in
/// [`relax::relax_until`].
pub fn relax_points(
    maps: &[Prepared],
    range: RadiusRange,
    points: &[Point],
    options: relax::RelaxOptions,
    progress: &mut dyn FnMut(Option<u32>) -> bool,
) -> Result<Vec<Point>> {
    let Some(first) = maps.first() else {
        return Err(Error::InvalidParameter("nothing to relax".into()));
    };
    let own = (first.map.width(), first.map.height());
    let (w, h) = first.domain();
    let xy: Vec<[f32; 2]> = points.iter().map(|p| [p.x, p.y]).collect();
    let moved = if let ([prepared], true) = (maps, first.domain() == own) {
        // Each pixel's radius (as the map's `radii` gives it) and its
        // weight.
        let radius = crate::importance::ImportanceMap::radius_fn(prepared.mapping, range);
        let values = prepared.map.values();
        relax_weighted(&xy, (w, h), options, progress, |i| {
            let v = values[i];
            if prepared.cutoff.is_some_and(|c| v > c) {
                0.0
            } else {
                1.0 / f64::from(radius(v)).powi(4)
            }
        })?
    } else {
        // The union's density (Σ 1/r_c² over the pens that have samples,
        // the rule the sampler ran under), squared as a radius's 1/r⁴.
        let classes = crate::importance::Classes { maps };
        let at = classes.union_density_at(range);
        relax_weighted(&xy, (w, h), options, progress, |i| {
            let inv = at(i);
            f64::from(inv * inv)
        })?
    };
    // Each point's new radius: its pen's at its new pixel (what the map's
    // `radii` hold there), found for the points alone.
    let radius: Vec<_> = maps
        .iter()
        .map(|m| crate::importance::ImportanceMap::radius_fn(m.mapping, range))
        .collect();
    Ok(moved
        .iter()
        .zip(points)
        .map(|(&[x, y], p)| {
            let px = (x.max(0.0) as u32).min(w - 1);
            let py = (y.max(0.0) as u32).min(h - 1);
            let class = if maps.len() == 1 { 0 } else { p.class };
            Point {
                x,
                y,
                radius: radius[class as usize](maps[class as usize].value(px, py)),
                class,
            }
        })
        .collect())
}

/// [`relax::relax_until`] of `xy` on the `(w, h)` domain, pixel `i`
/// weighing `weight(i)`: asked only where [`relax::Cells::Polygons`]
/// integrates, or for every pixel (checked) where the cells are pixels.
fn relax_weighted(
    xy: &[[f32; 2]],
    (width, height): (u32, u32),
    options: relax::RelaxOptions,
    progress: &mut dyn FnMut(Option<u32>) -> bool,
    weight: impl Fn(usize) -> f64 + Sync,
) -> Result<Vec<[f32; 2]>> {
    if let (relax::Cells::Polygons { edge }, false) = (options.cells, options.periodic) {
        let weights = relax::Weights {
            width,
            height,
            weight,
        };
        return Ok(relax::relax_polygons_until(
            xy,
            &weights,
            options.iterations,
            edge,
            options.over,
            progress,
        ));
    }
    use rayon::prelude::*;
    let weights: Vec<f32> = (0..width as usize * height as usize)
        .into_par_iter()
        .map(|i| weight(i) as f32)
        .collect();
    let density = relax::Density {
        width,
        height,
        weights: &weights,
    };
    relax::check(&density)?;
    Ok(relax::relax_until(xy, &density, options, progress))
}
