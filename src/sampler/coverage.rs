//! The coverage map every backend shares (paper §3.2): a bitmap of the
//! pixels (slots, with classes) that accepted samples cover, in bands of
//! rows that threads own, and the radius blocks that bound how far a disk
//! can cover under the policies that read the pixels' radii. The CPU
//! backend's cover stage (`cpu/cover.rs`), exact mode and the GPU backend
//! (which sizes its buffers from [`Blocks`]) all use them.

use rayon::prelude::*;

use super::fixed::{POS_FRAC_BITS, RADIUS_ONE};
use super::{Dart, Plan, Policy};

/// Asks the cache for the line holding `at`: a hint that changes no result.
#[inline]
pub(crate) fn prefetch<T>(at: &T) {
    #[cfg(target_arch = "x86_64")]
    #[expect(
        unsafe_code,
        reason = "_mm_prefetch takes a raw pointer; a prefetch never faults, and this one is of a live reference"
    )]
    // SAFETY: `at` is a valid reference; prefetching reads nothing back.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(at).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = at;
}

/// A sample's disk on one class's layer of the coverage map: its own
/// radius on its own layer, the cross-class radius on the others. Without
/// classes every sample has one disk, on layer 0, of its own radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Disk {
    /// x in 1/256 px.
    pub(crate) x: u32,
    /// y in 1/256 px, within the layer.
    pub(crate) y: u32,
    /// The disk's radius in 1/64 px.
    pub(crate) radius: u32,
    /// The layer (class) it covers.
    pub(crate) layer: u32,
    /// Whether the layer is the sample's own class.
    pub(crate) own: bool,
}

impl Disk {
    /// The disks of sample `s` on every layer.
    pub(crate) fn of(plan: &Plan, s: &Dart) -> impl Iterator<Item = Self> {
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
        // Filled in parallel: 1 byte a pixel, whose first touch (the
        // pages' faults) was a tenth of a 100K-dot drawing's sampling on
        // one core.
        let mut fine = Vec::with_capacity(bounds.len() * FINE_BLOCK);
        fine.par_extend(rayon::iter::repeat_n(FINE_FAR, bounds.len() * FINE_BLOCK));
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
    pub(crate) fn base(&self, s: &Disk) -> usize {
        let layer = if s.own { s.layer } else { self.classes };
        (layer * self.cols * self.rows) as usize
    }

    /// The largest pixel radius within reach of disk `s`'s centre.
    pub(crate) fn near(&self, s: &Disk) -> u32 {
        let (bx, by) = (
            (s.x >> POS_FRAC_BITS) / BLOCK,
            (s.y >> POS_FRAC_BITS) / BLOCK,
        );
        self.near[self.base(s) + (by * self.cols + bx) as usize]
    }

    /// The smallest and largest radius over the blocks that hold the
    /// unwrapped pixels `x0..=x1` of row `y` of disk `s`'s layer.
    pub(crate) fn row_bounds(
        &self,
        plan: &Plan,
        s: &Disk,
        y: u32,
        (x0, x1): (i64, i64),
    ) -> [u32; 2] {
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
    pub(crate) fn radius(&self, s: &Disk, x: u32, y: u32, radii: &[u32]) -> u32 {
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
    pub(crate) fn prefetch(&self, plan: &Plan, s: &Disk) {
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
    pub(crate) fn block_row(&self, s: &Disk, y: u32) -> &[[u32; 2]] {
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
    // enough for the corrections below to finish in a step or two. Below
    // 2^24 (a disk under 16 px at 1/256 px) m is exact in f32, whose root
    // costs about half of f64's (the cover's rows are mostly this root).
    let mut d = if m < 1 << 24 {
        (m as i32 as f32).sqrt() as i32 as u64
    } else {
        (m as i64 as f64).sqrt() as i64 as u64
    };
    while d * d > m {
        d -= 1;
    }
    while (d + 1) * (d + 1) <= m {
        d += 1;
    }
    d
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
pub(crate) fn set_bits(map: &mut [u64], lo: usize, hi: usize) {
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

/// Calls `f(q0, x0, x1)` for each run of the unwrapped pixels `a..=z` of a
/// row of `n` pixels that is contiguous on the domain: `x0..=x1` wrapped,
/// `q0` the unwrapped index of `x0`. Off a periodic domain, the pixels off
/// its edges are dropped.
pub(crate) fn for_each_run(
    a: i64,
    z: i64,
    n: u32,
    periodic: bool,
    mut f: impl FnMut(i64, usize, usize),
) {
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
pub(crate) fn for_each_bucket<T: Sync>(
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

#[cfg(test)]
mod tests {
    use super::isqrt;

    /// The root is exact on both sides of the f32 and f64 paths: every
    /// square and its neighbours, up to past 2^24 and near 2^62.
    #[test]
    fn isqrt_is_the_floor_of_the_root() {
        let check = |m: u64| {
            let d = isqrt(m);
            assert!(d * d <= m && (d + 1) * (d + 1) > m, "isqrt({m}) = {d}");
        };
        for d in (0..5000u64)
            .chain(4000..4200)
            .chain([(1 << 31) - 1, 1 << 30])
        {
            for m in [d * d, (d * d).saturating_sub(1), d * d + 1, d * d + 2 * d] {
                check(m);
            }
        }
        for m in ((1u64 << 24) - 3000..(1 << 24) + 3000).chain(0..70_000) {
            check(m);
        }
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            check(x >> 2);
            check(x >> 40);
        }
    }
}
