//! Pen-plotter order: a short open path through all dots, so that the pen
//! travels little between them (StippleGen and DrawingBot offer the same).
//!
//! The dots along a Hilbert curve (a start as short as a nearest-neighbour
//! tour's on stipples, in a parallel sort rather than a sequential search),
//! then 2-opt and Or-opt moves (a stretch of 1 to 3 dots moved elsewhere,
//! turned or not) found through each dot's nearest neighbours (from a grid
//! of cells, in parallel) with "don't look" bits (Bentley 1992; Johnson &
//! McGeoch 1997), then perturbations of that local optimum kept only when
//! they shorten it (iterated local search: [`KICKS_PER`], [`MAX_KICKS`]),
//! both up to [`FULL_SEARCH_UP_TO`] dots.
//! On photos' 2K-6K dots the path is about 1.5% longer than fast_tsp's
//! (within 0.1% of LKH-3), where 2-opt alone left it 6-7% longer
//! (docs/benchmarks.md). The path ends nearer the origin (the plotter's
//! home) start it. The path is open: a virtual city at distance 0 from
//! every dot closes it into a cycle, so the moves optimize the open path's
//! length and may move its ends. Reversals longer than
//! [`TspOptions::max_reversal`] are skipped, which bounds the worst case.

use std::collections::VecDeque;

use super::spatial::{Buckets, hilbert_path};

/// Options of [`plan`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TspOptions {
    /// Candidate neighbours per dot for 2-opt moves.
    pub neighbours: usize,
    /// The longest segment a 2-opt move may reverse (the shorter side of the
    /// cycle is reversed).
    pub max_reversal: usize,
    /// Perturbations per dot of the iterated local search (up to
    /// [`FULL_SEARCH_UP_TO`] dots): 0.2 for a drawing's order; a line,
    /// whose tour is what is drawn, takes more ([`TspOptions::line`]).
    pub kicks_per_dot: f64,
    /// The most perturbations of one tour.
    pub max_kicks: usize,
}

impl TspOptions {
    /// The options of a line's tour (`--style line`): 2.5 times the
    /// perturbations, for a path within 3% of an LKH-class tour's through
    /// a line's uneven points (at 4K points of the astronaut and the
    /// rocket 1.031× and 1.018× fast_tsp's with the drawings' options,
    /// 1.018× and 1.012× with these; twice as many again gave 1.013× and
    /// 1.009×).
    #[must_use]
    pub fn line() -> Self {
        Self {
            kicks_per_dot: 0.5,
            // As many as a drawing's at most: past 20K points a line's
            // tour is a drawing's (2×, not 1.3×, the dots' time at 100K).
            max_kicks: MAX_KICKS,
            ..Self::default()
        }
    }
}

impl Default for TspOptions {
    fn default() -> Self {
        Self {
            neighbours: 8,
            // At 1M dots of a photo: 10 000 orders in 0.52 s for a tour
            // 0.07% longer than 50 000's (0.70 s); 5 000, 0.47 s and 0.14%
            // (docs/benchmarks.md, session 51).
            max_reversal: 10_000,
            kicks_per_dot: 1.0 / KICKS_PER as f64,
            max_kicks: MAX_KICKS,
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
    /// Moves made: 2-opt and Or-opt, and the perturbations kept.
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
    // Past FULL_SEARCH_UP_TO dots, 2-opt alone: drawings that large are
    // not plotted, and Or-opt would double the order stage (1M dots: the
    // TSP drawing 2.39x the unordered one instead of 1.63x, for a tour
    // 5.7% shorter); the perturbations would cost 0.26 s for 0.3%.
    opt.use_or_opt = n <= FULL_SEARCH_UP_TO;
    let moves = neighbours.map_or(0, |lists| {
        let moves = opt.run(&lists, stop);
        let kicks = if opt.use_or_opt {
            ((n as f64 * opts.kicks_per_dot) as usize).min(opts.max_kicks)
        } else {
            0
        };
        moves + opt.perturb(&lists, kicks, stop)
    });
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

/// The path 2-opt and Or-opt make of `order` through `points` (without
/// perturbations, Or-opt up to the count [`plan`] uses it for): how much
/// shorter a local search makes a path that was changed after it was
/// planned.
///
/// ```
/// use pixelpie::stipple::tsp;
/// // A zigzag along a row: the search walks it end to end.
/// let pts: Vec<[f64; 2]> = (0..20).map(|i| [i as f64, 0.0]).collect();
/// let zigzag: Vec<usize> = (0..10).map(|i| 2 * i).chain((0..10).rev().map(|i| 2 * i + 1)).collect();
/// let order = tsp::improve(&pts, &zigzag, tsp::TspOptions::default());
/// assert!((tsp::path_length(&pts, &order) - 19.0).abs() < 1e-9);
/// ```
#[must_use]
pub fn improve(points: &[[f64; 2]], order: &[usize], opts: TspOptions) -> Vec<usize> {
    let n = order.len();
    if n < 4 {
        return order.to_vec();
    }
    let along_path: Vec<[f64; 2]> = order.iter().map(|&i| points[i]).collect();
    let Some(lists) = nearest_lists(&along_path, opts.neighbours, &mut || false) else {
        return order.to_vec();
    };
    let along: Vec<usize> = (0..n).collect();
    let mut opt = TwoOpt::new(&along_path, &along, opts.max_reversal.max(1));
    opt.use_or_opt = n <= FULL_SEARCH_UP_TO;
    opt.run(&lists, &mut || false);
    opt.open_path().into_iter().map(|s| order[s]).collect()
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

/// The longest segment an Or-opt move takes.
const OR_MAX: usize = 3;
/// The longest stretch a perturbation moves ([`TwoOpt::perturb`]): on
/// rocket's 6K dots at n/4 kicks, 8 left the tour 2.1% above fast_tsp's,
/// 30 1.6%, 100 1.3% (each kick dearer).
const KICK_SPAN: usize = 50;
/// The nearest neighbours an Or-opt move puts a stretch beside: 3 gave
/// nearly all of 8's gain at 1M dots (-11.9% against -12.0% of the
/// curve's length), 5 all of it.
const OR_NEIGHBOURS: usize = 5;
/// The most dots a tour takes Or-opt moves and perturbations for (past
/// them 2-opt alone, where a drawing stops being relaxed by default).
pub const FULL_SEARCH_UP_TO: usize = 200_000;
/// Dots per perturbation: n/5 kicks.
const KICKS_PER: usize = 5;
/// The most perturbations of one tour: about 26 µs each on two cores,
/// so at most about 0.3 s past 50K dots.
const MAX_KICKS: usize = 10_000;

/// 2-opt on a cycle of the n points plus a virtual city `n` at distance 0
/// from all, stored as an array with each city's position.
struct TwoOpt<'a> {
    points: &'a [[f64; 2]],
    tour: Vec<u32>,
    pos: Vec<u32>,
    max_reversal: usize,
    /// The reversals made since a perturbation, to undo it: (first
    /// position, last position, length).
    log: Option<Vec<(u32, u32, u32)>>,
    /// Whether Or-opt moves are tried beside 2-opt.
    use_or_opt: bool,
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
            log: None,
            use_or_opt: true,
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
        let (i, j, len) = if 2 * len <= m {
            (i, j, len)
        } else {
            ((j + 1) % m, (i + m - 1) % m, m - len)
        };
        if len > self.max_reversal {
            return false;
        }
        self.swap_run(i, j, len);
        true
    }

    /// Reverses the `len` positions from `i` to `j` (cyclic), and logs it
    /// when a perturbation is being tried; its own inverse.
    fn swap_run(&mut self, mut i: usize, mut j: usize, len: usize) {
        if let Some(log) = &mut self.log {
            log.push((i as u32, j as u32, len as u32));
        }
        let m = self.tour.len();
        for _ in 0..len / 2 {
            self.tour.swap(i, j);
            self.pos[self.tour[i] as usize] = i as u32;
            self.pos[self.tour[j] as usize] = j as u32;
            i = (i + 1) % m;
            j = (j + m - 1) % m;
        }
    }

    /// Runs to a 2-opt local optimum over the neighbour lists, or until
    /// `stop`; returns the number of moves.
    fn run(&mut self, neighbours: &Lists, stop: &mut dyn FnMut() -> bool) -> usize {
        let n = self.points.len();
        let mut queue: VecDeque<u32> = self
            .tour
            .iter()
            .copied()
            .filter(|&c| (c as usize) < n)
            .collect();
        let mut queued = vec![true; n + 1];
        queued[n] = false;
        self.improve(&mut queue, &mut queued, neighbours, stop).0
    }

    /// 2-opt and Or-opt moves from the cities of `queue` (and those each
    /// move touches) until none gains or `stop`; returns the moves made
    /// and the length they saved.
    fn improve(
        &mut self,
        queue: &mut VecDeque<u32>,
        queued: &mut [bool],
        neighbours: &Lists,
        stop: &mut dyn FnMut() -> bool,
    ) -> (usize, f64) {
        const EPS: f64 = 1e-9;
        let n = self.points.len();
        let mut saved = 0.0;
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
                            saved += gain;
                            break 'search;
                        }
                    }
                }
            }
            let touched: Option<Vec<u32>> = match touched {
                Some(cities) => Some(cities.to_vec()),
                None if !self.use_or_opt => None,
                None => self.or_opt(a, neighbours).map(|(cities, gain)| {
                    saved += gain;
                    cities
                }),
            };
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
        (moves, saved)
    }

    /// Perturbs the local optimum `kicks` times (iterated local search,
    /// Lourenço, Martin & Stützle 2003): two neighbouring stretches of
    /// the tour, each at most [`KICK_SPAN`] cities, trade places (a
    /// double bridge, which 2-opt and Or-opt cannot undo in one move), the
    /// cities at its seams are improved from, and the result is kept only
    /// when shorter, else undone. The kicks' places come from a fixed
    /// seed: the same tour every time. Returns the kicks kept.
    fn perturb(
        &mut self,
        neighbours: &Lists,
        kicks: usize,
        stop: &mut dyn FnMut() -> bool,
    ) -> usize {
        const EPS: f64 = 1e-9;
        let (n, m) = (self.points.len(), self.tour.len());
        if 4 * KICK_SPAN + 4 > m {
            return 0;
        }
        let mut queue = VecDeque::new();
        let mut queued = vec![false; n + 1];
        let mut state = 0x9E37_79B9_7F4A_7C15_u64 ^ n as u64;
        let mut next = move || {
            // xorshift64*
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            state.wrapping_mul(0x2545_F491_4F6C_DD1D)
        };
        let mut kept = 0;
        let span = KICK_SPAN;
        let mut log = Vec::new();
        for k in 0..kicks {
            if k % 64 == 0 && stop() {
                break;
            }
            let i = (next() % m as u64) as usize;
            let la = 1 + (next() % span as u64) as usize;
            let lb = 1 + (next() % span as u64) as usize;
            let at = |off: usize| self.tour[(i + off) % m];
            // x A B y, A = a1 … a2, B = b1 … b2, becomes x B A y.
            let (x, a1, a2) = (at(0), at(1), at(la));
            let (b1, b2, y) = (at(la + 1), at(la + lb), at(la + lb + 1));
            let worse = self.d(x, b1) + self.d(b2, a1) + self.d(a2, y)
                - self.d(x, a1)
                - self.d(a2, b1)
                - self.d(b2, y);
            log.clear();
            self.log = Some(log);
            let p = |off: usize| (i + off) % m;
            self.swap_run(p(1), p(la), la);
            self.swap_run(p(la + 1), p(la + lb), lb);
            self.swap_run(p(1), p(la + lb), la + lb);
            for c in [x, a1, a2, b1, b2, y] {
                if (c as usize) < n && !queued[c as usize] {
                    queued[c as usize] = true;
                    queue.push_back(c);
                }
            }
            let (_, saved) = self.improve(&mut queue, &mut queued, neighbours, stop);
            log = self.log.take().unwrap_or_default();
            if saved - worse > EPS {
                kept += 1;
            } else {
                for &(i, j, len) in log.iter().rev() {
                    self.swap_run(i as usize, j as usize, len as usize);
                }
            }
            // A stop inside leaves cities queued: clear them.
            for c in queue.drain(..) {
                queued[c as usize] = false;
            }
        }
        kept
    }

    /// The cities from `a`, `len` of them, stepping forward (`succ`) or
    /// back: the segment an Or-opt move takes out, or `None` when it holds
    /// the virtual city or wraps round the tour.
    fn segment(&self, a: u32, len: usize, forward: bool) -> Option<([u32; OR_MAX], usize)> {
        let n = self.points.len() as u32;
        if len + 3 > self.tour.len() {
            return None;
        }
        let mut seg = [0u32; OR_MAX];
        let mut c = a;
        for slot in seg.iter_mut().take(len) {
            if c == n {
                return None;
            }
            *slot = c;
            c = if forward { self.succ(c) } else { self.pred(c) };
        }
        Some((seg, len))
    }

    /// An Or-opt move (Or 1976): a segment of 1 to [`OR_MAX`] cities from
    /// `a` taken out and put back between two neighbouring cities of the
    /// tour near one of its ends, turned if that is shorter. The first move
    /// that gains is made; its cities come back to be looked at again.
    fn or_opt(&mut self, a: u32, neighbours: &Lists) -> Option<(Vec<u32>, f64)> {
        const EPS: f64 = 1e-9;
        let n = self.points.len() as u32;
        // Segments that end at `a` are those that start at the dot one or
        // two before it, looked at from there.
        {
            let forward = true;
            for len in 1..=OR_MAX {
                let Some((seg, len)) = self.segment(a, len, forward) else {
                    break;
                };
                let seg = &seg[..len];
                // p s1 … s2 nx in the direction of the search.
                let (s1, s2) = (seg[0], seg[len - 1]);
                let (p, nx) = if forward {
                    (self.pred(s1), self.succ(s2))
                } else {
                    (self.succ(s1), self.pred(s2))
                };
                if seg.contains(&p) || seg.contains(&nx) {
                    continue;
                }
                let removed = self.d(p, s1) + self.d(s2, nx) - self.d(p, nx);
                if removed <= EPS {
                    continue;
                }
                for (end, other) in [(s1, s2), (s2, s1)] {
                    if end == n {
                        continue;
                    }
                    for &c in neighbours.of(end as usize).iter().take(OR_NEIGHBOURS) {
                        let d_ec = self.d(end, c);
                        if d_ec >= removed {
                            break;
                        }
                        if seg.contains(&c) {
                            continue;
                        }
                        for d in [self.succ(c), self.pred(c)] {
                            if seg.contains(&d) {
                                continue;
                            }
                            // c end … other d, in place of the edge c d.
                            let gain = removed - (d_ec + self.d(other, d) - self.d(c, d));
                            if gain > EPS && self.insert(p, s1, s2, nx, c, d, end) {
                                let mut cities = vec![p, nx, c, d];
                                cities.extend_from_slice(seg);
                                return Some((cities, gain));
                            }
                        }
                    }
                }
            }
        }
        None
    }

    /// The number of cities from `a` to `b` following `succ`, both counted.
    fn span(&self, a: u32, b: u32) -> usize {
        let m = self.tour.len();
        (self.pos[b as usize] as usize + m - self.pos[a as usize] as usize) % m + 1
    }

    /// Whether a 2-opt move whose one side holds `k` cities reverses no
    /// more than the bound (the shorter side is reversed).
    fn within(&self, k: usize) -> bool {
        k.min(self.tour.len() - k) <= self.max_reversal
    }

    /// A 2-opt move by its edges: {u1, v1} and {u2, v2} become {u1, u2}
    /// and {v1, v2} (whichever way the tour runs).
    fn exchange(&mut self, u1: u32, v1: u32, u2: u32, v2: u32) {
        let done = if self.succ(u1) == v1 {
            self.reverse(v1, u2)
        } else {
            self.reverse(u1, v2)
        };
        debug_assert!(done, "an exchange checked beforehand");
    }

    /// Moves the segment `s1 … s2` (between `p` and `nx`, which the caller
    /// read in one direction) between the neighbouring cities `c` and `d`,
    /// `end` (`s1` or `s2`) next to `c`. `false`, and the tour unchanged,
    /// when a reversal would pass the bound.
    #[expect(clippy::too_many_arguments, reason = "the move's eight cities")]
    fn insert(&mut self, p: u32, s1: u32, s2: u32, nx: u32, c: u32, d: u32, end: u32) -> bool {
        // Read the tour so that s1 … s2 runs forward, and name the edge
        // (x, y) with y after x: then p s1 … s2 nx … x y … p.
        let (p, s1, s2, nx) = if self.succ(p) == s1 {
            (p, s1, s2, nx)
        } else {
            (nx, s2, s1, p)
        };
        let (x, y) = if self.succ(c) == d { (c, d) } else { (d, c) };
        // Which of s1, s2 ends next to x.
        let x_end = if x == c {
            end
        } else if end == s1 {
            s2
        } else {
            s1
        };
        let len = self.span(s1, s2);
        if y == p {
            // x p s1 … s2 nx: the mirror of x == nx below.
            if !(self.within(len + 1) && self.within(len)) {
                return false;
            }
            // x s2 … s1 p nx
            self.exchange(nx, s2, p, x);
            if x_end == s1 {
                // x s1 … s2 p nx
                self.exchange(p, s1, s2, x);
            }
            return true;
        }
        let g = self.span(nx, x);
        if x == nx {
            if !(self.within(len + 1) && self.within(len)) {
                return false;
            }
        } else if !(self.within(len + g) && self.within(g) && self.within(len)) {
            return false;
        }
        // p x … nx s2 … s1 y
        self.exchange(p, s1, x, y);
        if x != nx {
            // p nx … x s2 … s1 y
            self.exchange(p, x, nx, s2);
        }
        if x_end == s1 {
            // … x s1 … s2 y
            self.exchange(x, s2, s1, y);
        }
        true
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

/// At most this many rounds of [`uncross`]: every round removes at least
/// one crossing, so only a path with that many more crossings than a
/// round removes reaches it.
const UNCROSS_ROUNDS: usize = 10_000;

/// Removes the self-crossings of the open path through `points` in `order`
/// (indices into `points`, each at most once) by 2-opt moves, and returns
/// how many reversals it made.
///
/// Where segments `i` and `j` of the path cross ([`super::line::crossings`]),
/// reversing `order[i + 1..=j]` joins them the other way round, which
/// removes that crossing and makes the path strictly shorter (the two new
/// segments are shorter than the crossing pair, by the triangle
/// inequality): the path never lengthens and the moves end. In a round the
/// pairs are taken shortest reversal first, each found by its two edges
/// (its dots) wherever earlier reversals moved them, and skipped where one
/// of its edges was taken away. A reversal may cross the path elsewhere,
/// but only with the two edges it makes (the others keep their places on
/// the page): the next round's pairs are those edges' crossings, found
/// among the edges near them and the few long ones, so that a round costs
/// what it changed rather than the whole path. What a reversal cannot
/// shorten stays: two segments on one line overlapping in opposite
/// directions (the pen going back over its line), which dots with
/// real-valued coordinates do not make. A pen drawing of a tour is then a
/// line that never crosses itself ("TSP art").
///
/// ```
/// use pixelpie::stipple::tsp;
/// let pts = [[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]];
/// let mut order = vec![0, 1, 2, 3];
/// assert_eq!(tsp::uncross(&pts, &mut order), 1);
/// assert_eq!(order, [0, 2, 1, 3]);
/// ```
pub fn uncross(points: &[[f64; 2]], order: &mut [usize]) -> usize {
    let path: Vec<[f64; 2]> = order.iter().map(|&i| points[i]).collect();
    let mut pairs: Vec<[usize; 4]> = super::line::crossings(&path)
        .into_iter()
        .map(|(i, j)| [order[i], order[i + 1], order[j], order[j + 1]])
        .collect();
    if pairs.is_empty() {
        return 0;
    }
    // Each dot's place in the order.
    let mut pos = vec![0usize; points.len()];
    for (k, &i) in order.iter().enumerate() {
        pos[i] = k;
    }
    let mut near = NearEdges::new(points, order, &path);
    let mut reversals = 0;
    for _ in 0..UNCROSS_ROUNDS {
        let made = uncross_round(points, order, &mut pos, &mut pairs);
        if made.is_empty() {
            break;
        }
        reversals += made.len() / 2;
        pairs = near.crossings(&made, order, &pos);
        if pairs.is_empty() {
            break;
        }
    }
    reversals
}

/// One round of [`uncross`]: reverses the path between the edges of each
/// of `pairs` (the dots of two crossing edges; dot `i` at `pos[i]` in
/// `order`) where both edges are still there and the move shortens the
/// path, shortest reversals first, and returns the edges made (two a
/// move).
fn uncross_round(
    points: &[[f64; 2]],
    order: &mut [usize],
    pos: &mut [usize],
    pairs: &mut [[usize; 4]],
) -> Vec<[usize; 2]> {
    let at = |e: &[usize; 4], pos: &[usize]| {
        let (p, q) = (pos[e[0]].min(pos[e[1]]), pos[e[2]].min(pos[e[3]]));
        (p.min(q), p.max(q))
    };
    // The shortest reversals first: they are cheapest, and leave the most
    // of the others' edges in place.
    pairs.sort_unstable_by_key(|e| {
        let (i, j) = at(e, pos);
        (j - i, i)
    });
    let mut made = Vec::new();
    for e in pairs.iter() {
        let joined = |u: usize, v: usize| pos[u].abs_diff(pos[v]) == 1;
        if !(joined(e[0], e[1]) && joined(e[2], e[3])) {
            continue;
        }
        let (i, j) = at(e, pos);
        let p = |k: usize| points[order[k]];
        let gain = dist(p(i), p(i + 1)) + dist(p(j), p(j + 1))
            - dist(p(i), p(j))
            - dist(p(i + 1), p(j + 1));
        // Computed on the same lengths as the path's, a positive gain
        // shortens the path as summed: no cycle of moves.
        if gain > 0.0 {
            order[i + 1..=j].reverse();
            for k in i + 1..=j {
                pos[order[k]] = k;
            }
            made.push([order[i], order[i + 1]]);
            made.push([order[j], order[j + 1]]);
        }
    }
    made
}

/// Edges longer than this many mean edges are [`NearEdges`]' long ones,
/// tested against every new edge; shorter ones are looked for near it.
const LONG_EDGE: f64 = 4.0;

/// The dots of a path bucketed by cell, to find the path's edges that
/// cross an edge: an edge at most `reach` long that crosses it has both
/// ends within `reach` of it; the longer ones are few in a tour, and
/// tested all.
struct NearEdges<'a> {
    points: &'a [[f64; 2]],
    grid: CellGrid,
    /// The dots by cell, as places in the order the path had when made.
    cells: Buckets,
    /// The dots of `cells.items`, as indices into `points`.
    ids: Vec<usize>,
    reach: f64,
    /// The edges longer than `reach` (their dots), made or found: each
    /// still in the path where its dots are next to each other.
    long: Vec<[usize; 2]>,
}

/// Square cells over a bounding box, row by row.
#[derive(Clone, Copy)]
struct CellGrid {
    origin: [f64; 2],
    /// Cells per unit length.
    inv: f64,
    nx: usize,
    ny: usize,
}

impl CellGrid {
    /// About `side` wide cells over the box from `lo` to `hi`: at most
    /// about 4 a dot of `n`, and one where the extent is not finite.
    fn new(lo: [f64; 2], hi: [f64; 2], side: f64, n: usize) -> Self {
        let (ex, ey) = (hi[0] - lo[0], hi[1] - lo[1]);
        let side = side.max((ex * ey / (4.0 * n as f64)).sqrt());
        let count = |e: f64| (e / side).floor() + 1.0;
        if side.is_finite() && side > 0.0 && count(ex) * count(ey) <= 4.0 * n as f64 + 1e6 {
            Self {
                origin: lo,
                inv: 1.0 / side,
                nx: count(ex) as usize,
                ny: count(ey) as usize,
            }
        } else {
            Self {
                origin: lo,
                inv: 0.0,
                nx: 1,
                ny: 1,
            }
        }
    }

    /// The cell (column, row) of point `p`, clamped to the grid.
    fn cell(self, p: [f64; 2]) -> (usize, usize) {
        let at = |v: f64, o: f64, n: usize| {
            ((v - o) * self.inv).floor().clamp(0.0, (n - 1) as f64) as usize
        };
        (
            at(p[0], self.origin[0], self.nx),
            at(p[1], self.origin[1], self.ny),
        )
    }
}

impl<'a> NearEdges<'a> {
    /// The dots of `order` (at `path`), in cells about an edge of it
    /// across.
    fn new(points: &'a [[f64; 2]], order: &[usize], path: &[[f64; 2]]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in path {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let n = path.len().max(1);
        let mean = path.windows(2).map(|w| dist(w[0], w[1])).sum::<f64>() / n as f64;
        let grid = CellGrid::new(lo, hi, mean, n);
        let cells = Buckets::new(path, grid.nx * grid.ny, |&p| {
            let (cx, cy) = grid.cell(p);
            cy * grid.nx + cx
        });
        let ids = cells.items.iter().map(|&k| order[k as usize]).collect();
        let reach = LONG_EDGE * mean;
        let long = (0..path.len().saturating_sub(1))
            .filter(|&k| dist(path[k], path[k + 1]) > reach)
            .map(|k| [order[k], order[k + 1]])
            .collect();
        Self {
            points,
            grid,
            cells,
            ids,
            reach,
            long,
        }
    }

    /// The pairs of the path (in `order`, dot `i` at `pos[i]`) that cross
    /// one of the edges `made` (those still in it), as the dots of their
    /// two edges; the long ones of `made` kept among the long edges.
    fn crossings(
        &mut self,
        made: &[[usize; 2]],
        order: &[usize],
        pos: &[usize],
    ) -> Vec<[usize; 4]> {
        let points = self.points;
        let segment = |k: usize| (points[order[k]], points[order[k + 1]]);
        let joined = |[u, v]: [usize; 2]| pos[u].abs_diff(pos[v]) == 1;
        self.long.retain(|&e| joined(e));
        self.long.extend(
            made.iter()
                .filter(|&&e| joined(e) && dist(points[e[0]], points[e[1]]) > self.reach),
        );
        let mut found = Vec::new();
        for &e in made {
            if !joined(e) {
                continue;
            }
            let s = pos[e[0]].min(pos[e[1]]);
            let (a, b) = segment(s);
            let mut test = |k: usize| {
                if k + 1 < order.len() && k.abs_diff(s) > 1 {
                    let (c, d) = segment(k);
                    if a != b && c != d && super::line::segments_cross(a, b, c, d) {
                        found.push((s.min(k), s.max(k)));
                    }
                }
            };
            let r = self.reach;
            let (x0, y0) = self.grid.cell([a[0].min(b[0]) - r, a[1].min(b[1]) - r]);
            let (x1, y1) = self.grid.cell([a[0].max(b[0]) + r, a[1].max(b[1]) + r]);
            for cy in y0..=y1 {
                let row = cy * self.grid.nx;
                let from = self.cells.start[row + x0] as usize;
                let to = self.cells.start[row + x1 + 1] as usize;
                for &i in &self.ids[from..to] {
                    let k = pos[i];
                    test(k);
                    if k > 0 {
                        test(k - 1);
                    }
                }
            }
            for &[u, v] in &self.long {
                test(pos[u].min(pos[v]));
            }
        }
        found.sort_unstable();
        found.dedup();
        found
            .into_iter()
            .map(|(i, j)| [order[i], order[i + 1], order[j], order[j + 1]])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng, rngs::StdRng};

    /// The cycle from city 0, in the direction whose second city is the
    /// smaller: one form for a cycle whichever way and wherever it starts.
    fn canonical(cycle: &[u32]) -> Vec<u32> {
        let m = cycle.len();
        let at = cycle.iter().position(|&c| c == 0).unwrap();
        let fwd: Vec<u32> = (0..m).map(|k| cycle[(at + k) % m]).collect();
        let back: Vec<u32> = (0..m).map(|k| cycle[(at + m - k) % m]).collect();
        if fwd[1] < back[1] { fwd } else { back }
    }

    /// Every Or-opt insertion gives the cycle made by hand: the segment
    /// taken out and put back between the edge's cities, the chosen end
    /// next to `c`, whichever way the tour was read and wherever the edge
    /// lies (next to the segment too).
    #[test]
    fn an_or_opt_insertion_is_the_segment_moved_by_hand() {
        let mut rng = StdRng::seed_from_u64(7);
        for _ in 0..3000 {
            let m = rng.random_range(6..40usize);
            let points: Vec<[f64; 2]> = (0..m - 1)
                .map(|_| [rng.random_range(0.0..100.0), rng.random_range(0.0..100.0)])
                .collect();
            let mut path: Vec<usize> = (0..m - 1).collect();
            for i in (1..path.len()).rev() {
                path.swap(i, rng.random_range(0..=i));
            }
            let mut opt = TwoOpt::new(&points, &path, m);
            // Scramble the orientation with a few 2-opt reversals.
            for _ in 0..3 {
                let (a, b) = (rng.random_range(0..m) as u32, rng.random_range(0..m) as u32);
                opt.reverse(a, b);
            }
            let before = opt.tour.clone();
            let len = rng.random_range(1..=OR_MAX.min(m - 3));
            let i = rng.random_range(0..m);
            let seg: Vec<u32> = (0..len).map(|k| before[(i + k) % m]).collect();
            let (p, nx) = (before[(i + m - 1) % m], before[(i + len) % m]);
            // The edge (x, y), y after x, away from the segment's inside.
            let rest: Vec<usize> = (0..m)
                .filter(|&k| !seg.contains(&before[k]) && !seg.contains(&before[(k + 1) % m]))
                .collect();
            let k = rest[rng.random_range(0..rest.len())];
            let (x, y) = (before[k], before[(k + 1) % m]);
            let end = if rng.random_bool(0.5) {
                seg[0]
            } else {
                seg[len - 1]
            };
            // Read in either direction, as the search does.
            let (c, d) = if rng.random_bool(0.5) { (x, y) } else { (y, x) };
            let (rp, rs1, rs2, rnx) = if rng.random_bool(0.5) {
                (p, seg[0], seg[len - 1], nx)
            } else {
                (nx, seg[len - 1], seg[0], p)
            };
            if !opt.insert(rp, rs1, rs2, rnx, c, d, end) {
                continue;
            }
            // By hand: out, then in after x (or before, reversed).
            let mut out: Vec<u32> = before
                .iter()
                .copied()
                .filter(|c| !seg.contains(c))
                .collect();
            let at = out.iter().position(|&v| v == x).unwrap();
            let mut piece = seg.clone();
            // The end next to c; c is x or y.
            let next_to_x = if c == x {
                end
            } else if end == seg[0] {
                seg[len - 1]
            } else {
                seg[0]
            };
            if piece[0] != next_to_x {
                piece.reverse();
            }
            out.splice(at + 1..at + 1, piece);
            assert_eq!(
                canonical(&opt.tour),
                canonical(&out),
                "m {m} seg {seg:?} x {x} y {y}"
            );
            for (k, &c) in opt.tour.iter().enumerate() {
                assert_eq!(opt.pos[c as usize] as usize, k);
            }
        }
    }

    /// A tour is every dot once, and no longer than the curve it starts
    /// from; with enough dots the perturbations run and keep it so.
    #[test]
    fn a_tour_visits_every_dot_once_and_only_shortens() {
        let mut rng = StdRng::seed_from_u64(11);
        for n in [5, 50, 400, 3000] {
            let pts: Vec<[f64; 2]> = (0..n)
                .map(|_| [rng.random_range(0.0..500.0), rng.random_range(0.0..500.0)])
                .collect();
            let tour = plan(&pts, TspOptions::default());
            let mut seen = tour.order.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n).collect::<Vec<_>>());
            assert!((tour.length - path_length(&pts, &tour.order)).abs() < 1e-6);
            assert!(tour.length <= tour.start_length + 1e-9);
            assert_eq!(plan(&pts, TspOptions::default()), tour, "deterministic");
        }
    }

    /// The path's points in `order`.
    fn along(pts: &[[f64; 2]], order: &[usize]) -> Vec<[f64; 2]> {
        order.iter().map(|&i| pts[i]).collect()
    }

    /// After `uncross` the path crosses itself nowhere, is still every dot
    /// once, and is no longer: from a Hilbert order with long jumps made
    /// in it, and from random orders.
    #[test]
    fn uncross_leaves_no_crossing_and_no_longer_path() {
        let mut rng = StdRng::seed_from_u64(21);
        let pts: Vec<[f64; 2]> = (0..2000)
            .map(|_| [rng.random_range(0.0..500.0), rng.random_range(0.0..500.0)])
            .collect();
        let mut hilbert = hilbert_path(&pts);
        for _ in 0..100 {
            let (a, b) = (rng.random_range(0..2000), rng.random_range(0..2000));
            hilbert.swap(a, b);
        }
        let mut random: Vec<usize> = (0..300).collect();
        for i in (1..random.len()).rev() {
            random.swap(i, rng.random_range(0..=i));
        }
        for mut order in [hilbert, random] {
            let before = path_length(&pts, &order);
            let crossed = super::super::line::crossings(&along(&pts, &order)).len();
            let made = uncross(&pts, &mut order);
            assert!(
                made >= 1 && crossed >= 1,
                "{made} reversals, {crossed} crossings"
            );
            assert!(super::super::line::crossings(&along(&pts, &order)).is_empty());
            let mut seen = order.clone();
            seen.sort_unstable();
            assert!(
                seen.iter().enumerate().all(|(k, &i)| k == i),
                "a permutation"
            );
            assert!(path_length(&pts, &order) <= before, "no longer");
        }
    }

    /// A planned tour has few crossings or none, and none after `uncross`.
    #[test]
    fn uncross_after_a_plan() {
        let mut rng = StdRng::seed_from_u64(5);
        let pts: Vec<[f64; 2]> = (0..5000)
            .map(|_| [rng.random_range(0.0..800.0), rng.random_range(0.0..600.0)])
            .collect();
        let mut tour = plan(&pts, TspOptions::default());
        let made = uncross(&pts, &mut tour.order);
        println!("{made} reversals");
        assert!(made <= 50, "{made} reversals");
        assert!(super::super::line::crossings(&along(&pts, &tour.order)).is_empty());
        assert!(path_length(&pts, &tour.order) <= tour.length + 1e-9);
    }

    /// Times `uncross` on a planned tour of 1M random dots (`cargo test
    /// --release --lib tsp::tests::uncross_timing -- --ignored
    /// --nocapture`).
    #[test]
    #[ignore = "a timing, printed"]
    fn uncross_timing() {
        let mut rng = StdRng::seed_from_u64(8);
        let pts: Vec<[f64; 2]> = (0..1_000_000)
            .map(|_| [rng.random_range(0.0..4096.0), rng.random_range(0.0..4096.0)])
            .collect();
        let t = std::time::Instant::now();
        let mut tour = plan(&pts, TspOptions::default());
        println!("plan 1M: {:.3} s", t.elapsed().as_secs_f64());
        let crossed = super::super::line::crossings(&along(&pts, &tour.order)).len();
        let t = std::time::Instant::now();
        let made = uncross(&pts, &mut tour.order);
        println!(
            "uncross: {:.3} s, {made} reversals of {crossed} crossings, length {:.1} -> {:.1}",
            t.elapsed().as_secs_f64(),
            tour.length,
            path_length(&pts, &tour.order)
        );
    }
}
