//! The tone-reproduction curve of a stipple: how much ink dots put down.
//!
//! Dots of radius ρ = t·r on a maximal Poisson-disk set of radius r cover a
//! fraction of the paper that depends on t alone, up to the sampler's
//! pixel-resolution slack at small r: about 2.2 t² while the dots do not
//! touch (t < ½), then less, as the dots overlap, up to full cover at t ≈ 1.
//! The curve was measured with the project's own sampler
//! ([`super::ink_table`], written by `examples/ink_curve.rs`); inverting it
//! gives the sample radius that makes dots of a given size put down a given
//! ink, as printers calibrate a tone-reproduction curve.

use super::ink_table::{INK, RADII, T_STEP};

/// The darkest ink the tone mappings ask for: black and everything darker
/// than 1 − `K_MAX` grey get this much ink. Full cover would need dots as
/// wide as the disks, merging into one blot.
pub const K_MAX: f64 = 0.96;

/// The measured curve at sample radius `r` px (interpolated in log r
/// between the measured radii, clamped to their range), one entry per
/// multiple of [`T_STEP`].
fn row(r: f64) -> [f64; INK[0].len()] {
    let at = Between::of(r);
    std::array::from_fn(|j| at.ink(j))
}

/// The measured radii's logarithms, taken once (the curves interpolate in
/// log r; the same values as taking them each time).
static LN_RADII: std::sync::LazyLock<[f64; RADII.len()]> =
    std::sync::LazyLock::new(|| RADII.map(f64::ln));

/// Where a radius lies between two measured radii: the lower one's index
/// and the fraction of the way to the next, in log r (clamped to the
/// measured range).
#[derive(Clone, Copy)]
struct Between {
    i: usize,
    f: f64,
}

impl Between {
    fn of(r: f64) -> Self {
        let ln = &*LN_RADII;
        let lr = r.max(RADII[0]).min(RADII[RADII.len() - 1]).ln();
        let i = ln
            .windows(2)
            .position(|w| lr <= w[1])
            .unwrap_or(RADII.len() - 2);
        let f = ((lr - ln[i]) / (ln[i + 1] - ln[i])).clamp(0.0, 1.0);
        Self { i, f }
    }

    /// Entry `j` of the curve at this radius ([`row`]'s, one at a time).
    #[inline]
    fn ink(self, j: usize) -> f64 {
        INK[self.i][j] + self.f * (INK[self.i + 1][j] - INK[self.i][j])
    }
}

/// The density of the maximal sets the curve was measured on, over RSA's
/// ([`crate::sampler::RSA_DENSITY`] / (π r²/4)), at each of the curve's
/// radii: pixel-mode sets hold fewer points at small radii. Measured with
/// `pixelpie sample --width 2048 --height 2048 --radius R --periodic` (seed
/// 0, one set per radius).
pub const DENSITY: [f64; RADII.len()] = [
    0.6744, 0.7783, 0.8185, 0.8796, 0.9021, 0.9338, 0.9449, 0.9630, 0.9764, 0.9885, 0.9910,
];

/// The points per pixel of a saturated random sequential adsorption set of
/// radius `r` px: [`crate::sampler::RSA_DENSITY`] / (π r²/4).
#[must_use]
pub fn rsa_per_pixel(r: f64) -> f64 {
    crate::sampler::RSA_DENSITY / (std::f64::consts::PI * r * r / 4.0)
}

/// The density of a maximal set of radius `r` px over RSA's ([`DENSITY`],
/// interpolated in log r, clamped to the measured radii).
///
/// ```
/// use pixelpie::importance::ink;
/// assert!(ink::density(1.0) < ink::density(8.0) && ink::density(8.0) < 1.0);
/// ```
#[must_use]
pub fn density(r: f64) -> f64 {
    let Between { i, f } = Between::of(r);
    DENSITY[i] + f * (DENSITY[i + 1] - DENSITY[i])
}

/// The ink of dots of radius `t`·`r` on a maximal set of radius `r` px.
///
/// ```
/// use pixelpie::importance::ink;
/// assert_eq!(ink::ink(0.0, 4.0), 0.0);
/// assert!((ink::ink(0.3, 8.0) - 2.2 * 0.09).abs() < 0.02); // no overlap yet
/// assert!(ink::ink(1.2, 8.0) > 0.999); // the disks cover the domain
/// ```
#[must_use]
pub fn ink(t: f64, r: f64) -> f64 {
    let row = row(r);
    let x = (t.max(0.0) / T_STEP).min((row.len() - 1) as f64);
    let j = (x.floor() as usize).min(row.len() - 2);
    row[j] + (x - j as f64) * (row[j + 1] - row[j])
}

/// The dot ratio t that puts down ink `k` on a maximal set of radius `r`
/// px: the inverse of [`ink`] in t (k is clamped to what the curve reaches).
///
/// ```
/// use pixelpie::importance::ink;
/// let t = ink::dot_ratio(0.5, 6.0);
/// assert!((ink::ink(t, 6.0) - 0.5).abs() < 1e-9);
/// ```
#[must_use]
pub fn dot_ratio(k: f64, r: f64) -> f64 {
    if k.is_nan() || k <= 0.0 {
        return 0.0;
    }
    // The curve's entries are read as the search reaches them: the same
    // values as the whole row's, a fraction of the work.
    let at = Between::of(r);
    let n = INK[0].len();
    match (0..n - 1).find(|&j| at.ink(j + 1) >= k) {
        Some(j) => {
            let (lo, hi) = (at.ink(j), at.ink(j + 1));
            let span = hi - lo;
            let f = if span > 0.0 { (k - lo) / span } else { 0.0 };
            (j as f64 + f.clamp(0.0, 1.0)) * T_STEP
        }
        None => (n - 1) as f64 * T_STEP,
    }
}

/// The sample radius r at which dots of radius `rho` px put down ink `k`:
/// solves ρ = t(k, r)·r (the curve's weak dependence on r converges in a
/// few steps). Infinite for k ≤ 0.
///
/// ```
/// use pixelpie::importance::ink;
/// let r = ink::sample_radius(0.3, 2.0);
/// assert!((ink::ink(2.0 / r, r) - 0.3).abs() < 1e-3);
/// ```
#[must_use]
pub fn sample_radius(k: f64, rho: f64) -> f64 {
    if k.is_nan() || k <= 0.0 {
        return f64::INFINITY;
    }
    let mut r = rho / dot_ratio(k, 8.0);
    for _ in 0..4 {
        r = rho / dot_ratio(k, r);
    }
    r
}

/// The dot radius, as a fraction of the black dots' radius, of dots sized by
/// tone: `ratio` (the white dots' fraction) at no ink, growing linearly with
/// the ink `k` to 1 at [`K_MAX`].
///
/// ```
/// use pixelpie::importance::ink::{K_MAX, sized_dot};
/// assert_eq!(sized_dot(0.0, 0.4), 0.4);
/// assert_eq!(sized_dot(K_MAX, 0.4), 1.0);
/// ```
#[must_use]
pub fn sized_dot(k: f64, ratio: f64) -> f64 {
    let k = k.clamp(0.0, K_MAX) / K_MAX;
    ratio + (1.0 - ratio) * k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_measured_curves_rise_from_zero_to_full_cover() {
        for (i, row) in INK.iter().enumerate() {
            assert_eq!(row[0], 0.0, "r = {}", RADII[i]);
            assert!(row.windows(2).all(|w| w[1] >= w[0]), "r = {}", RADII[i]);
            assert!(row[row.len() - 1] > 0.99, "r = {}", RADII[i]);
        }
    }

    #[test]
    fn sample_radius_inverts_the_curve_at_every_radius() {
        for rho in [0.7, 1.5, 3.0, 10.0] {
            for k in [0.02, 0.1, 0.5, 0.9, K_MAX] {
                let r = sample_radius(k, rho);
                assert!((ink(rho / r, r) - k).abs() < 2e-3, "rho {rho} k {k}");
            }
        }
    }
}
