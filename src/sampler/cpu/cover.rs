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

use super::prefetch;
use crate::sampler::fixed::{POS_FRAC_BITS, RADIUS_FRAC_BITS, RADIUS_ONE};
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
}

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

/// A block's side in pixels: coverage under Current, Bigger and Smaller
/// reads the smallest and largest radius of the 8×8 blocks a disk meets.
pub const BLOCK: u32 = 8;

/// Bytes of a block in [`Blocks`]' `fine`.
const FINE_BLOCK: usize = (BLOCK * BLOCK) as usize;

/// A `fine` offset that does not fit in a byte: the radius map is read.
const FINE_FAR: u8 = u8::MAX;

/// The smallest and largest pixel radius of every [`BLOCK`]² block of each
/// radius layer (one per class, then the cross radii with classes), and the
/// largest within reach of each block.
///
/// A sample covers pixel p when |p − c| < f(r_s, r_p), and every policy's f
/// grows with r_p: over a block whose radii lie in [lo, hi], the pixels
/// within f(r_s, lo) are covered whatever their radius, those beyond
/// f(r_s, hi) are not, and only the ring between reads its pixels' radii.
/// Under Smaller, where most blocks have lo ≥ r_s, a disk's rows are then
/// filled as under Prior.
pub(crate) struct Blocks {
    /// Blocks per row.
    cols: u32,
    /// Block rows per layer.
    rows: u32,
    /// `[lo, hi]` of each block, layer by layer, row-major.
    bounds: Vec<[u32; 2]>,
    /// Each pixel's radius minus its block's `lo`, [`FINE_FAR`] when that
    /// is too large for a byte; a block's 64 pixels together (row-major
    /// within the block), blocks as in `bounds`.
    fine: Vec<u8>,
    /// The largest `hi` of the blocks within `BLOCK`·`near_blocks` px of
    /// each block: every pixel a disk can cover (within the map's largest
    /// radius) lies there.
    near: Vec<u32>,
    /// Layers of one class each, before the cross layer.
    classes: u32,
}

impl Blocks {
    /// The blocks of `plan`'s radius map; `None` without one or under Prior,
    /// whose coverage does not read the pixels' radii.
    pub(crate) fn new(plan: &Plan) -> Option<Self> {
        let map = plan.map.as_ref()?;
        if plan.policy == Policy::Prior {
            return None;
        }
        let (w, h) = (plan.width, plan.height);
        let (cols, rows) = (w.div_ceil(BLOCK), h.div_ceil(BLOCK));
        let pixels = plan.pixels() as usize;
        let radii = map.radii_fx();
        let mut layers: Vec<&[u32]> = radii.chunks(pixels).collect();
        if plan.classes > 1 {
            layers.push(plan.cross.as_deref().map_or(&radii[..pixels], |c| &c[..]));
        }
        let per_layer = (cols * rows) as usize;
        let mut bounds = vec![[u32::MAX, 0]; per_layer * layers.len()];
        // Each pixel's radius over its block's smallest, blocks in a row
        // of 64 bytes: what a ring pixel reads (one cache line a block,
        // not one a row). Made with the bounds, a row of blocks at a time
        // while its rows are in the cache.
        let mut fine = vec![FINE_FAR; bounds.len() * FINE_BLOCK];
        bounds
            .par_chunks_mut(cols as usize)
            .zip(fine.par_chunks_mut(cols as usize * FINE_BLOCK))
            .enumerate()
            .for_each(|(i, (out, fine))| {
                let (layer, by) = (i / rows as usize, i as u32 % rows);
                let src = layers[layer];
                let ys = by * BLOCK..((by + 1) * BLOCK).min(h);
                let row = |y: u32| &src[(y * w) as usize..((y + 1) * w) as usize];
                for y in ys.clone() {
                    for (b, chunk) in out.iter_mut().zip(row(y).chunks(BLOCK as usize)) {
                        for &r in chunk {
                            b[0] = b[0].min(r);
                            b[1] = b[1].max(r);
                        }
                    }
                }
                for y in ys {
                    let dy = (y % BLOCK) as usize * BLOCK as usize;
                    for (bx, chunk) in row(y).chunks(BLOCK as usize).enumerate() {
                        let (lo, at) = (out[bx][0], bx * FINE_BLOCK + dy);
                        for (o, &r) in fine[at..at + chunk.len()].iter_mut().zip(chunk) {
                            *o = u8::try_from(r - lo).unwrap_or(FINE_FAR);
                        }
                    }
                }
            });
        // Pixels within the largest radius of a centre in a block lie
        // within this many pixels of the block, along each axis.
        let reach = i64::from(plan.radius_range.1.div_ceil(RADIUS_ONE));
        let b = i64::from(BLOCK);
        // A max filter over those blocks, one axis at a time.
        let along = |i: u32, n_blocks: u32, n_px: u32| {
            let mut out = Vec::new();
            let i = i64::from(i);
            for_each_run(
                i * b - reach,
                i * b + b - 1 + reach,
                n_px,
                plan.periodic,
                |_, a, z| {
                    out.extend(a / BLOCK as usize..=z / BLOCK as usize);
                },
            );
            debug_assert!(out.iter().all(|&j| j < n_blocks as usize));
            out
        };
        let near_cols: Vec<Vec<usize>> = (0..cols).map(|bx| along(bx, cols, w)).collect();
        let near_rows: Vec<Vec<usize>> = (0..rows).map(|by| along(by, rows, h)).collect();
        let mut across = vec![0u32; bounds.len()];
        across
            .par_chunks_mut(cols as usize)
            .zip(bounds.par_chunks(cols as usize))
            .for_each(|(out, row)| {
                for (n, js) in out.iter_mut().zip(&near_cols) {
                    *n = js.iter().map(|&j| row[j][1]).max().unwrap_or(0);
                }
            });
        let mut near = vec![0u32; bounds.len()];
        near.par_chunks_mut(cols as usize)
            .enumerate()
            .for_each(|(i, out)| {
                let (layer, by) = (i / rows as usize, i % rows as usize);
                let base = layer * per_layer;
                for &j in &near_rows[by] {
                    let row = &across[base + j * cols as usize..][..cols as usize];
                    for (n, &a) in out.iter_mut().zip(row) {
                        *n = (*n).max(a);
                    }
                }
            });
        Some(Self {
            cols,
            rows,
            bounds,
            fine,
            near,
            classes: plan.classes,
        })
    }

    /// The first block of the layer whose radii disk `s` compares with.
    #[inline]
    fn base(&self, s: &Disk) -> usize {
        let layer = if s.own { s.layer } else { self.classes };
        (layer * self.cols * self.rows) as usize
    }

    /// The largest pixel radius within reach of disk `s`'s centre.
    fn near(&self, s: &Disk) -> u32 {
        let (bx, by) = (
            (s.x >> POS_FRAC_BITS) / BLOCK,
            (s.y >> POS_FRAC_BITS) / BLOCK,
        );
        self.near[self.base(s) + (by * self.cols + bx) as usize]
    }

    /// The smallest and largest radius over the blocks that hold the
    /// unwrapped pixels `x0..=x1` of row `y` of disk `s`'s layer.
    fn row_bounds(&self, plan: &Plan, s: &Disk, y: u32, (x0, x1): (i64, i64)) -> [u32; 2] {
        let row = self.block_row(s, y);
        let mut out = [u32::MAX, 0];
        for_each_run(x0, x1, plan.width, plan.periodic, |_, a, z| {
            for [lo, hi] in &row[a / BLOCK as usize..=z / BLOCK as usize] {
                out = [out[0].min(*lo), out[1].max(*hi)];
            }
        });
        out
    }

    /// The radius of pixel `x` of row `y` of disk `s`'s layer, read from
    /// its block (`radii`, that row of the map, when it does not fit).
    #[inline]
    fn radius(&self, s: &Disk, x: u32, y: u32, radii: &[u32]) -> u32 {
        let block = self.base(s) + (y / BLOCK * self.cols + x / BLOCK) as usize;
        let off = self.fine[block * FINE_BLOCK + ((y % BLOCK) * BLOCK + x % BLOCK) as usize];
        if off == FINE_FAR {
            radii[x as usize]
        } else {
            self.bounds[block][0] + u32::from(off)
        }
    }

    /// Asks the cache for the bytes of the blocks at the ends of disk `s`'s
    /// rows at its own radius: where its ring lies when the pixel radii near
    /// it are close to its own (under Current and Bigger the ring may lie
    /// farther out, and is then read as without the hint). A hint, no result.
    #[inline]
    fn prefetch(&self, plan: &Plan, s: &Disk) {
        let r = i64::from(s.radius.div_ceil(RADIUS_ONE));
        let (x, y) = (
            i64::from(s.x >> POS_FRAC_BITS),
            i64::from(s.y >> POS_FRAC_BITS),
        );
        let (w, h) = (i64::from(plan.width), i64::from(plan.height));
        let block = |q: i64, n: i64| (q.clamp(0, n - 1) / i64::from(BLOCK)) as usize;
        let (left, right) = (block(x - r, w), block(x + r, w));
        let base = self.base(s);
        for by in block(y - r, h)..=block(y + r, h) {
            let row = base + by * self.cols as usize;
            prefetch(&self.fine[(row + left) * FINE_BLOCK]);
            if right != left {
                prefetch(&self.fine[(row + right) * FINE_BLOCK]);
            }
        }
    }

    /// The bounds of the blocks of row `y` of disk `s`'s layer.
    #[inline]
    fn block_row(&self, s: &Disk, y: u32) -> &[[u32; 2]] {
        let row = self.base(s) + (y / BLOCK * self.cols) as usize;
        &self.bounds[row..row + self.cols as usize]
    }

    /// The largest radius within reach of each block, layer by layer, row
    /// by row: what the GPU's cover reads (`shaders/cover.wgsl`, `near`).
    #[cfg(feature = "gpu")]
    pub(crate) fn near_all(&self) -> &[u32] {
        &self.near
    }

    /// The blocks of `plan`'s layers: the length of `Self::near_all`.
    #[cfg(feature = "gpu")]
    pub(crate) fn count(plan: &Plan) -> usize {
        let layers = plan.classes + u32::from(plan.classes > 1);
        (plan.width.div_ceil(BLOCK) * plan.height.div_ceil(BLOCK) * layers) as usize
    }

    /// Bytes held.
    pub(crate) fn bytes(&self) -> usize {
        8 * self.bounds.capacity() + self.fine.capacity() + 4 * self.near.capacity()
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

/// Calls `f(q0, x0, x1)` for each run of the unwrapped pixels `a..=z` of a
/// row of `n` pixels that is contiguous on the domain: `x0..=x1` wrapped,
/// `q0` the unwrapped index of `x0`. Off a periodic domain, the pixels off
/// its edges are dropped.
fn for_each_run(a: i64, z: i64, n: u32, periodic: bool, mut f: impl FnMut(i64, usize, usize)) {
    let n = i64::from(n);
    if !periodic {
        let (a, z) = (a.max(0), z.min(n - 1));
        if a <= z {
            f(a, a as usize, z as usize);
        }
        return;
    }
    let mut q = a;
    while q <= z {
        let k = q.div_euclid(n);
        let end = z.min(k * n + n - 1);
        f(q, (q - k * n) as usize, (end - k * n) as usize);
        q = end + 1;
    }
}

/// Sets pixels `x0..=x1` of the `n`-pixel row starting at bit `row`,
/// wrapping or clipping at the row's ends.
pub(crate) fn fill_span(cov: &mut [u64], row: usize, n: usize, x0: i64, x1: i64, periodic: bool) {
    for_each_run(x0, x1, n as u32, periodic, |_, a, z| {
        set_bits(cov, row + a, row + z)
    });
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
    for_each_bucket(plan, coverage, buckets, |list, rows, cov| {
        for s in list {
            mark(s, rows.clone(), cov);
        }
    });
}

/// Runs `mark(bucket, rows, words)` for every band's bucket, one task per
/// band of [`BAND_ROWS`] rows, `words` the band's part of the coverage map.
fn for_each_bucket<T: Sync>(
    plan: &Plan,
    coverage: &mut [u64],
    buckets: &[Vec<T>],
    mark: impl Fn(&[T], std::ops::Range<u32>, &mut [u64]) + Sync,
) {
    let band_words = (BAND_ROWS * plan.width / 64) as usize;
    coverage
        .par_chunks_mut(band_words)
        .zip(buckets.par_iter())
        .enumerate()
        .for_each(|(b, (cov, list))| {
            let rows = b as u32 * BAND_ROWS..((b as u32 + 1) * BAND_ROWS).min(plan.slot_rows());
            mark(list, rows, cov);
        });
}

/// Marks the slots that the survivors cover, on every class's layer. Each
/// band of [`BAND_ROWS`] slot rows is one task: the map is the same for any
/// thread count.
pub(crate) fn cover(
    plan: &Plan,
    blocks: Option<&Blocks>,
    survivors: &[Dart],
    coverage: &mut [u64],
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
        cover(&plan, Blocks::new(&plan).as_ref(), &samples, &mut cov);
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
