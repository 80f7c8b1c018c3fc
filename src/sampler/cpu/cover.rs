//! Coverage (paper §3.2, the second half of step S2) on the CPU: every
//! survivor marks the pixels whose centres lie within the policy's distance
//! f(r_sample, r_pixel) in the coverage map.
//!
//! WGSL mirror: `shaders/cover.wgsl`.

use std::sync::atomic::{AtomicU8, Ordering};

use rayon::prelude::*;

use super::throw::Dart;
use crate::sampler::fixed::{POS_FRAC_BITS, RADIUS_FRAC_BITS, inside};
use crate::sampler::{Plan, Policy};

/// The largest distance (1/64 px) at which sample `s` can cover a pixel.
#[must_use]
pub fn reach(plan: &Plan, s: &Dart) -> u32 {
    match plan.policy {
        Policy::Prior | Policy::Smaller => s.radius,
        Policy::Current | Policy::Bigger => s.radius.max(plan.radius_range.1),
    }
}

/// The largest `d >= 0` with `d * d <= m`.
fn isqrt(m: u64) -> u64 {
    let mut d = (m as f64).sqrt() as u64;
    while d * d > m {
        d -= 1;
    }
    while (d + 1) * (d + 1) <= m {
        d += 1;
    }
    d
}

/// Maps an unwrapped pixel index onto the domain, or `None` off its edge.
fn wrap(q: i64, n: u32, periodic: bool) -> Option<u32> {
    if periodic {
        Some(q.rem_euclid(i64::from(n)) as u32)
    } else {
        u32::try_from(q).ok().filter(|&q| q < n)
    }
}

/// Marks the pixels that sample `s` covers.
fn cover_one(plan: &Plan, s: &Dart, coverage: &[AtomicU8]) {
    let one = 1i64 << POS_FRAC_BITS;
    let half = one / 2;
    let r = i64::from(reach(plan, s)) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    let (cx, cy) = (i64::from(s.x), i64::from(s.y));
    // Rows whose centre q·256 + 128 lies strictly within r of cy.
    let y0 = -(-(cy - r + 1 - half)).div_euclid(one);
    let y1 = (cy + r - 1 - half).div_euclid(one);
    for qy in y0..=y1 {
        let Some(y) = wrap(qy, plan.height, plan.periodic) else {
            continue;
        };
        let dy = (qy * one + half - cy).unsigned_abs();
        let dx_max = isqrt((r * r) as u64 - dy * dy - 1) as i64;
        let x0 = -(-(cx - dx_max - half)).div_euclid(one);
        let x1 = (cx + dx_max - half).div_euclid(one);
        for qx in x0..=x1 {
            let Some(x) = wrap(qx, plan.width, plan.periodic) else {
                continue;
            };
            let p = y * plan.width + x;
            let covered = plan.policy == Policy::Prior || {
                let dx = (qx * one + half - cx).unsigned_abs() as u32;
                let f = plan.policy.coverage_radius(s.radius, plan.radius_at(p));
                inside(dx, dy as u32, f)
            };
            if covered {
                coverage[p as usize].store(1, Ordering::Relaxed);
            }
        }
    }
}

/// Marks the pixels that the survivors cover. Order-independent: every store
/// writes the same 1, so the map is the same for any thread count.
pub fn cover(plan: &Plan, survivors: &[Dart], coverage: &[AtomicU8]) {
    survivors
        .par_iter()
        .for_each(|s| cover_one(plan, s, coverage));
}
