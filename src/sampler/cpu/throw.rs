//! Dart throwing (paper §3.1, step S1) on the CPU: each dart picks an empty
//! pixel by the counter-based hash, and the batch is binned into a grid, the
//! CPU's stand-in for the depth map that the GPU rasterizes.
//!
//! WGSL mirror: `shaders/throw.wgsl`.

use rayon::prelude::*;

use super::compact::EmptyList;
use crate::sampler::fixed::{self, POS_FRAC_BITS, RADIUS_ONE};
use crate::sampler::{Control, Dart, KeyLayout, Plan};

/// Dart `k` of the iteration with key `iteration_key`, as [`throw`] makes
/// it (in two passes): the tests' reference.
#[cfg(test)]
fn dart(plan: &Plan, iteration_key: u32, k: u32, empty: &EmptyList) -> Dart {
    let h = fixed::dart_hash(iteration_key, k);
    place(plan, h, empty.get(fixed::pick(h, empty.len())))
}

/// The dart of hash `h` on slot `slot`: its position in the slot's pixel and
/// the pixel's radius. With classes the list holds slots; the row is the
/// slot's row within its class's layer.
#[inline]
fn place(plan: &Plan, h: u32, slot: u32) -> Dart {
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
///
/// Dart `k`'s hash picks the `pick(h, len)`-th empty slot, and [`place`]
/// puts it there. Both reads, the empty list's and then the radius map's,
/// are at random into arrays larger than the cache: each is asked for
/// [`THROW_AHEAD`] darts ahead, chunk by chunk, so that many are in flight
/// at once (measured: the throw in 0.5–0.65× the time it took without).
///
/// Each chunk first polls `ctl`'s cancel: a cancelled throw leaves darts
/// unthrown, and the caller throws the iteration away.
pub fn throw(
    plan: &Plan,
    iteration: u32,
    count: u32,
    empty: &EmptyList,
    out: &mut Vec<Dart>,
    ctl: &Control<'_>,
) {
    let ik = fixed::iteration_key(plan.seed_key, iteration);
    let n = empty.len();
    out.clear();
    out.resize(count as usize, Dart::default());
    out.par_chunks_mut(THROW_CHUNK)
        .enumerate()
        .for_each(|(c, chunk)| {
            if ctl.cancelled() {
                return;
            }
            let first = (c * THROW_CHUNK) as u32;
            // The hash waits in `x`, the list index in `pixel`.
            for (k, d) in (first..).zip(chunk.iter_mut()) {
                let h = fixed::dart_hash(ik, k);
                (d.x, d.pixel) = (h, fixed::pick(h, n));
            }
            for i in 0..chunk.len() {
                if let Some(ahead) = chunk.get(i + THROW_AHEAD) {
                    empty.prefetch(ahead.pixel);
                }
                chunk[i].pixel = empty.get(chunk[i].pixel);
            }
            for i in 0..chunk.len() {
                if let Some(r) = chunk
                    .get(i + THROW_AHEAD)
                    .and_then(|ahead| plan.radius_in_map(ahead.pixel))
                {
                    super::prefetch(r);
                }
                let d = &mut chunk[i];
                *d = place(plan, d.x, d.pixel);
            }
        });
}

/// Darts between two polls of the cancel flag in a serial loop of
/// [`DartGrid::rebuild`].
pub const POLL_DARTS: usize = 1 << 16;

/// Darts per task of [`throw`].
const THROW_CHUNK: usize = 2048;

/// Darts ahead of the one read whose empty slot, then radius, is asked for.
const THROW_AHEAD: usize = 16;

/// Division of a `u32` by a fixed divisor as a multiplication by its
/// reciprocal (the cull divides by the grid's cell side a few times per
/// dart, and a hardware division costs tens of cycles): exact for every
/// `u32` dividend (`m` = ⌈2⁶⁴/d⌉, whose error times any dividend stays under
/// 2⁶⁴).
#[derive(Clone, Copy, Debug, Default)]
pub struct Recip {
    /// ⌈2⁶⁴/d⌉, or 0 for d = 1.
    m: u64,
}

impl Recip {
    /// The reciprocal of `d` (> 0).
    #[must_use]
    pub fn new(d: u32) -> Self {
        let d = d.max(1);
        Self {
            m: if d == 1 {
                0
            } else {
                u64::MAX / u64::from(d) + 1
            },
        }
    }

    /// `x / d`.
    #[inline]
    #[must_use]
    pub fn div(self, x: u32) -> u32 {
        if self.m == 0 {
            x
        } else {
            ((u128::from(x) * u128::from(self.m)) >> 64) as u32
        }
    }
}

/// The batch binned by pixel into square cells at least as wide as the largest
/// radius, so that every dart whose disk reaches a pixel centre lies in that
/// pixel's cell or one of its eight neighbours.
#[derive(Default)]
pub struct DartGrid {
    /// Cell side in pixels.
    pub cell: u32,
    /// Division by `cell` as a multiplication.
    pub per_cell: Recip,
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
    /// The darts' indices in winning order.
    order: Vec<u32>,
}

/// The indices of `darts` in winning order (ascending `layout.rank` of
/// their keys) into `out`. A key is the radius bits over the index, so
/// this is the index order (reversed when the greater key wins), stably
/// sorted by the radius bits: a counting sort, not a comparison sort.
fn winning_order(layout: KeyLayout, darts: &[Dart], out: &mut Vec<u32>) {
    let n = darts.len() as u32;
    out.clear();
    // By index, in the winning direction.
    let by_index = |k: u32| if layout.greater_wins { n - 1 - k } else { k };
    if layout.radius_bits == 0 {
        out.extend((0..n).map(by_index));
        return;
    }
    // The radius bits of dart k, as a bucket in winning order.
    let top = (1u32 << layout.radius_bits) - 1;
    let bucket = |k: u32| {
        let b = layout.key(0, darts[k as usize].radius) >> layout.index_bits;
        (if layout.greater_wins { top - b } else { b }) as usize
    };
    let mut at = vec![0u32; top as usize + 2];
    for k in 0..n {
        at[bucket(k) + 1] += 1;
    }
    for b in 1..at.len() {
        at[b] += at[b - 1];
    }
    out.resize(n as usize, 0);
    for k in (0..n).map(by_index) {
        let slot = &mut at[bucket(k)];
        out[*slot as usize] = k;
        *slot += 1;
    }
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
    /// Each task polls `ctl`'s cancel every [`POLL_DARTS`] darts: a
    /// cancelled grid is left unfinished, and the caller throws the
    /// iteration away.
    pub fn rebuild(&mut self, plan: &Plan, darts: &[Dart], ctl: &Control<'_>) {
        let r_max = darts
            .par_iter()
            .map(|d| d.radius)
            .max()
            .unwrap_or(RADIUS_ONE);
        let cell = r_max.div_ceil(RADIUS_ONE).max(1);
        let cols = plan.width.div_ceil(cell);
        let rows = plan.height.div_ceil(cell);
        (self.cell, self.cols, self.rows) = (cell, cols, rows);
        self.per_cell = Recip::new(cell);
        let by = self.per_cell;
        darts
            .par_iter()
            .map(|d| {
                let (px, py) = (d.x >> POS_FRAC_BITS, d.y >> POS_FRAC_BITS);
                by.div(py) * cols + by.div(px)
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
        // The darts in winning order, so that each cell's darts land in it
        // in that order: the cull stops at the first that cannot beat the
        // dart it tests.
        if ctl.cancelled() {
            return;
        }
        winning_order(plan.layout, darts, &mut self.order);
        let order = &self.order;
        tasks
            .into_par_iter()
            .for_each(|(b, start, entries, first)| {
                let lo = (b * band_cells) as u32;
                let hi = lo + start.len() as u32;
                start.fill(0);
                for part in cell_of.chunks(POLL_DARTS) {
                    if ctl.cancelled() {
                        return;
                    }
                    for &c in part {
                        if (lo..hi).contains(&c) {
                            start[(c - lo) as usize] += 1;
                        }
                    }
                }
                // Exclusive prefix sum, offset by the band's first entry.
                let mut at = first;
                for s in start.iter_mut() {
                    (*s, at) = (at, at + *s);
                }
                // Place the band's darts, then restore the starts.
                for (i, &k) in order.iter().enumerate() {
                    if i % POLL_DARTS == 0 && ctl.cancelled() {
                        return;
                    }
                    let (c, d) = (cell_of[k as usize], &darts[k as usize]);
                    if (lo..hi).contains(&c) {
                        let slot = &mut start[(c - lo) as usize];
                        let pixels = plan.pixels();
                        entries[(*slot - first) as usize] = GridEntry {
                            key: plan.layout.key(k, d.radius),
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
            });
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        4 * (self.start.capacity() + self.cell_of.capacity() + self.order.capacity())
            + self.entries.capacity() * std::mem::size_of::<GridEntry>()
    }
}

#[cfg(test)]
mod tests {

    /// The reciprocal divides every dividend exactly: the edges of u32,
    /// multiples of the divisor and their neighbours, and a pseudo-random
    /// sweep, for divisors from 1 to large.
    #[test]
    fn the_reciprocal_divides_exactly() {
        let mut state = 0x9e37_79b9_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut divisors: Vec<u32> = (1..=4100).collect();
        divisors.extend([
            65_535,
            65_536,
            65_537,
            1 << 20,
            u32::MAX / 3,
            u32::MAX - 1,
            u32::MAX,
        ]);
        divisors.extend((0..200).map(|_| (next() as u32).max(1)));
        for d in divisors {
            let by = Recip::new(d);
            let mut xs = vec![0, 1, d - 1, d, d.saturating_add(1), u32::MAX, u32::MAX - 1];
            xs.extend((1..4u32).map(|k| d.saturating_mul(k).saturating_sub(1)));
            xs.extend((0..64).map(|_| next() as u32));
            for x in xs {
                assert_eq!(by.div(x), x / d, "{x} / {d}");
            }
        }
    }
    use std::sync::Arc;

    use super::*;
    use crate::sampler::{Params, RadiusMap};

    /// The counting sort gives the darts in ascending rank of their keys,
    /// under every policy's key layout.
    #[test]
    fn winning_order_sorts_the_darts_by_rank() {
        let (w, h) = (64u32, 48u32);
        let radii: Vec<f32> = (0..w * h)
            .map(|i| 1.0 + (fixed::mix(i) % 400) as f32 / 64.0)
            .collect();
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        for policy in crate::sampler::Policy::ALL {
            let plan = Params::new(w, h)
                .with_radius_map(map.clone())
                .with_policy(policy)
                .plan()
                .unwrap();
            let empty = EmptyList::all(w * h, w);
            let mut darts = Vec::new();
            throw(&plan, 2, 900, &empty, &mut darts, &Control::new());
            let layout = plan.layout;
            let mut want: Vec<u32> = (0..darts.len() as u32).collect();
            want.sort_by_key(|&k| layout.rank(layout.key(k, darts[k as usize].radius)));
            let mut got = Vec::new();
            winning_order(layout, &darts, &mut got);
            assert_eq!(got, want, "{policy:?}");
        }
    }

    /// The two-pass throw gives [`dart`] for every dart, on a compacted list
    /// of empty slots, with classes and sub-pixel bits.
    #[test]
    fn the_two_pass_throw_gives_each_darts_own_values() {
        let (w, h) = (97u32, 61u32);
        let radii: Vec<f32> = (0..w * h).map(|i| 1.0 + (i % 13) as f32 / 3.0).collect();
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        for bits in [0, 3] {
            let plan = Params::new(w, h)
                .with_radius_map(map.clone())
                .with_subpixel_bits(bits)
                .with_seed(5)
                .plan()
                .unwrap();
            let mut empty = EmptyList::all(w * h, w);
            let mut coverage = crate::sampler::coverage::new_map(w * h);
            for p in (0..w * h).filter(|p| p % 3 == 0 || p % 7 == 1) {
                coverage[(p / 64) as usize] |= 1 << (p % 64);
            }
            for list in 0..2 {
                if list == 1 {
                    empty.compact(&coverage);
                }
                let mut out = Vec::new();
                throw(&plan, 4, 3000, &empty, &mut out, &Control::new());
                let ik = fixed::iteration_key(plan.seed_key, 4);
                assert_eq!(out.len(), 3000);
                for (k, d) in out.iter().enumerate() {
                    assert_eq!(
                        *d,
                        dart(&plan, ik, k as u32, &empty),
                        "dart {k} bits {bits}"
                    );
                }
            }
        }
    }
}
