//! Coverage (paper §3.2, the second half of step S2) on the CPU: every
//! survivor marks the pixels whose centres lie within the policy's distance
//! f(r_sample, r_pixel) in the coverage map.
//!
//! The map is a bitmap, as on the GPU: pixel `p` is bit `p % 64` of word
//! `p / 64`. A band of [`BAND_ROWS`] rows is `BAND_ROWS * width` pixels, a
//! whole number of words, so threads own whole words.
//!
//! WGSL mirror: `shaders/cover.wgsl`.

use rayon::prelude::*;

use crate::sampler::fixed::{POS_FRAC_BITS, RADIUS_FRAC_BITS, inside};
use crate::sampler::{Dart, Plan, Policy};

/// A sample's disk on one class's layer of the coverage map: its own
/// radius on its own layer, the cross-class radius on the others. Without
/// classes every sample has one disk, on layer 0, of its own radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Disk {
    /// x in 1/256 px.
    x: u32,
    /// y in 1/256 px, within the layer.
    y: u32,
    /// The disk's radius in 1/64 px.
    radius: u32,
    /// The layer (class) it covers.
    layer: u32,
    /// Whether the layer is the sample's own class.
    own: bool,
}

impl Disk {
    /// The disks of sample `s` on every layer.
    fn of(plan: &Plan, s: &Dart) -> impl Iterator<Item = Self> {
        let (class, local) = (s.pixel / plan.pixels(), s.pixel % plan.pixels());
        let cross = if plan.classes == 1 {
            s.radius
        } else {
            plan.cross_at(local)
        };
        (0..plan.classes).map(move |layer| Self {
            x: s.x,
            y: s.y,
            radius: if layer == class { s.radius } else { cross },
            layer,
            own: layer == class,
        })
    }

    /// The radius (1/64 px) of pixel `p` of this disk's layer that the
    /// policy compares with: the class's own, or the cross radius.
    #[inline]
    fn pixel_radius(&self, plan: &Plan, p: u32) -> u32 {
        if self.own {
            plan.radius_at(self.layer * plan.pixels() + p)
        } else {
            plan.cross_at(p)
        }
    }
}

/// The largest distance (1/64 px) at which disk `s` can cover a pixel.
#[must_use]
fn reach(plan: &Plan, s: &Disk) -> u32 {
    match plan.policy {
        Policy::Prior | Policy::Smaller => s.radius,
        Policy::Current | Policy::Bigger => s.radius.max(plan.radius_range.1),
    }
}

/// The largest `d >= 0` with `d * d <= m`.
pub(crate) fn isqrt(m: u64) -> u64 {
    // m < 2^62, so the signed conversions (one instruction each) are exact
    // enough for the corrections below to finish in a step or two.
    let mut d = (m as i64 as f64).sqrt() as i64 as u64;
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
/// own, so that no atomics are needed. 64, so that a band is whole words.
pub const BAND_ROWS: u32 = 64;

/// An empty coverage map for `pixels` pixels. The bits past the last pixel
/// are set, so that they never read as empty.
#[must_use]
pub fn new_map(pixels: u32) -> Vec<u64> {
    let mut map = vec![0u64; pixels.div_ceil(64) as usize];
    if let Some(last) = map.last_mut().filter(|_| !pixels.is_multiple_of(64)) {
        *last = !0u64 << (pixels % 64);
    }
    map
}

/// Whether pixel `p` is covered.
#[inline]
#[must_use]
pub fn is_covered(map: &[u64], p: u32) -> bool {
    map[(p / 64) as usize] >> (p % 64) & 1 == 1
}

/// Sets bits `lo..=hi` of `map`.
#[inline]
fn set_bits(map: &mut [u64], lo: usize, hi: usize) {
    let (wl, wh) = (lo / 64, hi / 64);
    let (ml, mh) = (!0u64 << (lo % 64), !0u64 >> (63 - hi % 64));
    if wl == wh {
        map[wl] |= ml & mh;
    } else {
        map[wl] |= ml;
        map[wl + 1..wh].fill(!0);
        map[wh] |= mh;
    }
}

/// The unwrapped rows of its layer whose centres may lie within reach of `s`.
fn row_range(plan: &Plan, s: &Disk) -> (i64, i64) {
    let one = 1i64 << POS_FRAC_BITS;
    let r = i64::from(reach(plan, s)) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    let cy = i64::from(s.y);
    // Rows whose centre q·256 + 128 lies strictly within r of cy.
    (
        -(-(cy - r + 1 - one / 2)).div_euclid(one),
        (cy + r - 1 - one / 2).div_euclid(one),
    )
}

/// Marks the pixels of the slot rows `band.start..band.end` (rows of the
/// stacked layers) that disk `s` covers; `cov` holds those rows.
fn cover_band(plan: &Plan, s: &Disk, band: std::ops::Range<u32>, cov: &mut [u64]) {
    let one = 1i64 << POS_FRAC_BITS;
    let half = one / 2;
    let r = i64::from(reach(plan, s)) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    let (cx, cy) = (i64::from(s.x), i64::from(s.y));
    let (y0, y1) = row_range(plan, s);
    let w = plan.width as usize;
    let top = i64::from(s.layer * plan.height);
    // Off a periodic domain, only the band's own rows are visited.
    let (y0, y1) = if plan.periodic {
        (y0, y1)
    } else {
        (
            y0.max(i64::from(band.start) - top),
            y1.min(i64::from(band.end) - 1 - top),
        )
    };
    for qy in y0..=y1 {
        let Some(y) = wrap(qy, plan.height, plan.periodic) else {
            continue;
        };
        let sy = s.layer * plan.height + y;
        if !band.contains(&sy) {
            continue;
        }
        let row = (sy - band.start) as usize * w;
        let dy = (qy * one + half - cy).unsigned_abs();
        let dx_max = isqrt((r * r) as u64 - dy * dy - 1) as i64;
        let x0 = -(-(cx - dx_max - half)).div_euclid(one);
        let x1 = (cx + dx_max - half).div_euclid(one);
        if plan.policy == Policy::Prior {
            fill_span(cov, row, w, x0, x1, plan.periodic);
            continue;
        }
        for qx in x0..=x1 {
            let Some(x) = wrap(qx, plan.width, plan.periodic) else {
                continue;
            };
            let dx = (qx * one + half - cx).unsigned_abs() as u32;
            let f = plan
                .policy
                .coverage_radius(s.radius, s.pixel_radius(plan, y * plan.width + x));
            if inside(dx, dy as u32, f) {
                let p = row + x as usize;
                cov[p / 64] |= 1 << (p % 64);
            }
        }
    }
}

/// Sets pixels `x0..=x1` of the `n`-pixel row starting at bit `row`,
/// wrapping or clipping at the row's ends.
pub(crate) fn fill_span(cov: &mut [u64], row: usize, n: usize, x0: i64, x1: i64, periodic: bool) {
    let n = n as i64;
    if x0 > x1 {
        return;
    }
    let mut set = |a: i64, b: i64| set_bits(cov, row + a as usize, row + b as usize);
    if !periodic {
        let (a, b) = (x0.max(0), x1.min(n - 1));
        if a <= b {
            set(a, b);
        }
        return;
    }
    if x1 - x0 + 1 >= n {
        set(0, n - 1);
        return;
    }
    let (a, b) = (x0.rem_euclid(n), x1.rem_euclid(n));
    if a <= b {
        set(a, b);
    } else {
        set(a, n - 1);
        set(0, b);
    }
}

/// Runs `mark(item, rows, words)` for every item of every band's bucket,
/// one task per band of [`BAND_ROWS`] rows, `words` the band's part of the
/// coverage map: the map is the same for any thread count.
pub(crate) fn for_each_band<T: Sync>(
    plan: &Plan,
    coverage: &mut [u64],
    buckets: &[Vec<T>],
    mark: impl Fn(&T, std::ops::Range<u32>, &mut [u64]) + Sync,
) {
    let band_words = (BAND_ROWS * plan.width / 64) as usize;
    coverage
        .par_chunks_mut(band_words)
        .zip(buckets.par_iter())
        .enumerate()
        .for_each(|(b, (cov, list))| {
            let rows = b as u32 * BAND_ROWS..((b as u32 + 1) * BAND_ROWS).min(plan.slot_rows());
            for s in list {
                mark(s, rows.clone(), cov);
            }
        });
}

/// Marks the slots that the survivors cover, on every class's layer. Each
/// band of [`BAND_ROWS`] slot rows is one task: the map is the same for any
/// thread count.
pub fn cover(plan: &Plan, survivors: &[Dart], coverage: &mut [u64]) {
    let bands = plan.slot_rows().div_ceil(BAND_ROWS) as usize;
    // Copies, not indices: a band then reads its disks in sequence.
    let mut buckets: Vec<Vec<Disk>> = vec![Vec::new(); bands];
    for s in survivors.iter().flat_map(|s| Disk::of(plan, s)) {
        let (y0, y1) = row_range(plan, &s);
        let top = s.layer * plan.height;
        let mut add = |y: u32| {
            let b = &mut buckets[((top + y) / BAND_ROWS) as usize];
            if b.last() != Some(&s) {
                b.push(s);
            }
        };
        if plan.periodic {
            (y0..=y1)
                .filter_map(|q| wrap(q, plan.height, true))
                .for_each(add);
        } else {
            let (a, b) = (y0.max(0) as u32, y1.min(i64::from(plan.height) - 1) as u32);
            if a > b {
                continue;
            }
            // Every band the rows a..=b of the layer touch.
            ((top + a) / BAND_ROWS..=(top + b) / BAND_ROWS)
                .for_each(|band| add((band * BAND_ROWS).max(top + a) - top));
        }
    }
    for_each_band(plan, coverage, &buckets, |s, rows, cov| {
        cover_band(plan, s, rows, cov)
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
        let mut cov = new_map(w * h);
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
                is_covered(&cov, p),
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
