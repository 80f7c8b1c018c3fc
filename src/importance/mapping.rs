//! From importance to radius: the paper's linear ramp (§3.4) and the
//! calibrated tone mappings of stippling.
//!
//! **Tone.** A stipple reproduces grey v when its dots put down ink
//! k = 1 − v. Dots of radius ρ on a maximal set of radius r put down
//! ink(ρ/r, r), the measured curve of [`super::ink`]; it saturates as the
//! dots overlap, so the mapping inverts it: r(v) = the radius at which dots
//! of radius ρ put down 1 − v. The black dots' radius ρ_b is set by r_min:
//! v = 0 (ink [`K_MAX`]) maps to r_min. Tones lighter than the ink of
//! dots ρ_b on disks r_max stay at r_max (the white cutoff removes them).
//!
//! With [`Mapping::Tone`] every dot has radius ρ_b; with
//! [`Mapping::ToneSized`] dots shrink with the ink, from ρ_b at black to
//! ratio·ρ_b at white ([`super::ink::sized_dot`]), so light areas get more,
//! smaller dots. [`Mapping::dot_radius`] gives the dot radius of a tone.

use super::ink::{self, K_MAX};

/// How an importance value v ∈ [0, 1] becomes a radius.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mapping {
    /// r = r_min + (r_max − r_min)·v (paper §3.4).
    #[default]
    Linear,
    /// Calibrated for equal dots: dots of the black radius put down ink 1 − v.
    Tone,
    /// Calibrated for dots sized by tone: the white dots' radius is this
    /// fraction (0..1] of the black dots'.
    ToneSized(f32),
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
    /// use pixelpie::importance::ink;
    /// let r = RadiusRange::new(2.0, 16.0).unwrap();
    /// for m in [Mapping::Linear, Mapping::Tone, Mapping::ToneSized(0.5)] {
    ///     assert_eq!(m.radius(0.0, r), 2.0);
    ///     assert_eq!(m.radius(1.0, r), 16.0);
    /// }
    /// // Tone: the black dots put down ink 0.5 on the disks of grey 0.5.
    /// let (rho, r5) = (Mapping::Tone.dot_radius(0.0, r), Mapping::Tone.radius(0.5, r));
    /// assert!((ink::ink(f64::from(rho / r5), f64::from(r5)) - 0.5).abs() < 0.01);
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
            Self::Tone | Self::ToneSized(_) => {
                let k = (1.0 - f64::from(v)).min(K_MAX);
                ink::sample_radius(k, f64::from(self.dot_radius(v, range)))
            }
        };
        (r as f32).clamp(min, max)
    }

    /// The calibrated dot radius in px for importance `v`: the black dots'
    /// radius ρ_b, at which dots on disks of r_min put down [`K_MAX`] ink,
    /// scaled by [`ink::sized_dot`] under [`Mapping::ToneSized`]. [`Mapping::Linear`]
    /// has no calibration; it gets ρ_b too.
    ///
    /// ```
    /// use pixelpie::importance::{Mapping, RadiusRange};
    /// let r = RadiusRange::new(4.0, 32.0).unwrap();
    /// let black = Mapping::Tone.dot_radius(0.0, r);
    /// assert!(black > 0.7 * 4.0 && black < 4.0);
    /// assert_eq!(Mapping::Tone.dot_radius(0.9, r), black);
    /// assert!((Mapping::ToneSized(0.5).dot_radius(1.0, r) - 0.5 * black).abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn dot_radius(self, v: f32, range: RadiusRange) -> f32 {
        self.dot_radii(range)(v)
    }

    /// [`Self::dot_radius`] for one radius range, as a function of the
    /// importance: the black dots' radius (an inversion of the ink curve)
    /// is found once, for the many dots of a drawing.
    pub fn dot_radii(self, range: RadiusRange) -> impl Fn(f32) -> f32 + Sync {
        let min = f64::from(range.min);
        let black = ink::dot_ratio(K_MAX, min) * min;
        move |v: f32| {
            let f = match self {
                Self::ToneSized(ratio) => {
                    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                    ink::sized_dot(1.0 - f64::from(v), f64::from(ratio))
                }
                Self::Linear | Self::Tone => 1.0,
            };
            (black * f) as f32
        }
    }

    /// The radius range whose black dots have radius `rho` px, with
    /// r_max = `ratio` × r_min: the inverse of [`Mapping::dot_radius`] at black.
    ///
    /// ```
    /// use pixelpie::importance::{Mapping, RadiusRange};
    /// let r = Mapping::range_for_dot(2.0, 8.0).unwrap();
    /// assert!((Mapping::Tone.dot_radius(0.0, r) - 2.0).abs() < 0.01);
    /// ```
    pub fn range_for_dot(rho: f32, ratio: f32) -> super::Result<RadiusRange> {
        if !(rho.is_finite() && rho > 0.0) {
            return Err(super::Error::InvalidParameter(format!(
                "dot radius {rho} px must be a positive number"
            )));
        }
        let min = ink::sample_radius(K_MAX, f64::from(rho)) as f32;
        RadiusRange::new(min, min * ratio)
    }
}
