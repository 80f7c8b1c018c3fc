//! Quality measures of 2-D point sets (paper §4): minimum distance and the
//! relative radius ρ, coverage (maximality), the Delaunay-neighbour angle
//! histogram of §4.3, and the power spectrum after Schlömer & Deussen's PSA.
//!
//! Everything takes points in pixel units on a `width`×`height` domain, so
//! sets from any sampler can be compared ([`csv`] reads any file with x and y
//! columns). [`plots`] draws the figures.

pub mod angles;
pub mod csv;
pub mod fidelity;
pub mod gaps;
pub mod metrics;
#[cfg(feature = "plots")]
pub mod plots;
pub mod spectrum;

use serde::Serialize;

use crate::sampler::Control;

/// What can go wrong in an analysis.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A CSV line that cannot be read.
    #[error("line {line}: {message}")]
    Parse {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A parameter out of range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// Drawing a plot failed.
    #[error("cannot draw plot: {0}")]
    Plot(String),
    /// The caller cancelled the analysis ([`report_with`]).
    #[error("cancelled")]
    Cancelled,
}

/// The result type of this module.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// The radius that coverage and density use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoverRadius<'a> {
    /// The same radius for every point.
    Uniform(f64),
    /// One radius per point (the CSV's radius column).
    PerPoint(&'a [f64]),
}

impl CoverRadius<'_> {
    /// The radius of point `i`.
    #[must_use]
    pub fn of(&self, i: usize) -> f64 {
        match self {
            Self::Uniform(r) => *r,
            Self::PerPoint(r) => r[i],
        }
    }
}

/// A point set on its domain.
#[derive(Clone, Copy, Debug)]
pub struct Domain {
    /// Width in pixels.
    pub width: f64,
    /// Height in pixels.
    pub height: f64,
    /// Whether distances wrap around (a periodic set).
    pub periodic: bool,
}

impl Domain {
    /// Checks that the sides are positive numbers.
    pub fn validate(&self) -> Result<()> {
        if self.width.is_finite()
            && self.height.is_finite()
            && self.width > 0.0
            && self.height > 0.0
        {
            Ok(())
        } else {
            Err(Error::InvalidParameter(format!(
                "domain {}x{} must have positive sides",
                self.width, self.height
            )))
        }
    }

    /// The area in square pixels.
    #[must_use]
    pub fn area(&self) -> f64 {
        self.width * self.height
    }
}

/// The measures that `pixelpie analyze` prints.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Number of points.
    pub count: usize,
    /// The smallest distance between two points (`None` below two points).
    pub min_distance: Option<f64>,
    /// d_min / d_hex with d_hex = sqrt(2 A / (√3 N)), the PSA relative radius.
    pub rho: Option<f64>,
    /// Pixel centres farther than their covering radius from every point
    /// (0 = maximal); `None` without a radius.
    pub uncovered_pixels: Option<u64>,
    /// Σ π (r_i/2)² / A; `None` without a radius.
    pub density: Option<f64>,
    /// The largest empty circle centred in the closed domain (boundary
    /// mirrored, or wrapped when periodic): its radius and centre.
    pub largest_gap: Option<gaps::Gap>,
    /// Whether the disks cover every point of the closed domain, not only
    /// pixel centres (maximality in the continuous sense; a sampler run's
    /// `maximal` is that no pixel is left empty); `None` without a radius.
    pub continuous_maximal: Option<bool>,
    /// Standard deviation of the 360-bin Delaunay-neighbour angle histogram.
    pub angle_std: Option<f64>,
    /// Delaunay edges the histogram counts (each in both directions).
    pub angle_edges: usize,
}

/// [`Error::Cancelled`] once `ctl`'s cancel flag is set.
pub(crate) fn heed(ctl: &Control<'_>) -> Result<()> {
    if ctl.cancelled() {
        Err(Error::Cancelled)
    } else {
        Ok(())
    }
}

/// Points between two polls of the cancel flag in a serial loop.
pub(crate) const POLL_EVERY: usize = 1 << 14;

/// Computes the report for `points` on `domain`, covering with `radius`.
///
/// ```
/// use pixelpie::analyze::{CoverRadius, Domain, report};
/// let d = Domain { width: 4.0, height: 4.0, periodic: false };
/// let pts = [[1.0, 1.0], [3.0, 1.0], [1.0, 3.0], [3.0, 3.0]];
/// let r = report(&pts, d, Some(CoverRadius::Uniform(1.5))).unwrap();
/// assert_eq!((r.count, r.min_distance, r.uncovered_pixels), (4, Some(2.0), Some(0)));
/// assert_eq!(r.angle_edges, 5); // four sides and a diagonal
/// ```
pub fn report(
    points: &[[f64; 2]],
    domain: Domain,
    radius: Option<CoverRadius<'_>>,
) -> Result<Report> {
    report_with(points, domain, radius, Control::new())
}

/// [`report`], cancellable: each stage, and the long loops inside the
/// stages, poll `ctl`'s cancel flag and end with [`Error::Cancelled`] once
/// it is set (a Delaunay triangulation, which cannot be stopped inside,
/// runs to its end first). A report that is not cancelled is [`report`]'s.
///
/// ```
/// use std::sync::atomic::AtomicBool;
/// use pixelpie::analyze::{Domain, Error, report_with};
/// use pixelpie::sampler::Control;
/// let d = Domain { width: 4.0, height: 4.0, periodic: false };
/// let cancel = AtomicBool::new(true);
/// let r = report_with(&[[1.0, 1.0], [3.0, 3.0]], d, None, Control::new().with_cancel(&cancel));
/// assert!(matches!(r, Err(Error::Cancelled)));
/// ```
pub fn report_with(
    points: &[[f64; 2]],
    domain: Domain,
    radius: Option<CoverRadius<'_>>,
    ctl: Control<'_>,
) -> Result<Report> {
    let check = || heed(&ctl);
    check()?;
    domain.validate()?;
    if let Some(CoverRadius::PerPoint(r)) = radius
        && r.len() != points.len()
    {
        return Err(Error::InvalidParameter(format!(
            "{} radii for {} points",
            r.len(),
            points.len()
        )));
    }
    let min_distance = metrics::min_distance_with(points, domain, &ctl)?;
    let rho = min_distance.map(|d| metrics::rho(d, points.len(), domain.area()));
    let (uncovered_pixels, density) = match radius {
        Some(r) => (
            Some(metrics::uncovered_pixels_with(points, r, domain, &ctl)?),
            Some(metrics::density(points.len(), r, domain.area())),
        ),
        None => (None, None),
    };
    check()?;
    let largest_gap = gaps::largest_gap_with(points, domain, &ctl)?;
    check()?;
    let continuous_maximal = match radius {
        Some(r) => Some(gaps::uncovered_cells_with(points, r, domain, &ctl)? == 0),
        None => None,
    };
    check()?;
    let angles = angles::delaunay_angles(points);
    check()?;
    let angle_std =
        (!angles.is_empty()).then(|| angles::histogram_std(&angles::histogram(&angles, 360)));
    Ok(Report {
        count: points.len(),
        min_distance,
        rho,
        uncovered_pixels,
        density,
        largest_gap,
        continuous_maximal,
        angle_std,
        angle_edges: angles.len() / 2,
    })
}
