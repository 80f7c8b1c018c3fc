//! Fixed-point geometry, the counter-based dart hash and the depth-key layout:
//! the integer arithmetic that every backend performs bit for bit.
//!
//! WGSL mirror: `shaders/common.wgsl`. Every function here has a twin of the
//! same name there; `tests/gpu_equivalence.rs` checks that they agree.

/// Fractional bits of a position: positions are integers in 1/256 px.
pub const POS_FRAC_BITS: u32 = 8;
/// Fractional bits of a radius: radii are integers in 1/64 px.
pub const RADIUS_FRAC_BITS: u32 = 6;
/// One pixel in radius units.
pub const RADIUS_ONE: u32 = 1 << RADIUS_FRAC_BITS;
/// The most sub-pixel bits per axis a dart may use (2^7 = 128 positions).
pub const MAX_SUBPIXEL_BITS: u32 = 7;
/// The largest width or height: positions stay below 2^24, exact in an `f32`.
pub const MAX_SIDE: u32 = 1 << 16;
/// Bits of a depth key: keys are below 2^29 so that `0x0080_0000 + key` is a
/// positive normal `f32` in (0, 1), which a Depth32Float target stores exactly.
pub const KEY_BITS: u32 = 29;
/// The largest batch on any backend (2^22 darts, 64 MiB of darts on a GPU,
/// within every adapter's storage-binding limit); larger batches are split.
pub const MAX_BATCH: u32 = 1 << 22;
/// The smallest radius, 1 px: a dart's own disk then always covers the centre
/// of its own pixel, which the depth-key cull relies on.
pub const MIN_RADIUS_FX: u32 = RADIUS_ONE;

/// A 32-bit integer finaliser (Wellons' `lowbias32`): the dart generator's
/// only mixing step, cheap on a GPU and the same on every backend.
#[inline]
#[must_use]
pub const fn mix(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The 32-bit key of a 64-bit seed.
#[inline]
#[must_use]
pub const fn seed_key(seed: u64) -> u32 {
    mix(mix(seed as u32) ^ mix((seed >> 32) as u32 ^ 0x9e37_79b9))
}

/// The key of one iteration of a run.
#[inline]
#[must_use]
pub const fn iteration_key(seed_key: u32, iteration: u32) -> u32 {
    mix(seed_key ^ mix(iteration ^ 0x85eb_ca6b))
}

/// The hash of dart `dart` of an iteration: it picks the dart's empty pixel.
#[inline]
#[must_use]
pub const fn dart_hash(iteration_key: u32, dart: u32) -> u32 {
    mix(iteration_key ^ mix(dart ^ 0x27d4_eb2f))
}

/// The second hash of a dart: its sub-pixel offsets (low and high 16 bits).
#[inline]
#[must_use]
pub const fn offset_hash(dart_hash: u32) -> u32 {
    mix(dart_hash ^ 0x68e3_1da4)
}

/// Maps a hash uniformly onto `0..n` by a 32×32→64 multiply (no modulo bias
/// worth the name, and no division on the GPU).
#[inline]
#[must_use]
pub const fn pick(hash: u32, n: u32) -> u32 {
    ((hash as u64 * n as u64) >> 32) as u32
}

/// The position, in 1/256 px, of a dart in pixel `p` (one axis) with sub-pixel
/// offset `o` of `bits` bits: the centre of sub-cell `o`, so `bits = 0` gives
/// the pixel centre.
#[inline]
#[must_use]
pub const fn dart_coord(p: u32, o: u32, bits: u32) -> u32 {
    (p << POS_FRAC_BITS) + ((2 * o + 1) << (POS_FRAC_BITS - 1 - bits))
}

/// The centre of pixel `p` (one axis) in 1/256 px.
#[inline]
#[must_use]
pub const fn pixel_centre(p: u32) -> u32 {
    (p << POS_FRAC_BITS) + (1 << (POS_FRAC_BITS - 1))
}

/// The distance along one axis, wrapped when `period` (in 1/256 px) is not 0.
#[inline]
#[must_use]
pub const fn axis_delta(a: u32, b: u32, period: u32) -> u32 {
    let d = a.abs_diff(b);
    if period != 0 && period - d < d {
        period - d
    } else {
        d
    }
}

/// Whether a point at offset (dx, dy) (1/256 px) lies strictly inside a disk of
/// radius `r_fx` (1/64 px). Exact: 64-bit squares of 24-bit integers.
#[inline]
#[must_use]
pub const fn inside(dx: u32, dy: u32, r_fx: u32) -> bool {
    let r = (r_fx as u64) << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    (dx as u64) * (dx as u64) + (dy as u64) * (dy as u64) < r * r
}

/// The depth value of a key: the bit pattern of a positive normal float, which
/// orders like the integer and survives a Depth32Float target unchanged.
#[inline]
#[must_use]
pub fn key_to_depth(key: u32) -> f32 {
    f32::from_bits(0x0080_0000 + key)
}

/// Converts a radius in pixels to radius units, rounding to the nearest 1/64 px.
#[must_use]
pub fn radius_to_fx(r: f32) -> u32 {
    // r·64 is exact in f64 with at most 24 significant bits, so adding ½ is
    // exact below 2^52 and truncating rounds half away from zero, as
    // `round()` does (a libm call on baseline x86-64), saturating alike.
    (f64::from(r) * f64::from(RADIUS_ONE) + 0.5) as u32
}

/// Converts radius units to pixels (exact).
#[must_use]
pub fn fx_to_radius(r_fx: u32) -> f32 {
    r_fx as f32 / RADIUS_ONE as f32
}

/// Converts a position in 1/256 px to pixels (exact below 2^24).
#[must_use]
pub fn fx_to_pos(p: u32) -> f32 {
    p as f32 / (1u32 << POS_FRAC_BITS) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_subpixel_bits_put_darts_on_pixel_centres() {
        for p in [0, 1, 77, MAX_SIDE - 1] {
            assert_eq!(dart_coord(p, 0, 0), pixel_centre(p));
        }
    }

    #[test]
    fn subpixel_darts_stay_inside_their_pixel_and_are_symmetric() {
        for bits in 0..=MAX_SUBPIXEL_BITS {
            let n = 1 << bits;
            let first = dart_coord(5, 0, bits) - (5 << POS_FRAC_BITS);
            let last = dart_coord(5, n - 1, bits) - (5 << POS_FRAC_BITS);
            assert!(first > 0 && last < 256, "bits {bits}");
            assert_eq!(first + last, 256, "bits {bits}: offsets centred");
        }
    }

    #[test]
    fn keys_order_like_their_depths() {
        let keys = [0u32, 1, 2, 1000, (1 << KEY_BITS) - 2, (1 << KEY_BITS) - 1];
        for w in keys.windows(2) {
            let (a, b) = (key_to_depth(w[0]), key_to_depth(w[1]));
            assert!(a < b && a.is_normal() && b < 1.0);
        }
    }

    #[test]
    fn radius_to_fx_rounds_as_round_does() {
        let mut state = 0x9e37_79b9_u32;
        let mut values = vec![0.0, -0.0, 0.5 / 64.0, 1.5 / 64.0, -0.5 / 64.0, 1e30, -1e30];
        values.extend([
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN_POSITIVE,
        ]);
        for _ in 0..1_000_000 {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            values.push(f32::from_bits(state));
            values.push((state % 100_000) as f32 / 128.0);
        }
        for r in values {
            let want = (f64::from(r) * f64::from(RADIUS_ONE)).round() as u32;
            assert_eq!(radius_to_fx(r), want, "{r:e}");
        }
    }

    #[test]
    fn inside_is_strict_and_exact() {
        // A 3-4-5 triangle: (3 px, 4 px) is exactly 5 px away.
        assert!(!inside(3 * 256, 4 * 256, 5 * 64));
        assert!(inside(3 * 256, 4 * 256 - 1, 5 * 64));
        // The largest operands do not overflow.
        assert!(inside((1 << 24) - 1, (1 << 24) - 1, 1 << 23));
    }

    #[test]
    fn periodic_delta_takes_the_short_way_round() {
        let period = 100 << POS_FRAC_BITS;
        assert_eq!(axis_delta(256, 99 * 256, period), 2 * 256);
        assert_eq!(axis_delta(256, 99 * 256, 0), 98 * 256);
    }

    #[test]
    fn pick_is_in_range_and_spreads() {
        let n = 1000;
        let mut seen = vec![0u32; n as usize];
        for k in 0..100_000 {
            let i = pick(dart_hash(iteration_key(seed_key(1), 0), k), n);
            seen[i as usize] += 1;
        }
        assert!(seen.iter().all(|&c| (50..=160).contains(&c)), "{seen:?}");
    }
}
