//! The size stage's closed loop: the drawing rendered, blurred by the mean
//! dot spacing (the measure's σ) and compared with its target, blurred
//! alike; each dot then resized by the ink curve to put down the ink its
//! neighbourhood lacks, in [`rounds`]. The calibration's curves hold for
//! maximal Poisson-disk sets on average; the loop corrects what they miss:
//! relaxed sets (evener, so their dots overlap less), edges, the policies'
//! spacing. The plan decides whether it runs and on which grid
//! ([`grid`]); grey drawings are corrected by [`grey`], colour drawings by
//! [`colour`] with their pens' render model.

mod colour;
mod grey;
mod grid;

pub(crate) use colour::Correction;
pub(crate) use grey::GreyCorrection;
pub(crate) use grid::{Grid, GridSpec};

/// The error's own blur, in σ: corrections follow the local bias, not each
/// dot's own noise.
pub(crate) const ERROR_BLUR: f64 = 1.0;

/// The correction's blurs in the measure's σ (the mean spacing), for a
/// render of `px_per_spacing` pixels between dots: the photo and the
/// drawing are blurred by it, and their difference by it again
/// ([`ERROR_BLUR`] times), so that the error is seen at √2 times it. 0.75
/// (the error at 1.06 σ) where the render resolves the dots (4 px between
/// them or more), else 1 (1.41 σ; finer there chases the render's own
/// noise: colour at 1M dots 5.31 → 5.98 ΔE00). At 0.75, grey drawings
/// measured 0.3–1.8 dB closer at σ and σ/2 on astronaut at 10K–200K dots
/// and five photos at LBG's counts (2σ within −0.13 dB); colour at 20K
/// 0.24 ΔE00 closer at σ and 0.5 at σ/2 on five photos (docs/colour.md).
pub(crate) fn blur_sigmas(px_per_spacing: f64) -> f64 {
    if px_per_spacing >= 4.0 { 0.75 } else { 1.0 }
}

/// The fraction of each round's ink change that is made, by the blur's σ
/// in work-grid cells: 1.15 (a little past the linear model's step, which
/// falls short) where σ spans 1.5 cells or more, 0.7 at one cell and less
/// (the work grid then finer than the dots' noise). Measured by `pixelpie
/// fidelity` on two photos at 20K, 100K, 300K and 1M dots (docs/colour.md).
pub(crate) fn damping(sigma_cells: f64) -> f64 {
    (0.7 + 0.9 * (sigma_cells - 1.0)).clamp(0.7, 1.15)
}

/// The rounds of a correction: three, or two where the blur's σ spans
/// less than 1.25 work-grid cells (dense drawings: there a third round
/// chases the dots' own noise, ΔE00 0.03–0.2 worse on two photos at 1M
/// dots). Each is reported as [`super::Stage::Correct`].
pub(crate) fn rounds(sigma_cells: f64) -> u8 {
    if sigma_cells < 1.25 { 2 } else { 3 }
}

/// The most ink a correction asks of a dot: past
/// [`crate::importance::ink::K_MAX`], where the
/// calibration stops, since overlaps with other pens' dots (colour) and
/// the holes of dark areas (grey) hide some of it.
pub(crate) const MAX_INK: f64 = 0.995;
