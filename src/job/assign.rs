//! The pen of each point of a colour drawing's union sample
//! ([`super::count::sample_union`]), by error diffusion over the point set:
//! the points are taken along a Hilbert curve through the domain; each
//! takes the pen whose share of the union's density there, plus what its
//! neighbours passed on, is largest, and passes what is left over (its
//! shares less one for the pen it took) on to the neighbours within
//! [`REACH`] sample radii not yet taken, by nearness. Each pen gets its
//! share of the points, spread evenly with its own density (a diffusion
//! along the curve alone, without the neighbours, was 1 ΔE00 worse).
//!
//! The count fit's chosen sample then has its pens swapped between
//! neighbours so that each pen's points repel as its own sample's would
//! ([`spread_pens`]): each pen's dots evener, the drawing's colour at
//! five photos' mean spacing 0.7 ΔE00 closer (docs/colour.md).

use rayon::prelude::*;

use crate::colour::pens::MAX_PENS;
use crate::sampler::Point;
use crate::stipple::spatial::{Buckets, hilbert};

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
    let Curve {
        along,
        points: curve,
        mut shares,
    } = Curve::new(points, (w, h), pens, share);
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
    let grid = Buckets::new(&curve, cols * rows, cell_of);
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
                // Row by row, the cells the disk of `reach` touches (a
                // hundredth of a cell more, for rounding): the same
                // neighbours in the same order as the whole square's.
                let margin = 0.01 * cell;
                for cy in y0..=y1 {
                    // The first and last rows hold whatever lies past them.
                    let lo = if cy == 0 {
                        f32::NEG_INFINITY
                    } else {
                        cy as f32 * cell
                    };
                    let hi = if cy + 1 == rows {
                        f32::INFINITY
                    } else {
                        (cy + 1) as f32 * cell
                    };
                    let dy = ((lo - p.y).max(p.y - hi) - margin).max(0.0);
                    if dy >= reach {
                        continue;
                    }
                    let half = (reach * reach - dy * dy).sqrt() + margin;
                    let rx0 = (((p.x - half).max(0.0) / cell) as usize).max(x0);
                    let rx1 = (((p.x + half).max(0.0) / cell) as usize).min(x1);
                    if rx0 > rx1 {
                        continue;
                    }
                    let row = cy * cols;
                    for &j in grid.span(row + rx0, row + rx1) {
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

/// The points along a Hilbert curve through the domain (near points near
/// in memory too), what [`pens`] and [`spread_pens`] walk.
struct Curve {
    /// Each point's place on the curve and its index in the caller's
    /// points, in the curve's order.
    along: Vec<(u64, u32)>,
    /// The points in the curve's order.
    points: Vec<Point>,
    /// Each point's pen shares (`pens` a point), in the curve's order: all
    /// NaN where no pen has dots.
    shares: Vec<f32>,
}

impl Curve {
    /// `points` over a `(w, h)` domain along the curve, with the shares
    /// `share(pixel, out)` writes (false: no pen there).
    fn new(
        points: &[Point],
        (w, h): (u32, u32),
        pens: usize,
        share: &(impl Fn(usize, &mut [f32]) -> bool + Sync),
    ) -> Self {
        let side = ((w.max(h) as f32 * CELLS_PER_PX) as u64)
            .next_power_of_two()
            .max(1);
        let order = side.trailing_zeros();
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
        let curve: Vec<Point> = along.iter().map(|&(_, i)| points[i as usize]).collect();
        let mut shares = vec![0f32; curve.len() * pens];
        shares
            .par_chunks_mut(pens)
            .zip(curve.par_iter())
            .for_each(|(out, p)| {
                let px = (p.x.max(0.0) as u32).min(w - 1) as usize;
                let py = (p.y.max(0.0) as u32).min(h - 1) as usize;
                if !share(py * w as usize + px, out) {
                    out.fill(f32::NAN);
                }
            });
        Self {
            along,
            points: curve,
            shares,
        }
    }
}

/// `points` (given pens by [`pens`], each with the union's sample radius)
/// with their pens swapped between neighbours so that each pen's points
/// spread apart ([`spread`]), along the same curve as [`pens`], cut into
/// [`PARTS`] runs of equal length spread apart in parallel: the same pens
/// for any thread count. A point with no pen, or whose radius is not a
/// positive number, is left out.
pub(crate) fn spread_pens(
    points: &mut [Point],
    (w, h): (u32, u32),
    pens: usize,
    share: &(impl Fn(usize, &mut [f32]) -> bool + Sync),
) {
    let n = points.len();
    let pens = pens.clamp(1, MAX_PENS);
    if pens < 2 || n < 2 {
        return;
    }
    let Curve {
        along,
        points: curve,
        shares,
    } = Curve::new(points, (w, h), pens, share);
    let kept = |p: &Point| p.radius.is_finite() && p.radius > 0.0 && (p.class as usize) < pens;
    let mut pen: Vec<u32> = curve
        .iter()
        .map(|p| if kept(p) { p.class } else { u32::MAX })
        .collect();
    let part = n.div_ceil(PARTS).max(1);
    pen.par_chunks_mut(part)
        .zip(shares.par_chunks(part * pens))
        .zip(curve.par_chunks(part))
        .for_each(|((pen, shares), curve)| spread(curve, pen, shares, pens));
    for (&(_, i), &c) in along.iter().zip(&pen) {
        if c != u32::MAX {
            points[i as usize].class = c;
        }
    }
}

/// The cell (column, row) of (`x`, `y`) in a grid of `size` cells `cell`
/// wide from `origin`; places off the grid read as its edge cells.
fn cell_at(origin: (f32, f32), cell: f32, size: (usize, usize), x: f32, y: f32) -> (usize, usize) {
    (
        (((x - origin.0).max(0.0) / cell) as usize).min(size.0 - 1),
        (((y - origin.1).max(0.0) / cell) as usize).min(size.1 - 1),
    )
}

/// The points of one run in a grid of cells `cell` wide.
struct Local {
    origin: (f32, f32),
    cell: f32,
    cols: usize,
    rows: usize,
    grid: Buckets,
}

impl Local {
    fn new(points: &[Point], cell: f32) -> Self {
        let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
        for p in points {
            (x0, y0, x1, y1) = (x0.min(p.x), y0.min(p.y), x1.max(p.x), y1.max(p.y));
        }
        // At most 4096 cells a side and about four a point.
        let span = ((x1 - x0).max(0.0), (y1 - y0).max(0.0));
        let cell = cell
            .max(1.0)
            .max(span.0.max(span.1) / 4095.0)
            .max((span.0 * span.1 / (4.0 * points.len().max(1) as f32)).sqrt());
        let along = |s: f32| ((s / cell).min(4095.0) as usize + 1).max(1);
        let (cols, rows) = (along(span.0), along(span.1));
        let origin = (x0, y0);
        let grid = Buckets::new(points, cols * rows, |p| {
            let c = cell_at(origin, cell, (cols, rows), p.x, p.y);
            c.1 * cols + c.0
        });
        Self {
            origin,
            cell,
            cols,
            rows,
            grid,
        }
    }

    fn cell_of(&self, x: f32, y: f32) -> (usize, usize) {
        cell_at(self.origin, self.cell, (self.cols, self.rows), x, y)
    }

    /// Calls `f(j)` for the points in the cells within `reach` of `p`.
    fn each(&self, p: &Point, reach: f32, mut f: impl FnMut(usize)) {
        let (x0, y0) = self.cell_of(p.x - reach, p.y - reach);
        let (x1, y1) = self.cell_of(p.x + reach, p.y + reach);
        for cy in y0..=y1 {
            let row = cy * self.cols;
            for &j in self.grid.span(row + x0, row + x1) {
                f(j as usize);
            }
        }
    }
}

/// Swaps pens between neighbouring points of one run (`curve`, the
/// points along the curve with the union's radii; `pen` theirs; `shares`
/// each point's pen shares, NaN where it has none) so that each pen's
/// points spread apart, as each pen's own sample would have them.
///
/// Two points of pen c at distance d repel by k(d²/σ²) = (1 − x/3)³
/// (x = d²/σ², zero past 3; a Gaussian's slope at 0 at a fraction of its
/// cost), σ² = 2 min over the two of (KAPPA r)² / max(s_c, FLOOR), r the
/// point's union radius and s_c its share of pen c: a pen's points lie
/// about r/√s_c apart, and the floor keeps a rare pen's reach a few
/// neighbours wide. Each point in turn takes the swap with a point of
/// another pen among its neighbours (those within both points' reach, the
/// widest kernel's: about four radii; walking the grid cells within 2.5
/// radii instead measured the same ΔE00 at σ and σ/2 on five photos, for
/// 20 % more of the spreading's time) that lowers the sum of the
/// repulsions most, a pen going only where it has ink; each pen's sum at
/// every point is kept up to date. At most [`SWEEPS`] passes, fewer when a
/// pass swaps nothing. Swaps keep each pen's count and, between points a
/// few radii apart, its share of every area.
fn spread(curve: &[Point], pen: &mut [u32], shares: &[f32], pens: usize) {
    let n = curve.len();
    if n < 2 {
        return;
    }
    // 1 / (CUT σ²) of pen c at point k, σ² = 2 (KAPPA r)² / max(s_c, FLOOR):
    // a pair's kernel takes the larger of its two (the narrower σ).
    let inv: Vec<f32> = (0..n * pens)
        .map(|i| {
            let s = shares[i];
            let s = if s.is_finite() { s.max(FLOOR) } else { 1.0 };
            let r = curve[i / pens].radius * KAPPA;
            s / (CUT * 2.0 * r * r)
        })
        .collect();
    let d2 = |k: usize, m: usize| {
        let (p, q) = (&curve[k], &curve[m]);
        (p.x - q.x).powi(2) + (p.y - q.y).powi(2)
    };
    let kernel = |k: usize, m: usize, d2: f32, c: usize| {
        let t = 1.0 - d2 * inv[k * pens + c].max(inv[m * pens + c]);
        if t <= 0.0 { 0.0 } else { t * t * t }
    };
    // The widest σ at point k over the pens, times √CUT: past it no
    // kernel of k reaches.
    let reach = |k: usize| (2.0 * CUT).sqrt() * curve[k].radius * KAPPA / FLOOR.sqrt();
    let mut radii: Vec<f32> = curve.iter().map(|p| p.radius).collect();
    let mid = radii.len() / 2;
    let median = *radii.select_nth_unstable_by(mid, f32::total_cmp).1;
    // Cells about three median radii wide (a rare pen's reach at the
    // median).
    let grid = Local::new(curve, 2.0 * median * KAPPA / FLOOR.sqrt());
    // Each point's neighbours within both points' reach (every pair whose
    // kernel is not zero, both ways), and each pen's sum at each point.
    let mut start = Vec::with_capacity(n + 1);
    let mut near: Vec<u32> = Vec::with_capacity(n * 16);
    let mut field = vec![0f32; n * pens];
    start.push(0u32);
    // Points left out (pen u32::MAX) have no neighbours and are no one's.
    let kept = |k: usize| (pen[k] as usize) < pens;
    for k in 0..n {
        let rk = reach(k);
        let mut acc = [0f32; MAX_PENS];
        grid.each(&curve[k], rk, |m| {
            if !kept(k) || !kept(m) {
                return;
            }
            let d = d2(k, m);
            let r = rk.min(reach(m));
            if m != k && d < r * r {
                near.push(m as u32);
                let c = pen[m] as usize;
                if c < pens {
                    acc[c] += kernel(k, m, d, c);
                }
            }
        });
        start.push(near.len() as u32);
        field[k * pens..(k + 1) * pens].copy_from_slice(&acc[..pens]);
    }
    let around = |k: usize| &near[start[k] as usize..start[k + 1] as usize];
    for _ in 0..SWEEPS {
        let mut swaps = 0;
        for k in 0..n {
            let a = pen[k] as usize;
            if a >= pens {
                continue;
            }
            let mut best = (-1e-4f32, usize::MAX);
            for &j in around(k) {
                let j = j as usize;
                let b = pen[j] as usize;
                // Each takes only a pen that has ink where it lies.
                if b >= pens
                    || b == a
                    || !(shares[k * pens + b] > 0.0 && shares[j * pens + a] > 0.0)
                {
                    continue;
                }
                let d = d2(k, j);
                let delta = (field[k * pens + b] - kernel(k, j, d, b))
                    + (field[j * pens + a] - kernel(j, k, d, a))
                    - field[k * pens + a]
                    - field[j * pens + b];
                if delta < best.0 {
                    best = (delta, j);
                }
            }
            let j = best.1;
            if j == usize::MAX {
                continue;
            }
            let b = pen[j] as usize;
            // k: a → b; j: b → a.
            for &m in around(k) {
                let (m, d) = (m as usize, d2(m as usize, k));
                field[m * pens + a] -= kernel(m, k, d, a);
                field[m * pens + b] += kernel(m, k, d, b);
            }
            for &m in around(j) {
                let (m, d) = (m as usize, d2(m as usize, j));
                field[m * pens + b] -= kernel(m, j, d, b);
                field[m * pens + a] += kernel(m, j, d, a);
            }
            pen[k] = b as u32;
            pen[j] = a as u32;
            swaps += 1;
        }
        if swaps == 0 {
            break;
        }
    }
}

/// The repulsion's reach, in σ²: (1 − x/3)³ is zero from x = 3.
const CUT: f32 = 3.0;
/// The repulsion's width in a pen's spacing (union radius over √share):
/// on coffee, ihc and chelsea at 20K dots, 0.5–0.8 measured, 0.7 the best
/// at σ and σ/2 together (docs/colour.md).
const KAPPA: f32 = 0.7;
/// The least share a pen's width is taken at.
const FLOOR: f32 = 0.2;
/// Passes over the points, at most: the first swaps about a third of
/// them, the third under 1%.
const SWEEPS: usize = 3;

/// Runs of the curve diffused apart (in parallel).
const PARTS: usize = 8;

/// The reach of a point's residual, in its sample radii (the union's
/// points lie about two radii apart).
const REACH: f32 = 2.5;

#[cfg(test)]
mod tests {
    use super::*;

    /// Three pens' shares on a domain `width` pixels wide: `left` on its
    /// left half, `right` on its right.
    fn halves(
        width: usize,
        left: [f32; 3],
        right: [f32; 3],
    ) -> impl Fn(usize, &mut [f32]) -> bool + Sync {
        move |i, out| {
            out.copy_from_slice(if i % width < width / 2 { &left } else { &right });
            true
        }
    }

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

    /// Pairs of points of the same pen nearer than `d`, over all pairs.
    fn close_pairs(points: &[Point], d: f32) -> usize {
        let mut n = 0;
        for (i, p) in points.iter().enumerate() {
            for q in &points[i + 1..] {
                if p.class == q.class && (p.x - q.x).hypot(p.y - q.y) < d {
                    n += 1;
                }
            }
        }
        n
    }

    /// Spreading swaps pens between neighbours: each pen keeps its count
    /// and its share of every region, its points lie farther apart (fewer
    /// pairs of the rare pen within its spacing), and the pens are the
    /// same for any thread count.
    #[test]
    fn spreading_keeps_each_pens_count_and_spaces_its_points() {
        // A jittered 64×64 lattice 4 px apart: union radius 2; shares of
        // 0.2, 0.3 and 0.5 on the left half, 0.6, 0.2 and 0.2 on the right.
        let points: Vec<Point> = (0..64 * 64u32)
            .map(|i| {
                let j = (i.wrapping_mul(2_654_435_761) >> 8) as f32 / (1u32 << 24) as f32;
                Point {
                    x: (i % 64) as f32 * 4.0 + 1.5 + j,
                    y: (i / 64) as f32 * 4.0 + 2.5 - j,
                    radius: 2.0,
                    class: 0,
                }
            })
            .collect();
        let share = halves(256, [0.2, 0.3, 0.5], [0.6, 0.2, 0.2]);
        let given = pens(&points, (256, 256), 3, &share);
        let run = |threads| {
            let mut p = given.clone();
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| spread_pens(&mut p, (256, 256), 3, &share));
            p
        };
        let spread = run(1);
        assert_eq!(spread, run(3), "the same pens for any thread count");
        let count = |p: &[Point], c: u32, left: bool| {
            p.iter()
                .filter(|p| p.class == c && (p.x < 128.0) == left)
                .count()
        };
        for c in 0..3 {
            let (before, after) = (
                count(&given, c, true) + count(&given, c, false),
                count(&spread, c, true) + count(&spread, c, false),
            );
            assert_eq!(before, after, "pen {c}'s count");
            for left in [true, false] {
                let (b, a) = (count(&given, c, left), count(&spread, c, left));
                assert!(
                    b.abs_diff(a) <= b / 20 + 2,
                    "pen {c}, left {left}: {b} → {a}"
                );
            }
        }
        assert!(spread.iter().zip(&given).any(|(a, b)| a.class != b.class));
        assert!(
            spread
                .iter()
                .zip(&given)
                .all(|(a, b)| (a.x, a.y) == (b.x, b.y))
        );
        // Pen 0 on the left: 0.2 of the points, about 4/√0.2 ≈ 9 px apart.
        let rare = |p: &[Point]| {
            let left: Vec<Point> = p.iter().filter(|p| p.x < 120.0).copied().collect();
            close_pairs(
                &left
                    .into_iter()
                    .filter(|p| p.class == 0)
                    .collect::<Vec<_>>(),
                7.0,
            )
        };
        let (before, after) = (rare(&given), rare(&spread));
        println!("pairs of the rare pen within 7 px: {before} before, {after} after");
        assert!(
            after * 2 < before,
            "pairs of the rare pen within 7 px: {before} before, {after} after"
        );
    }

    /// A pen is never swapped to where it has no ink, and a point whose
    /// radius is not a positive number keeps its pen (and breaks nothing).
    #[test]
    fn spreading_keeps_pens_where_they_have_ink() {
        let mut points: Vec<Point> = (0..48 * 48u32)
            .map(|i| Point {
                x: (i % 48) as f32 * 4.0 + 2.0 + ((i * 7) % 5) as f32 * 0.3,
                y: (i / 48) as f32 * 4.0 + 2.0,
                radius: 2.0,
                class: 0,
            })
            .collect();
        points[100].radius = f32::NAN;
        points[101].radius = -1.0;
        // Pen 2 has no ink right of x = 96; pen 0 none left of it.
        let share = halves(192, [0.0, 0.5, 0.5], [0.5, 0.5, 0.0]);
        let given = pens(&points, (192, 192), 3, &share);
        let mut spread = given.clone();
        spread_pens(&mut spread, (192, 192), 3, &share);
        assert!(spread.iter().zip(&given).any(|(a, b)| a.class != b.class));
        for (a, b) in spread.iter().zip(&given) {
            let left = (a.x as usize) < 96;
            assert!(
                if left { a.class != 0 } else { a.class != 2 },
                "pen {} at x = {} (was pen {})",
                a.class,
                a.x,
                b.class
            );
            if a.radius.is_nan() || a.radius <= 0.0 {
                assert_eq!(
                    a.class, b.class,
                    "a point with radius {} kept its pen",
                    a.radius
                );
            }
        }
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
