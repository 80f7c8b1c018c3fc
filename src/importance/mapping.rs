//! From importance to radius: the paper's linear ramp (§3.4) and a
//! tone-faithful mapping for stippling.
//!
//! **Tone.** A maximal Poisson-disk set of radius r has about
//! 0.547 / (π r²/4) points per unit area (RSA saturation), so the density
//! goes as 1/r². For a stipple of equal dots to reproduce a tone, the dot
//! density must grow linearly with darkness d = 1 − v. Asking the density to
//! be affine in d, from 1/r_max² at white to 1/r_min² at black,
//!
//! 1/r(v)² = 1/r_max² + (1/r_min² − 1/r_max²)·(1 − v),
//!
//! gives v = 0 ↦ r_min and v = 1 ↦ r_max exactly, and any two tones keep the
//! ratio of their darkness above the white floor 1/r_max².

/// How an importance value v ∈ [0, 1] becomes a radius.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mapping {
    /// r = r_min + (r_max − r_min)·v (paper §3.4).
    #[default]
    Linear,
    /// Dot density affine in darkness: 1/r² = 1/r_max² + (1/r_min² − 1/r_max²)(1 − v).
    Tone,
}

/// The radii that v = 0 and v = 1 map to, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RadiusRange {
    /// The radius of the most important value (v = 0).
    pub min: f32,
    /// The radius of the least important value (v = 1).
    pub max: f32,
}

impl RadiusRange {
    /// A range, checked: 0 < min ≤ max, both finite.
    ///
    /// ```
    /// use pixelpie::importance::RadiusRange;
    /// assert!(RadiusRange::new(2.0, 8.0).is_ok());
    /// assert!(RadiusRange::new(8.0, 2.0).is_err());
    /// ```
    pub fn new(min: f32, max: f32) -> super::Result<Self> {
        if !(min.is_finite() && max.is_finite() && min > 0.0 && min <= max) {
            return Err(super::Error::InvalidParameter(format!(
                "radius range {min}..{max} px: need 0 < min <= max"
            )));
        }
        Ok(Self { min, max })
    }

    /// Both ends multiplied by `s` (count targeting scales them together).
    #[must_use]
    pub fn scaled(self, s: f64) -> Self {
        Self {
            min: (f64::from(self.min) * s) as f32,
            max: (f64::from(self.max) * s) as f32,
        }
    }
}

impl Mapping {
    /// The radius for importance `v` (clamped to [0, 1]).
    ///
    /// ```
    /// use pixelpie::importance::{Mapping, RadiusRange};
    /// let r = RadiusRange::new(2.0, 8.0).unwrap();
    /// for m in [Mapping::Linear, Mapping::Tone] {
    ///     assert_eq!(m.radius(0.0, r), 2.0);
    ///     assert_eq!(m.radius(1.0, r), 8.0);
    /// }
    /// // Tone: half the darkness, half the density (above the white floor).
    /// let (d1, d2) = (Mapping::Tone.radius(0.0, r), Mapping::Tone.radius(0.5, r));
    /// let floor = 1.0 / 64.0;
    /// assert!(((1.0 / (d2 * d2) - floor) / (1.0 / (d1 * d1) - floor) - 0.5).abs() < 1e-5);
    /// ```
    #[must_use]
    pub fn radius(self, v: f32, range: RadiusRange) -> f32 {
        let RadiusRange { min, max } = range;
        if v.is_nan() || v <= 0.0 {
            return min;
        }
        if v >= 1.0 {
            return max;
        }
        let r = match self {
            Self::Linear => f64::from(min) + f64::from(max - min) * f64::from(v),
            Self::Tone => {
                let (lo, hi) = (f64::from(min), f64::from(max));
                let floor = 1.0 / (hi * hi);
                let inv_sq = floor + (1.0 / (lo * lo) - floor) * (1.0 - f64::from(v));
                1.0 / inv_sq.sqrt()
            }
        };
        (r as f32).clamp(min, max)
    }
}
