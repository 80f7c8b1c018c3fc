//! One weighted Lloyd iteration over the Voronoi cells as polygons, whose
//! cost follows the points and the area's resolution instead of visiting
//! every pixel through a tree.
//!
//! - Each point's cell is found on its own (module `voronoi`): the
//!   domain's box `[0, W] × [0, H]` cut by the bisectors of its
//!   neighbours, taken from square buckets ring by ring until the next
//!   ring lies too far to cut the cell. No triangulation of all points
//!   is made, so the cells are found in parallel too (at 100K dots a
//!   drawing took 0.93× the time it took with one Delaunay triangulation
//!   per step, `delaunator`, a thread's work).
//! - The cell is cut into triangles from its point. A triangle whose
//!   longest side passes `edge` pixels is halved across that side until
//!   none does;
//!   each is then integrated by the rule exact for quadratics (the weight
//!   at its sides' midpoints, a third of its area each). The weight at a
//!   place is that of its block's middle pixel ([`Grid`]: the
//!   [`super::Weights`] asked once per block of `step`² pixels; negative
//!   or not finite counts as zero).
//! - The point moves to the weighted centroid, or `over` times the way
//!   there (over-relaxation), held within the domain; a cell of no weight
//!   leaves it where it is.
//!
//! Cells are independent, so they run in parallel and give the same
//! result bit for bit for any number of threads.

use rayon::prelude::*;

use super::Weights;
use super::voronoi::{Buckets, CellScratch};

/// A place in pixels, `f64`.
type P = [f64; 2];

/// One Lloyd iteration of `points` on `density`, integrating with
/// triangles of sides at most `edge` pixels.
pub(super) fn polygon_step(
    points: &[[f32; 2]],
    weights: &Grid,
    edge: f64,
    over: f64,
) -> Vec<[f32; 2]> {
    let (w, h) = (f64::from(weights.width), f64::from(weights.height));
    let buckets = Buckets::new(points, [w, h], BUCKET_POINTS);
    let field = Field {
        weights,
        edge2: edge * edge,
    };
    // Cells in the order of a Hilbert curve, so that neighbours, which
    // share buckets and pixels, are taken one after the other. In 8 px
    // cells, the curve a drawing's dots already follow (`job::plan`):
    // their order is kept.
    let mut order: Vec<(u64, usize)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (crate::stipple::spatial::pixel_key(p[0], p[1], 3), i))
        .collect();
    order.par_sort_unstable();
    let moved: Vec<[f32; 2]> = order
        .par_iter()
        .map(|&(_, i)| (i, points[i]))
        .map_init(CellScratch::default, |s, (i, p)| {
            // A point not finite, one outside the domain, or a duplicate
            // of another stays where it is.
            let outside =
                !(0.0..w).contains(&f64::from(p[0])) || !(0.0..h).contains(&f64::from(p[1]));
            if outside || !buckets.cell(i, [w, h], s) {
                return p;
            }
            let site = [f64::from(p[0]), f64::from(p[1])];
            let mut sums = [0.0f64; 3];
            let n = s.cell.len();
            for k in 0..n {
                let (a, b) = (s.cell[k], s.cell[(k + 1) % n]);
                field.integrate(site, a, b, site, &mut sums, 0);
            }
            // `over` times the way to the centroid.
            let q = [
                site[0] + over * sums[1] / sums[0],
                site[1] + over * sums[2] / sums[0],
            ];
            if !(sums[0] > 0.0 && q[0].is_finite() && q[1].is_finite()) {
                return p;
            }
            // Inside the domain's half-open box, as sampled points are.
            [
                (q[0] as f32).clamp(0.0, (w as f32).next_down()),
                (q[1] as f32).clamp(0.0, (h as f32).next_down()),
            ]
        })
        .collect();
    let mut out = vec![[0.0; 2]; points.len()];
    for (&(_, i), q) in order.iter().zip(moved) {
        out[i] = q;
    }
    out
}

/// Points per bucket of the cells' search, on average.
const BUCKET_POINTS: f64 = 1.0;

/// The weights, asked once at every `step`-th pixel of every `step`-th
/// row (the middle pixel of each `step`×`step` block): a place weighs
/// what its block's middle pixel does. One array the size of the domain
/// over `step²`, read many times by the cells.
pub(super) struct Grid {
    /// The domain's width in pixels.
    width: u32,
    /// The domain's height in pixels.
    height: u32,
    /// Pixels per block side.
    step: u32,
    /// Blocks per row.
    cols: usize,
    /// Block rows.
    rows: usize,
    /// Each block's weight (zero where it is negative or not finite).
    data: Vec<f64>,
}

impl Grid {
    /// `weights` asked at each block's middle pixel.
    pub(super) fn new<F: Fn(usize) -> f64 + Sync>(weights: &Weights<F>, step: u32) -> Self {
        let (width, height, step) = (weights.width, weights.height, step.max(1));
        let (cols, rows) = (
            width.div_ceil(step) as usize,
            height.div_ceil(step) as usize,
        );
        let middle = |k: usize, len: u32| (k as u32 * step + step / 2).min(len - 1) as usize;
        let data = (0..cols * rows)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (middle(i % cols, width), middle(i / cols, height));
                let v = (weights.weight)(y * width as usize + x);
                if v.is_finite() && v > 0.0 { v } else { 0.0 }
            })
            .collect();
        Self {
            width,
            height,
            step,
            cols,
            rows,
            data,
        }
    }
}

/// The weight field and the integration's finest side.
struct Field<'a> {
    weights: &'a Grid,
    /// The longest side a triangle is integrated whole with, squared.
    edge2: f64,
}

impl Field<'_> {
    /// The weight of the block `q` lies in (the nearest one, outside).
    fn at(&self, q: P) -> f64 {
        let g = &self.weights;
        let x = ((q[0].max(0.0) as u32) / g.step).min(g.cols as u32 - 1) as usize;
        let y = ((q[1].max(0.0) as u32) / g.step).min(g.rows as u32 - 1) as usize;
        g.data[y * g.cols + x]
    }

    /// Adds `[∫w, ∫w·dx, ∫w·dy]` over the triangle `a b c` to `sums`, `d`
    /// measured from `origin`. A triangle whose longest side passes the
    /// finest is cut in two across that side's midpoint (so a long thin
    /// triangle costs about its length over the side, not its square),
    /// at most [`MAX_DEPTH`] times.
    fn integrate(&self, a: P, b: P, c: P, origin: P, sums: &mut [f64; 3], depth: u32) {
        let twice = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
        if twice == 0.0 || !twice.is_finite() {
            return;
        }
        let (ab, bc, ca) = (dist2(a, b), dist2(b, c), dist2(c, a));
        let longest = ab.max(bc).max(ca);
        if longest > self.edge2 && depth < MAX_DEPTH {
            // Rotate so that the longest side is a–b, then halve it.
            let (a, b, c) = if longest == ab {
                (a, b, c)
            } else if longest == bc {
                (b, c, a)
            } else {
                (c, a, b)
            };
            let m = mid(a, b);
            self.integrate(a, m, c, origin, sums, depth + 1);
            self.integrate(m, b, c, origin, sums, depth + 1);
            return;
        }
        let area = twice / 6.0;
        for m in [mid(a, b), mid(b, c), mid(c, a)] {
            let wt = self.at(m) * area;
            sums[0] += wt;
            sums[1] += wt * (m[0] - origin[0]);
            sums[2] += wt * (m[1] - origin[1]);
        }
    }
}

/// How many times a triangle may be halved: 2⁴⁰ pieces bound no real
/// cell, only a degenerate one or a tiny finest side.
const MAX_DEPTH: u32 = 40;

fn mid(a: P, b: P) -> P {
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

fn dist2(a: P, b: P) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

#[cfg(test)]
mod tests {
    use super::super::test_util::{random_weights, uniform_points};
    use super::super::{Cells, Density, RelaxOptions, relax};

    fn step(points: &[[f32; 2]], density: &Density<'_>, cells: Cells) -> Vec<[f32; 2]> {
        let options = RelaxOptions {
            iterations: 1,
            periodic: false,
            cells,
            over: 1.0,
        };
        relax(points, density, options, |_| true)
    }

    /// Where many pixels make a cell, the polygons' centroids are the
    /// pixel cells' within a small part of a pixel.
    #[test]
    fn polygons_agree_with_pixel_cells() {
        let (w, h) = (400usize, 300usize);
        // A smooth field: a slope and a bump.
        let weights: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                0.2 + x / w as f32 + (-((x - 250.0).powi(2) + (y - 120.0).powi(2)) / 4000.0).exp()
            })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(300, w as f64, h as f64, 21);
        let pixels = step(&start, &density, Cells::Pixels);
        // Integrated at 1 px with every pixel's weight, and at 9 px with
        // the weight of each 3×3 block's middle pixel.
        let mut moved = 0.0f32;
        for (edge, near, at_worst) in [(1.0, 0.1, 0.4), (9.0, 0.2, 1.0)] {
            let polygons = step(&start, &density, Cells::Polygons { edge });
            let (mut worst, mut apart) = (0.0f32, 0.0f32);
            moved = 0.0;
            for ((a, b), s) in pixels.iter().zip(&polygons).zip(&start) {
                let d = (a[0] - b[0]).hypot(a[1] - b[1]);
                worst = worst.max(d);
                apart += d / start.len() as f32;
                moved += (a[0] - s[0]).hypot(a[1] - s[1]) / start.len() as f32;
            }
            // The pixels' lattice and the polygons differ at the cells' edges.
            assert!(
                worst < at_worst && apart < near,
                "edge {edge}: {apart} px apart on average, {worst} at worst (points moved {moved} px on average)"
            );
        }
        assert!(moved > 2.0, "the step moved the points only {moved} px");
    }

    /// The same points from one thread as from several, bit for bit.
    #[test]
    fn the_same_points_for_any_number_of_threads() {
        let (w, h) = (120usize, 90usize);
        let weights = random_weights(w, h, 5);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(500, w as f64, h as f64, 9);
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| step(&start, &density, Cells::Polygons { edge: 1.5 }))
        };
        let one = run(1);
        assert_ne!(one, start);
        assert_eq!(one, run(3));
    }

    /// Duplicated and non-finite points stay; every other point stays in
    /// the domain's half-open box.
    #[test]
    fn odd_points_stay_and_the_rest_stay_inside() {
        let (w, h) = (60usize, 40usize);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let mut start = uniform_points(30, w as f64, h as f64, 2);
        start.push(start[0]);
        start.push([f32::NAN, 3.0]);
        start.push([0.0, 0.0]);
        start.push([59.999, 39.999]);
        let out = step(&start, &density, Cells::Polygons { edge: 2.0 });
        // The later copy of a duplicate stays; the earlier takes the cell.
        assert!(
            out[30] == start[30] && out[0] != start[0],
            "{:?} {:?}",
            out[0],
            out[30]
        );
        assert!(out[31][0].is_nan() && out[31][1] == 3.0);
        for p in out.iter().filter(|p| p[0].is_finite()) {
            assert!(
                (0.0..60.0).contains(&p[0]) && (0.0..40.0).contains(&p[1]),
                "{p:?}"
            );
        }
        // The corner points move in, to their cells' centroids.
        assert!(out[32][0] > 0.0 && out[32][1] > 0.0, "{:?}", out[32]);
        assert!(out[33][0] < 59.999 && out[33][1] < 39.999, "{:?}", out[33]);
    }

    /// A row of points 2 px apart across a tall domain: each cell is a
    /// strip 2 px wide and 1000 px tall, integrated at 2 px. Halving the
    /// longest side keeps the pieces near the area over 2², where quartering
    /// made (1000 / 2)² of each fan triangle. The strips' centroids are
    /// their middles; a point outside the domain stays.
    #[test]
    fn thin_cells_and_points_outside() {
        let (w, h) = (1000usize, 1000usize);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start: Vec<[f32; 2]> = (0..500).map(|i| [1.0 + 2.0 * i as f32, 300.0]).collect();
        let t = std::time::Instant::now();
        let out = step(&start, &density, Cells::Polygons { edge: 2.0 });
        for (p, q) in start.iter().zip(&out) {
            assert!(
                (q[0] - p[0]).abs() < 0.01 && (q[1] - 500.0).abs() < 0.01,
                "{p:?} -> {q:?}"
            );
        }
        // A few hundred thousand pieces, not tens of millions.
        assert!(t.elapsed().as_secs_f64() < 5.0, "{:?}", t.elapsed());
        // A point outside the domain stays (its neighbour's cell is what
        // the outside point leaves it).
        let small = vec![1.0f32; 100];
        let density = Density {
            width: 10,
            height: 10,
            weights: &small,
        };
        let out = step(
            &[[5.0, 5.0], [-1.0, 5.0]],
            &density,
            Cells::Polygons { edge: 2.0 },
        );
        assert_eq!(out[1], [-1.0, 5.0]);
        assert!(
            (out[0][0] - 6.0).abs() < 0.01 && (out[0][1] - 5.0).abs() < 0.01,
            "{:?}",
            out[0]
        );
    }
}
