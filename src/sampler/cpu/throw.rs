//! Dart throwing (paper §3.1, step S1) on the CPU: each dart picks an empty
//! pixel by the counter-based hash, and the batch is binned into a grid, the
//! CPU's stand-in for the depth map that the GPU rasterizes.
//!
//! WGSL mirror: `shaders/throw.wgsl`.

use rayon::prelude::*;

use super::compact::EmptyList;
use crate::sampler::fixed::{self, POS_FRAC_BITS, RADIUS_ONE};
use crate::sampler::{Dart, Plan};

/// Dart `k` of the iteration with key `iteration_key`.
#[inline]
#[must_use]
pub fn dart(plan: &Plan, iteration_key: u32, k: u32, empty: &EmptyList) -> Dart {
    let h = fixed::dart_hash(iteration_key, k);
    // With classes the list holds slots; the row is the slot's row within
    // its class's layer.
    let slot = empty.get(fixed::pick(h, empty.len()));
    let o = fixed::offset_hash(h);
    let mask = (1u32 << plan.subpixel_bits) - 1;
    let bits = plan.subpixel_bits;
    Dart {
        x: fixed::dart_coord(slot % plan.width, o & mask, bits),
        y: fixed::dart_coord(slot / plan.width % plan.height, (o >> 16) & mask, bits),
        pixel: slot,
        radius: plan.radius_at(slot),
    }
}

/// The `count` darts of iteration `iteration`, in dart order, into `out`
/// (reused between iterations: fresh memory costs page faults).
pub fn throw(plan: &Plan, iteration: u32, count: u32, empty: &EmptyList, out: &mut Vec<Dart>) {
    let ik = fixed::iteration_key(plan.seed_key, iteration);
    (0..count)
        .into_par_iter()
        .map(|k| dart(plan, ik, k, empty))
        .collect_into_vec(out);
}

/// The batch binned by pixel into square cells at least as wide as the largest
/// radius, so that every dart whose disk reaches a pixel centre lies in that
/// pixel's cell or one of its eight neighbours.
#[derive(Default)]
pub struct DartGrid {
    /// Cell side in pixels.
    pub cell: u32,
    /// Cells per row.
    pub cols: u32,
    /// Cells per column.
    pub rows: u32,
    /// `start[c]..start[c + 1]` indexes `entries` for cell `c`.
    pub start: Vec<u32>,
    /// The darts with their keys, grouped by cell, in winning order within a
    /// cell (the best key first).
    pub entries: Vec<GridEntry>,
    /// The cell of each dart, in dart order.
    cell_of: Vec<u32>,
}

/// A dart as the grid holds it: its depth key, centre and radii, stored
/// together so that the cull reads one cell's darts from contiguous memory.
#[derive(Clone, Copy, Debug, Default)]
pub struct GridEntry {
    /// The dart's depth key.
    pub key: u32,
    /// x in 1/256 px.
    pub x: u32,
    /// y in 1/256 px.
    pub y: u32,
    /// Radius in 1/64 px.
    pub radius: u32,
    /// The cross-class radius in 1/64 px (the radius without classes).
    pub cross: u32,
    /// The dart's class (0 without classes).
    pub class: u32,
}

impl DartGrid {
    /// Bins `darts` (counting sort, deterministic), reusing the buffers.
    ///
    /// The grid is cut into bands of cell rows, one per thread, each sorted
    /// by its own task: every task reads the whole list of cell numbers,
    /// keeps its band's darts in dart order, and writes only its band's
    /// counts and entries. The result does not depend on the band count.
    pub fn rebuild(&mut self, plan: &Plan, darts: &[Dart]) {
        let r_max = darts
            .par_iter()
            .map(|d| d.radius)
            .max()
            .unwrap_or(RADIUS_ONE);
        let cell = r_max.div_ceil(RADIUS_ONE).max(1);
        let cols = plan.width.div_ceil(cell);
        let rows = plan.height.div_ceil(cell);
        (self.cell, self.cols, self.rows) = (cell, cols, rows);
        darts
            .par_iter()
            .map(|d| {
                let (px, py) = (d.x >> POS_FRAC_BITS, d.y >> POS_FRAC_BITS);
                (py / cell) * cols + px / cell
            })
            .collect_into_vec(&mut self.cell_of);
        // One band per thread: each task reads every dart's cell number.
        let bands = rayon::current_num_threads().clamp(1, 64) as u32;
        let band_cells = (rows.div_ceil(bands) * cols) as usize;
        let n_cells = (cols * rows) as usize;
        let mut band_len = vec![0u32; n_cells.div_ceil(band_cells)];
        for &c in &self.cell_of {
            band_len[c as usize / band_cells] += 1;
        }
        self.start.clear();
        self.start.resize(n_cells + 1, 0);
        self.start[n_cells] = darts.len() as u32;
        self.entries.clear();
        self.entries.resize(darts.len(), GridEntry::default());
        let mut tasks = Vec::with_capacity(band_len.len());
        let (mut start, mut entries, mut first) =
            (&mut self.start[..n_cells], &mut self.entries[..], 0u32);
        for (b, &len) in band_len.iter().enumerate() {
            let (s, s_rest) = start.split_at_mut(band_cells.min(start.len()));
            let (e, e_rest) = entries.split_at_mut(len as usize);
            tasks.push((b, s, e, first));
            (start, entries, first) = (s_rest, e_rest, first + len);
        }
        let cell_of = &self.cell_of;
        tasks
            .into_par_iter()
            .for_each(|(b, start, entries, first)| {
                let lo = (b * band_cells) as u32;
                let hi = lo + start.len() as u32;
                start.fill(0);
                for &c in cell_of {
                    if (lo..hi).contains(&c) {
                        start[(c - lo) as usize] += 1;
                    }
                }
                // Exclusive prefix sum, offset by the band's first entry.
                let mut at = first;
                for s in start.iter_mut() {
                    (*s, at) = (at, at + *s);
                }
                // Place the band's darts, then restore the starts.
                for (k, (&c, d)) in cell_of.iter().zip(darts).enumerate() {
                    if (lo..hi).contains(&c) {
                        let slot = &mut start[(c - lo) as usize];
                        let pixels = plan.pixels();
                        entries[(*slot - first) as usize] = GridEntry {
                            key: plan.layout.key(k as u32, d.radius),
                            x: d.x,
                            y: d.y,
                            radius: d.radius,
                            cross: if plan.classes == 1 {
                                d.radius
                            } else {
                                plan.cross_at(d.pixel % pixels)
                            },
                            class: d.pixel / pixels,
                        };
                        *slot += 1;
                    }
                }
                let mut prev = first;
                for s in start.iter_mut() {
                    (*s, prev) = (prev, *s);
                }
                // Each cell's darts in winning order, so that the cull stops
                // at the first that cannot beat the dart it tests.
                let layout = plan.layout;
                let end = first + entries.len() as u32;
                for (c, &a) in start.iter().enumerate() {
                    let b = start.get(c + 1).copied().unwrap_or(end);
                    entries[(a - first) as usize..(b - first) as usize]
                        .sort_unstable_by_key(|e| layout.rank(e.key));
                }
            });
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        4 * (self.start.capacity() + self.cell_of.capacity())
            + self.entries.capacity() * std::mem::size_of::<GridEntry>()
    }
}
