//! Choosing K pens from an inventory for a photo: the K whose drawing has
//! the lowest predicted colour error under the render model.
//!
//! # The prediction
//!
//! A drawing's colour error, blurred at its dot spacing, comes mostly from
//! the colours its pens cannot make: the separation maps each colour to
//! the nearest colour the pens make, and the dots reproduce that. So a set
//! of pens is scored by its separation's error over the photo's colours:
//! the photo is reduced to a weighted palette (its pixels binned on an 8³
//! grid of sRGB, the [`PALETTE_COLOURS`] heaviest bins' mean colours), each
//! colour separated into the pens' inks ([`Separation::inks`]), and the
//! score is the weighted mean ΔE00 between the colour and the model's mix
//! of its inks. No dot is drawn.
//!
//! # The search
//!
//! Greedy, then swaps: the best single pen, then the pen that lowers the
//! score most, K times; then, while some swap of a chosen pen for another
//! lowers the score, the best swap (at most [`SWAP_PASSES`] of them). Candidates are scored in parallel and
//! compared in a fixed order (ties to the pen earlier in the inventory), so
//! the choice is the same on every machine.

use rayon::prelude::*;

use super::pens::{MAX_PENS, Pen, PenError, PenSet};
use super::{Lab, RenderModel, Separation, delta_e00, encode};

/// Colours of the palette a choice is scored on.
pub const PALETTE_COLOURS: usize = 32;

/// The finest step of the separation's search when scoring a choice: a
/// 64th of an ink (the drawing's own separation goes to a 512th).
const FINEST_STEP: f64 = 1.0 / 256.0;

/// Rounds of swaps after the greedy choice.
const SWAP_PASSES: usize = 2;

/// The weight of the dots' noise against the gamut's error.
const NOISE_WEIGHT: f64 = 0.05;

/// Bins per sRGB axis of the palette's histogram: 8, so that the heaviest
/// bins hold most of a photo, its dark and saturated tails included (at
/// 16 the 32 heaviest left them out, and with the pens relaxed one by one
/// the choice for motorcycle_left measured 1.98 ΔE00 against `cmyk`'s
/// 1.71; at 8, 1.55; docs/colour.md).
const BINS: usize = 8;

/// A weighted palette of a photo's colours.
#[derive(Clone, Debug)]
pub struct Palette {
    /// Each colour (CIELAB) and its share of the photo.
    pub colours: Vec<(Lab, f64)>,
}

impl Palette {
    /// The palette of linear-RGB pixels.
    #[must_use]
    pub fn of_linear(pixels: &[[f32; 3]]) -> Self {
        let mut sums = vec![[0f64; 4]; BINS * BINS * BINS];
        for p in pixels {
            let e = p.map(|v| encode(f64::from(v.clamp(0.0, 1.0))));
            let bin = e.map(|v| ((v * BINS as f64) as usize).min(BINS - 1));
            let s = &mut sums[(bin[0] * BINS + bin[1]) * BINS + bin[2]];
            for i in 0..3 {
                s[i] += e[i];
            }
            s[3] += 1.0;
        }
        let mut bins: Vec<(usize, [f64; 4])> = sums
            .into_iter()
            .enumerate()
            .filter(|(_, s)| s[3] > 0.0)
            .collect();
        // The heaviest bins, ties by position: the same palette everywhere.
        bins.sort_by(|a, b| b.1[3].total_cmp(&a.1[3]).then(a.0.cmp(&b.0)));
        bins.truncate(PALETTE_COLOURS);
        let total: f64 = bins.iter().map(|(_, s)| s[3]).sum();
        Self {
            colours: bins
                .into_iter()
                .map(|(_, s)| {
                    let srgb = [s[0] / s[3], s[1] / s[3], s[2] / s[3]];
                    (Lab::from_srgb(srgb), s[3] / total)
                })
                .collect(),
        }
    }
}

/// The pens chosen and their predicted error.
#[derive(Clone, Debug)]
pub struct Choice {
    /// The chosen pens, in the inventory's order.
    pub pens: PenSet,
    /// The predicted mean ΔE00 over the photo's palette.
    pub predicted: f64,
    /// How many sets of pens were scored.
    pub sets_scored: usize,
}

/// The predicted error of drawing `palette` with `pens`.
#[must_use]
pub fn predicted_error(pens: &PenSet, palette: &Palette, linear: bool, max_ink: f64) -> f64 {
    let sep = Separation::new(RenderModel::new(pens, linear), max_ink);
    let model = sep.model();
    palette
        .colours
        .iter()
        .map(|&(c, w)| {
            let mut a = sep.inks_to(c, FINEST_STEP);
            let gamut = delta_e00(model.lab(model.mix(&a)), c);
            // The dots' noise: each pen's share a(1 − a) of the spots it
            // makes or not, times the colour step it makes there.
            let mut noise = 0.0;
            for k in 0..a.len() {
                let ak = a[k];
                a[k] = 1.0;
                let on = model.lab(model.mix(&a));
                a[k] = 0.0;
                let off = model.lab(model.mix(&a));
                a[k] = ak;
                let step2 =
                    (on.l - off.l).powi(2) + (on.a - off.a).powi(2) + (on.b - off.b).powi(2);
                noise += ak * (1.0 - ak) * step2;
            }
            w * (gamut + NOISE_WEIGHT * noise.sqrt())
        })
        .sum()
}

/// Chooses `k` pens of `inventory` for `palette` (see the module's text).
/// Err when `k` is 0, above [`MAX_PENS`] or above the inventory's size.
pub fn choose(
    inventory: &[Pen],
    k: usize,
    palette: &Palette,
    linear: bool,
    max_ink: f64,
) -> Result<Choice, PenError> {
    let n = inventory.len();
    if k == 0 || k > n || k > MAX_PENS {
        return Err(PenError(format!(
            "--choose {k}: choose 1 to {} of the {n} pens",
            n.min(MAX_PENS)
        )));
    }
    let set = |chosen: &[usize]| -> PenSet {
        let mut idx = chosen.to_vec();
        idx.sort_unstable();
        PenSet::new(idx.iter().map(|&i| inventory[i].clone()).collect())
            .expect("distinct pens of a checked inventory")
    };
    let mut scored = 0;
    let mut score = |sets: Vec<Vec<usize>>| -> Vec<f64> {
        scored += sets.len();
        sets.par_iter()
            .map(|s| predicted_error(&set(s), palette, linear, max_ink))
            .collect()
    };
    // The best of candidates (lowest score, the first on ties).
    let best = |scores: &[f64]| -> Option<(usize, f64)> {
        scores
            .iter()
            .copied()
            .enumerate()
            .fold(None, |b: Option<(usize, f64)>, (i, e)| match b {
                Some((_, be)) if be <= e => b,
                _ => Some((i, e)),
            })
    };
    let mut chosen: Vec<usize> = Vec::new();
    let mut current = f64::INFINITY;
    while chosen.len() < k {
        let others: Vec<usize> = (0..n).filter(|i| !chosen.contains(i)).collect();
        let sets = others
            .iter()
            .map(|&o| [chosen.clone(), vec![o]].concat())
            .collect();
        let (i, e) = best(&score(sets)).expect("an inventory larger than the choice");
        chosen.push(others[i]);
        current = e;
    }
    // Swaps, while one helps, at most [`SWAP_PASSES`] times.
    for _ in 0..SWAP_PASSES {
        let mut swaps = Vec::new();
        for slot in 0..k {
            for o in (0..n).filter(|i| !chosen.contains(i)) {
                let mut s = chosen.clone();
                s[slot] = o;
                swaps.push(s);
            }
        }
        if swaps.is_empty() {
            break;
        }
        let scores = score(swaps.clone());
        match best(&scores) {
            Some((i, e)) if e < current - 1e-9 => {
                chosen.clone_from(&swaps[i]);
                current = e;
            }
            _ => break,
        }
    }
    Ok(Choice {
        pens: set(&chosen),
        predicted: current,
        sets_scored: scored,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pen(name: &str, hex: &str) -> Pen {
        Pen {
            name: name.into(),
            colour: super::super::pens::parse_hex(hex).unwrap(),
            width_mm: None,
            dot_gain: None,
            opacity: None,
        }
    }

    fn inventory() -> Vec<Pen> {
        vec![
            pen("black", "#1a1a1a"),
            pen("red", "#d62728"),
            pen("green", "#2ca02c"),
            pen("blue", "#1f77b4"),
            pen("orange", "#ff7f0e"),
            pen("yellow", "#f5d800"),
            pen("brown", "#8c564b"),
        ]
    }

    /// A palette of colours, each with the same weight.
    fn palette(srgb: &[[f64; 3]]) -> Palette {
        Palette {
            colours: srgb
                .iter()
                .map(|&c| (Lab::from_srgb(c), 1.0 / srgb.len() as f64))
                .collect(),
        }
    }

    #[test]
    fn a_green_photo_gets_the_green_pen_and_a_red_one_the_red() {
        let green = palette(&[[0.2, 0.6, 0.2], [0.5, 0.8, 0.5], [0.9, 0.95, 0.9]]);
        let c = choose(&inventory(), 1, &green, false, 0.96).unwrap();
        assert_eq!(c.pens.pens()[0].name, "green", "{c:?}");
        let red = palette(&[[0.8, 0.2, 0.2], [0.95, 0.6, 0.6]]);
        let c = choose(&inventory(), 1, &red, false, 0.96).unwrap();
        assert_eq!(c.pens.pens()[0].name, "red", "{c:?}");
    }

    #[test]
    fn the_choice_beats_every_other_set_of_its_size_but_little() {
        // Exhaustive over the 7-pen inventory's 35 triples: the greedy and
        // swap search finds the best, or one within 2% of it.
        let photo = palette(&[
            [0.8, 0.5, 0.2],
            [0.3, 0.2, 0.1],
            [0.9, 0.9, 0.8],
            [0.2, 0.4, 0.7],
            [0.6, 0.6, 0.6],
        ]);
        let inv = inventory();
        let c = choose(&inv, 3, &photo, false, 0.96).unwrap();
        let mut best = f64::INFINITY;
        for a in 0..7 {
            for b in a + 1..7 {
                for d in b + 1..7 {
                    let set =
                        PenSet::new(vec![inv[a].clone(), inv[b].clone(), inv[d].clone()]).unwrap();
                    best = best.min(predicted_error(&set, &photo, false, 0.96));
                }
            }
        }
        assert!(
            c.predicted <= best * 1.02 + 1e-9,
            "{} vs best {best}",
            c.predicted
        );
        assert!((c.predicted - predicted_error(&c.pens, &photo, false, 0.96)).abs() < 1e-9);
        assert!(c.sets_scored < 35 + 35, "{}", c.sets_scored);
        // More pens never predict worse.
        let four = choose(&inv, 4, &photo, false, 0.96).unwrap();
        assert!(four.predicted <= c.predicted + 1e-9);
    }

    #[test]
    fn impossible_choices_are_refused_in_words() {
        let photo = palette(&[[0.5, 0.5, 0.5]]);
        for k in [0, 8, 9] {
            let e = choose(&inventory(), k, &photo, false, 0.96)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("--choose {k}")) && e.contains("1 to 7"),
                "{e}"
            );
        }
    }

    #[test]
    fn a_palette_weighs_the_photo_s_colours() {
        let mut px = vec![[0.0f32, 0.0, 0.0]; 300];
        px.extend(vec![[1.0f32, 1.0, 1.0]; 100]);
        let p = Palette::of_linear(&px);
        assert_eq!(p.colours.len(), 2);
        assert!((p.colours[0].1 - 0.75).abs() < 1e-12 && p.colours[0].0.l < 1.0);
        assert!((p.colours[1].1 - 0.25).abs() < 1e-12 && p.colours[1].0.l > 99.0);
    }
}
