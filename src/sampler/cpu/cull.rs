//! Conflict removal (paper §3.2, step S2) on the CPU: a dart survives when no
//! dart with a winning depth key covers the centre of its pixel.
//!
//! The GPU reads the winning key from the depth map it rasterized; here the
//! same minimum (or maximum) is found among the darts of the 3×3 grid cells
//! around the pixel. WGSL mirror: `shaders/cull.wgsl`.

use rayon::prelude::*;

use super::throw::{Dart, DartGrid};
use crate::sampler::Plan;
use crate::sampler::fixed::{axis_delta, inside, pixel_centre};

/// The grid columns (or rows) that hold pixels within `reach` pixels of pixel
/// `p` along an axis of `n` pixels, wrapping when periodic. At most 4, since
/// cells are at least `reach` wide; a partial last cell may add one at the seam.
fn cells_along(p: u32, reach: u32, n: u32, cell: u32, periodic: bool) -> ([u32; 4], usize) {
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
    let (lo, hi) = if periodic {
        (
            i64::from(p) - i64::from(reach),
            i64::from(p) + i64::from(reach),
        )
    } else {
        (
            i64::from(p.saturating_sub(reach)),
            i64::from((p + reach).min(n - 1)),
        )
    };
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

/// Whether dart `j` is occluded at the centre of its pixel.
fn occluded(plan: &Plan, darts: &[Dart], grid: &DartGrid, j: u32) -> bool {
    let dj = darts[j as usize];
    let layout = plan.layout;
    let key_j = layout.key(j, dj.radius);
    let (px, py) = (dj.pixel % plan.width, dj.pixel / plan.width);
    let (cx, cy) = (pixel_centre(px), pixel_centre(py));
    let (period_x, period_y) = plan.periods();
    let (cols, ncols) = cells_along(px, grid.cell, plan.width, grid.cell, plan.periodic);
    let (rows, nrows) = cells_along(py, grid.cell, plan.height, grid.cell, plan.periodic);
    for &ny in &rows[..nrows] {
        for &nx in &cols[..ncols] {
            let c = (ny * grid.cols + nx) as usize;
            for di in &grid.entries[grid.start[c] as usize..grid.start[c + 1] as usize] {
                // Keys are unique, so a key beating j's is another dart's.
                if layout.beats(di.key, key_j)
                    && inside(
                        axis_delta(di.x, cx, period_x),
                        axis_delta(di.y, cy, period_y),
                        di.radius,
                    )
                {
                    return true;
                }
            }
        }
    }
    false
}

/// The darts that survive, in dart order, into `out`.
pub fn survivors(plan: &Plan, darts: &[Dart], grid: &DartGrid, out: &mut Vec<Dart>) {
    out.clear();
    out.par_extend(
        (0..darts.len() as u32)
            .into_par_iter()
            .filter(|&j| !occluded(plan, darts, grid, j))
            .map(|j| darts[j as usize]),
    );
}
