//! Colour science for drawing in colour: the sRGB transfer function,
//! CIELAB (D65) and the CIEDE2000 colour difference, the pens a drawing uses
//! ([`pens`]), and the render model with the separation of a photo into pen
//! inks ([`separation`]). A leaf: it imports nothing else of the crate.

pub mod choose;
pub mod pens;
pub mod separation;

pub use pens::{Pen, PenSet};
pub use separation::{RenderModel, Separation};

/// The relative luminance of an 8-bit sRGB colour (0 black, 1 white).
#[must_use]
pub fn luminance(c: [u8; 3]) -> f64 {
    let [r, g, b] = c.map(|v| decode(f64::from(v) / 255.0));
    0.2126 * r + 0.7152 * g + 0.0722 * b
}

/// The sRGB transfer function's inverse: encoded value in [0, 1] to linear.
#[must_use]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB transfer function: linear value in [0, 1] to encoded.
///
/// Every drawing's default tones pass each pixel of the photo (or of the
/// photo made smaller) through it, so above the linear toe it is read off a table, interpolated
/// linearly within segments of 1/1024 octave: within 1.5e-7 of the curve
/// (about one `f32` step), cheaper than `powf` (a 100K-dot drawing takes
/// 0.92× the time, `docs/benchmarks.md`), and the same on every platform
/// (the table is made with `libm`, no FMA is fused). Values at or above 1
/// (and NaN) take `libm`'s `powf`.
#[must_use]
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else if v < 1.0 {
        encode_table::read(v)
    } else {
        1.055 * libm::powf(v, 1.0 / 2.4) - 0.055
    }
}

/// The table behind [`linear_to_srgb`] on (0.0031308, 1).
mod encode_table {
    use std::sync::LazyLock;

    /// Segments per octave: 2^SEGMENT_BITS.
    const SEGMENT_BITS: u32 = 10;
    /// Mantissa bits below a segment's index.
    const FRACTION_BITS: u32 = 23 - SEGMENT_BITS;
    /// The table's first octave starts at 2^FIRST_EXPONENT, below the toe.
    const FIRST_EXPONENT: i32 = -9;
    /// Octaves up to 1.
    const OCTAVES: usize = 9;

    /// The curve at the start of each segment, and at 1.
    static TABLE: LazyLock<Vec<f32>> = LazyLock::new(|| {
        (0..=OCTAVES << SEGMENT_BITS)
            .map(|j| {
                let octave = (j >> SEGMENT_BITS) as i32 + FIRST_EXPONENT;
                let step = (j & ((1 << SEGMENT_BITS) - 1)) as f64;
                let v = libm::ldexp(1.0 + step / f64::from(1u32 << SEGMENT_BITS), octave);
                (1.055 * libm::pow(v, 1.0 / 2.4) - 0.055) as f32
            })
            .collect()
    });

    /// The curve at `v` in [2^FIRST_EXPONENT, 1).
    #[inline]
    pub(super) fn read(v: f32) -> f32 {
        debug_assert!((libm::ldexpf(1.0, FIRST_EXPONENT)..1.0).contains(&v));
        let bits = v.to_bits();
        // The biased exponent and the top mantissa bits: the segment.
        let first = ((127 + FIRST_EXPONENT) as u32) << SEGMENT_BITS;
        let i = ((bits >> FRACTION_BITS) - first) as usize;
        // Within an octave v is linear in its mantissa: an exact fraction.
        let t = (bits & ((1 << FRACTION_BITS) - 1)) as f32 / (1u32 << FRACTION_BITS) as f32;
        let (a, b) = (TABLE[i], TABLE[i + 1]);
        a + t * (b - a)
    }
}

/// [`srgb_to_linear`] in `f64`.
#[must_use]
pub fn decode(c: f64) -> f64 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// [`linear_to_srgb`] in `f64` (negative values clamp to 0).
#[must_use]
pub fn encode(v: f64) -> f64 {
    if v <= 0.003_130_8 {
        12.92 * v.max(0.0)
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// A CIELAB colour (D65 white, CIE 1931 2° observer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lab {
    /// Lightness, 0..100.
    pub l: f64,
    /// Green–red.
    pub a: f64,
    /// Blue–yellow.
    pub b: f64,
}

/// The determinant of a 3×3 matrix (rows).
#[must_use]
pub(crate) fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// The cube root of `t`, within one unit in the last place of the exact
/// one over (1e-300, 1e300) (`f64::cbrt` elsewhere, and `f64::cbrt` takes
/// 2.5× as long): a guess from the exponent's bits, two of Halley's steps
/// and one of Newton's, in plain arithmetic (the same on every platform).
/// Lab's conversions were 4% of a CMYK drawing's time; 16 colour drawings
/// came out byte for byte the same.
fn cube_root(t: f64) -> f64 {
    if !(t > 1e-300 && t < 1e300) {
        return t.cbrt();
    }
    let mut y = f64::from_bits(t.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..2 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * t) / (2.0 * y3 + t);
    }
    y - (y * y * y - t) / (3.0 * y * y)
}

/// D65 white in XYZ (Y = 1).
const WHITE: [f64; 3] = [0.950_47, 1.0, 1.088_83];

impl Lab {
    /// The Lab colour of linear sRGB `rgb` (components in [0, 1]).
    ///
    /// ```
    /// use pixelpie::colour::Lab;
    /// let white = Lab::from_linear([1.0, 1.0, 1.0]);
    /// assert!((white.l - 100.0).abs() < 1e-3 && white.a.abs() < 1e-3 && white.b.abs() < 1e-3);
    /// ```
    #[must_use]
    pub fn from_linear(rgb: [f64; 3]) -> Self {
        let [r, g, b] = rgb;
        let x = 0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b;
        let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175_0 * b;
        let z = 0.019_333_9 * r + 0.119_192_0 * g + 0.950_304_1 * b;
        let f = |t: f64| {
            const D: f64 = 6.0 / 29.0;
            if t > D * D * D {
                cube_root(t)
            } else {
                t / (3.0 * D * D) + 4.0 / 29.0
            }
        };
        let (fx, fy, fz) = (f(x / WHITE[0]), f(y / WHITE[1]), f(z / WHITE[2]));
        Self {
            l: 116.0 * fy - 16.0,
            a: 500.0 * (fx - fy),
            b: 200.0 * (fy - fz),
        }
    }

    /// The Lab colour of sRGB-encoded `rgb` (components in [0, 1]).
    #[must_use]
    pub fn from_srgb(rgb: [f64; 3]) -> Self {
        Self::from_linear(rgb.map(decode))
    }

    /// The Lab colour of an 8-bit sRGB colour.
    #[must_use]
    pub fn from_srgb8(rgb: [u8; 3]) -> Self {
        Self::from_srgb(rgb.map(|c| f64::from(c) / 255.0))
    }
}

/// The CIEDE2000 colour difference ΔE00 (kL = kC = kH = 1), after Sharma,
/// Wu & Dalal (2005).
///
/// ```
/// use pixelpie::colour::{Lab, delta_e00};
/// // Pair 1 of Sharma et al.'s test data.
/// let a = Lab { l: 50.0, a: 2.6772, b: -79.7751 };
/// let b = Lab { l: 50.0, a: 0.0, b: -82.7485 };
/// assert!((delta_e00(a, b) - 2.0425).abs() < 1e-4);
/// ```
#[must_use]
pub fn delta_e00(c1: Lab, c2: Lab) -> f64 {
    use std::f64::consts::PI;
    let deg = PI / 180.0;
    let c1s = c1.a.hypot(c1.b);
    let c2s = c2.a.hypot(c2.b);
    let cbar = (c1s + c2s) / 2.0;
    let cbar7 = cbar.powi(7);
    let g = 0.5 * (1.0 - (cbar7 / (cbar7 + 25f64.powi(7))).sqrt());
    let a1 = (1.0 + g) * c1.a;
    let a2 = (1.0 + g) * c2.a;
    let cp1 = a1.hypot(c1.b);
    let cp2 = a2.hypot(c2.b);
    let hue = |b: f64, a: f64| {
        if a == 0.0 && b == 0.0 {
            0.0
        } else {
            let h = b.atan2(a);
            if h < 0.0 { h + 2.0 * PI } else { h }
        }
    };
    let h1 = hue(c1.b, a1);
    let h2 = hue(c2.b, a2);
    let dl = c2.l - c1.l;
    let dc = cp2 - cp1;
    let dh = if cp1 * cp2 == 0.0 {
        0.0
    } else {
        let d = h2 - h1;
        if d > PI {
            d - 2.0 * PI
        } else if d < -PI {
            d + 2.0 * PI
        } else {
            d
        }
    };
    let dhh = 2.0 * (cp1 * cp2).sqrt() * (dh / 2.0).sin();
    let lbar = (c1.l + c2.l) / 2.0;
    let cpbar = (cp1 + cp2) / 2.0;
    let hbar = if cp1 * cp2 == 0.0 {
        h1 + h2
    } else if (h1 - h2).abs() <= PI {
        (h1 + h2) / 2.0
    } else if h1 + h2 < 2.0 * PI {
        (h1 + h2 + 2.0 * PI) / 2.0
    } else {
        (h1 + h2 - 2.0 * PI) / 2.0
    };
    let t = 1.0 - 0.17 * (hbar - 30.0 * deg).cos()
        + 0.24 * (2.0 * hbar).cos()
        + 0.32 * (3.0 * hbar + 6.0 * deg).cos()
        - 0.20 * (4.0 * hbar - 63.0 * deg).cos();
    let dtheta = 30.0 * deg * (-((hbar / deg - 275.0) / 25.0).powi(2)).exp();
    let cpbar7 = cpbar.powi(7);
    let rc = 2.0 * (cpbar7 / (cpbar7 + 25f64.powi(7))).sqrt();
    let l50 = (lbar - 50.0).powi(2);
    let sl = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let sc = 1.0 + 0.045 * cpbar;
    let sh = 1.0 + 0.015 * cpbar * t;
    let rt = -(2.0 * dtheta).sin() * rc;
    let (tl, tc, th) = (dl / sl, dc / sc, dhh / sh);
    (tl * tl + tc * tc + th * th + rt * tc * th).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within one unit in the last place of the cube root over the Lab
    /// range and far past it (checked against the platform's `cbrt`, with
    /// one more unit for its own rounding), and the platform's where `t`
    /// lies outside (1e-300, 1e300).
    #[test]
    fn the_cube_root_is_within_one_ulp() {
        let mut t = 1e-4f64;
        let mut off = 0;
        while t < 1e6 {
            let (a, b) = (cube_root(t), t.cbrt());
            let ulps = (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
            assert!(ulps <= 2, "{t}: {a} against {b}");
            off += usize::from(ulps > 0);
            t *= 1.000_01;
        }
        // Not the platform's cbrt itself.
        assert!(off > 0);
        for t in [0.0, -0.0, f64::INFINITY, -1.0, 1e-310, 1e305] {
            assert_eq!(cube_root(t).to_bits(), t.cbrt().to_bits());
        }
        assert!(cube_root(f64::NAN).is_nan());
    }

    /// The table stays within 1.5e-7 of the curve (in `f64`) over the whole
    /// of [0, 1], is continuous at the toe and monotone.
    #[test]
    fn linear_to_srgb_follows_the_curve() {
        let mut worst = 0.0f64;
        let mut last = -1.0f32;
        for k in 0..=2_000_000u32 {
            let v = k as f32 / 2_000_000.0;
            let got = linear_to_srgb(v);
            worst = worst.max((f64::from(got) - encode(f64::from(v))).abs());
            assert!(got >= last, "not monotone at {v}");
            last = got;
        }
        // Around the toe and the top, f32 step by f32 step.
        for start in [0.003_130_8f32, 0.001_953_125, 0.5, 0.999_9] {
            let mut v = start;
            for _ in 0..20_000 {
                let got = linear_to_srgb(v);
                worst = worst.max((f64::from(got) - encode(f64::from(v))).abs());
                v = f32::from_bits(v.to_bits() + 1);
            }
        }
        assert!(worst < 1.5e-7, "worst error {worst}");
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-7);
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!(linear_to_srgb(f32::NAN).is_nan());
        assert!(linear_to_srgb(2.0) > 1.0);
    }

    /// Sharma, Wu & Dalal (2005), Table 1: a selection of the 34 pairs,
    /// those that exercise the hue and mean-hue branches.
    #[test]
    fn delta_e00_matches_sharmas_test_data() {
        let pairs = [
            ((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),
            ((50.0, 3.1571, -77.2803), (50.0, 0.0, -82.7485), 2.8615),
            ((50.0, -1.3802, -84.2814), (50.0, 0.0, -82.7485), 1.0),
            ((50.0, 0.0, 0.0), (50.0, -1.0, 2.0), 2.3669),
            ((50.0, 2.49, -0.001), (50.0, -2.49, 0.0009), 7.1792),
            ((50.0, 2.49, -0.001), (50.0, -2.49, 0.0011), 7.2195),
            ((50.0, -0.001, 2.49), (50.0, 0.0009, -2.49), 4.8045),
            ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
            (
                (60.2574, -34.0099, 36.2677),
                (60.4626, -34.1751, 39.4387),
                1.2644,
            ),
            (
                (22.7233, 20.0904, -46.694),
                (23.0331, 14.973, -42.5619),
                2.0373,
            ),
            (
                (90.8027, -2.0831, 1.441),
                (91.1528, -1.6435, 0.0447),
                1.4441,
            ),
            ((2.0776, 0.0795, -1.135), (0.9033, -0.0636, -0.5514), 0.9082),
        ];
        for ((l1, a1, b1), (l2, a2, b2), want) in pairs {
            let x = Lab {
                l: l1,
                a: a1,
                b: b1,
            };
            let y = Lab {
                l: l2,
                a: a2,
                b: b2,
            };
            assert!((delta_e00(x, y) - want).abs() < 1e-4, "{x:?} {y:?}");
            assert!((delta_e00(y, x) - want).abs() < 1e-4, "symmetric");
        }
    }

    #[test]
    fn lab_of_primaries_matches_the_reference_values() {
        // sRGB red, green and blue in CIELAB D65 (Lindbloom's calculator).
        let red = Lab::from_srgb([1.0, 0.0, 0.0]);
        assert!(
            (red.l - 53.24).abs() < 0.05
                && (red.a - 80.09).abs() < 0.1
                && (red.b - 67.20).abs() < 0.1
        );
        let blue = Lab::from_srgb([0.0, 0.0, 1.0]);
        assert!((blue.l - 32.30).abs() < 0.05 && (blue.b + 107.86).abs() < 0.15);
        let black = Lab::from_linear([0.0; 3]);
        assert!(black.l.abs() < 1e-9);
    }
}
