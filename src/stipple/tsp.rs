//! Pen-plotter order: a short open path through all dots, so that the pen
//! travels little between them (StippleGen and DrawingBot offer the same).
//!
//! The dots along a Hilbert curve (a start as short as a nearest-neighbour
//! tour's on stipples, in a parallel sort rather than a sequential search),
//! then 2-opt moves found through each dot's nearest neighbours (from a
//! grid of cells, in parallel) with "don't look" bits (Bentley 1992; Johnson &
//! McGeoch 1997); the path ends nearer the origin (the plotter's home)
//! start it. The path is open: a virtual city at distance 0 from every dot
//! closes it into a cycle, so 2-opt optimizes the open path's length and
//! may move its ends. Reversals longer than [`TspOptions::max_reversal`] are
//! skipped, which bounds the worst case. A million dots of a photo take
//! about 0.5 s on two cores.

use std::collections::VecDeque;

use super::spatial::{Buckets, hilbert_path};

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
            // At 1M dots of a photo: 10 000 orders in 0.52 s for a tour
            // 0.07% longer than 50 000's (0.70 s); 5 000, 0.47 s and 0.14%
            // (docs/benchmarks.md, session 51).
            max_reversal: 10_000,
        }
    }
}

/// An ordering of the dots and the pen travel before and after 2-opt.
#[derive(Clone, Debug, PartialEq)]
pub struct Tour {
    /// A permutation of `0..n`: the drawing order.
    pub order: Vec<usize>,
    /// Length of the starting path, along the Hilbert curve (pixels).
    pub start_length: f64,
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
    dist2(a, b).sqrt()
}

/// The squared distance (no `hypot`: the coordinates are far from
/// overflow, and `hypot` costs several times as much).
fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
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
            start_length: 0.0,
            length: 0.0,
            moves: 0,
        };
    }
    let start = hilbert_path(points);
    let start_length = path_length(points, &start);
    if n < 4 {
        return Tour {
            order: start,
            start_length,
            length: start_length,
            moves: 0,
        };
    }
    // The work on the points renumbered along the curve: neighbours in
    // space are neighbours in memory (the tree, the lists and the tour).
    let sorted: Vec<[f64; 2]> = start.iter().map(|&i| points[i]).collect();
    let neighbours = nearest_lists(&sorted, opts.neighbours, stop);
    let along: Vec<usize> = (0..n).collect();
    let mut opt = TwoOpt::new(&sorted, &along, opts.max_reversal.max(1));
    let moves = neighbours.map_or(0, |lists| opt.run(&lists, stop));
    let mut order: Vec<usize> = opt.open_path().into_iter().map(|s| start[s]).collect();
    let home = [0.0, 0.0];
    if let (Some(&first), Some(&last)) = (order.first(), order.last())
        && dist(points[last], home) < dist(points[first], home)
    {
        order.reverse();
    }
    let length = path_length(points, &order);
    Tour {
        order,
        start_length,
        length,
        moves,
    }
}

/// Points of the neighbour lists found in parallel between two calls of
/// [`nearest_lists`]'s `stop`.
const LISTS_AT_ONCE: usize = 1 << 16;

/// Each point's `k` nearest other points, nearest first, in parallel, from
/// a grid of cells ([`Cells`]). `points`
/// come along a Hilbert curve. No lists when `stop` says so.
fn nearest_lists(points: &[[f64; 2]], k: usize, stop: &mut dyn FnMut() -> bool) -> Option<Lists> {
    use rayon::prelude::*;
    // At least one, and no more than there are other points.
    let k = k.clamp(1, points.len().saturating_sub(1).max(1));
    let cells = Cells::new(points);
    let mut items = vec![NONE; points.len() * k];
    for (chunk, out) in items.chunks_mut(LISTS_AT_ONCE * k).enumerate() {
        if stop() {
            return None;
        }
        let first = chunk * LISTS_AT_ONCE;
        out.par_chunks_mut(k)
            .enumerate()
            .for_each_init(Vec::new, |best, (i, list)| {
                cells.nearest(points, first + i, k, best);
                for (slot, b) in list.iter_mut().zip(best.iter()) {
                    *slot = b.1;
                }
            });
    }
    Some(Lists { k, items })
}

/// No neighbour: the end of a list shorter than `k`.
const NONE: u32 = u32::MAX;

/// Each point's nearest other points, nearest first, `k` slots a point in
/// one array (the unused ones [`NONE`]).
struct Lists {
    k: usize,
    items: Vec<u32>,
}

impl Lists {
    /// Point `i`'s list.
    fn of(&self, i: usize) -> &[u32] {
        let list = &self.items[i * self.k..(i + 1) * self.k];
        &list[..list.iter().position(|&c| c == NONE).unwrap_or(self.k)]
    }
}

/// A grid of square cells over the points, each cell's points contiguous.
/// A photo's dots are dense in the dark and sparse in the light: the cells
/// are as wide as the median step along the curve (on astronaut's 1M dots
/// the lists cost least there; kiddo's k-d tree took twice as long), so
/// that a query in the dark reads a few points, and one in the light more
/// cells, most of them empty (cheap).
struct Cells {
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    /// The points, cell by cell.
    buckets: Buckets,
}

/// The share of the steps along the curve shorter than a cell's width
/// (0.1 to 0.9 tried on astronaut's 1M dots: 0.5 is the fastest).
const CELL_QUANTILE: f64 = 0.5;
/// The most cells a grid holds, about (memory: 4 bytes a cell).
const MAX_CELLS: f64 = 16.0 * 1024.0 * 1024.0;

impl Cells {
    /// `points`, along a Hilbert curve.
    fn new(points: &[[f64; 2]]) -> Self {
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let (w, h) = ((hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9));
        let mut steps: Vec<f64> = points
            .windows(2)
            .map(|p| dist(p[0], p[1]))
            .filter(|&d| d > 0.0)
            .collect();
        let floor = (w * h / MAX_CELLS).sqrt();
        let cell = if steps.is_empty() {
            w.max(h)
        } else {
            let at = ((steps.len() as f64 * CELL_QUANTILE) as usize).min(steps.len() - 1);
            *steps.select_nth_unstable_by(at, f64::total_cmp).1
        }
        .max(floor)
        .max(1e-9);
        let nx = (w / cell) as usize + 1;
        let ny = (h / cell) as usize + 1;
        let of = |p: [f64; 2]| {
            let cx = (((p[0] - lo[0]) / cell) as usize).min(nx - 1);
            let cy = (((p[1] - lo[1]) / cell) as usize).min(ny - 1);
            cy * nx + cx
        };
        Self {
            origin: lo,
            cell,
            nx,
            ny,
            buckets: Buckets::new(points, nx * ny, |p| of(*p)),
        }
    }

    /// The `k` nearest other points of point `i`, nearest first, into
    /// `best` (with their squared distances).
    fn nearest(&self, points: &[[f64; 2]], i: usize, k: usize, best: &mut Vec<(f64, u32)>) {
        best.clear();
        let p = points[i];
        let cx = (((p[0] - self.origin[0]) / self.cell) as isize).clamp(0, self.nx as isize - 1);
        let cy = (((p[1] - self.origin[1]) / self.cell) as isize).clamp(0, self.ny as isize - 1);
        let consider = |c: usize, best: &mut Vec<(f64, u32)>| {
            for &j in self.buckets.span(c, c) {
                if j as usize == i {
                    continue;
                }
                let d = dist2(p, points[j as usize]);
                if best.len() < k || d < best[best.len() - 1].0 {
                    let at = best.partition_point(|b| b.0 <= d);
                    best.insert(at, (d, j));
                    best.truncate(k);
                }
            }
        };
        let (nx, ny) = (self.nx as isize, self.ny as isize);
        for r in 0..nx.max(ny) {
            // The Chebyshev ring r around the query's cell.
            for y in (cy - r).max(0)..=(cy + r).min(ny - 1) {
                let edge = y == cy - r || y == cy + r;
                let step = if edge || r == 0 { 1 } else { 2 * r };
                let mut x = cx - r;
                while x <= cx + r {
                    if x >= 0 && x < nx {
                        consider((y * nx + x) as usize, best);
                    }
                    x += step;
                }
            }
            // Every cell beyond ring r lies at least r cells away.
            let reach = r as f64 * self.cell;
            if best.len() == k.min(points.len() - 1) && best[best.len() - 1].0 <= reach * reach {
                break;
            }
        }
    }
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
    fn run(&mut self, neighbours: &Lists, stop: &mut dyn FnMut() -> bool) -> usize {
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
                for &c in neighbours.of(a as usize) {
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
