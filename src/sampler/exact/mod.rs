//! Exact mode: maximal Poisson-disk sets with no sub-pixel slack, maximal
//! in the continuous domain, and unbiased (random sequential addition).
//!
//! The pixel mode tests disks against pixel centres, so its sets break the
//! disk condition by up to √2/2 px and leave gaps between pixel centres
//! (paper §6). Exact mode keeps PixelPie's loop, with cells in place of
//! pixel centres, after Ebeida et al. (2011, 2012).
//!
//! # Semantics
//!
//! * **Units.** Positions are integers in 1/2^F px, with
//!   F = min(16, 24 − ⌈log₂ max(W, H)⌉) ([`frac_bits`]), so every position
//!   is exact in an `f32`. Radii are the contract's 1/64 px, scaled to
//!   1/2^F px. Distance tests are `dx² + dy² < f²` on 64-bit integers.
//! * **Cells.** Level 0 cells are the pixels; a cell of level L splits into
//!   four of level L + 1, down to level F, whose cells hold one position. A
//!   cell is *covered* when one accepted sample holds its four corners
//!   strictly within f(r_i, r_cell), r_cell the radius of the cell's pixel:
//!   then the whole closed cell is covered (a disk is convex).
//! * **Darts.** Iteration t throws b = min(batch, active cells, 2^22) darts.
//!   Dart k takes h = `dart_hash(iteration_key(seed_key(seed), t), k)`,
//!   picks the active cell `pick(h, cells)` and, within it, the position
//!   whose offsets are the low F − L bits of `offset_hash(h)`'s two halves:
//!   uniform over the cell's positions. Its radius is r at its pixel.
//! * **Acceptance,** in dart order: dart k is accepted iff for every sample
//!   i accepted before it (in earlier iterations, or darts j < k of this
//!   one) |c_i − c_k| ≥ f(r_i, r_k). This is sequential random addition
//!   computed in parallel: each dart is uniform over the active cells,
//!   which hold all of the uncovered area, and kept only where uncovered, so
//!   every sample is uniform over the area still uncovered when it comes.
//! * **Coverage.** After the accepted darts join the set, the active cells
//!   they cover leave the list, which keeps its order (level 0: the empty
//!   pixel list of the pixel mode, with the corner rule for coverage).
//! * **Refinement.** When an iteration accepts fewer than 1/[`REFINE_BELOW`]
//!   of its darts and the level is below F, every active cell is split in
//!   four (children in the order (0,0), (1,0), (0,1), (1,1)), and the
//!   children that one sample covers are dropped.
//! * **The finest level.** A cell of level F whose one position is covered
//!   can take no dart. It is dropped when the disks cover it together, which
//!   [`union::covers`] decides in `f64` with a margin towards "not covered".
//!   Otherwise it is a *void*: uncovered area too small to hold a position.
//! * **Repair.** When no cell is active and voids are left, each void takes
//!   back one sample: the latest accepted whose disk comes within 2 units
//!   (1/2^F px) of the void's cell, which bounds the void. Those samples
//!   leave the set (and the grid); every pixel within reach of one of them
//!   that no remaining disk holds whole is reopened as a level-0 cell, in
//!   pixel order, and the loop goes on from level 0 with the next
//!   iteration's darts. The void, and all the area the taken samples
//!   covered alone, lie in the reopened pixels. At most [`MAX_REPAIRS`]
//!   rounds run; voids left after them end the run, not maximal. A repair
//!   is a rejection after the fact of a dart that closed a region to less
//!   than one position: the set is RSA's with those darts refused.
//!   Measured at 4096²: 4 samples taken back among 486K over three seeds
//!   at r = 8.5 px, 177 among 2.92M at r = 2 px.
//! * **Stopping.** The run ends when no cell is active and no void is left:
//!   the set is then maximal in the continuous domain, since every point of
//!   the closed domain lies in a closed cell that some disk, or the union of
//!   disks, covers. With `max_iterations` too small it ends early, not
//!   maximal. [`crate::sampler::Stats::repaired`] counts the samples taken
//!   back.
//! * **Periodic domain.** Distances take the short way round, as in pixel
//!   mode.
//! * **Backends.** This module is the CPU's run. The GPU backend
//!   (`gpu::exact`) runs the iterations bit for bit as above until a
//!   refinement reaches level F, and hands its samples, coverage and cells
//!   to `ExactStepper::resume`, which runs the rest here.

mod grid;
pub(crate) mod rules;
pub mod union;

use std::time::Instant;

use rayon::prelude::*;

use super::coverage::{BAND_ROWS, fill_span, for_each_band, isqrt, new_map};
use super::cpu::compact::EmptyList;
use super::fixed::{self, RADIUS_FRAC_BITS, axis_delta, iteration_key};
use super::run::{StageTimes, Step, Stepper};
use super::{Control, Plan, Point, Policy, Result};
use grid::SampleGrid;
#[cfg(feature = "gpu")]
use rules::Handover;
use rules::Placed;

/// An iteration that accepts fewer than 1/`REFINE_BELOW` of its darts
/// refines the cells.
pub const REFINE_BELOW: usize = 8;

/// Rounds of void repair before a run gives up, not maximal.
pub const MAX_REPAIRS: u32 = 16;

/// Fractional bits of an exact-mode position for a `width`×`height` domain.
#[must_use]
pub fn frac_bits(width: u32, height: u32) -> u32 {
    let side = width.max(height).max(1);
    let k = 32 - (side - 1).leading_zeros();
    (24 - k).min(16)
}

/// An accepted sample or a dart, in 1/2^F px.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Sample {
    x: u32,
    y: u32,
    /// The pixel index.
    pixel: u32,
    /// The radius in 1/2^F px.
    r: u32,
}

/// A cell of the current level, in cell units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Cell {
    x: u32,
    y: u32,
}

/// The exact sampler between iterations.
pub struct ExactStepper<'p> {
    plan: &'p Plan,
    frac: u32,
    /// Wrap periods in 1/2^F px (0 when not periodic).
    periods: (u32, u32),
    samples: Vec<Sample>,
    grid: SampleGrid,
    level: u32,
    /// Level 0: pixels covered by one disk, and the list of the others.
    coverage: Vec<u64>,
    empty: EmptyList,
    /// Levels 1 to F: the active cells.
    cells: Vec<Cell>,
    /// Cells of level F that no dart can fill.
    unfillable: Vec<Cell>,
    /// Repair rounds run.
    repairs: u32,
    /// The batch's valid darts by grid cell (reused buffers).
    batch_start: Vec<u32>,
    batch_entries: Vec<u32>,
    peak_bytes: usize,
    /// Polled between the phases of an iteration and inside the long ones
    /// ([`Self::with_control`]).
    ctl: Control<'p>,
}

impl<'p> ExactStepper<'p> {
    /// A run of `plan` with every pixel empty.
    #[must_use]
    pub fn new(plan: &'p Plan) -> Self {
        let frac = frac_bits(plan.width, plan.height);
        Self {
            plan,
            frac,
            periods: rules::periods(plan, frac),
            samples: Vec::new(),
            grid: SampleGrid::new(plan),
            level: 0,
            coverage: new_map(plan.pixels()),
            empty: EmptyList::all(plan.pixels(), plan.width),
            cells: Vec::new(),
            unfillable: Vec::new(),
            repairs: 0,
            batch_start: Vec::new(),
            batch_entries: Vec::new(),
            peak_bytes: 0,
            ctl: Control::new(),
        }
    }

    /// The run heeds `ctl`'s cancel inside an iteration as well as before
    /// it: between its phases and within the long ones (the refinement, the
    /// finest level's cells, a repair). A cancelled step ends with
    /// [`crate::sampler::Error::Cancelled`] and its state is thrown away; a
    /// run not cancelled is the same.
    #[must_use]
    pub fn with_control(mut self, ctl: Control<'p>) -> Self {
        self.ctl = ctl;
        self
    }

    /// The run after iterations done elsewhere: the GPU backend
    /// (`gpu::exact`), which follows these semantics bit for bit up to and
    /// including an iteration's refinement, hands its state over. The
    /// iteration's rest (the finest level's cells set aside, a repair) runs
    /// here, and the samples it takes back are returned.
    #[cfg(feature = "gpu")]
    pub(crate) fn resume(plan: &'p Plan, handover: Handover) -> (Self, Vec<u32>) {
        let mut st = Self::new(plan);
        for p in handover.samples {
            let s = Sample {
                x: p.x,
                y: p.y,
                pixel: p.pixel,
                r: st.r_at(p.pixel),
            };
            st.grid.insert(s);
            st.samples.push(s);
        }
        st.coverage = handover.coverage;
        st.empty.compact(&st.coverage);
        st.level = handover.level;
        st.cells = handover
            .cells
            .into_iter()
            .map(|[x, y]| Cell { x, y })
            .collect();
        if st.level == st.frac {
            st.settle_finest();
        }
        let removed = st.repair_voids();
        (st, removed)
    }

    /// An iteration's end: with no cell active and voids left, a repair.
    /// Returns the samples taken back.
    fn repair_voids(&mut self) -> Vec<u32> {
        if self.active() == 0 && !self.unfillable.is_empty() && self.repairs < MAX_REPAIRS {
            self.repair()
        } else {
            Vec::new()
        }
    }

    /// What is left: the active cells and the cells set aside (a step's
    /// `empty`).
    pub(crate) fn left(&self) -> u64 {
        self.active() + self.unfillable.len() as u64
    }

    fn active(&self) -> u64 {
        if self.level == 0 {
            u64::from(self.empty.len())
        } else {
            self.cells.len() as u64
        }
    }

    /// The radius of pixel `p` in 1/2^F px.
    fn r_at(&self, p: u32) -> u32 {
        self.plan.radius_at(p) << (self.frac - RADIUS_FRAC_BITS)
    }

    /// Whether (ax, ay) lies strictly within `r` of (bx, by).
    fn within(&self, (ax, ay): (u32, u32), (bx, by): (u32, u32), r: u32) -> bool {
        let dx = u64::from(axis_delta(ax, bx, self.periods.0));
        let dy = u64::from(axis_delta(ay, by, self.periods.1));
        dx * dx + dy * dy < u64::from(r) * u64::from(r)
    }

    /// The pixel of a position or corner (a corner on the far edge belongs
    /// to the last pixel).
    fn pixel_xy(&self, x: u32, y: u32) -> (u32, u32) {
        (
            (x >> self.frac).min(self.plan.width - 1),
            (y >> self.frac).min(self.plan.height - 1),
        )
    }

    /// Dart `k` of the iteration with key `ik`.
    fn dart(&self, ik: u32, k: u32) -> Sample {
        let h = fixed::dart_hash(ik, k);
        let o = fixed::offset_hash(h);
        let shift = self.frac - self.level;
        let (cx, cy) = if self.level == 0 {
            let p = self.empty.get(fixed::pick(h, self.empty.len()));
            (p % self.plan.width, p / self.plan.width)
        } else {
            let c = self.cells[fixed::pick(h, self.cells.len() as u32) as usize];
            (c.x, c.y)
        };
        let mask = (1u32 << shift) - 1;
        let (x, y) = (
            (cx << shift) | (o & mask),
            (cy << shift) | ((o >> 16) & mask),
        );
        let pixel = (y >> self.frac) * self.plan.width + (x >> self.frac);
        Sample {
            x,
            y,
            pixel,
            r: self.r_at(pixel),
        }
    }

    /// Whether no accepted sample lies within the policy's distance of `d`.
    fn free(&self, d: &Sample) -> bool {
        let policy = self.plan.policy;
        let (px, py) = self.pixel_xy(d.x, d.y);
        !self.grid.any_near(px, py, 0, |_, s| {
            self.within((s.x, s.y), (d.x, d.y), policy.coverage_radius(s.r, d.r))
        })
    }

    /// The darts accepted among `darts`, in dart order: the valid ones that
    /// no earlier accepted dart of the batch excludes.
    fn accept(&mut self, darts: &[Sample]) -> Vec<Sample> {
        let policy = self.plan.policy;
        let this = &*self;
        // Cancelled: no dart is valid, and the step's result is thrown away.
        let valid: Vec<bool> = darts
            .par_iter()
            .map(|d| !this.ctl.cancelled() && this.free(d))
            .collect();
        // The valid darts by grid cell (counting sort: dart order per cell).
        let (g, cols) = (self.grid.cell(), self.grid.cols());
        let cell_of = |d: &Sample| {
            let (px, py) = (d.pixel % self.plan.width, d.pixel / self.plan.width);
            ((py / g) * cols + px / g) as usize
        };
        let mut start = std::mem::take(&mut self.batch_start);
        start.clear();
        start.resize(self.grid.cells() + 1, 0);
        for (d, _) in darts.iter().zip(&valid).filter(|(_, v)| **v) {
            start[cell_of(d) + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut entries = std::mem::take(&mut self.batch_entries);
        entries.clear();
        entries.resize(start[start.len() - 1] as usize, 0);
        let mut fill = start.clone();
        for (k, d) in darts.iter().enumerate().filter(|(k, _)| valid[*k]) {
            let c = cell_of(d);
            entries[fill[c] as usize] = k as u32;
            fill[c] += 1;
        }
        let this = &*self;
        // Pairs (k, j), j < k, of valid darts in conflict, ordered by k.
        let pairs: Vec<(u32, u32)> = (0..darts.len() as u32)
            .into_par_iter()
            .with_min_len(256)
            .filter(|&k| valid[k as usize] && !this.ctl.cancelled())
            .flat_map_iter(|k| {
                let d = darts[k as usize];
                let (px, py) = (d.pixel % this.plan.width, d.pixel / this.plan.width);
                let mut out = Vec::new();
                this.grid.for_cells_near(px, py, |cell| {
                    let run = &entries[start[cell] as usize..start[cell + 1] as usize];
                    for &j in run.iter().take_while(|&&j| j < k) {
                        let e = darts[j as usize];
                        if this.within((e.x, e.y), (d.x, d.y), policy.coverage_radius(e.r, d.r)) {
                            out.push((k, j));
                        }
                    }
                });
                out
            })
            .collect();
        self.batch_start = start;
        self.batch_entries = entries;
        let mut accepted = valid;
        for (k, j) in pairs {
            if accepted[j as usize] {
                accepted[k as usize] = false;
            }
        }
        darts
            .iter()
            .zip(accepted)
            .filter(|(_, a)| *a)
            .map(|(d, _)| *d)
            .collect()
    }

    /// Whether sample `s` covers the closed square of corners (x0, y0) and
    /// (x1, y1) whose pixel has radius `r_cell`.
    fn covers(&self, s: &Sample, (x0, y0, x1, y1): (u32, u32, u32, u32), r_cell: u32) -> bool {
        let f = u64::from(self.plan.policy.coverage_radius(s.r, r_cell));
        let dx =
            u64::from(axis_delta(x0, s.x, self.periods.0).max(axis_delta(x1, s.x, self.periods.0)));
        let dy =
            u64::from(axis_delta(y0, s.y, self.periods.1).max(axis_delta(y1, s.y, self.periods.1)));
        dx * dx + dy * dy < f * f
    }

    /// The corners of a cell of the current level.
    fn corners(&self, c: Cell) -> (u32, u32, u32, u32) {
        let shift = self.frac - self.level;
        let (x0, y0) = (c.x << shift, c.y << shift);
        (x0, y0, x0 + (1 << shift), y0 + (1 << shift))
    }

    /// Whether a sample of index `from` or later covers cell `c`.
    fn cell_covered(&self, c: Cell, from: u32) -> bool {
        let k = self.corners(c);
        let (px, py) = self.pixel_xy(k.0, k.1);
        let r_cell = self.r_at(py * self.plan.width + px);
        self.grid
            .any_near(px, py, from, |_, s| self.covers(s, k, r_cell))
    }

    /// Level 0: marks the pixels that the samples from `from` on cover.
    fn cover_pixels(&mut self, from: usize) {
        let plan = self.plan;
        let one = 1i64 << self.frac;
        let mut coverage = std::mem::take(&mut self.coverage);
        let bands = plan.height.div_ceil(BAND_ROWS) as usize;
        let reach_max = |s: &Sample| self.reach_max(s);
        let mut buckets: Vec<Vec<Sample>> = vec![Vec::new(); bands];
        for s in &self.samples[from..] {
            let r = i64::from(reach_max(s));
            let (y0, y1) = (
                (i64::from(s.y) - r).div_euclid(one),
                (i64::from(s.y) + r).div_euclid(one),
            );
            if plan.periodic {
                let mut last = usize::MAX;
                for q in y0..=y1 {
                    let b = (q.rem_euclid(i64::from(plan.height)) as u32 / BAND_ROWS) as usize;
                    if b != last && buckets[b].last() != Some(s) {
                        buckets[b].push(*s);
                    }
                    last = b;
                }
            } else {
                let (a, b) = (y0.max(0) as u32, y1.min(i64::from(plan.height) - 1) as u32);
                for band in a / BAND_ROWS..=b / BAND_ROWS {
                    buckets[band as usize].push(*s);
                }
            }
        }
        let this = &*self;
        let uniform_f = plan.map.is_none() || !plan.policy.reads_pixel_radius();
        for_each_band(plan, &mut coverage, &buckets, |s, rows, cov| {
            // Cancelled: the map is left unfinished, the step thrown away.
            if !this.ctl.cancelled() {
                this.cover_band(s, rows, cov, reach_max(s), uniform_f, one);
            }
        });
        self.coverage = coverage;
    }

    /// Marks the pixels of `rows` (held by `cov`) that `s` covers whole.
    fn cover_band(
        &self,
        s: &Sample,
        rows: std::ops::Range<u32>,
        cov: &mut [u64],
        reach: u32,
        uniform_f: bool,
        one: i64,
    ) {
        let plan = self.plan;
        let (w, h) = (i64::from(plan.width), i64::from(plan.height));
        let (sx, sy, r) = (i64::from(s.x), i64::from(s.y), i64::from(reach));
        let wrap = |q: i64, n: i64| {
            if plan.periodic {
                Some(q.rem_euclid(n))
            } else {
                Some(q).filter(|q| (0..n).contains(q))
            }
        };
        for qy in (sy - r).div_euclid(one)..=(sy + r).div_euclid(one) {
            let Some(y) = wrap(qy, h).filter(|&y| rows.contains(&(y as u32))) else {
                continue;
            };
            let dy = (qy * one - sy).abs().max((qy * one + one - sy).abs());
            if dy >= r {
                continue;
            }
            let row = (y as u32 - rows.start) as usize * plan.width as usize;
            let dxm = isqrt((r * r - dy * dy - 1) as u64) as i64;
            // Pixels whose both x corners lie within dxm of sx.
            let x0 = (sx - dxm + one - 1).div_euclid(one);
            let x1 = (sx + dxm).div_euclid(one) - 1;
            if uniform_f {
                fill_span(cov, row, plan.width as usize, x0, x1, plan.periodic);
                continue;
            }
            for qx in x0..=x1 {
                let Some(x) = wrap(qx, w) else { continue };
                let p = row + x as usize;
                let f = i64::from(
                    plan.policy
                        .coverage_radius(s.r, self.r_at(y as u32 * plan.width + x as u32)),
                );
                let dx = (qx * one - sx).abs().max((qx * one + one - sx).abs());
                if dx * dx + dy * dy < f * f {
                    cov[p / 64] |= 1 << (p % 64);
                }
            }
        }
    }

    /// Splits the active cells in four and keeps the children no sample
    /// covers; the level goes one down.
    fn refine(&mut self) {
        let parents: Vec<Cell> = if self.level == 0 {
            (0..self.empty.len())
                .map(|i| {
                    let p = self.empty.get(i);
                    Cell {
                        x: p % self.plan.width,
                        y: p / self.plan.width,
                    }
                })
                .collect()
        } else {
            std::mem::take(&mut self.cells)
        };
        let this = &*self;
        let half = 1u32 << (self.frac - self.level - 1);
        let cells: Vec<Cell> = parents
            .par_iter()
            .flat_map_iter(|&c| {
                let (x0, y0, _, _) = this.corners(c);
                let (px, py) = this.pixel_xy(x0, y0);
                let r_cell = this.r_at(py * this.plan.width + px);
                let xs = [x0, x0 + half, x0 + 2 * half];
                let ys = [y0, y0 + half, y0 + 2 * half];
                // Cancelled: no child, the step's result is thrown away.
                let mut covered = [this.ctl.cancelled(); 4];
                this.grid.any_near(px, py, 0, |_, s| {
                    for (n, cov) in covered.iter_mut().enumerate() {
                        let (a, b) = (n % 2, n / 2);
                        *cov = *cov || this.covers(s, (xs[a], ys[b], xs[a + 1], ys[b + 1]), r_cell);
                    }
                    covered.iter().all(|&c| c)
                });
                (0..4u32)
                    .filter(move |&n| !covered[n as usize])
                    .map(move |n| Cell {
                        x: 2 * c.x + n % 2,
                        y: 2 * c.y + n / 2,
                    })
            })
            .collect();
        self.level += 1;
        self.cells = cells;
    }

    /// At the finest level: sets aside the cells whose one position is
    /// covered, as pending, and drops the pending cells that the disks now
    /// cover together. A dart elsewhere may still cover a pending cell; those
    /// left pending when no cell is active are voids finer than the grid.
    fn settle_finest(&mut self) {
        let this = &*self;
        let policy = self.plan.policy;
        let (open, taken): (Vec<Cell>, Vec<Cell>) = self.cells.par_iter().partition(|&&c| {
            if this.ctl.cancelled() {
                return false;
            }
            let k = this.corners(c);
            let (px, py) = this.pixel_xy(k.0, k.1);
            let r_cell = this.r_at(py * this.plan.width + px);
            !this.grid.any_near(px, py, 0, |_, s| {
                this.within((s.x, s.y), (k.0, k.1), policy.coverage_radius(s.r, r_cell))
            })
        });
        let mut pending = std::mem::take(&mut self.unfillable);
        pending.extend(taken);
        let this = &*self;
        let pending = pending
            .into_par_iter()
            .filter(|&c| {
                if this.ctl.cancelled() {
                    return false;
                }
                let k = this.corners(c);
                let (px, py) = this.pixel_xy(k.0, k.1);
                !this.union_covers(k, this.r_at(py * this.plan.width + px))
            })
            .collect();
        self.cells = open;
        self.unfillable = pending;
    }

    /// Whether the disks near the closed square `k` cover it together.
    fn union_covers(&self, k: (u32, u32, u32, u32), r_cell: u32) -> bool {
        let one = f64::from(1u32 << self.frac);
        let (px, py) = self.pixel_xy(k.0, k.1);
        let mut disks = Vec::new();
        // The image of coordinate `s` nearest to `c` on a torus of `period`.
        let unwrap = |s: u32, c: u32, period: u32| -> f64 {
            let (s, c, p) = (i64::from(s), i64::from(c), i64::from(period));
            let d = s - c;
            let d = if p != 0 && 2 * d.abs() > p {
                d - p * d.signum()
            } else {
                d
            };
            (c + d) as f64
        };
        self.grid.any_near(px, py, 0, |_, s| {
            disks.push(union::Disk {
                x: unwrap(s.x, k.0, self.periods.0) / one,
                y: unwrap(s.y, k.1, self.periods.1) / one,
                r: f64::from(self.plan.policy.coverage_radius(s.r, r_cell)) / one,
            });
            false
        });
        let q = |v: u32| f64::from(v) / one;
        union::covers(&disks, (q(k.0), q(k.1), q(k.2), q(k.3)))
    }

    /// How far sample `s`'s coverage disk can reach, in 1/2^F px.
    fn reach_max(&self, s: &Sample) -> u32 {
        match self.plan.policy {
            Policy::Prior | Policy::Smaller => s.r,
            Policy::Current | Policy::Bigger => {
                s.r.max(self.plan.radius_range.1 << (self.frac - RADIUS_FRAC_BITS))
            }
        }
    }

    /// Repairs the voids: takes back, for each, the latest sample whose disk
    /// comes within 2 units of it, and reopens at level 0 the pixels within
    /// their reach that no remaining disk holds whole. Returns the samples
    /// taken back, in index order.
    fn repair(&mut self) -> Vec<u32> {
        let policy = self.plan.policy;
        let (w, h) = (self.plan.width, self.plan.height);
        let voids = std::mem::take(&mut self.unfillable);
        let mut victims: Vec<u32> = voids
            .iter()
            .filter_map(|&c| {
                let k = self.corners(c);
                let (px, py) = self.pixel_xy(k.0, k.1);
                let r_cell = self.r_at(py * w + px);
                let mut latest = None;
                self.grid.any_near(px, py, 0, |i, s| {
                    let f = policy.coverage_radius(s.r, r_cell) + 2;
                    if self.within((s.x, s.y), (k.0, k.1), f) {
                        latest = latest.max(Some(i));
                    }
                    false
                });
                latest
            })
            .collect();
        victims.sort_unstable();
        victims.dedup();
        let one = 1i64 << self.frac;
        let mut reopen = Vec::new();
        for &v in &victims {
            let s = self.samples[v as usize];
            self.grid.remove(v);
            let r = i64::from(self.reach_max(&s));
            let span = |c: u32, n: u32| {
                let (a, b) = (
                    (i64::from(c) - r).div_euclid(one) - 1,
                    (i64::from(c) + r).div_euclid(one) + 1,
                );
                let n = i64::from(n);
                if self.plan.periodic {
                    (a..=b.min(a + n - 1))
                        .map(|q| q.rem_euclid(n))
                        .collect::<Vec<_>>()
                } else {
                    (a.max(0)..=b.min(n - 1)).collect()
                }
            };
            let (xs, ys) = (span(s.x, w), span(s.y, h));
            for &y in &ys {
                for &x in &xs {
                    reopen.push(y as u32 * w + x as u32);
                }
            }
        }
        reopen.sort_unstable();
        reopen.dedup();
        self.level = 0;
        self.cells.clear();
        let this = &*self;
        let open: Vec<u32> = reopen
            .into_par_iter()
            .filter(|&p| {
                !this.ctl.cancelled() && !this.cell_covered(Cell { x: p % w, y: p / w }, 0)
            })
            .collect();
        for word in &mut self.coverage {
            *word = !0;
        }
        for &p in &open {
            self.coverage[(p / 64) as usize] &= !(1u64 << (p % 64));
        }
        self.empty = EmptyList::all(self.plan.pixels(), w);
        self.empty.compact(&self.coverage);
        self.repairs += 1;
        victims
    }

    fn point(&self, s: &Sample) -> Point {
        let placed = Placed {
            x: s.x,
            y: s.y,
            pixel: s.pixel,
        };
        placed.point(self.plan, self.frac)
    }
}

impl Stepper for ExactStepper<'_> {
    fn empty(&self) -> u64 {
        self.active()
    }

    fn darts_for(&self, plan: &Plan, empty: u64) -> u32 {
        rules::darts_for(plan, empty)
    }

    fn step(&mut self, iteration: u32, darts: u32) -> Result<Step> {
        let t0 = Instant::now();
        let ik = iteration_key(self.plan.seed_key, iteration);
        let batch: Vec<Sample> = (0..darts)
            .into_par_iter()
            .map(|k| self.dart(ik, k))
            .collect();
        self.ctl.check()?;
        let t1 = Instant::now();
        let accepted = self.accept(&batch);
        self.ctl.check()?;
        let from = self.samples.len();
        for s in &accepted {
            self.grid.insert(*s);
            self.samples.push(*s);
        }
        let t2 = Instant::now();
        if self.level == 0 {
            self.cover_pixels(from);
            self.empty.compact(&self.coverage);
        } else {
            let this = &*self;
            let cells = this
                .cells
                .par_iter()
                .copied()
                .filter(|&c| !this.ctl.cancelled() && !this.cell_covered(c, from as u32))
                .collect();
            self.ctl.check()?;
            self.cells = cells;
        }
        self.ctl.check()?;
        let t3 = Instant::now();
        if rules::refines(self.level, self.frac, accepted.len(), batch.len()) {
            self.refine();
            self.ctl.check()?;
        }
        if self.level == self.frac {
            self.settle_finest();
            self.ctl.check()?;
        }
        let t4 = Instant::now();
        let removed = self.repair_voids();
        self.ctl.check()?;
        let t5 = Instant::now();
        self.peak_bytes = self.peak_bytes.max(
            self.empty.bytes()
                + self.grid.bytes()
                + 8 * self.cells.capacity()
                + 4 * (self.batch_start.capacity() + self.batch_entries.capacity())
                + 16 * (self.samples.capacity() + batch.capacity()),
        );
        let mut stages = StageTimes::default();
        stages.add("throw", (t1 - t0).as_secs_f64());
        stages.add("cull", (t2 - t1).as_secs_f64());
        stages.add("compact", (t3 - t2).as_secs_f64());
        stages.add("refine", (t4 - t3).as_secs_f64());
        stages.add("repair", (t5 - t4).as_secs_f64());
        let active = self.active();
        Ok(Step {
            empty: self.left(),
            accepted: accepted.iter().map(|s| self.point(s)).collect(),
            stages,
            finished: active == 0,
            removed,
            held: 0,
        })
    }

    fn bytes(&self) -> usize {
        8 * self.coverage.len() + self.peak_bytes
    }
}

#[cfg(test)]
mod tests {
    use super::super::coverage::is_covered;
    use super::*;

    #[test]
    fn positions_stay_exact_in_f32() {
        for (w, h, f) in [
            (1, 1, 16),
            (256, 100, 16),
            (1000, 700, 14),
            (4096, 4096, 12),
            (65536, 1, 8),
        ] {
            assert_eq!(frac_bits(w, h), f, "{w}x{h}");
            assert!(u64::from(w.max(h)) << f <= 1 << 24);
        }
    }

    #[test]
    fn pixel_cover_marks_exactly_the_pixels_one_disk_holds_whole() {
        // Step radius map, every policy, bounded and periodic.
        let (w, h) = (70u32, 66u32);
        for policy in Policy::ALL {
            for periodic in [false, true] {
                let radii: Vec<f32> = (0..w * h)
                    .map(|i| if i % w < 35 { 3.0 } else { 5.5 })
                    .collect();
                let map = std::sync::Arc::new(
                    super::super::RadiusMap::from_pixels(w, h, &radii).unwrap(),
                );
                let plan = super::super::Params::new(w, h)
                    .with_radius_map(map)
                    .with_policy(policy)
                    .with_periodic(periodic)
                    .with_exact(true)
                    .plan()
                    .unwrap();
                let mut st = ExactStepper::new(&plan);
                for k in 0..40u32 {
                    let m = fixed::mix(k + 17);
                    let (x, y) = ((m % (w << st.frac)), ((m >> 8) % (h << st.frac)));
                    let pixel = (y >> st.frac) * w + (x >> st.frac);
                    let s = Sample {
                        x,
                        y,
                        pixel,
                        r: st.r_at(pixel),
                    };
                    st.grid.insert(s);
                    st.samples.push(s);
                }
                st.cover_pixels(0);
                let one = 1u32 << st.frac;
                for p in 0..w * h {
                    let (px, py) = (p % w, p / w);
                    let k = (px * one, py * one, px * one + one, py * one + one);
                    let want = st.samples.iter().any(|s| st.covers(s, k, st.r_at(p)));
                    assert_eq!(
                        is_covered(&st.coverage, p),
                        want,
                        "{policy:?} periodic {periodic} pixel ({px}, {py})"
                    );
                }
            }
        }
    }
}
