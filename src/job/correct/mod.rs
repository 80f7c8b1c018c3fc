//! The size stage's closed loop: the drawing rendered, blurred by the mean
//! dot spacing (the measure's σ) and compared with its target, blurred
//! alike; each dot then resized by the ink curve to put down the ink its
//! neighbourhood lacks, in the rounds of a [`Schedule`]. The calibration's curves hold for
//! maximal Poisson-disk sets on average; the loop corrects what they miss:
//! relaxed sets (evener, so their dots overlap less), edges, the policies'
//! spacing. The plan decides whether it runs and on which grid
//! ([`grid`]); grey drawings are corrected by [`grey`], colour drawings by
//! [`colour`] with their pens' render model.

mod colour;
mod grey;
mod grid;

pub(crate) use colour::ColourCorrection;
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

/// The rounds of a correction, and which of them render the drawing.
/// Dense drawings (the blur's σ under 1.25 work-grid cells) take two
/// rounds, both rendered: there a third round chases the dots' own
/// noise (ΔE00 0.03–0.2 worse on two photos at 1M dots).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Schedule {
    /// The rounds, each reported as [`super::Stage::Correct`].
    pub rounds: u8,
    /// Whether the rounds between the first and the last are predicted
    /// rather than rendered: each sees the last render changed by every
    /// dot's ink change as the update meant it, spread over the work
    /// cells around the dot ([`Grid::spread`]), at a fraction of a
    /// render's cost.
    pub predicted: bool,
}

impl Schedule {
    /// A grey drawing's: five rounds, the first and the last rendered and
    /// the three between predicted. Against three rendered rounds, at
    /// about the same time: 0.7–2.2 dB closer at σ on five photos at 20K
    /// dots, 0.55 dB on astronaut at 100K (docs/drawing.md). The
    /// predictions alone drift (1.6 dB worse than three rendered rounds),
    /// so the last round renders.
    pub(crate) fn grey(sigma_cells: f64) -> Self {
        if sigma_cells < 1.25 {
            Self::rendered(2)
        } else {
            Self {
                rounds: 5,
                predicted: true,
            }
        }
    }

    /// A colour drawing's: three rounds, each rendered. The pens' dots lie
    /// apart, so their overlaps depart from the model's, whose Jacobian
    /// the predictions would need: predicted rounds measured ΔE00 1.34
    /// against three rendered rounds' 1.18 (`cmyk`, five photos at 20K).
    pub(crate) fn colour(sigma_cells: f64) -> Self {
        Self::rendered(if sigma_cells < 1.25 { 2 } else { 3 })
    }

    /// `rounds` rounds, each rendered.
    fn rendered(rounds: u8) -> Self {
        Self {
            rounds,
            predicted: false,
        }
    }

    /// Whether round `round` (from 1) renders the drawing.
    pub(crate) fn renders(&self, round: u8) -> bool {
        !self.predicted || round == 1 || round == self.rounds
    }
}

/// The share of a dot's previous ink change added to its next one, from
/// the third round on (heavy-ball momentum: the rounds' fine detail
/// converges slowly, since the blurs weaken each dot's own effect; the
/// first round's change, mostly the calibration's bias, is not carried).
pub(crate) const MOMENTUM: f64 = 0.3;

/// The momentum of round `round`: [`MOMENTUM`] from the third round.
pub(crate) fn momentum(round: u8) -> f64 {
    if round >= 3 { MOMENTUM } else { 0.0 }
}

/// One dot's update in a round, as grey and colour make it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Step {
    /// The ink the dot is now sized for.
    pub after: f64,
    /// The factor on its radius that puts that ink down, within 0.6–1.6.
    pub factor: f64,
    /// Whether the 0.6–1.6 clamp held the factor back.
    pub held: bool,
}

/// The update of a dot sized for ink `before`, at `place` among `ratios`'
/// rows: `delta` and the `carried` share of its last change added, within
/// half its ink and [`MAX_INK`], and the radius factor that puts the new
/// ink down. `None` where the dot is left as it is (almost no ink, or no
/// radius for it).
pub(crate) fn step(
    ratios: &super::density::Ratios,
    place: f64,
    before: f64,
    delta: f64,
    carried: f64,
) -> Option<Step> {
    if before < 1e-3 {
        return None;
    }
    let after = (before + delta + carried).clamp(0.5 * before, MAX_INK);
    let had = ratios.at_place(before, place);
    if had <= 0.0 {
        return None;
    }
    let wanted = ratios.at_place(after, place) / had;
    let factor = wanted.clamp(0.6, 1.6);
    Some(Step {
        after,
        factor,
        held: factor != wanted,
    })
}

/// The most ink a correction asks of a dot: past
/// [`crate::importance::ink::K_MAX`], where the
/// calibration stops, since overlaps with other pens' dots (colour) and
/// the holes of dark areas (grey) hide some of it.
pub(crate) const MAX_INK: f64 = 0.995;

#[cfg(test)]
mod tests {
    use super::*;

    /// Grey drawings take five rounds, rendering the first and the last;
    /// colour drawings three rendered rounds; dense drawings two rendered
    /// rounds either way.
    #[test]
    fn schedules_render_where_they_say() {
        let renders = |s: Schedule| (1..=s.rounds).map(|r| s.renders(r)).collect::<Vec<_>>();
        assert_eq!(
            renders(Schedule::grey(2.0)),
            [true, false, false, false, true]
        );
        assert_eq!(renders(Schedule::colour(2.0)), [true, true, true]);
        assert_eq!(renders(Schedule::grey(1.0)), [true, true]);
        assert_eq!(renders(Schedule::colour(1.0)), [true, true]);
        assert_eq!(
            (momentum(1), momentum(2), momentum(3)),
            (0.0, 0.0, MOMENTUM)
        );
    }

    /// A step adds the change and the carried share, keeps at least half
    /// the ink, grows the radius for more ink, and says when the 0.6–1.6
    /// clamp held it back; a dot without ink is left alone.
    #[test]
    fn a_step_moves_the_ink_and_says_when_a_clamp_holds_it() {
        let ratios = super::super::density::Ratios::new(2.0, 8.0);
        let place = ratios.place(4.0);
        assert!(step(&ratios, place, 5e-4, 0.1, 0.0).is_none());
        let s = step(&ratios, place, 0.4, 0.02, 0.01).unwrap();
        assert!(
            (s.after - 0.43).abs() < 1e-12 && s.factor > 1.0 && !s.held,
            "{s:?}"
        );
        let big = step(&ratios, place, 0.05, 0.9, 0.0).unwrap();
        assert!(big.held && big.factor == 1.6, "{big:?}");
        let cut = step(&ratios, place, 0.4, -0.5, 0.0).unwrap();
        assert!(cut.after == 0.2 && cut.factor < 1.0, "{cut:?}");
    }
}
