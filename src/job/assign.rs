//! The pen of each point of a colour drawing's union sample
//! ([`super::count::sample_union`]), by error diffusion over the point set:
//! the points are taken along a Hilbert curve through the domain; each
//! takes the pen whose share of the union's density there, plus what its
//! neighbours passed on, is largest, and passes what is left over (its
//! shares less one for the pen it took) on to the neighbours within
//! [`REACH`] sample radii not yet taken, by nearness. Each pen gets its
//! share of the points, spread evenly with its own density (a diffusion
//! along the curve alone, without the neighbours, was 1 ΔE00 worse).

use rayon::prelude::*;

use crate::colour::pens::MAX_PENS;
use crate::sampler::Point;
use crate::stipple::tsp::hilbert;

/// Hilbert-curve cells per pixel side (points lie at least 1 px apart).
const CELLS_PER_PX: f32 = 4.0;

/// `points` (over a `domain` of pixels) given pens `0..pens` by the shares
/// `share(pixel, out)` writes (false where no pen has dots: the point is
/// dropped), in their own order.
pub(crate) fn pens(
    points: &[Point],
    (w, h): (u32, u32),
    pens: usize,
    share: &(impl Fn(usize, &mut [f32]) -> bool + Sync),
) -> Vec<Point> {
    let n = points.len();
    let pens = pens.clamp(1, MAX_PENS);
    let side = ((w.max(h) as f32 * CELLS_PER_PX) as u64)
        .next_power_of_two()
        .max(1);
    let order = side.trailing_zeros();
    // Each point's place on the curve, and the points along it.
    let mut along: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let cx = ((p.x.max(0.0) * CELLS_PER_PX) as u64).min(side - 1);
            let cy = ((p.y.max(0.0) * CELLS_PER_PX) as u64).min(side - 1);
            (hilbert(cx, cy, order), i as u32)
        })
        .collect();
    along.par_sort_unstable();
    // The points along the curve: near points near in memory too.
    let curve: Vec<Point> = along.iter().map(|&(_, i)| points[i as usize]).collect();
    // The shares, point by point along the curve (NaN first: no pen there).
    let mut shares = vec![0f32; n * pens];
    shares
        .par_chunks_mut(pens)
        .zip(curve.par_iter())
        .for_each(|(out, p)| {
            let px = (p.x.max(0.0) as u32).min(w - 1) as usize;
            let py = (p.y.max(0.0) as u32).min(h - 1) as usize;
            if !share(py * w as usize + px, out) {
                out[0] = f32::NAN;
            }
        });
    // A grid of the points (their places along the curve) for their
    // neighbours.
    let cell = curve
        .iter()
        .map(|p| p.radius)
        .fold(f32::INFINITY, f32::min)
        .max(1.0)
        * 2.0;
    let cols = ((w as f32 / cell) as usize + 1).max(1);
    let rows = ((h as f32 / cell) as usize + 1).max(1);
    let cell_of = |p: &Point| {
        let cx = ((p.x.max(0.0) / cell) as usize).min(cols - 1);
        let cy = ((p.y.max(0.0) / cell) as usize).min(rows - 1);
        cy * cols + cx
    };
    let mut start = vec![0u32; cols * rows + 1];
    for p in &curve {
        start[cell_of(p) + 1] += 1;
    }
    for c in 0..cols * rows {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut items = vec![0u32; n];
    for (k, p) in curve.iter().enumerate() {
        let c = cell_of(p);
        items[fill[c] as usize] = k as u32;
        fill[c] += 1;
    }
    // The curve in PARTS runs of equal length (near points are near on
    // the curve, so most neighbours share a run), diffused in parallel,
    // each within its own run: the same pens for any thread count.
    let part = n.div_ceil(PARTS).max(1);
    let mut pen = vec![u32::MAX; n];
    shares
        .par_chunks_mut(part * pens)
        .zip(pen.par_chunks_mut(part))
        .enumerate()
        .for_each(|(run, (shares, pen))| {
            let first = run * part;
            let mut near: Vec<(usize, f32)> = Vec::new();
            for (k, p) in curve[first..first + pen.len()].iter().enumerate() {
                let e = &shares[k * pens..(k + 1) * pens];
                if e[0].is_nan() {
                    continue;
                }
                let mut best = 0;
                for c in 1..pens {
                    if e[c] > e[best] {
                        best = c;
                    }
                }
                pen[k] = best as u32;
                let mut residual = [0f32; MAX_PENS];
                residual[..pens].copy_from_slice(e);
                residual[best] -= 1.0;
                // The residual to the neighbours not yet taken in this run,
                // by nearness.
                let reach = REACH * p.radius;
                let (x0, x1) = (
                    ((p.x - reach).max(0.0) / cell) as usize,
                    (((p.x + reach).max(0.0) / cell) as usize).min(cols - 1),
                );
                let (y0, y1) = (
                    ((p.y - reach).max(0.0) / cell) as usize,
                    (((p.y + reach).max(0.0) / cell) as usize).min(rows - 1),
                );
                near.clear();
                let mut total = 0f32;
                let inv_reach2 = 1.0 / (reach * reach);
                for cy in y0..=y1 {
                    let row = cy * cols;
                    let (a, b) = (start[row + x0] as usize, start[row + x1 + 1] as usize);
                    for &j in &items[a..b] {
                        let j = j as usize;
                        if j <= first + k || j >= first + pen.len() {
                            continue;
                        }
                        let q = &curve[j];
                        let d2 = (q.x - p.x).powi(2) + (q.y - p.y).powi(2);
                        let t = 1.0 - d2 * inv_reach2;
                        if t <= 0.0 {
                            continue;
                        }
                        total += t * t;
                        near.push((j - first, t * t));
                    }
                }
                if total <= 0.0 {
                    continue;
                }
                for &(j, wgt) in &near {
                    let to = &mut shares[j * pens..(j + 1) * pens];
                    if to[0].is_nan() {
                        continue;
                    }
                    for c in 0..pens {
                        to[c] += residual[c] * wgt / total;
                    }
                }
            }
        });
    // Back to the points' own order.
    let mut given = vec![u32::MAX; n];
    for (&(_, i), &c) in along.iter().zip(&pen) {
        given[i as usize] = c;
    }
    let pen = given;
    points
        .iter()
        .zip(&pen)
        .filter(|(_, c)| **c != u32::MAX)
        .map(|(p, &c)| Point { class: c, ..*p })
        .collect()
}

/// Runs of the curve diffused apart (in parallel).
const PARTS: usize = 8;

/// The reach of a point's residual, in its sample radii (the union's
/// points lie about two radii apart).
const REACH: f32 = 2.5;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curve_visits_every_cell_once_moving_one_cell_at_a_time() {
        let order = 4;
        let n = 1u64 << order;
        let mut at = vec![(0u64, 0u64); (n * n) as usize];
        for y in 0..n {
            for x in 0..n {
                at[hilbert(x, y, order) as usize] = (x, y);
            }
        }
        let mut seen = std::collections::HashSet::new();
        for w in at.windows(2) {
            let (a, b) = (w[0], w[1]);
            assert_eq!(a.0.abs_diff(b.0) + a.1.abs_diff(b.1), 1, "{a:?} → {b:?}");
            seen.insert(a);
        }
        seen.insert(at[at.len() - 1]);
        assert_eq!(seen.len(), (n * n) as usize);
    }

    #[test]
    fn each_pen_gets_its_share_spread_and_inkless_points_go() {
        // A 64×64 grid of points; the left half's shares 1/4, 3/4; the
        // right half has no ink.
        let points: Vec<Point> = (0..64 * 64)
            .map(|i| Point {
                x: (i % 64) as f32 * 4.0 + 2.0,
                y: (i / 64) as f32 * 4.0 + 2.0,
                radius: 2.0,
                class: 0,
            })
            .collect();
        let share = |i: usize, out: &mut [f32]| {
            if i % 256 >= 128 {
                return false;
            }
            out[0] = 0.25;
            out[1] = 0.75;
            true
        };
        let given = pens(&points, (256, 256), 2, &share);
        assert_eq!(given.len(), 32 * 64);
        let first = given.iter().filter(|p| p.class == 0).count();
        assert!(
            (first as f64 / given.len() as f64 - 0.25).abs() < 0.01,
            "{first}"
        );
        // Spread: every 16×16 px block of the left half holds its share.
        for by in 0..16 {
            for bx in 0..8 {
                let in_block = |p: &&Point| (p.x / 16.0) as u32 == bx && (p.y / 16.0) as u32 == by;
                let n0 = given
                    .iter()
                    .filter(in_block)
                    .filter(|p| p.class == 0)
                    .count();
                assert!((2..=6).contains(&n0), "block {bx},{by}: {n0} of 16");
            }
        }
    }
}
