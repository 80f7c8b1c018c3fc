//! Conflict removal (paper §3.2, step S2) on the CPU: a dart survives when no
//! dart with a winning depth key covers the centre of its pixel.
//!
//! The GPU reads the winning key from the depth map it rasterized; here the
//! same minimum (or maximum) is found among the darts of the 3×3 grid cells
//! around the pixel. WGSL mirror: `shaders/cull.wgsl`.

use rayon::prelude::*;

use super::throw::{DartGrid, GridEntry};
use crate::sampler::fixed::{POS_FRAC_BITS, RADIUS_ONE, axis_delta, inside, pixel_centre};
use crate::sampler::{Control, Dart, Plan, Policy};

/// The grid columns (or rows) that hold pixels within `reach` pixels of pixel
/// `p` along an axis of `n` pixels, wrapping when periodic. At most 4, since
/// cells are at least `reach` wide; a partial last cell may add one at the seam.
pub(crate) fn cells_along(
    p: u32,
    reach: u32,
    n: u32,
    cell: u32,
    periodic: bool,
) -> ([u32; 4], usize) {
    let (mut out, mut len) = ([0u32; 4], 0);
    if !periodic {
        let (a, b) = (
            p.saturating_sub(reach) / cell,
            (p + reach).min(n - 1) / cell,
        );
        for c in a..=b {
            out[len] = c;
            len += 1;
        }
        return (out, len);
    }
    let (lo, hi) = (
        i64::from(p) - i64::from(reach),
        i64::from(p) + i64::from(reach),
    );
    let mut x = lo;
    while x <= hi {
        let w = x.rem_euclid(i64::from(n)) as u32;
        let c = w / cell;
        if !out[..len].contains(&c) {
            out[len] = c;
            len += 1;
        }
        x += i64::from(((c + 1) * cell).min(n) - w);
    }
    (out, len)
}

/// [`cells_along`] off a periodic domain, dividing by the cell side as
/// `by` does.
fn span_cells(p: u32, reach: u32, n: u32, by: super::throw::Recip) -> ([u32; 4], usize) {
    let (mut out, mut len) = ([0u32; 4], 0);
    let (a, b) = (
        by.div(p.saturating_sub(reach)),
        by.div((p + reach).min(n - 1)),
    );
    for c in a..=b {
        out[len] = c;
        len += 1;
    }
    (out, len)
}

/// Whether the dart of grid entry `e` is occluded at the centre of its pixel.
fn occluded(plan: &Plan, grid: &DartGrid, e: &GridEntry) -> bool {
    let layout = plan.layout;
    let (px, py) = (e.x >> POS_FRAC_BITS, e.y >> POS_FRAC_BITS);
    let (cx, cy) = (pixel_centre(px), pixel_centre(py));
    let (period_x, period_y) = plan.periods();
    // Under Smaller only a dart of radius at most e's beats it, and its disk
    // (or its cross-class disk, no larger) reaches at most that far.
    let reach = if plan.policy == Policy::Smaller {
        e.radius.div_ceil(RADIUS_ONE).min(grid.cell)
    } else {
        grid.cell
    };
    let by = grid.per_cell;
    let (cols, ncols, rows, nrows) = if plan.periodic {
        let (c, nc) = cells_along(px, reach, plan.width, grid.cell, true);
        let (r, nr) = cells_along(py, reach, plan.height, grid.cell, true);
        (c, nc, r, nr)
    } else {
        let (c, nc) = span_cells(px, reach, plan.width, by);
        let (r, nr) = span_cells(py, reach, plan.height, by);
        (c, nc, r, nr)
    };
    // A cell's darts are in winning order: its scan stops at the first
    // that does not beat e (e itself at the latest: keys are unique), or at
    // the first that covers e's pixel centre. e's own cell comes first: the
    // nearest darts are the likeliest to cover it (in the crowded late
    // iterations of Smaller this reads a twentieth of the darts).
    let own = by.div(py) * grid.cols + by.div(px);
    let others = rows[..nrows]
        .iter()
        .flat_map(|&ny| cols[..ncols].iter().map(move |&nx| ny * grid.cols + nx))
        .filter(|&c| c != own);
    for c in std::iter::once(own).chain(others) {
        let (a, b) = (grid.start[c as usize], grid.start[c as usize + 1]);
        for di in &grid.entries[a as usize..b as usize] {
            if !layout.beats(di.key, e.key) {
                break;
            }
            // Another class keeps the cross radius away.
            let reach = if di.class == e.class {
                di.radius
            } else {
                di.cross
            };
            if inside(
                axis_delta(di.x, cx, period_x),
                axis_delta(di.y, cy, period_y),
                reach,
            ) {
                return true;
            }
        }
    }
    false
}

/// Per-batch flags, reused between iterations.
#[derive(Default)]
pub struct Culler {
    /// Whether each grid entry is occluded, in grid order.
    by_entry: Vec<bool>,
    /// Whether each dart is occluded, in dart order.
    by_dart: Vec<bool>,
}

impl Culler {
    /// The darts that survive, in dart order, into `out`.
    ///
    /// The test runs over the grid's entries in cell order, so that the
    /// neighbouring cells it reads are close in memory; the flags are then
    /// put back in dart order, read from the low bits of each key. Once
    /// `ctl`'s cancel is set the test stops (every dart left counts as
    /// occluded), and the caller throws the iteration away.
    pub fn survivors(
        &mut self,
        plan: &Plan,
        darts: &[Dart],
        grid: &DartGrid,
        out: &mut Vec<Dart>,
        ctl: &Control<'_>,
    ) {
        grid.entries
            .par_iter()
            .with_min_len(1024)
            .map(|e| ctl.cancelled() || occluded(plan, grid, e))
            .collect_into_vec(&mut self.by_entry);
        // index_bits <= KEY_BITS (29), so the shift cannot overflow.
        let index_mask = (1u32 << plan.layout.index_bits) - 1;
        self.by_dart.clear();
        self.by_dart.resize(darts.len(), false);
        for (e, &occ) in grid.entries.iter().zip(&self.by_entry) {
            self.by_dart[(e.key & index_mask) as usize] = occ;
        }
        out.clear();
        out.extend(
            darts
                .iter()
                .zip(&self.by_dart)
                .filter(|(_, occ)| !**occ)
                .map(|(d, _)| *d),
        );
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.by_entry.capacity() + self.by_dart.capacity()
    }
}
