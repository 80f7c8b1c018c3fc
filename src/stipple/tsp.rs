//! Pen-plotter order: a short open path through all dots, so that the pen
//! travels little between them (StippleGen and DrawingBot offer the same).
//!
//! A nearest-neighbour tour from the dot nearest the origin (the plotter's
//! home), then 2-opt moves found through each dot's nearest neighbours with
//! "don't look" bits (Bentley 1992; Johnson & McGeoch 1997). The path is
//! open: a virtual city at distance 0 from every dot closes it into a cycle,
//! so 2-opt optimizes the open path's length and may move its ends. A uniform
//! grid finds neighbours in O(1), so 100K dots take seconds. Reversals longer
//! than [`TspOptions::max_reversal`] are skipped, which bounds the worst case.

use std::collections::VecDeque;

/// Options of [`plan`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TspOptions {
    /// Candidate neighbours per dot for 2-opt moves.
    pub neighbours: usize,
    /// The longest segment a 2-opt move may reverse (the shorter side of the
    /// cycle is reversed).
    pub max_reversal: usize,
}

impl Default for TspOptions {
    fn default() -> Self {
        Self {
            neighbours: 8,
            max_reversal: 50_000,
        }
    }
}

/// An ordering of the dots and the pen travel before and after 2-opt.
#[derive(Clone, Debug, PartialEq)]
pub struct Tour {
    /// A permutation of `0..n`: the drawing order.
    pub order: Vec<usize>,
    /// Length of the nearest-neighbour path (pixels).
    pub nearest_neighbour_length: f64,
    /// Length of the final path (pixels), at most the former.
    pub length: f64,
    /// 2-opt moves made.
    pub moves: usize,
}

/// The length of the open path through `points` in `order`.
///
/// ```
/// let pts = [[0.0, 0.0], [3.0, 4.0], [3.0, 0.0]];
/// assert_eq!(pixelpie::stipple::tsp::path_length(&pts, &[0, 2, 1]), 7.0);
/// ```
#[must_use]
pub fn path_length(points: &[[f64; 2]], order: &[usize]) -> f64 {
    order
        .windows(2)
        .map(|w| dist(points[w[0]], points[w[1]]))
        .sum()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Orders `points` for a pen plotter.
///
/// ```
/// use pixelpie::stipple::tsp;
/// let pts: Vec<[f64; 2]> = (0..50).map(|i| [((i * 37) % 50) as f64, 0.0]).collect();
/// let tour = tsp::plan(&pts, tsp::TspOptions::default());
/// assert!((tour.length - 49.0).abs() < 1e-9); // a line is walked end to end
/// ```
#[must_use]
pub fn plan(points: &[[f64; 2]], opts: TspOptions) -> Tour {
    plan_until(points, opts, &mut || false)
}

/// How many steps of the tour's loops run between two calls of
/// [`plan_until`]'s `stop` (a few milliseconds of work).
const STOP_EVERY: usize = 4096;

/// [`plan`], asking `stop` every few milliseconds whether to end early: a
/// stopped plan is still a tour of every dot (its remaining dots in any
/// order, or 2-opt left where it was), only longer.
pub fn plan_until(points: &[[f64; 2]], opts: TspOptions, stop: &mut dyn FnMut() -> bool) -> Tour {
    let n = points.len();
    if n == 0 {
        return Tour {
            order: Vec::new(),
            nearest_neighbour_length: 0.0,
            length: 0.0,
            moves: 0,
        };
    }
    let grid = Grid::new(points);
    let nn = nearest_neighbour_path(points, &grid, stop);
    let nn_length = path_length(points, &nn);
    if n < 4 {
        return Tour {
            order: nn,
            nearest_neighbour_length: nn_length,
            length: nn_length,
            moves: 0,
        };
    }
    let mut neighbours: Vec<Vec<u32>> = Vec::with_capacity(n);
    for start in (0..n).step_by(STOP_EVERY) {
        if stop() {
            break;
        }
        neighbours.extend(
            (start..n.min(start + STOP_EVERY)).map(|i| grid.nearest(points, i, opts.neighbours)),
        );
    }
    let mut opt = TwoOpt::new(points, &nn, opts.max_reversal.max(1));
    let moves = if neighbours.len() == n {
        opt.run(&neighbours, stop)
    } else {
        0
    };
    let mut order = opt.open_path();
    let home = [0.0, 0.0];
    if let (Some(&first), Some(&last)) = (order.first(), order.last())
        && dist(points[last], home) < dist(points[first], home)
    {
        order.reverse();
    }
    let length = path_length(points, &order);
    Tour {
        order,
        nearest_neighbour_length: nn_length,
        length,
        moves,
    }
}

/// A uniform grid of about two points per cell.
struct Grid {
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn new(points: &[[f64; 2]]) -> Self {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let (w, h) = ((hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9));
        let cell = (2.0 * w * h / points.len() as f64).sqrt().max(1e-9);
        let nx = ((w / cell) as usize + 1).min(1 << 12);
        let ny = ((h / cell) as usize + 1).min(1 << 12);
        let cell = (w / nx as f64).max(h / ny as f64) * (1.0 + 1e-9);
        let mut g = Self {
            origin: lo,
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        };
        for (i, p) in points.iter().enumerate() {
            let c = g.cell_of(*p);
            g.cells[c.1 * nx + c.0].push(i as u32);
        }
        g
    }

    fn cell_of(&self, p: [f64; 2]) -> (usize, usize) {
        let cx = ((p[0] - self.origin[0]) / self.cell).max(0.0) as usize;
        let cy = ((p[1] - self.origin[1]) / self.cell).max(0.0) as usize;
        (cx.min(self.nx - 1), cy.min(self.ny - 1))
    }

    /// Calls `f` on every cell of the Chebyshev ring `r` around `c`.
    fn ring(&self, c: (usize, usize), r: usize, mut f: impl FnMut(usize)) {
        let (cx, cy) = (c.0 as isize, c.1 as isize);
        let r = r as isize;
        for y in cy - r..=cy + r {
            if y < 0 || y >= self.ny as isize {
                continue;
            }
            let on_edge = y == cy - r || y == cy + r;
            let step = if on_edge || r == 0 { 1 } else { 2 * r };
            let mut x = cx - r;
            while x <= cx + r {
                if x >= 0 && x < self.nx as isize {
                    f(y as usize * self.nx + x as usize);
                }
                x += step;
            }
        }
    }

    /// The `k` nearest other points of point `i`, nearest first.
    fn nearest(&self, points: &[[f64; 2]], i: usize, k: usize) -> Vec<u32> {
        let p = points[i];
        let c = self.cell_of(p);
        let mut best: Vec<(f64, u32)> = Vec::with_capacity(k + 1);
        let max_r = self.nx.max(self.ny);
        for r in 0..=max_r {
            self.ring(c, r, |cell| {
                for &j in &self.cells[cell] {
                    if j as usize == i {
                        continue;
                    }
                    let d = dist(p, points[j as usize]);
                    if best.len() < k || d < best[best.len() - 1].0 {
                        let at = best.partition_point(|b| b.0 <= d);
                        best.insert(at, (d, j));
                        best.truncate(k);
                    }
                }
            });
            if best.len() == k && best[k - 1].0 <= r as f64 * self.cell {
                break;
            }
        }
        best.into_iter().map(|b| b.1).collect()
    }
}

/// The nearest-neighbour path from the point nearest the origin; when
/// `stop` says so, the points left follow in grid order.
fn nearest_neighbour_path(
    points: &[[f64; 2]],
    grid: &Grid,
    stop: &mut dyn FnMut() -> bool,
) -> Vec<usize> {
    let n = points.len();
    let mut cells = grid.cells.clone();
    let mut slot = vec![0u32; n];
    for cell in &cells {
        for (s, &i) in cell.iter().enumerate() {
            slot[i as usize] = s as u32;
        }
    }
    let mut remove = |cells: &mut Vec<Vec<u32>>, i: usize| {
        let c = grid.cell_of(points[i]);
        let cell = &mut cells[c.1 * grid.nx + c.0];
        let s = slot[i] as usize;
        cell.swap_remove(s);
        if let Some(&moved) = cell.get(s) {
            slot[moved as usize] = s as u32;
        }
    };
    let start = (0..n)
        .min_by(|&a, &b| {
            points[a][0]
                .hypot(points[a][1])
                .total_cmp(&points[b][0].hypot(points[b][1]))
        })
        .unwrap_or(0);
    let mut order = Vec::with_capacity(n);
    let mut cur = start;
    remove(&mut cells, cur);
    order.push(cur);
    let max_r = grid.nx.max(grid.ny);
    while order.len() < n {
        if order.len().is_multiple_of(STOP_EVERY) && stop() {
            order.extend(cells.iter().flatten().map(|&j| j as usize));
            break;
        }
        let p = points[cur];
        let c = grid.cell_of(p);
        let mut best: Option<(f64, usize)> = None;
        for r in 0..=max_r {
            grid.ring(c, r, |cell| {
                for &j in &cells[cell] {
                    let d = dist(p, points[j as usize]);
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, j as usize));
                    }
                }
            });
            if best.is_some_and(|b| b.0 <= r as f64 * grid.cell) {
                break;
            }
        }
        let Some((_, next)) = best else { break };
        remove(&mut cells, next);
        order.push(next);
        cur = next;
    }
    order
}

/// 2-opt on a cycle of the n points plus a virtual city `n` at distance 0
/// from all, stored as an array with each city's position.
struct TwoOpt<'a> {
    points: &'a [[f64; 2]],
    tour: Vec<u32>,
    pos: Vec<u32>,
    max_reversal: usize,
}

impl<'a> TwoOpt<'a> {
    fn new(points: &'a [[f64; 2]], path: &[usize], max_reversal: usize) -> Self {
        let mut tour: Vec<u32> = path.iter().map(|&i| i as u32).collect();
        tour.push(points.len() as u32);
        let mut pos = vec![0u32; tour.len()];
        for (k, &c) in tour.iter().enumerate() {
            pos[c as usize] = k as u32;
        }
        Self {
            points,
            tour,
            pos,
            max_reversal,
        }
    }

    fn d(&self, a: u32, b: u32) -> f64 {
        let n = self.points.len() as u32;
        if a == n || b == n {
            0.0
        } else {
            dist(self.points[a as usize], self.points[b as usize])
        }
    }

    fn succ(&self, a: u32) -> u32 {
        let m = self.tour.len();
        self.tour[(self.pos[a as usize] as usize + 1) % m]
    }

    fn pred(&self, a: u32) -> u32 {
        let m = self.tour.len();
        self.tour[(self.pos[a as usize] as usize + m - 1) % m]
    }

    /// Reverses the cyclic segment from city `from` to city `to` (inclusive),
    /// or the complementary one when shorter; `false` when both exceed the bound.
    fn reverse(&mut self, from: u32, to: u32) -> bool {
        let m = self.tour.len();
        let (i, j) = (
            self.pos[from as usize] as usize,
            self.pos[to as usize] as usize,
        );
        let len = (j + m - i) % m + 1;
        let (mut i, mut j, len) = if 2 * len <= m {
            (i, j, len)
        } else {
            ((j + 1) % m, (i + m - 1) % m, m - len)
        };
        if len > self.max_reversal {
            return false;
        }
        for _ in 0..len / 2 {
            self.tour.swap(i, j);
            self.pos[self.tour[i] as usize] = i as u32;
            self.pos[self.tour[j] as usize] = j as u32;
            i = (i + 1) % m;
            j = (j + m - 1) % m;
        }
        true
    }

    /// Runs to a 2-opt local optimum over the neighbour lists, or until
    /// `stop`; returns the number of moves.
    fn run(&mut self, neighbours: &[Vec<u32>], stop: &mut dyn FnMut() -> bool) -> usize {
        const EPS: f64 = 1e-9;
        let n = self.points.len();
        let mut queue: VecDeque<u32> = self
            .tour
            .iter()
            .copied()
            .filter(|&c| (c as usize) < n)
            .collect();
        let mut queued = vec![true; n + 1];
        queued[n] = false;
        let mut moves = 0;
        let mut popped = 0usize;
        while let Some(a) = queue.pop_front() {
            popped += 1;
            if popped.is_multiple_of(STOP_EVERY) && stop() {
                break;
            }
            queued[a as usize] = false;
            let mut touched = None;
            'search: for forward in [true, false] {
                let b = if forward { self.succ(a) } else { self.pred(a) };
                let d_ab = self.d(a, b);
                for &c in &neighbours[a as usize] {
                    let g1 = d_ab - self.d(a, c);
                    if g1 <= EPS {
                        break;
                    }
                    let d = if forward { self.succ(c) } else { self.pred(c) };
                    if c == b || d == a {
                        continue;
                    }
                    let gain = g1 + self.d(c, d) - self.d(b, d);
                    if gain > EPS {
                        // Forward: a b … c d becomes a c … b d.
                        // Backward: b a … d c reversed between a and d.
                        let done = if forward {
                            self.reverse(b, c)
                        } else {
                            self.reverse(a, d)
                        };
                        if done {
                            touched = Some([a, b, c, d]);
                            break 'search;
                        }
                    }
                }
            }
            if let Some(cities) = touched {
                moves += 1;
                for c in cities {
                    if (c as usize) < n && !queued[c as usize] {
                        queued[c as usize] = true;
                        queue.push_back(c);
                    }
                }
            }
        }
        moves
    }

    /// The cycle cut at the virtual city.
    fn open_path(&self) -> Vec<usize> {
        let n = self.points.len();
        let k = self.pos[n] as usize;
        self.tour[k + 1..]
            .iter()
            .chain(&self.tour[..k])
            .map(|&c| c as usize)
            .collect()
    }
}
