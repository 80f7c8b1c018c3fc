//! Each point's Voronoi cell found on its own, clipped to the domain: the
//! domain's box cut by the bisector of every neighbour that can reach the
//! cell, the neighbours taken from square buckets ring by ring until the
//! next ring is too far to matter. Cells are independent, so they are
//! made in parallel, each the same whatever the thread count.

/// A place in pixels, `f64`.
type P = [f64; 2];

/// The points in square buckets (points outside the domain in the border
/// buckets nearest to them: no nearer than those buckets, which is all the
/// search needs).
pub(super) struct Buckets {
    /// A bucket's side in pixels.
    side: f64,
    cols: usize,
    rows: usize,
    /// Where each bucket's points begin in `items` (and where the last ends).
    start: Vec<u32>,
    /// The buckets' point counts summed over rectangles from the top left,
    /// (cols + 1) × (rows + 1): a run of empty buckets is passed over at once.
    summed: Vec<u32>,
    /// The points' indices, bucket by bucket, in increasing order within one.
    items: Vec<u32>,
    /// Their places, in the same order (read together as the buckets are).
    at: Vec<P>,
    /// Every point's place, by index (non-finite points are in no bucket).
    places: Vec<P>,
}

impl Buckets {
    /// `points` on a `size` domain, in buckets of about `per` points
    /// where most points are: the buckets are sized for the density the
    /// median point has (a picture's dots may crowd a small part of it),
    /// at least a quarter point each on average over the domain, and at
    /// most 2^15 a side.
    pub(super) fn new(points: &[[f32; 2]], size: [f64; 2], per: f64) -> Self {
        let finite: Vec<P> = points
            .iter()
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .map(|p| p.map(f64::from))
            .collect();
        let n = finite.len().max(1) as f64;
        let area = size[0] * size[1];
        // The density around the median point, from a coarse grid of about
        // 16 points a cell.
        let coarse = (area * 16.0 / n)
            .sqrt()
            .max(size[0] / 4096.0)
            .max(size[1] / 4096.0)
            .max(1.0);
        let (ccols, crows) = (
            ((size[0] / coarse).ceil() as usize).max(1),
            ((size[1] / coarse).ceil() as usize).max(1),
        );
        let coarse_of = |q: &P| {
            let x = ((q[0] / coarse).max(0.0) as usize).min(ccols - 1);
            let y = ((q[1] / coarse).max(0.0) as usize).min(crows - 1);
            y * ccols + x
        };
        let mut counts = vec![0u32; ccols * crows];
        for q in &finite {
            counts[coarse_of(q)] += 1;
        }
        let mut around: Vec<u32> = finite.iter().map(|q| counts[coarse_of(q)]).collect();
        let typical = if around.is_empty() {
            1.0
        } else {
            let mid = around.len() / 2;
            f64::from(*around.select_nth_unstable(mid).1)
        };
        let side = (coarse * coarse * per / typical.max(1.0))
            .sqrt()
            .max((area / (4.0 * n)).sqrt())
            .max(size[0] / 32768.0)
            .max(size[1] / 32768.0)
            .max(1.0);
        let cols = ((size[0] / side).ceil() as usize).max(1);
        let rows = ((size[1] / side).ceil() as usize).max(1);
        let places: Vec<P> = points.iter().map(|p| p.map(f64::from)).collect();
        let bucket = |q: P| -> Option<usize> {
            if !(q[0].is_finite() && q[1].is_finite()) {
                return None;
            }
            let x = ((q[0] / side).max(0.0) as usize).min(cols - 1);
            let y = ((q[1] / side).max(0.0) as usize).min(rows - 1);
            Some(y * cols + x)
        };
        let mut start = vec![0u32; cols * rows + 1];
        for q in &places {
            if let Some(b) = bucket(*q) {
                start[b + 1] += 1;
            }
        }
        for b in 0..cols * rows {
            start[b + 1] += start[b];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[cols * rows] as usize];
        let mut at = vec![[0.0; 2]; items.len()];
        for (i, q) in places.iter().enumerate() {
            if let Some(b) = bucket(*q) {
                items[fill[b] as usize] = i as u32;
                at[fill[b] as usize] = *q;
                fill[b] += 1;
            }
        }
        let mut summed = vec![0u32; (cols + 1) * (rows + 1)];
        for y in 0..rows {
            let mut row = 0;
            for x in 0..cols {
                let b = y * cols + x;
                row += start[b + 1] - start[b];
                summed[(y + 1) * (cols + 1) + x + 1] = summed[y * (cols + 1) + x + 1] + row;
            }
        }
        Self {
            side,
            cols,
            rows,
            start,
            summed,
            items,
            at,
            places,
        }
    }

    /// The cell of point `i` (finite, inside the `size` domain) into
    /// `s.cell`, its corners in order: the box `[0, W] × [0, H]` cut by
    /// the bisector between `i` and each other point. False where `i`
    /// repeats a point of a lower index (that point takes the cell; `i`
    /// stays).
    pub(super) fn cell(&self, i: usize, size: [f64; 2], s: &mut CellScratch) -> bool {
        let p = self.places[i];
        // In coordinates relative to p.
        s.cell.clear();
        s.cell.extend([
            [-p[0], -p[1]],
            [size[0] - p[0], -p[1]],
            [size[0] - p[0], size[1] - p[1]],
            [-p[0], size[1] - p[1]],
        ]);
        let bx = ((p[0] / self.side).max(0.0) as usize).min(self.cols - 1) as i64;
        let by = ((p[1] / self.side).max(0.0) as usize).min(self.rows - 1) as i64;
        let (cols, rows) = (self.cols as i64, self.rows as i64);
        // The 3×3 buckets around p first, nearest first: the near
        // bisectors make the cell small at once, and the farther points
        // are then passed over by distance alone.
        s.near.clear();
        for y in (by - 1).max(0)..=(by + 1).min(rows - 1) {
            for x in (bx - 1).max(0)..=(bx + 1).min(cols - 1) {
                for (j, q) in self.bucket(x, y) {
                    if j == i {
                        continue;
                    }
                    let d = [q[0] - p[0], q[1] - p[1]];
                    let d2 = d[0] * d[0] + d[1] * d[1];
                    if d2 == 0.0 {
                        if j < i {
                            return false;
                        }
                        continue;
                    }
                    s.near.push((d2, j, d));
                }
            }
        }
        s.near
            .sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut reach2 = farthest2(&s.cell);
        for &(d2, _, d) in &s.near {
            // The bisector lies d/2 away: past the farthest corner, it
            // cuts nothing, nor does any point farther.
            if d2 >= 4.0 * reach2 {
                break;
            }
            if cut(&mut s.cell, &mut s.spare, d, 0.5 * d2) {
                reach2 = farthest2(&s.cell);
            }
        }
        let mut ring = 1i64;
        loop {
            // Points not yet seen lie outside the (2·ring + 1)² buckets
            // around p's: at least as far as that square's nearest side
            // that does not already reach the domain's edge.
            let (x0, x1, y0, y1) = (bx - ring, bx + ring, by - ring, by + ring);
            let open = |reached: bool, d: f64| if reached { f64::INFINITY } else { d };
            let beyond = [
                open(x0 <= 0, p[0] - x0 as f64 * self.side),
                open(x1 >= cols - 1, (x1 + 1) as f64 * self.side - p[0]),
                open(y0 <= 0, p[1] - y0 as f64 * self.side),
                open(y1 >= rows - 1, (y1 + 1) as f64 * self.side - p[1]),
            ]
            .into_iter()
            .fold(f64::INFINITY, f64::min);
            if beyond * beyond >= 4.0 * reach2 || s.cell.is_empty() {
                break;
            }
            ring += 1;
            let (x0, x1, y0, y1) = (bx - ring, bx + ring, by - ring, by + ring);
            // The ring's four sides, each passed over whole where empty.
            let (cx0, cx1) = (x0.max(0), x1.min(cols - 1));
            let (cy0, cy1) = ((y0 + 1).max(0), (y1 - 1).min(rows - 1));
            let sides = [
                (y0 >= 0).then_some((cx0, cx1, y0, y0)),
                (y1 < rows).then_some((cx0, cx1, y1, y1)),
                (x0 >= 0).then_some((x0, x0, cy0, cy1)),
                (x1 < cols).then_some((x1, x1, cy0, cy1)),
            ];
            for (sx0, sx1, sy0, sy1) in sides.into_iter().flatten() {
                if sx0 > sx1 || sy0 > sy1 || self.count(sx0, sx1, sy0, sy1) == 0 {
                    continue;
                }
                for y in sy0..=sy1 {
                    for x in sx0..=sx1 {
                        for (_, q) in self.bucket(x, y) {
                            let d = [q[0] - p[0], q[1] - p[1]];
                            let d2 = d[0] * d[0] + d[1] * d[1];
                            if d2 < 4.0 * reach2 && cut(&mut s.cell, &mut s.spare, d, 0.5 * d2) {
                                reach2 = farthest2(&s.cell);
                            }
                        }
                    }
                }
            }
        }
        for v in &mut s.cell {
            *v = [v[0] + p[0], v[1] + p[1]];
        }
        true
    }

    /// The points in buckets `x0..=x1` × `y0..=y1` (within the grid).
    fn count(&self, x0: i64, x1: i64, y0: i64, y1: i64) -> u32 {
        let stride = self.cols + 1;
        let at = |x: i64, y: i64| self.summed[y as usize * stride + x as usize];
        at(x1 + 1, y1 + 1) + at(x0, y0) - at(x0, y1 + 1) - at(x1 + 1, y0)
    }

    /// The points of bucket (`x`, `y`): index and place.
    fn bucket(&self, x: i64, y: i64) -> impl Iterator<Item = (usize, P)> + '_ {
        let b = y as usize * self.cols + x as usize;
        let (s, e) = (self.start[b] as usize, self.start[b + 1] as usize);
        self.items[s..e]
            .iter()
            .zip(&self.at[s..e])
            .map(|(&j, &q)| (j as usize, q))
    }
}

/// One thread's buffers for [`Buckets::cell`].
#[derive(Default)]
pub(super) struct CellScratch {
    /// The cell's corners.
    pub(super) cell: Vec<P>,
    /// The other buffer of the cutting.
    spare: Vec<P>,
    /// The points of the 3×3 buckets around the cell's: squared
    /// distance, index, offset.
    near: Vec<(f64, usize, P)>,
}

/// The largest squared distance of a corner of `cell` from the origin.
fn farthest2(cell: &[P]) -> f64 {
    cell.iter()
        .map(|v| v[0] * v[0] + v[1] * v[1])
        .fold(0.0, f64::max)
}

/// Cuts the convex polygon `cell` to the half-plane `v·d <= c`; whether
/// anything was cut.
fn cut(cell: &mut Vec<P>, spare: &mut Vec<P>, d: P, c: f64) -> bool {
    let side = |v: &P| v[0] * d[0] + v[1] * d[1] - c;
    if cell.iter().all(|v| side(v) <= 0.0) {
        return false;
    }
    spare.clear();
    let n = cell.len();
    for k in 0..n {
        let (a, b) = (cell[k], cell[(k + 1) % n]);
        let (sa, sb) = (side(&a), side(&b));
        if sa <= 0.0 {
            spare.push(a);
        }
        if (sa <= 0.0) != (sb <= 0.0) {
            let t = sa / (sa - sb);
            spare.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    std::mem::swap(cell, spare);
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signed area and the centroid of a polygon.
    fn area_centroid(poly: &[P]) -> (f64, P) {
        let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for k in 0..poly.len() {
            let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
            let c = p[0] * q[1] - q[0] * p[1];
            a += c;
            cx += (p[0] + q[0]) * c;
            cy += (p[1] + q[1]) * c;
        }
        (a / 2.0, [cx / (3.0 * a), cy / (3.0 * a)])
    }

    /// A stream of numbers in [0, 1) from `seed` (an LCG).
    fn stream(seed: u32) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32
        }
    }

    /// The cell of `i` cut by every other point's bisector, one by one.
    fn brute_force(points: &[[f32; 2]], i: usize, size: [f64; 2]) -> Vec<P> {
        let p = points[i].map(f64::from);
        let mut cell = vec![
            [0.0, 0.0],
            [size[0], 0.0],
            [size[0], size[1]],
            [0.0, size[1]],
        ];
        let mut spare = Vec::new();
        for (j, q) in points.iter().enumerate() {
            let q = q.map(f64::from);
            if j == i || !(q[0].is_finite() && q[1].is_finite()) || q == p {
                continue;
            }
            let d = [q[0] - p[0], q[1] - p[1]];
            // The half-plane in absolute coordinates: v·d <= (|q|² − |p|²)/2.
            let c = 0.5 * ((q[0] * q[0] + q[1] * q[1]) - (p[0] * p[0] + p[1] * p[1]));
            cut(&mut cell, &mut spare, d, c);
        }
        cell
    }

    /// Clustered and spread points, a duplicate, points outside the
    /// domain and one not finite: each cell found ring by ring is the cell
    /// every other point's bisector leaves (the same area and centroid),
    /// a duplicate's later copy has none, and the cells of the points
    /// inside tile what the points outside leave of the domain.
    #[test]
    fn the_cells_found_ring_by_ring_are_the_voronoi_cells() {
        let size = [300.0, 200.0];
        let mut next = stream(11);
        let mut points: Vec<[f32; 2]> =
            (0..400).map(|_| [next() * 300.0, next() * 200.0]).collect();
        // A dense cluster, where buckets hold many points.
        points.extend((0..200).map(|_| [20.0 + next() * 10.0, 150.0 + next() * 10.0]));
        points.push(points[7]);
        points.extend([[-5.0, 50.0], [310.0, 100.0], [f32::NAN, 1.0]]);
        check_against_brute_force(&points, size, 600, &[601, 602]);
    }

    /// The dots crowd one corner (a dark corner on white paper): buckets
    /// sized for the crowd, cells far into the empty part, still right.
    #[test]
    fn cells_are_right_where_the_points_crowd_a_corner() {
        let size = [400.0, 300.0];
        let mut next = stream(5);
        let mut points: Vec<[f32; 2]> = (0..500)
            .map(|_| [next() * 40.0, 270.0 + next() * 30.0])
            .collect();
        points.extend((0..12).map(|_| [next() * 400.0, next() * 300.0]));
        let buckets = Buckets::new(&points, size, 1.0);
        // Sized for the crowd, not for the domain's mean density.
        let mean = (400.0f64 * 300.0 / 512.0).sqrt();
        assert!(buckets.side < 0.6 * mean, "{} against {mean}", buckets.side);
        check_against_brute_force(&points, size, usize::MAX, &[]);
    }

    /// Every cell of `points` inside `size` against [`brute_force`]; point
    /// `duplicate` has no cell; the cells and those of the points
    /// `outside` tile the domain.
    fn check_against_brute_force(
        points: &[[f32; 2]],
        size: [f64; 2],
        duplicate: usize,
        outside: &[usize],
    ) {
        let buckets = Buckets::new(points, size, 1.0);
        let mut s = CellScratch::default();
        let mut total = 0.0;
        for i in 0..points.len() {
            let p = points[i].map(f64::from);
            if !((0.0..size[0]).contains(&p[0]) && (0.0..size[1]).contains(&p[1])) {
                continue;
            }
            let found = buckets.cell(i, size, &mut s);
            if i == duplicate {
                assert!(!found, "the duplicate's later copy has no cell");
                continue;
            }
            assert!(found, "point {i}");
            let (a, c) = area_centroid(&s.cell);
            let (b, d) = area_centroid(&brute_force(points, i, size));
            assert!(
                (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                "{i}: area {a} against {b}"
            );
            assert!(
                (c[0] - d[0]).abs() < 1e-7 && (c[1] - d[1]).abs() < 1e-7,
                "{i}: centroid {c:?} against {d:?}"
            );
            total += a;
        }
        let outside: f64 = outside
            .iter()
            .map(|&i| area_centroid(&brute_force(points, i, size)).0)
            .sum();
        assert!(
            (total + outside - size[0] * size[1]).abs() < 1e-6,
            "{total} + {outside}"
        );
    }

    /// One point alone owns the whole domain; two split it at their
    /// bisector.
    #[test]
    fn one_point_owns_the_domain() {
        let size = [50.0, 40.0];
        let mut s = CellScratch::default();
        let one = Buckets::new(&[[10.0, 10.0]], size, 1.0);
        assert!(one.cell(0, size, &mut s));
        assert!((area_centroid(&s.cell).0 - 2000.0).abs() < 1e-9);
        let two = Buckets::new(&[[10.0, 20.0], [30.0, 20.0]], size, 1.0);
        assert!(two.cell(0, size, &mut s));
        let (a, c) = area_centroid(&s.cell);
        assert!(
            (a - 800.0).abs() < 1e-9 && (c[0] - 10.0).abs() < 1e-9,
            "{a} {c:?}"
        );
    }
}
