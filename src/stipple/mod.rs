//! Stipple drawings from point sets: dots of a chosen size ([`DotSize`]),
//! written as SVG for plotters and browsers ([`svg`]) or as an anti-aliased
//! PNG ([`raster`]), optionally in a pen-plotter order ([`tsp`]).
//!
//! All coordinates are in the sampling domain's pixels, origin top left, as
//! in [`crate::sampler`].

pub mod calibrate;
pub mod line;
pub mod paper;
pub mod plot;
pub mod raster;
pub mod read;
pub mod refine;
pub mod relax;
pub(crate) mod spatial;
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

/// A pen stroke: a polyline the pen draws without lifting, in domain
/// pixels. A drawing is layers of marks, each a [`Dot`] or a stroke
/// (`--style line` draws one stroke per pen).
#[derive(Clone, Debug, PartialEq)]
pub struct Stroke {
    /// The points the pen's centre passes through, in order.
    pub points: Vec<[f32; 2]>,
    /// The line's width in domain pixels (the pen's).
    pub width: f32,
    /// Whether it is drawn as smooth curves through its points
    /// ([`line::catmull_rom`]) rather than straight between them.
    pub smooth: bool,
}

impl Stroke {
    /// The polyline the pen follows, in domain pixels: the points
    /// themselves, or the curves through them flattened within `tolerance`
    /// px.
    #[must_use]
    pub fn path(&self, tolerance: f64) -> Vec<[f64; 2]> {
        let pts: Vec<[f64; 2]> = self
            .points
            .iter()
            .map(|p| [f64::from(p[0]), f64::from(p[1])])
            .collect();
        if self.smooth && pts.len() > 2 {
            line::flatten(&line::catmull_rom(&pts), tolerance)
        } else {
            pts
        }
    }
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
                "«dot_factor={v}» must be a positive number"
            )))
        }
    }

    /// The drawn radius of a dot of sample radius `sample` and calibrated
    /// radius `calibrated`, drawn by a pen whose dots spread by `gain` (the
    /// calibrated dot is the one on paper: drawn smaller by the gain). The
    /// one rule every drawing's dots follow.
    ///
    /// ```
    /// use pixelpie::stipple::DotSize;
    /// assert_eq!(DotSize::Proportional(0.5).radius(4.0, 3.0, 1.0), 2.0);
    /// assert_eq!(DotSize::Calibrated(0.5).radius(4.0, 3.0, 1.0), 1.5);
    /// ```
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
/// density, hence the tones. With several pens each pen's points relax on
/// their own toward the pen's own density ([`relax_pens`]). Each point's
/// radius becomes its pen's sample radius at its new pixel. `progress` as
/// in [`relax::relax_until`].
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
    if maps.len() > 1
        && let Some(p) = points.iter().find(|p| p.class as usize >= maps.len())
    {
        return Err(Error::InvalidParameter(format!(
            "a point of pen {} among {} pens: give each point a pen below {}",
            p.class,
            maps.len(),
            maps.len()
        )));
    }
    let (w, h) = first.domain();
    let xy: Vec<[f32; 2]> = points.iter().map(|p| [p.x, p.y]).collect();
    let moved = if let [prepared] = maps {
        // Each pixel's radius (as the map's `radii` gives it) and its
        // weight.
        let radius = crate::importance::ImportanceMap::radius_fn(prepared.mapping, range);
        relax_weighted(&xy, (w, h), options, progress, |i| {
            let v = prepared.value_index(i);
            if prepared.cutoff().is_some_and(|c| v > c) {
                0.0
            } else {
                1.0 / f64::from(radius(v)).powi(4)
            }
        })?
    } else {
        relax_pens(maps, range, points, &xy, options, progress)?
    };
    // Each point's new radius: its pen's at its new pixel (what the map's
    // `radii` hold there), found for the points alone.
    let radius: Vec<_> = maps
        .iter()
        .map(|m| crate::importance::ImportanceMap::radius_fn(m.mapping, range))
        .collect();
    use rayon::prelude::*;
    Ok(moved
        .par_iter()
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

/// The points `xy` of `points` (several pens) after `options.iterations` weighted Lloyd steps, each pen's
/// points relaxed on their own, toward their own density: a pixel weighs
/// 1/r_c⁴ for pen c's sample radius r_c there, zero where the pen has no
/// samples ([`crate::importance::Classes`]). Each pen's dots are then as
/// even as a grey drawing's, as if each pen were stippled alone, while the
/// union sample and the spreading ([`crate::job`]) start them interleaved:
/// `--pens cmyk` at 20K dots on five held-out photos measured a blurred
/// ΔE00 of 1.08–1.73 at the mean spacing σ and 6.2–9.6 at σ/2, against
/// 2.1–2.7 and 8.8–12.6 spread but not relaxed, and 2.5–3.0 and 9.5–13.3
/// with all pens relaxed together toward the union's density, as before
/// (docs/colour.md). The pens take each step in parallel, and each step
/// is reported; the result does not depend on the thread count.
fn relax_pens(
    maps: &[Prepared],
    range: RadiusRange,
    points: &[Point],
    xy: &[[f32; 2]],
    options: relax::RelaxOptions,
    progress: &mut dyn FnMut(Option<u32>) -> bool,
) -> Result<Vec<[f32; 2]>> {
    use rayon::prelude::*;
    let (w, h) = maps[0].domain();
    let pens = maps.len();
    let classes = crate::importance::Classes { maps };
    let radius = classes.class_radius(range);
    let pen_of = |p: &Point| if pens == 1 { 0 } else { p.class as usize };
    let groups: Vec<Vec<usize>> = (0..pens)
        .map(|c| {
            (0..points.len())
                .filter(|&i| pen_of(&points[i]) == c)
                .collect()
        })
        .collect();
    // Integrated at the pen's own spacing: the edge given for all points
    // times √(all / the pen's), as the union's cells would be at the
    // union's (at 20K dots 0.037 → 0.020 s, ΔE00 within 0.06 on five
    // photos), at most twice it, so that a pen whose ink lies in a small
    // part of the picture is not integrated coarser than its cells.
    let options_of = |own: usize| match options.cells {
        relax::Cells::Polygons { edge } => relax::RelaxOptions {
            iterations: 1,
            cells: relax::Cells::Polygons {
                edge: edge
                    * (xy.len() as f32 / own.max(1) as f32)
                        .sqrt()
                        .min(MAX_PEN_EDGE),
            },
            ..options
        },
        _ => relax::RelaxOptions {
            iterations: 1,
            ..options
        },
    };
    let weight = |c: usize| {
        let radius = &radius;
        move |i: usize| {
            let r = f64::from(radius(c, i));
            if r.is_finite() && r > 0.0 {
                r.powi(-4)
            } else {
                0.0
            }
        }
    };
    let step = |c: usize, idx: &Vec<usize>, now: &[[f32; 2]]| -> Result<Vec<[f32; 2]>> {
        let own: Vec<[f32; 2]> = idx.iter().map(|&i| now[i]).collect();
        if own.len() < 3 {
            return Ok(own);
        }
        relax_weighted(
            &own,
            (w, h),
            options_of(own.len()),
            &mut |_| true,
            weight(c),
        )
    };
    // On polygon cells each pen's weights are asked once for every step
    // (on the first).
    let on_polygons = matches!(options.cells, relax::Cells::Polygons { .. }) && !options.periodic;
    let make_polygons = || -> Vec<Option<relax::Polygons>> {
        groups
            .par_iter()
            .enumerate()
            .map(|(c, idx)| {
                let relax::Cells::Polygons { edge } = options_of(idx.len()).cells else {
                    return None;
                };
                let weights = relax::Weights {
                    width: w,
                    height: h,
                    weight: weight(c),
                };
                (idx.len() >= 3)
                    .then(|| relax::Polygons::new(&weights, edge, options.over))
                    .flatten()
            })
            .collect()
    };
    let mut polygons: Option<Vec<Option<relax::Polygons>>> = None;
    let mut now = xy.to_vec();
    for done in 1..=options.iterations {
        if !progress(None) {
            break;
        }
        if on_polygons && polygons.is_none() {
            polygons = Some(make_polygons());
        }
        // The pens in parallel on polygon cells; one after another on
        // pixel cells, whose weights span the whole domain per pen.
        let moved: Vec<Vec<[f32; 2]>> = if let Some(polygons) = &polygons {
            groups
                .par_iter()
                .zip(polygons)
                .map(|(idx, cells)| {
                    let own: Vec<[f32; 2]> = idx.iter().map(|&i| now[i]).collect();
                    Ok(match cells {
                        Some(c) => c.step(&own),
                        None => own,
                    })
                })
                .collect::<Result<_>>()?
        } else {
            groups
                .iter()
                .enumerate()
                .map(|(c, idx)| step(c, idx, &now))
                .collect::<Result<_>>()?
        };
        for (idx, own) in groups.iter().zip(moved) {
            for (&i, p) in idx.iter().zip(own) {
                now[i] = p;
            }
        }
        if !progress(Some(done)) {
            break;
        }
    }
    Ok(now)
}

/// The most a pen's integration edge is widened over the one given for
/// all its points ([`relax_pens`]).
const MAX_PEN_EDGE: f32 = 2.0;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::importance::{ImportanceMap, Mapping};

    /// Each pen relaxes on its own: a pen's dots move as they would with
    /// the other pen's dots gone, toward its own map's density, and keep
    /// their pen.
    #[test]
    fn each_pen_relaxes_on_its_own() {
        let (w, h) = (96u32, 64u32);
        let range = RadiusRange::new(2.0, 6.0).unwrap();
        // Pen 0 dark on the left, pen 1 dark on the right.
        let ramp = |flip: bool| {
            let values = (0..w * h)
                .map(|i| {
                    let x = (i % w) as f32 / (w - 1) as f32;
                    0.02 + 0.96 * if flip { 1.0 - x } else { x }
                })
                .collect();
            let map = ImportanceMap::from_values(w, h, values).unwrap();
            Prepared::new(map, Mapping::Tone, range, None).stretched((w, h))
        };
        let maps = [ramp(false), ramp(true)];
        let mut state = 7u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        let points: Vec<Point> = (0..1200)
            .map(|i| Point {
                x: next() * w as f32,
                y: next() * h as f32,
                radius: 2.0,
                class: i % 2,
            })
            .collect();
        let options = relax::RelaxOptions {
            iterations: 4,
            periodic: false,
            cells: relax::Cells::Polygons { edge: 2.0 },
            over: relax::OVER_RELAX,
        };
        let mut steps = Vec::new();
        let both = relax_points(&maps, range, &points, options, &mut |s| {
            steps.extend(s);
            true
        })
        .unwrap();
        assert_eq!(steps, [1, 2, 3, 4], "each step is reported");
        assert!(both.iter().zip(&points).all(|(a, b)| a.class == b.class));
        // Each pen as the relaxation of its points alone on its own
        // density (1/r⁴ of its own radius) makes it, at the edge its cells
        // had among both pens' (each pen's integrated at its own spacing).
        let classes = crate::importance::Classes { maps: &maps };
        let radius = classes.class_radius(range);
        for pen in 0..2u32 {
            let own: Vec<[f32; 2]> = points
                .iter()
                .filter(|p| p.class == pen)
                .map(|p| [p.x, p.y])
                .collect();
            let scaled = relax::RelaxOptions {
                cells: relax::Cells::Polygons {
                    edge: 2.0 * (points.len() as f32 / own.len() as f32).sqrt(),
                },
                ..options
            };
            let want = relax_weighted(&own, (w, h), scaled, &mut |_| true, |i| {
                f64::from(radius(pen as usize, i)).powi(-4)
            })
            .unwrap();
            let got: Vec<[f32; 2]> = both
                .iter()
                .filter(|p| p.class == pen)
                .map(|p| [p.x, p.y])
                .collect();
            assert_eq!(got, want, "pen {pen}");
        }
        // Pen 0 is darkest on the left, pen 1 on the right: each drifts
        // toward its own dark side (relaxed together toward the union's
        // density, even across the picture, neither would).
        let mean_x = |pts: &[Point], c: u32| {
            let xs: Vec<f32> = pts.iter().filter(|p| p.class == c).map(|p| p.x).collect();
            xs.iter().sum::<f32>() / xs.len() as f32
        };
        let drift = (
            mean_x(&both, 0) - mean_x(&points, 0),
            mean_x(&both, 1) - mean_x(&points, 1),
        );
        assert!(drift.0 < -0.25 && drift.1 > 0.25, "{drift:?}");
        // A point of a pen the maps do not have is refused.
        let mut odd = points.clone();
        odd[5].class = 2;
        assert!(relax_points(&maps, range, &odd, options, &mut |_| true).is_err());
    }
}
