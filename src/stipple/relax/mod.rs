//! Weighted Lloyd relaxation: weighted Voronoi stippling (Secord 2002, the
//! algorithm of StippleGen).
//!
//! Each iteration moves every point to the darkness-weighted centroid of its
//! Voronoi cell, or [`RelaxOptions::over`] times the way there
//! (over-relaxation, held within the domain). Cells are restricted to pixel centres: pixel `(x, y)`, centre
//! `(x + 0.5, y + 0.5)`, belongs to the point nearest to that centre, and the
//! centroid is the weighted mean of the centres of the cell's pixels.
//!
//! # How the Voronoi diagram is computed
//!
//! Exactly (every weighted pixel goes to its nearest point, ties to the point
//! with the lowest index), without visiting most pixels one by one:
//!
//! - Each iteration puts the points in a k-d tree.
//! - The image is cut into 16×16 tiles. For each tile, the tree gives `s1`, the
//!   point nearest to the tile's centre, and then every point that is at least
//!   as near as `s1` to one of the tile's corners. Those are exactly the points
//!   that can own a pixel of the tile: `|q - p|² - |q - s1|²` is linear in `q`,
//!   so if `p` beats `s1` anywhere in the tile it does at a corner. The tree
//!   prunes its boxes by the same test, so the search stays short whether the
//!   points are dense, sparse or far away from the tile.
//! - If only `s1` is left, the whole tile is its, and the tile's weight
//!   moments `[Σw, Σw·x, Σw·y]` come from a precomputed pyramid (4×4 to 16×16
//!   blocks) in O(1). Otherwise the tile is split in four and each quarter
//!   prunes the list again against its own nearest candidate, down to 4×4
//!   blocks whose pixels are assigned one by one.
//! - Tiles and blocks of zero weight are skipped at once: white paper costs
//!   nothing.
//!
//! Rows of tiles run in parallel with rayon; each produces its partial sums
//! (`Σw`, `Σw·dx`, `Σw·dy` per point, in `f64`, `dx` relative to the point) in
//! a fixed order, and these are added up row by row, so the result is the same
//! bit for bit whatever the number of threads.
//!
//! In periodic mode distances wrap around the domain (a torus): the tree is
//! searched for the points' images in the eight neighbouring copies of the
//! domain too, pixel offsets are taken from the nearest image of the point
//! (so they lie in `(-W/2, W/2] × (-H/2, H/2]`), and the new position is
//! wrapped back into `[0, W) × [0, H)`.
//!
//! With 100 000 points on 3200×2400 pixels, an iteration takes about 0.1 s on
//! two cores.
//!
//! # Cells as polygons
//!
//! [`Cells::Polygons`] takes each cell as the polygon it is (module
//! `cells`: each cell the domain cut by its neighbours' bisectors) and
//! integrates the weight over it at a given resolution, asking the weight
//! only there ([`Weights`]). Its cost follows the points, not the pixels:
//! at 100K points on 3163² pixels, an iteration took about 0.09 s on two
//! cores against 0.13 s for pixel cells, and about three quarters of that
//! since its cells are found without a triangulation; drawings relaxed so measure
//! as well or better (docs/drawing.md). Drawings use it; periodic
//! domains always take pixel cells.

mod cells;
mod kdtree;
mod lloyd;
mod pyramid;
mod start;
#[cfg(test)]
mod test_util;
mod voronoi;

use lloyd::lloyd_step;
use pyramid::Field;

pub use start::random_start;

/// A darkness (weight) field on the pixel grid: `weights[y * width + x] >= 0`, finite.
#[derive(Clone, Copy, Debug)]
pub struct Density<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major weights, `width * height` of them.
    pub weights: &'a [f32],
}

/// Options.
#[derive(Clone, Copy, Debug)]
pub struct RelaxOptions {
    /// Lloyd iterations.
    pub iterations: u32,
    /// Distances wrap around the domain (torus); centroids wrap too.
    pub periodic: bool,
    /// How the cells are taken.
    pub cells: Cells,
    /// How far each step moves a point, in its way to the centroid: 1 is
    /// Lloyd's step; between 1 and 2 over-relaxes, which converges in
    /// fewer steps ([`OVER_RELAX`]). Not finite, or outside (0, 2],
    /// counts as 1.
    pub over: f32,
}

/// The over-relaxation the drawings use ([`RelaxOptions::over`]): two
/// steps of 1.6 make drawings at least as close to their photos as three
/// of Lloyd's at σ and σ/2 (five photos at LBG's count, and astronaut at
/// 100K and 200K dots; docs/drawing.md), in two thirds of the time.
pub const OVER_RELAX: f32 = 1.6;

/// [`RelaxOptions::over`] as used: 1 where it is not in (0, 2].
fn over_factor(over: f32) -> f64 {
    if over > 0.0 && over <= 2.0 {
        f64::from(over)
    } else {
        1.0
    }
}

/// How a Lloyd iteration takes the Voronoi cells and their centroids.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Cells {
    /// Cells of pixel centres, exact: every pixel goes to its nearest point
    /// and the centroid is its pixels' weighted mean. Periodic domains are
    /// always relaxed so.
    #[default]
    Pixels,
    /// The cells as polygons, clipped to the domain and integrated over
    /// triangles of sides at most `edge` pixels, the weight taken from the
    /// pixel under each quadrature point: the cost follows the points and
    /// the area at `edge`'s resolution, not the pixels (module `cells`).
    Polygons {
        /// The longest side integrated whole, in pixels (> 0; at least
        /// [`MIN_EDGE`] is used). The weight is read once per block of
        /// ⌊edge/3⌋² pixels, at its middle pixel: detail thinner than a
        /// block (a 1 px line at edge 9) may be missed.
        edge: f32,
    },
}

/// Checks a density: `width` and `height` > 0, `width * height` weights, all
/// finite and >= 0. The error is a one-line message.
pub fn check(density: &Density<'_>) -> Result<(), super::Error> {
    check_density(density).map_err(super::Error::InvalidParameter)
}

/// [`check`], its error a message.
fn check_density(density: &Density<'_>) -> Result<(), String> {
    let (w, h) = (density.width, density.height);
    if w == 0 || h == 0 {
        return Err(format!("density is {w}×{h}: width and height must be > 0"));
    }
    let expected = u64::from(w) * u64::from(h);
    if density.weights.len() as u64 != expected {
        let len = density.weights.len();
        return Err(format!(
            "density has {len} weights, expected {w}×{h} = {expected}"
        ));
    }
    match density
        .weights
        .iter()
        .position(|v| !(v.is_finite() && *v >= 0.0))
    {
        Some(i) => {
            let (x, y, v) = (i % w as usize, i / w as usize, density.weights[i]);
            Err(format!(
                "weight at pixel ({x}, {y}) is {v}: weights must be finite and >= 0"
            ))
        }
        None => Ok(()),
    }
}

/// Moves each point to the darkness-weighted centroid of its Voronoi cell
/// (cells restricted to pixel centres: pixel (x,y) has centre (x+0.5, y+0.5)),
/// or `options.over` times the way there, `options.iterations` times. Points are (x, y) in pixel units, 0..width, 0..height.
///
/// A point whose cell has zero total weight stays where it is (so does a point
/// with a non-finite coordinate, which owns no pixel).
/// `progress(done_iterations)` is called after each iteration; if it returns false,
/// relaxation stops early and returns the points as they are then.
///
/// Deterministic: the same input gives the same output bit for bit whatever
/// the number of rayon threads.
///
/// Call [`check`] first: here, weights that are negative or not finite count
/// as zero, and a density with no pixels or the wrong number of weights
/// returns the points unchanged without calling `progress`.
pub fn relax(
    points: &[[f32; 2]],
    density: &Density<'_>,
    options: RelaxOptions,
    mut progress: impl FnMut(u32) -> bool,
) -> Vec<[f32; 2]> {
    relax_until(points, density, options, &mut |done| {
        done.is_none_or(&mut progress)
    })
}

/// [`relax`], with `progress(Some(done))` after each iteration and
/// `progress(None)` every few milliseconds within one: false stops (an
/// iteration stopped within leaves the points of the one before).
pub fn relax_until(
    points: &[[f32; 2]],
    density: &Density<'_>,
    options: RelaxOptions,
    progress: &mut dyn FnMut(Option<u32>) -> bool,
) -> Vec<[f32; 2]> {
    let mut current = points.to_vec();
    if let (Cells::Polygons { edge }, false) = (options.cells, options.periodic) {
        if density.weights.len() as u64 != u64::from(density.width) * u64::from(density.height)
            || density.weights.is_empty()
        {
            return current;
        }
        let weights = Weights {
            width: density.width,
            height: density.height,
            weight: |i| f64::from(density.weights[i]),
        };
        return relax_polygons_until(
            points,
            &weights,
            options.iterations,
            edge,
            options.over,
            progress,
        );
    }
    let Some(field) = Field::new(density) else {
        return current;
    };
    for done in 1..=options.iterations {
        let over = over_factor(options.over);
        match lloyd_step(&current, &field, options.periodic, over, &mut || {
            !progress(None)
        }) {
            Some(moved) => current = moved,
            None => break,
        }
        if !progress(Some(done)) {
            break;
        }
    }
    current
}

/// The finest side [`Cells::Polygons`] integrates at, pixels.
pub const MIN_EDGE: f32 = 0.5;

/// A weight per pixel, asked for where it is needed ([`Cells::Polygons`]
/// asks only at its quadrature points, not at every pixel).
pub struct Weights<F: Fn(usize) -> f64 + Sync> {
    /// Width in pixels (> 0).
    pub width: u32,
    /// Height in pixels (> 0).
    pub height: u32,
    /// The weight of pixel `y * width + x`; negative or not finite counts
    /// as zero.
    pub weight: F,
}

/// `iterations` Lloyd steps over the cells as polygons ([`Cells::Polygons`]
/// with sides of at most `edge` pixels, the weight asked at the middle of
/// each block of ⌊edge/3⌋² pixels) on a bounded domain, each moving a
/// point `over` times the way to its centroid ([`RelaxOptions::over`]),
/// with `progress` as [`relax_until`] has it. Points outside the domain,
/// not finite, or duplicated stay where they are.
pub fn relax_polygons_until<F: Fn(usize) -> f64 + Sync>(
    points: &[[f32; 2]],
    weights: &Weights<F>,
    iterations: u32,
    edge: f32,
    over: f32,
    progress: &mut dyn FnMut(Option<u32>) -> bool,
) -> Vec<[f32; 2]> {
    let mut current = points.to_vec();
    let Some(polygons) = Polygons::new(weights, edge, over) else {
        return current;
    };
    for done in 1..=iterations {
        if !progress(None) {
            break;
        }
        current = polygons.step(&current);
        if !progress(Some(done)) {
            break;
        }
    }
    current
}

/// The Lloyd step of [`relax_polygons_until`] with its weights asked once,
/// for callers that step one set several times or several sets apart.
pub struct Polygons {
    grid: cells::Grid,
    edge: f64,
    over: f64,
}

impl Polygons {
    /// The steps of [`relax_polygons_until`] on `weights`; `None` where it
    /// leaves the points where they are (an empty domain, a side that is
    /// not a positive number).
    pub fn new<F: Fn(usize) -> f64 + Sync>(
        weights: &Weights<F>,
        edge: f32,
        over: f32,
    ) -> Option<Self> {
        if weights.width == 0 || weights.height == 0 || edge.is_nan() || edge <= 0.0 {
            return None;
        }
        // Finer than half a pixel reads no more of the weights, only slower.
        let edge = edge.max(MIN_EDGE);
        // The weights asked once, at a third of the finest side: astronaut
        // and rocket at 10K, 100K and 200K dots measure the same as with
        // every pixel's weight (docs/drawing.md), and the cells read a
        // ninth of the memory.
        let grid = cells::Grid::new(weights, (edge / 3.0).floor().max(1.0) as u32);
        Some(Self {
            grid,
            edge: f64::from(edge),
            over: over_factor(over),
        })
    }

    /// One step of `points`.
    #[must_use]
    pub fn step(&self, points: &[[f32; 2]]) -> Vec<[f32; 2]> {
        cells::polygon_step(points, &self.grid, self.edge, self.over)
    }
}

/// Squared distance.
fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

/// `x` wrapped into `[0, len)`.
fn wrap(x: f64, len: f64) -> f64 {
    let r = x.rem_euclid(len);
    if r >= len { 0.0 } else { r }
}

#[cfg(test)]
mod tests {
    use super::test_util::{
        BOTH, assert_close, opts, opts_with, random_weights, relax_all, uniform_points,
    };
    use super::*;

    /// Pixels per point.
    fn cell_areas(points: &[[f32; 2]], w: usize, h: usize) -> Vec<f64> {
        let mut areas = vec![0.0; points.len()];
        for i in 0..w * h {
            let q = [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
            let p = points.iter().map(|p| dist2(p.map(f64::from), q));
            let k = p
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(0, |m| m.0);
            areas[k] += 1.0;
        }
        areas
    }

    fn std_dev(v: &[f64]) -> f64 {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64).sqrt()
    }

    fn min_nn_distance(points: &[[f32; 2]]) -> f64 {
        let mut best = f64::INFINITY;
        for (i, a) in points.iter().enumerate() {
            for b in &points[i + 1..] {
                best = best.min(dist2(a.map(f64::from), b.map(f64::from)).sqrt());
            }
        }
        best
    }

    #[test]
    fn regular_grid_stays_put_on_uniform_density() {
        let (w, h) = (160, 120);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let points: Vec<[f32; 2]> = (0..12)
            .flat_map(|j| (0..16).map(move |i| [5.0 + 10.0 * i as f32, 5.0 + 10.0 * j as f32]))
            .collect();
        for periodic in [false, true] {
            for cells in BOTH {
                let out = relax_all(&points, &density, opts_with(5, periodic, cells));
                assert_close(
                    &out,
                    &points,
                    1e-3,
                    &format!("periodic {periodic}, {cells:?}"),
                );
            }
        }
    }

    /// An over-relaxed step moves each point `over` times as far as
    /// Lloyd's step, the same way (held in the domain), for both kinds of
    /// cells and on a torus; `over` outside (0, 2] is Lloyd's step; and two
    /// steps of [`OVER_RELAX`] spread random points more evenly than two
    /// of Lloyd's.
    #[test]
    fn over_relaxation_goes_past_the_centroid_and_converges_sooner() {
        let (w, h) = (128usize, 96usize);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = random_start(150, &density, 3);
        for periodic in [false, true] {
            for cells in BOTH {
                let with = |iterations, over| {
                    let options = RelaxOptions {
                        over,
                        ..opts_with(iterations, periodic, cells)
                    };
                    relax_all(&start, &density, options)
                };
                let lloyd = with(1, 1.0);
                let over = with(1, 1.6);
                let (mut checked, mut seam) = (0, 0);
                let dom = [w as f32, h as f32];
                // On a torus, the step the short way round and the place
                // it reaches wrapped.
                let short = |d: f32, len: f32| {
                    if periodic {
                        d - len * (d / len).round()
                    } else {
                        d
                    }
                };
                let wrapped = |v: f32, len: f32| if periodic { v.rem_euclid(len) } else { v };
                for ((s, l), o) in start.iter().zip(&lloyd).zip(&over) {
                    let step = [0, 1].map(|a| short(l[a] - s[a], dom[a]));
                    let far = [0, 1].map(|a| s[a] + 1.6 * step[a]);
                    let inside = periodic
                        || ((1.0..w as f32 - 1.0).contains(&far[0])
                            && (1.0..h as f32 - 1.0).contains(&far[1]));
                    if inside {
                        seam += usize::from(
                            far.iter()
                                .zip(dom)
                                .any(|(&v, len)| !(0.0..len).contains(&v)),
                        );
                        let far = [0, 1].map(|a| wrapped(far[a], dom[a]));
                        let [dx, dy] = [0, 1].map(|a| short(o[a] - far[a], dom[a]));
                        assert!(
                            dx.hypot(dy) < 1e-3,
                            "periodic {periodic}, {cells:?}: {s:?} to {l:?} by Lloyd, {o:?} over-relaxed"
                        );
                        checked += 1;
                    } else {
                        assert!((0.0..w as f32).contains(&o[0]) && (0.0..h as f32).contains(&o[1]));
                    }
                }
                assert!(checked > 100, "{checked} points checked");
                // On the torus every point is checked, some across the seam.
                assert!(
                    !periodic || (checked == start.len() && seam > 0),
                    "{seam} across the seam"
                );
                for odd in [0.0, -1.0, 2.5, f32::NAN, f32::INFINITY] {
                    assert_eq!(with(1, odd), lloyd, "over = {odd}");
                }
                let spread = |p: &[[f32; 2]]| std_dev(&cell_areas(p, w, h));
                let (plain, fast) = (spread(&with(2, 1.0)), spread(&with(2, OVER_RELAX)));
                assert!(
                    fast < 0.9 * plain,
                    "periodic {periodic}, {cells:?}: cell areas' spread {fast} over-relaxed, {plain} plain"
                );
            }
        }
    }

    #[test]
    fn relaxation_spreads_random_points_evenly() {
        let (w, h) = (128, 96);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = random_start(150, &density, 3);
        for cells in BOTH {
            let out = relax_all(&start, &density, opts_with(30, false, cells));
            let (d0, d1) = (min_nn_distance(&start), min_nn_distance(&out));
            let (s0, s1) = (
                std_dev(&cell_areas(&start, w, h)),
                std_dev(&cell_areas(&out, w, h)),
            );
            assert!(
                d1 > 2.0 * d0 && d1 > 4.0,
                "{cells:?}: min distance {d0} -> {d1}"
            );
            assert!(s1 < 0.5 * s0, "{cells:?}: std of cell areas {s0} -> {s1}");
        }
    }

    #[test]
    fn points_leave_the_white_half() {
        let (w, h) = (80, 60);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| if i % w < w / 2 { 0.0 } else { 1.0 })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(40, w as f64, h as f64, 5);
        for cells in BOTH {
            let out = relax_all(&start, &density, opts_with(10, false, cells));
            let mut moved = 0;
            // Pixel cells weigh pixel centres; polygons the pixels' area.
            let edge = if cells == Cells::Pixels { 0.5 } else { 0.0 };
            for (a, b) in start.iter().zip(&out) {
                if a != b {
                    moved += 1;
                    assert!(b[0] > (w / 2) as f32 + edge, "{cells:?}: {a:?} -> {b:?}");
                }
            }
            assert!(moved >= 20, "{cells:?}: only {moved} points moved");
        }
    }

    #[test]
    fn points_gather_in_a_dark_disc() {
        let (w, h) = (80, 80);
        let inside = |x: f32, y: f32| (x - 40.0).hypot(y - 40.0) < 15.0;
        let weights: Vec<f32> = (0..w * h)
            .map(|i| {
                if inside((i % w) as f32 + 0.5, (i / w) as f32 + 0.5) {
                    1.0
                } else {
                    0.01
                }
            })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(100, w as f64, h as f64, 11);
        let count = |v: &[[f32; 2]]| v.iter().filter(|p| inside(p[0], p[1])).count();
        for cells in BOTH {
            let out = relax_all(&start, &density, opts_with(10, false, cells));
            assert!(
                count(&out) >= 2 * count(&start),
                "{cells:?}: {} -> {} points in the disc",
                count(&start),
                count(&out)
            );
        }
    }

    #[test]
    fn progress_false_stops_after_the_first_iteration() {
        let (w, h) = (50, 40);
        let weights = random_weights(w, h, 4);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(30, w as f64, h as f64, 8);
        let mut calls = Vec::new();
        let out = relax(&start, &density, opts(10, false), |done| {
            calls.push(done);
            false
        });
        assert_eq!(calls, [1]);
        assert_eq!(out, relax_all(&start, &density, opts(1, false)));
        let mut all = Vec::new();
        relax(&start, &density, opts(4, true), |done| {
            all.push(done);
            true
        });
        assert_eq!(all, [1, 2, 3, 4]);
    }

    #[test]
    fn check_reports_bad_densities() {
        let good = vec![0.5f32; 6];
        assert!(
            check(&Density {
                width: 3,
                height: 2,
                weights: &good
            })
            .is_ok()
        );
        assert!(
            check(&Density {
                width: 0,
                height: 2,
                weights: &[]
            })
            .is_err()
        );
        let err = check(&Density {
            width: 4,
            height: 2,
            weights: &good,
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains("6 weights") && !err.contains('\n'), "{err}");
        for bad in [f32::NAN, f32::INFINITY, -1.0] {
            let mut weights = good.clone();
            weights[4] = bad;
            let err = check(&Density {
                width: 3,
                height: 2,
                weights: &weights,
            })
            .unwrap_err()
            .to_string();
            assert!(err.contains("(1, 1)"), "{err}");
        }
    }

    #[test]
    fn bad_input_is_handled_without_panicking() {
        let points = uniform_points(10, 20.0, 10.0, 3);
        let weights = vec![1.0f32; 200];
        let short = Density {
            width: 20,
            height: 10,
            weights: &weights[..50],
        };
        let mut called = false;
        assert_eq!(
            relax(&points, &short, opts(3, false), |_| {
                called = true;
                true
            }),
            points
        );
        assert!(!called);
        // Bad weights count as zero.
        let mut bad = weights.clone();
        bad[..100]
            .iter_mut()
            .enumerate()
            .for_each(|(i, v)| *v = [f32::NAN, -2.0, f32::INFINITY][i % 3]);
        let zeroed: Vec<f32> = (0..200).map(|i| if i < 100 { 0.0 } else { 1.0 }).collect();
        let a = relax_all(
            &points,
            &Density {
                width: 20,
                height: 10,
                weights: &bad,
            },
            opts(2, false),
        );
        let b = relax_all(
            &points,
            &Density {
                width: 20,
                height: 10,
                weights: &zeroed,
            },
            opts(2, false),
        );
        assert_eq!(a, b);
        // No points, duplicate points.
        assert!(
            relax_all(
                &[],
                &Density {
                    width: 20,
                    height: 10,
                    weights: &weights
                },
                opts(2, true)
            )
            .is_empty()
        );
        let dup = relax_all(
            &[[3.0, 3.0], [3.0, 3.0]],
            &Density {
                width: 20,
                height: 10,
                weights: &weights,
            },
            opts(1, false),
        );
        assert_eq!(dup, [[10.0, 5.0], [3.0, 3.0]]);
    }
}
