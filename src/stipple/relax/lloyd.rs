//! One weighted Lloyd iteration: rows of 16×16 tiles in parallel; each tile
//! gets its candidate owners from the k-d tree, prunes them quarter by
//! quarter down to 4×4 blocks assigned pixel by pixel, and takes the moments
//! of a block with a single owner from the pyramid. The per-point sums are
//! added in a fixed order, and each point moves to its centroid.

use rayon::prelude::*;

use super::kdtree::{SiteTree, site_position};
use super::pyramid::{Field, LEAF_LEVEL, TOP_LEVEL, Tile};
use super::{dist2, wrap};

/// A point that may own pixels of a tile: an image position, its index in the
/// tile's candidate list and its index in the caller's points.
#[derive(Clone, Copy, Debug)]
struct Cand {
    /// Position (an image of the point in periodic mode).
    p: [f64; 2],
    /// Index into [`Scratch::sites`] and [`Scratch::acc`].
    k: usize,
    /// Index into the caller's points: the lowest wins ties.
    id: usize,
}

/// Working memory for one row of tiles.
#[derive(Default)]
struct Scratch {
    /// The current tile's candidates: the caller's index and image position.
    sites: Vec<(usize, [f64; 2])>,
    /// Per candidate: `[Σw, Σw·x, Σw·y]` of the pixels it owns in the tile.
    acc: Vec<[f64; 3]>,
    /// The candidate lists of the tiles being subdivided, nested as a stack.
    stack: Vec<Cand>,
    /// The row's partial sums: the caller's index, `[Σw, Σw·dx, Σw·dy]`.
    out: Vec<(usize, [f64; 3])>,
}

/// Rows of top tiles done in parallel between two calls of
/// [`lloyd_step`]'s `stop`.
const ROWS_AT_ONCE: usize = 16;

/// One Lloyd iteration; `None` when `stop`, asked between groups of tile
/// rows, says to end it.
pub(super) fn lloyd_step(
    points: &[[f32; 2]],
    field: &Field<'_>,
    periodic: bool,
    over: f64,
    stop: &mut dyn FnMut() -> bool,
) -> Option<Vec<[f32; 2]>> {
    let dom = [field.width as f64, field.height as f64];
    let tree = SiteTree::new(points, dom, periodic);
    let tile_rows = field.height.div_ceil(1 << TOP_LEVEL);
    let mut sums = vec![[0.0f64; 3]; points.len()];
    for first in (0..tile_rows).step_by(ROWS_AT_ONCE) {
        if stop() {
            return None;
        }
        let rows: Vec<Vec<(usize, [f64; 3])>> = (first..tile_rows.min(first + ROWS_AT_ONCE))
            .into_par_iter()
            .map(|ty| tile_row(field, &tree, ty << TOP_LEVEL))
            .collect();
        // In row order, as one pass over all rows would add them.
        for &(id, m) in rows.iter().flatten() {
            (0..3).for_each(|k| sums[id][k] += m[k]);
        }
    }
    Some(
        points
            .iter()
            .zip(&sums)
            .map(|(p, s)| centroid(*p, s, dom, periodic, over))
            .collect(),
    )
}

/// The new position of point `p` from its sums `[Σw, Σw·dx, Σw·dy]`:
/// `over` times the way to the centroid (1: the centroid itself), within
/// the domain.
fn centroid(p: [f32; 2], sums: &[f64; 3], dom: [f64; 2], periodic: bool, over: f64) -> [f32; 2] {
    if sums[0] <= 0.0 {
        return p;
    }
    let base = site_position(p, dom, periodic);
    let q = [
        base[0] + over * sums[1] / sums[0],
        base[1] + over * sums[2] / sums[0],
    ];
    match periodic {
        // Rounding to f32 may land on the far edge, which is the near one.
        true => [0, 1].map(|a| {
            Some(wrap(q[a], dom[a]) as f32)
                .filter(|&v| v < dom[a] as f32)
                .unwrap_or(0.0)
        }),
        // Past the centroid may be past the edge: held inside the
        // domain's half-open box, as sampled points are.
        false => [0, 1].map(|a| (q[a] as f32).clamp(0.0, (dom[a] as f32).next_down())),
    }
}

/// The partial sums of one row of top tiles, starting at pixel row `y0`.
fn tile_row(field: &Field<'_>, tree: &SiteTree, y0: usize) -> Vec<(usize, [f64; 3])> {
    let mut scratch = Scratch::default();
    for x0 in (0..field.width).step_by(1 << TOP_LEVEL) {
        if let Some(tile) = Tile::new(TOP_LEVEL, x0, y0, field) {
            top_tile(field, tree, tile, &mut scratch);
        }
    }
    scratch.out
}

/// Gathers a top tile's candidates, assigns its pixels and appends its sums.
fn top_tile(field: &Field<'_>, tree: &SiteTree, tile: Tile, s: &mut Scratch) {
    if field.moments(&tile)[0] <= 0.0 {
        return;
    }
    let Some(s1) = tree.nearest(tile.centre()) else {
        return;
    };
    s.sites.clear();
    s.stack.clear();
    tree.owners(&tile.hull(), s1, &mut |id, p| {
        s.stack.push(Cand {
            p,
            k: s.sites.len(),
            id,
        });
        s.sites.push((id, p));
    });
    s.acc.clear();
    s.acc.resize(s.sites.len(), [0.0; 3]);
    subdivide(field, tile, s, 0, s.stack.len());
    for (a, &(id, p)) in s.acc.iter().zip(&s.sites) {
        if a[0] > 0.0 {
            s.out
                .push((id, [a[0], a[1] - p[0] * a[0], a[2] - p[1] * a[0]]));
        }
    }
}

/// Assigns the pixels of `tile` among the candidates `s.stack[lo..hi]`
/// (a superset of the points that own some of them).
fn subdivide(field: &Field<'_>, tile: Tile, s: &mut Scratch, lo: usize, hi: usize) {
    let moments = field.moments(&tile);
    if moments[0] <= 0.0 {
        return;
    }
    let (lo, hi) = prune(&mut s.stack, lo, hi, &tile);
    if hi - lo == 1 {
        let a = &mut s.acc[s.stack[lo].k];
        (0..3).for_each(|k| a[k] += moments[k]);
    } else if tile.level <= LEAF_LEVEL {
        assign_pixels(field, &tile, &s.stack[lo..hi], &mut s.acc);
    } else {
        for child in tile.children(field) {
            subdivide(field, child, s, lo, hi);
        }
    }
    s.stack.truncate(lo);
}

/// Pushes onto the stack the candidates of `stack[lo..hi]` that may own a
/// pixel of `tile`, nearest to its centre first, and returns their range.
fn prune(stack: &mut Vec<Cand>, lo: usize, hi: usize, tile: &Tile) -> (usize, usize) {
    let centre = tile.centre();
    let (mut best, mut best_d) = (lo, f64::INFINITY);
    for (i, c) in stack[lo..hi].iter().enumerate() {
        let d = dist2(c.p, centre);
        if d < best_d {
            (best, best_d) = (lo + i, d);
        }
    }
    let (first, hull, new_lo) = (stack[best], tile.hull(), stack.len());
    stack.push(first);
    for i in lo..hi {
        let c = stack[i];
        if i != best && may_own(&c, &first, &hull) {
            stack.push(c);
        }
    }
    (new_lo, stack.len())
}

/// Whether `c` is at least as near as `first` to some point of the box `hull`
/// (`[xmin, ymin, xmax, ymax]`). The difference of squared distances is linear
/// over the box, so testing the corner farthest towards `c` is enough. Of two
/// points at the same place, the one with the higher index owns nothing.
fn may_own(c: &Cand, first: &Cand, hull: &[f64; 4]) -> bool {
    let (p, s1) = (c.p, first.p);
    if p == s1 {
        return c.id < first.id;
    }
    let x = if p[0] > s1[0] { hull[2] } else { hull[0] };
    let y = if p[1] > s1[1] { hull[3] } else { hull[1] };
    dist2(p, [x, y]) <= dist2(s1, [x, y])
}

/// Assigns each weighted pixel of `tile` to its nearest candidate.
fn assign_pixels(field: &Field<'_>, tile: &Tile, cands: &[Cand], acc: &mut [[f64; 3]]) {
    for y in tile.y0..tile.y1 {
        let py = y as f64 + 0.5;
        let row = &field.weights[y * field.width + tile.x0..y * field.width + tile.x1];
        for (x, &v) in (tile.x0..).zip(row) {
            if v > 0.0 {
                let q = [x as f64 + 0.5, py];
                let (v, a) = (f64::from(v), &mut acc[nearest_cand(cands, q)]);
                a[0] += v;
                a[1] += v * q[0];
                a[2] += v * q[1];
            }
        }
    }
}

/// The list index (`k`) of the candidate nearest to `q`. On ties, the one
/// with the lowest index in the caller's points; between two images of a
/// point, the one to the left (then above), so that offsets from a point to
/// its pixels lie in `(-W/2, W/2] × (-H/2, H/2]`.
fn nearest_cand(cands: &[Cand], q: [f64; 2]) -> usize {
    let mut best = (f64::INFINITY, usize::MAX, [0.0; 2], 0);
    for c in cands {
        let d = dist2(c.p, q);
        if d < best.0 || d == best.0 && (c.id < best.1 || c.id == best.1 && c.p < best.2) {
            best = (d, c.id, c.p, c.k);
        }
    }
    best.3
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stipple::relax::test_util::{
        assert_close, opts, random_weights, relax_all, uniform_points,
    };
    use crate::stipple::relax::{Density, random_start};

    /// One Lloyd step by brute force: every pixel against every point.
    fn reference_step(
        points: &[[f32; 2]],
        w: usize,
        h: usize,
        weights: &[f32],
        periodic: bool,
    ) -> Vec<[f32; 2]> {
        let dom = [w as f64, h as f64];
        let sites: Vec<[f64; 2]> = points
            .iter()
            .map(|p| site_position(*p, dom, periodic))
            .collect();
        // Offsets in (-len/2, len/2].
        let offset = |d: f64, len: f64| {
            if periodic {
                d - len * (d / len - 0.5).ceil()
            } else {
                d
            }
        };
        let mut sums = vec![[0.0f64; 3]; points.len()];
        for (i, &v) in weights.iter().enumerate().filter(|(_, v)| **v > 0.0) {
            let q = [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
            let (mut best, mut best_d, mut best_off) = (usize::MAX, f64::INFINITY, [0.0; 2]);
            for (k, s) in sites.iter().enumerate() {
                let off = [offset(q[0] - s[0], dom[0]), offset(q[1] - s[1], dom[1])];
                let d = off[0] * off[0] + off[1] * off[1];
                if d < best_d {
                    (best, best_d, best_off) = (k, d, off);
                }
            }
            if best != usize::MAX {
                let v = f64::from(v);
                sums[best] = [
                    sums[best][0] + v,
                    sums[best][1] + v * best_off[0],
                    sums[best][2] + v * best_off[1],
                ];
            }
        }
        points
            .iter()
            .zip(&sums)
            .map(|(p, s)| centroid(*p, s, dom, periodic, 1.0))
            .collect()
    }

    #[test]
    fn one_step_matches_brute_force() {
        let sizes = [(1, 1), (5, 3), (37, 29), (64, 64), (101, 67), (17, 130)];
        for (case, &(w, h)) in sizes.iter().enumerate() {
            let weights = random_weights(w, h, case as u64);
            let density = Density {
                width: w as u32,
                height: h as u32,
                weights: &weights,
            };
            for n in [1, 2, 3, 10, 100, 500] {
                for periodic in [false, true] {
                    let seed = 100 * case as u64 + n as u64;
                    let mut points = uniform_points(n, w as f64, h as f64, seed);
                    for step in 0..3 {
                        let fast = relax_all(&points, &density, opts(1, periodic));
                        let slow = reference_step(&points, w, h, &weights, periodic);
                        let what = format!("{w}×{h}, {n} points, periodic {periodic}, step {step}");
                        assert_close(&fast, &slow, 1e-3, &what);
                        points = fast;
                    }
                }
            }
        }
    }

    #[test]
    fn varying_spacing_matches_brute_force() {
        let (w, h) = (170, 120);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 - 50.0, (i / w) as f32 - 40.0);
                if x > 100.0 {
                    0.0
                } else {
                    (-(x * x + y * y) / 2000.0).exp() * 64.0 + 1.0
                }
            })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        for periodic in [false, true] {
            let mut points = random_start(700, &density, 2);
            for step in 0..2 {
                let fast = relax_all(&points, &density, opts(1, periodic));
                let slow = reference_step(&points, w, h, &weights, periodic);
                assert_close(
                    &fast,
                    &slow,
                    1e-3,
                    &format!("periodic {periodic}, step {step}"),
                );
                points = fast;
            }
        }
    }

    #[test]
    fn clustered_and_stray_points_match_brute_force() {
        let (w, h) = (150, 90);
        let weights = random_weights(w, h, 9);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        // A tight cluster in a corner, a sparse spread, points outside, a NaN.
        let mut points: Vec<[f32; 2]> = uniform_points(300, 8.0, 5.0, 1)
            .iter()
            .map(|p| [p[0] + 140.0, p[1] + 2.0])
            .collect();
        points.extend(uniform_points(20, w as f64, h as f64, 2));
        points.extend([[-3.0, 40.0], [160.0, -7.5], [f32::NAN, 3.0], [75.0, 200.0]]);
        for periodic in [false, true] {
            let fast = relax_all(&points, &density, opts(1, periodic));
            let slow = reference_step(&points, w, h, &weights, periodic);
            assert_close(&fast, &slow, 1e-3, &format!("periodic {periodic}"));
        }
    }

    #[test]
    fn ties_and_duplicates_match_brute_force() {
        let (w, h) = (90, 70);
        let weights = random_weights(w, h, 3);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        for n in [2, 5, 40, 400] {
            // Points on the half-pixel lattice: many pixels are equally near to two or more.
            let mut points: Vec<[f32; 2]> = uniform_points(n, w as f64, h as f64, n as u64)
                .iter()
                .map(|p| p.map(|v| (v * 2.0).floor() / 2.0))
                .collect();
            points.extend_from_slice(&points.clone()[..n / 2]);
            for periodic in [false, true] {
                let fast = relax_all(&points, &density, opts(1, periodic));
                let slow = reference_step(&points, w, h, &weights, periodic);
                assert_close(
                    &fast,
                    &slow,
                    1e-4,
                    &format!("{n} points, periodic {periodic}"),
                );
            }
        }
    }

    #[test]
    fn same_result_for_any_thread_count() {
        let (w, h) = (300, 200);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| ((i % w) as f32 / 30.0).sin().abs() + (i / w) as f32 / 200.0)
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = random_start(3000, &density, 1);
        for periodic in [false, true] {
            let run = |threads| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("thread pool");
                pool.install(|| relax_all(&start, &density, opts(3, periodic)))
            };
            let bits = |v: Vec<[f32; 2]>| {
                v.iter()
                    .flat_map(|p| p.map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            let one = bits(run(1));
            assert_eq!(one, bits(run(2)));
            assert_eq!(one, bits(run(3)));
        }
    }

    #[test]
    fn periodic_centroid_wraps_across_the_seam() {
        let (w, h) = (20, 10);
        let column = |c0: f32, c19: f32| -> Vec<f32> {
            (0..w * h)
                .map(|i| match i % w {
                    0 => c0,
                    19 => c19,
                    _ => 0.0,
                })
                .collect()
        };
        let weights = column(3.0, 1.0);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let one = |density: &Density<'_>, periodic| {
            relax_all(&[[1.0, 5.0]], density, opts(1, periodic))[0]
        };
        // Offsets -0.5 (column 0, weight 3) and -1.5 (column 19 seen across the seam).
        assert_close(&[one(&density, true)], &[[0.25, 5.0]], 1e-6, "periodic");
        assert_close(&[one(&density, false)], &[[5.25, 5.0]], 1e-6, "flat");
        let weights = column(1.0, 3.0);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        // 1 - 1.25 = -0.25 wraps to 19.75.
        assert_close(
            &[one(&density, true)],
            &[[19.75, 5.0]],
            1e-5,
            "wrapped back",
        );
        // Two points across the seam split the columns between them.
        let two = relax_all(&[[19.0, 5.0], [1.0, 5.0]], &density, opts(1, true));
        assert_close(&two, &[[19.5, 5.0], [0.5, 5.0]], 1e-6, "two points");
    }
}
