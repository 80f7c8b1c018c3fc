//! Coverage (paper §3.2, the second half of step S2) on the CPU: every
//! survivor marks the pixels whose centres lie within the policy's distance
//! f(r_sample, r_pixel) in the coverage map.
//!
//! WGSL mirror: `shaders/cover.wgsl`.

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

/// Rows per band: the coverage map is split into bands of rows that threads
/// own, so that spans are plain `fill`s and no atomics are needed.
pub const BAND_ROWS: u32 = 64;

/// The unwrapped rows whose centres may lie within reach of sample `s`.
fn row_range(plan: &Plan, s: &Dart) -> (i64, i64) {
    let one = 1i64 << POS_FRAC_BITS;
    let r = i64::from(reach(plan, s)) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    let cy = i64::from(s.y);
    // Rows whose centre q·256 + 128 lies strictly within r of cy.
    (
        -(-(cy - r + 1 - one / 2)).div_euclid(one),
        (cy + r - 1 - one / 2).div_euclid(one),
    )
}

/// Marks the pixels of rows `band.start..band.end` that sample `s` covers;
/// `cov` holds those rows.
fn cover_band(plan: &Plan, s: &Dart, band: std::ops::Range<u32>, cov: &mut [u8]) {
    let one = 1i64 << POS_FRAC_BITS;
    let half = one / 2;
    let r = i64::from(reach(plan, s)) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    let (cx, cy) = (i64::from(s.x), i64::from(s.y));
    let (y0, y1) = row_range(plan, s);
    let w = plan.width as usize;
    for qy in y0..=y1 {
        let Some(y) = wrap(qy, plan.height, plan.periodic).filter(|y| band.contains(y)) else {
            continue;
        };
        let row = &mut cov[(y - band.start) as usize * w..][..w];
        let dy = (qy * one + half - cy).unsigned_abs();
        let dx_max = isqrt((r * r) as u64 - dy * dy - 1) as i64;
        let x0 = -(-(cx - dx_max - half)).div_euclid(one);
        let x1 = (cx + dx_max - half).div_euclid(one);
        if plan.policy == Policy::Prior {
            fill_span(row, x0, x1, plan.periodic);
            continue;
        }
        for qx in x0..=x1 {
            let Some(x) = wrap(qx, plan.width, plan.periodic) else {
                continue;
            };
            let dx = (qx * one + half - cx).unsigned_abs() as u32;
            let f = plan
                .policy
                .coverage_radius(s.radius, plan.radius_at(y * plan.width + x));
            if inside(dx, dy as u32, f) {
                row[x as usize] = 1;
            }
        }
    }
}

/// Sets `row[x0..=x1]`, wrapping or clipping at the row's ends.
fn fill_span(row: &mut [u8], x0: i64, x1: i64, periodic: bool) {
    let n = row.len() as i64;
    if x0 > x1 {
        return;
    }
    if !periodic {
        let (a, b) = (x0.max(0), x1.min(n - 1));
        if a <= b {
            row[a as usize..=b as usize].fill(1);
        }
        return;
    }
    if x1 - x0 + 1 >= n {
        row.fill(1);
        return;
    }
    let (a, b) = (x0.rem_euclid(n), x1.rem_euclid(n));
    if a <= b {
        row[a as usize..=b as usize].fill(1);
    } else {
        row[a as usize..].fill(1);
        row[..=b as usize].fill(1);
    }
}

/// Marks the pixels that the survivors cover. Each band of [`BAND_ROWS`] rows
/// is one task: the map is the same for any thread count.
pub fn cover(plan: &Plan, survivors: &[Dart], coverage: &mut [u8]) {
    let bands = plan.height.div_ceil(BAND_ROWS) as usize;
    let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (i, s) in survivors.iter().enumerate() {
        let (y0, y1) = row_range(plan, s);
        let mut add = |y: u32| {
            let b = &mut buckets[(y / BAND_ROWS) as usize];
            if b.last() != Some(&(i as u32)) {
                b.push(i as u32);
            }
        };
        if plan.periodic {
            (y0..=y1)
                .filter_map(|q| wrap(q, plan.height, true))
                .for_each(add);
        } else {
            let (a, b) = (y0.max(0) as u32, y1.min(i64::from(plan.height) - 1) as u32);
            (a / BAND_ROWS..=b / BAND_ROWS).for_each(|band| add(band * BAND_ROWS));
        }
    }
    let band_px = (BAND_ROWS * plan.width) as usize;
    coverage
        .par_chunks_mut(band_px)
        .zip(buckets.par_iter())
        .enumerate()
        .for_each(|(b, (cov, list))| {
            let rows = b as u32 * BAND_ROWS..((b as u32 + 1) * BAND_ROWS).min(plan.height);
            for &i in list {
                cover_band(plan, &survivors[i as usize], rows.clone(), cov);
            }
        });
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::sampler::fixed::{axis_delta, mix, pixel_centre};
    use crate::sampler::{Params, RadiusMap};

    /// Covers random samples and compares every pixel with the rule itself.
    fn check(policy: Policy, periodic: bool) {
        let (w, h) = (150u32, 140u32);
        let radii: Vec<f32> = (0..w * h).map(|i| 2.0 + ((i % w) / 30) as f32).collect();
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        let plan = Params::new(w, h)
            .with_radius_map(map)
            .with_policy(policy)
            .with_periodic(periodic)
            .plan()
            .unwrap();
        let samples: Vec<Dart> = (0..200u32)
            .map(|k| {
                let r = mix(k);
                let pixel = r % (w * h);
                Dart {
                    x: (pixel % w) * 256 + (r >> 24),
                    y: (pixel / w) * 256 + ((r >> 16) & 255),
                    pixel,
                    radius: plan.radius_at(pixel),
                }
            })
            .collect();
        let mut cov = vec![0u8; (w * h) as usize];
        cover(&plan, &samples, &mut cov);
        let (px, py) = plan.periods();
        for p in 0..w * h {
            let want = samples.iter().any(|s| {
                let dx = axis_delta(s.x, pixel_centre(p % w), px);
                let dy = axis_delta(s.y, pixel_centre(p / w), py);
                inside(dx, dy, policy.coverage_radius(s.radius, plan.radius_at(p)))
            });
            assert_eq!(
                want,
                cov[p as usize] == 1,
                "{policy:?} periodic {periodic} pixel {p}"
            );
        }
    }

    #[test]
    fn cover_marks_exactly_the_pixels_within_the_policy_distance() {
        for policy in Policy::ALL {
            for periodic in [false, true] {
                check(policy, periodic);
            }
        }
    }
}
