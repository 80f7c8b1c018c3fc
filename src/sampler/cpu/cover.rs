//! Coverage (paper §3.2, the second half of step S2) on the CPU: every
//! survivor marks the pixels whose centres lie within the policy's distance
//! f(r_sample, r_pixel) in the coverage map.
//!
//! The map and the radius blocks are the sampler's
//! ([`crate::sampler::coverage`]): a bitmap, as on the GPU, pixel `p` bit
//! `p % 64` of word `p / 64`, in bands of [`BAND_ROWS`] rows that threads
//! own.
//!
//! WGSL mirror: `shaders/cover.wgsl`.

use rayon::prelude::*;

use crate::sampler::coverage::{
    BAND_ROWS, BLOCK, Blocks, Disk, fill_span, for_each_bucket, isqrt, set_bits,
};
use crate::sampler::fixed::{POS_FRAC_BITS, RADIUS_FRAC_BITS};
use crate::sampler::{Control, Dart, Plan, Policy};

/// The largest distance (1/64 px) at which disk `s` can cover a pixel: its
/// radius under Prior and Smaller; under Current and Bigger, f(r_s, r) for
/// the largest pixel radius r near it (the map's largest without blocks).
#[must_use]
fn reach(plan: &Plan, blocks: Option<&Blocks>, s: &Disk) -> u32 {
    match (plan.policy, blocks) {
        (Policy::Prior | Policy::Smaller, _) => s.radius,
        (policy, Some(b)) => policy.coverage_radius(s.radius, b.near(s)),
        (Policy::Current | Policy::Bigger, None) => s.radius.max(plan.radius_range.1),
    }
}

/// Maps an unwrapped pixel index onto the domain, or `None` off its edge.
fn wrap(q: i64, n: u32, periodic: bool) -> Option<u32> {
    if periodic {
        Some(q.rem_euclid(i64::from(n)) as u32)
    } else {
        u32::try_from(q).ok().filter(|&q| q < n)
    }
}

/// The unwrapped rows of its layer whose centres lie within `reach` (1/64
/// px) of `s`'s centre.
fn row_range(s: &Disk, reach: u32) -> (i64, i64) {
    let one = 1i64 << POS_FRAC_BITS;
    let r = i64::from(reach) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    let cy = i64::from(s.y);
    // Rows whose centre q·256 + 128 lies strictly within r of cy.
    (
        -(-(cy - r + 1 - one / 2)).div_euclid(one),
        (cy + r - 1 - one / 2).div_euclid(one),
    )
}

/// Whether a row `dy` (1/256 px) from a centre has pixels within `f` (1/64
/// px) of it, as [`span`] finds them: a test without the square root.
#[inline]
fn reaches(dy: u64, f: u32) -> bool {
    (u64::from(f) << (POS_FRAC_BITS - RADIUS_FRAC_BITS)) > dy
}

/// The first and last unwrapped pixel of a row `dy` (1/256 px) from centre
/// x `cx` whose centres lie strictly within `f` (1/64 px), or `None`.
#[inline]
fn span(cx: i64, dy: u64, f: u32) -> Option<(i64, i64)> {
    let one = 1i64 << POS_FRAC_BITS;
    let half = one / 2;
    let r = u64::from(f) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    if !reaches(dy, f) {
        return None;
    }
    let dx_max = isqrt(r * r - dy * dy - 1) as i64;
    Some((
        -(-(cx - dx_max - half)).div_euclid(one),
        (cx + dx_max - half).div_euclid(one),
    ))
}

/// Marks the pixels of the slot rows `band.start..band.end` (rows of the
/// stacked layers) that disk `s` covers; `cov` holds those rows.
fn cover_band(
    plan: &Plan,
    blocks: Option<&Blocks>,
    s: &Disk,
    band: std::ops::Range<u32>,
    cov: &mut [u64],
) {
    let one = 1i64 << POS_FRAC_BITS;
    let half = one / 2;
    let (cx, cy) = (i64::from(s.x), i64::from(s.y));
    let reach = reach(plan, blocks, s);
    let (y0, y1) = row_range(s, reach);
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
    if blocks.is_none() && !plan.periodic {
        // One distance for every pixel, on a domain with edges: each row's
        // span straight into the band's words.
        let f = i64::from(reach) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
        let Some(ff) = (f * f).checked_sub(1) else {
            return;
        };
        let ff = ff as u64;
        let last = i64::from(plan.width) - 1;
        for qy in y0.max(0)..=y1.min(i64::from(plan.height) - 1) {
            let sy = s.layer * plan.height + qy as u32;
            if !band.contains(&sy) {
                continue;
            }
            let dy = (qy * one + half - cy).unsigned_abs();
            let Some(left) = ff.checked_sub(dy * dy) else {
                continue;
            };
            let dx = isqrt(left) as i64;
            // Pixels whose centres x·256 + 128 lie within dx of cx.
            let x0 = ((cx - dx - half + one - 1) >> POS_FRAC_BITS).max(0);
            let x1 = ((cx + dx - half) >> POS_FRAC_BITS).min(last);
            if x0 <= x1 {
                let row = (sy - band.start) as usize * w;
                set_bits(cov, row + x0 as usize, row + x1 as usize);
            }
        }
        return;
    }
    // The bounds of the last row of blocks: (its index, [lo, hi]).
    let mut bounds: Option<(u32, [u32; 2])> = None;
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
        let Some(b) = blocks else {
            // Every pixel within reach is covered.
            if let Some((x0, x1)) = span(cx, dy, reach) {
                fill_span(cov, row, w, x0, x1, plan.periodic);
            }
            continue;
        };
        if !reaches(dy, reach) {
            continue;
        }
        // The blocks bound f over the span: one f for all its pixels fills
        // the span as under Prior, else the ring where f varies reads its
        // pixels' radii. The bounds are taken once per row of blocks, over
        // the disk's widest row in it (a span that holds every other's).
        let by = y / BLOCK;
        let [lo, hi] = match bounds {
            Some((at, bounds)) if at == by => bounds,
            _ => {
                let first = qy - i64::from(y % BLOCK);
                let widest = (cy >> POS_FRAC_BITS).clamp(first, first + i64::from(BLOCK) - 1);
                let dy_w = (widest * one + half - cy).unsigned_abs();
                // The widest row is no farther from the centre than this
                // one, so its span is not empty.
                let Some(wide) = span(cx, dy_w, reach) else {
                    continue;
                };
                let got = b.row_bounds(plan, s, y, wide);
                bounds = Some((by, got));
                got
            }
        };
        if lo > hi {
            // No pixel of the span lies on the domain.
            continue;
        }
        // The span of f_hi, the largest distance at which the row's pixels
        // can be covered: the only square root of the row (the reach's span
        // is not needed where the blocks bound f).
        let f_hi = plan.policy.coverage_radius(s.radius, hi);
        let Some((a, z)) = span(cx, dy, f_hi) else {
            continue;
        };
        let f_lo = plan.policy.coverage_radius(s.radius, lo);
        if f_lo == f_hi {
            fill_span(cov, row, w, a, z, plan.periodic);
            continue;
        }
        // Within f_lo every pixel is covered whatever its radius: only the
        // ring between f_lo and f_hi reads the pixels' radii.
        let ring = Ring {
            s,
            y,
            row,
            dy,
            f_lo,
        };
        ring.cover(plan, b, (a, z), cov);
    }
}

/// The pixels of one row of a disk's span whose coverage radius varies,
/// between f_lo and f_hi.
struct Ring<'a> {
    /// The disk.
    s: &'a Disk,
    /// The row within the disk's layer.
    y: u32,
    /// The row's first bit in the band's words.
    row: usize,
    /// The row's distance from the disk's centre, 1/256 px.
    dy: u64,
    /// The coverage radius of the row's smallest pixel radius (1/64 px).
    f_lo: u32,
}

impl Ring<'_> {
    /// Marks the covered pixels of the unwrapped span `a..=z` (f_hi's).
    /// The pixels within f_lo are one run, so the ring is walked in from
    /// both ends until a pixel lies within f_lo and the run between is
    /// filled: the ring is mostly a pixel wide, or none.
    fn cover(&self, plan: &Plan, b: &Blocks, (a, z): (i64, i64), cov: &mut [u64]) {
        let one = 1i64 << POS_FRAC_BITS;
        let (s, y, row) = (self.s, self.y, self.row);
        let cx = i64::from(s.x) - one / 2;
        let (policy, r_s, dy2) = (plan.policy, s.radius, self.dy * self.dy);
        let within = |q: i64, f: u32| {
            let dx = (q * one - cx).unsigned_abs();
            let f = u64::from(f) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
            dx * dx + dy2 < f * f
        };
        let radii = radius_row(plan, s, y);
        // A ring pixel's own block mostly decides it: its radius is read
        // only when f over the block's radii straddles the pixel.
        let block_row = b.block_row(s, y);
        let mut test = |q: i64| {
            if let Some(x) = wrap(q, plan.width, plan.periodic) {
                let [lo, hi] = block_row[(x / BLOCK) as usize];
                let covered = within(q, policy.coverage_radius(r_s, lo))
                    || (within(q, policy.coverage_radius(r_s, hi))
                        && within(q, policy.coverage_radius(r_s, b.radius(s, x, y, radii))));
                if covered {
                    let bit = row + x as usize;
                    cov[bit / 64] |= 1 << (bit % 64);
                }
            }
        };
        let mut ia = a;
        while ia <= z && !within(ia, self.f_lo) {
            test(ia);
            ia += 1;
        }
        if ia > z {
            return;
        }
        let mut iz = z;
        while !within(iz, self.f_lo) {
            test(iz);
            iz -= 1;
        }
        fill_span(cov, row, plan.width as usize, ia, iz, plan.periodic);
    }
}

/// The pixel radii (1/64 px) of row `y` of the layer disk `s` compares with.
fn radius_row<'p>(plan: &'p Plan, s: &Disk, y: u32) -> &'p [u32] {
    let w = plan.width as usize;
    let at = y as usize * w;
    match (&plan.map, &plan.cross, s.own) {
        (Some(m), _, true) => &m.radii_fx()[s.layer as usize * plan.pixels() as usize + at..][..w],
        (_, Some(c), false) => &c[at..at + w],
        (Some(m), None, false) => &m.radii_fx()[at..at + w],
        (None, ..) => unreachable!("blocks need a radius map"),
    }
}

/// Marks the slots that the survivors cover, on every class's layer. Each
/// band of [`BAND_ROWS`] slot rows is one task: the map is the same for any
/// thread count. Each band first polls `ctl`'s cancel: a cancelled map is
/// left unfinished, and the caller throws the iteration away.
pub(crate) fn cover(
    plan: &Plan,
    blocks: Option<&Blocks>,
    survivors: &[Dart],
    coverage: &mut [u64],
    ctl: &Control<'_>,
) {
    let bands = plan.slot_rows().div_ceil(BAND_ROWS) as usize;
    // Copies, not indices: a band then reads its disks in sequence.
    let mut buckets: Vec<Vec<Disk>> = vec![Vec::new(); bands];
    for s in survivors.iter().flat_map(|s| Disk::of(plan, s)) {
        let (y0, y1) = row_range(&s, reach(plan, blocks, &s));
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
    if blocks.is_some() {
        // Disks that read pixel radii read them left to right: the radius
        // map's band is too large for the cache in any other order. Bits
        // are only ever set, so the order does not change the map.
        buckets
            .par_iter_mut()
            .for_each(|b| b.sort_unstable_by_key(|d| d.x));
    }
    // The ring's pixels read the blocks' bytes at the ends of the disk's
    // rows, lines of a table too large for the cache: they are asked for a
    // few disks ahead, so that they arrive while the disks before are
    // covered (half the ring's time was spent waiting on them).
    for_each_bucket(plan, coverage, &buckets, |list, rows, cov| {
        if ctl.cancelled() {
            return;
        }
        for (k, s) in list.iter().enumerate() {
            if let (Some(b), Some(ahead)) = (blocks, list.get(k + PREFETCH_AHEAD)) {
                b.prefetch(plan, ahead);
            }
            cover_band(plan, blocks, s, rows.clone(), cov);
        }
    });
}

/// Disks ahead of the one covered whose blocks' bytes are asked for.
const PREFETCH_AHEAD: usize = 4;

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::sampler::coverage::{is_covered, new_map};
    use crate::sampler::fixed::{axis_delta, inside, mix, pixel_centre};
    use crate::sampler::{Params, RadiusMap};

    /// Covers random samples and compares every pixel with the rule itself.
    fn check(policy: Policy, periodic: bool, noise: bool) {
        let (w, h) = (150u32, 141u32);
        // Steps of 1 px every 30 columns, and with noise: radii that differ
        // within most 8×8 blocks (1/64 px steps), some blocks flat.
        let radii: Vec<f32> = (0..w * h)
            .map(|i| {
                let step = 2.0 + ((i % w) / 30) as f32;
                let flat = (i / w / 24) % 2 == 0;
                if noise && !flat {
                    step + (mix(i) % 256) as f32 / 64.0
                } else {
                    step
                }
            })
            .collect();
        let map = Arc::new(RadiusMap::from_pixels(w, h, &radii).unwrap());
        let plan = Params::new(w, h)
            .with_radius_map(map)
            .with_policy(policy)
            .with_periodic(periodic)
            .plan()
            .unwrap();
        let samples: Vec<Dart> = (0..400u32)
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
        cover(
            &plan,
            Blocks::new(&plan).as_ref(),
            &samples,
            &mut cov,
            &Control::new(),
        );
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
                "{policy:?} periodic {periodic} noise {noise} pixel {p}"
            );
        }
    }

    #[test]
    fn cover_marks_exactly_the_pixels_within_the_policy_distance() {
        for policy in Policy::ALL {
            for periodic in [false, true] {
                for noise in [false, true] {
                    check(policy, periodic, noise);
                }
            }
        }
    }
}
