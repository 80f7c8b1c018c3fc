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
//! score is the weighted mean over the palette of the ΔE00 between the
//! colour and the model's mix of its inks, plus the dots' noise
//! ([`NOISE_WEIGHT`]), less the inks' weakest gain there
//! ([`GAIN_WEIGHT`], [`weakest_gain`]): of two sets that make a colour
//! equally well, the one that can move it every way measures closer,
//! since the correction can then undo the dots' errors in any direction
//! (coffee drawn with four warm pens and a blue one measured 1.34 ΔE00;
//! with one warm pen swapped for light green, 0.95). No dot is drawn.
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

/// The weight of the weakest gain (ΔE76 per unit ink in the direction the
/// inks move the colour least): a set that can move the colour every way
/// lets the correction undo the dots' errors ([`weakest_gain`]). Of the
/// pairs of this weight and [`NOISE_WEIGHT`] measured (docs/colour.md),
/// the pair that gains 0.05 ΔE00 at σ on eight photos for 0.05 at σ/2
/// (0.03 and 0.01 gained 0.08 at σ but lost 0.25 at σ/2).
const GAIN_WEIGHT: f64 = 0.01;

/// Added to every set's score so that the prediction lands on the
/// measured mean error of the five photos' chosen drawings (it changes no
/// choice).
const OFFSET: f64 = -0.12;

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
    /// The predicted mean ΔE00 over the photo's palette: the choice's
    /// score ([`predicted_error`]), at least 0.
    pub predicted: f64,
    /// How many sets of pens were scored.
    pub sets_scored: usize,
}

/// The predicted error of drawing `palette` with `pens`: the choice's
/// score (the module's text), which lands near the measured mean ΔE00
/// and may fall below 0 where the gamut's error is nil and the inks'
/// gain large.
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
            let gain = weakest_gain(model, &mut a);
            w * (gamut + NOISE_WEIGHT * noise.sqrt() - GAIN_WEIGHT * gain)
        })
        .sum::<f64>()
        + OFFSET
}

/// The weakest gain of the colour (CIELAB) in the inks at `a`: the
/// smallest singular value of the mix's Jacobian (each ink stepped by
/// 0.02, down where it is full), ΔE76 per unit ink. It is 0 where the
/// pens move the colour in fewer than three directions (fewer than three
/// pens: exactly; pens of one hue: nearly), and large where the pens
/// together move it every way. `a` is stepped and restored.
fn weakest_gain(model: &RenderModel, a: &mut [f64]) -> f64 {
    const D: f64 = 0.02;
    // Rank two at most: no third direction (and no rounding noise to
    // break ties between sets of one or two pens).
    if a.len() < 3 {
        return 0.0;
    }
    let base = model.lab(model.mix(a));
    let mut m = [[0.0f64; 3]; 3];
    for k in 0..a.len() {
        let ak = a[k];
        let d = if ak + D <= 1.0 { D } else { -D };
        a[k] = ak + d;
        let l = model.lab(model.mix(a));
        a[k] = ak;
        let r = [(l.l - base.l) / d, (l.a - base.a) / d, (l.b - base.b) / d];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += r[i] * r[j];
            }
        }
    }
    smallest_eigenvalue(m).max(0.0).sqrt()
}

/// The smallest eigenvalue of a symmetric 3×3 matrix (closed form).
fn smallest_eigenvalue(m: [[f64; 3]; 3]) -> f64 {
    let p1 = m[0][1].powi(2) + m[0][2].powi(2) + m[1][2].powi(2);
    let q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    if p1 <= f64::EPSILON * q.abs().max(1.0) {
        return m[0][0].min(m[1][1]).min(m[2][2]);
    }
    let p2 = (m[0][0] - q).powi(2) + (m[1][1] - q).powi(2) + (m[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let b: [[f64; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| (m[i][j] - if i == j { q } else { 0.0 }) / p)
    });
    let det = super::det3(b);
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos()
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
            "«choose={k}»: choose 1 to {} of the {n} pens",
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
        predicted: current.max(0.0),
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
        let own = predicted_error(&c.pens, &photo, false, 0.96);
        assert!(
            own <= best + 0.02 * best.abs() + 1e-9,
            "{own} vs best {best}"
        );
        assert!((c.predicted - own.max(0.0)).abs() < 1e-9);
        assert!(c.sets_scored < 35 + 35, "{}", c.sets_scored);
        // More pens never predict worse.
        let four = choose(&inv, 4, &photo, false, 0.96).unwrap();
        assert!(four.predicted <= c.predicted + 1e-9);
    }

    #[test]
    fn the_smallest_eigenvalue_of_symmetric_matrices() {
        // Diagonal, a diagonal turned in the xy plane, and rank one.
        assert_eq!(
            smallest_eigenvalue([[3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]),
            1.0
        );
        let (c, s) = (0.6f64, 0.8f64);
        // R diag(5, 2, 7) Rᵀ with R a turn in the xy plane.
        let m = [
            [5.0 * c * c + 2.0 * s * s, (5.0 - 2.0) * c * s, 0.0],
            [(5.0 - 2.0) * c * s, 5.0 * s * s + 2.0 * c * c, 0.0],
            [0.0, 0.0, 7.0],
        ];
        assert!((smallest_eigenvalue(m) - 2.0).abs() < 1e-9);
        // Rank one: u uᵀ.
        let u = [1.0, -2.0, 0.5];
        let r1 = [0, 1, 2].map(|i| [0, 1, 2].map(|j| u[i] * u[j]));
        assert!(smallest_eigenvalue(r1).abs() < 1e-9);
    }

    #[test]
    fn pens_of_one_hue_have_no_gain_across_it_and_spread_pens_do() {
        let model = |names: &[&str]| {
            let mut all = inventory();
            all.extend([pen("grey", "#808080"), pen("light grey", "#c8c8c8")]);
            let pens = names
                .iter()
                .map(|n| all.iter().find(|p| p.name == *n).unwrap().clone())
                .collect();
            RenderModel::new(&PenSet::new(pens).unwrap(), false)
        };
        let gain = |names: &[&str], a: f64| {
            let mut inks = vec![a; names.len()];
            let g = weakest_gain(&model(names), &mut inks);
            assert!(inks.iter().all(|&v| v == a), "the inks are restored");
            g
        };
        // Fewer than three pens leave a direction without gain.
        assert_eq!(gain(&["black"], 0.3), 0.0);
        assert_eq!(gain(&["red", "orange"], 0.3), 0.0);
        // Three greys move the colour along the grey axis only.
        let g = gain(&["black", "grey", "light grey"], 0.3);
        assert!(g < 1e-3, "{g}");
        // Three pens of three hues move it every way.
        let spread = gain(&["red", "green", "blue"], 0.3);
        assert!(spread > 5.0, "{spread}");
        // Full ink is stepped down to 0.98 (its difference backwards), not
        // past 1; the others up.
        let rgb = model(&["red", "green", "blue"]);
        let at = [1.0, 0.2, 0.1];
        let g_full = weakest_gain(&rgb, &mut at.clone());
        let base = rgb.lab(rgb.mix(&at));
        let mut m = [[0.0; 3]; 3];
        for k in 0..3 {
            let mut a = at;
            let d = if k == 0 { -0.02 } else { 0.02 };
            a[k] += d;
            let l = rgb.lab(rgb.mix(&a));
            let r = [l.l - base.l, l.a - base.a, l.b - base.b].map(|v| v / d);
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += r[i] * r[j];
                }
            }
        }
        let backwards = smallest_eigenvalue(m).max(0.0).sqrt();
        assert!(
            g_full > 1.0 && (g_full - backwards).abs() <= 1e-9 * g_full,
            "{g_full} {backwards}"
        );
    }

    #[test]
    fn impossible_choices_are_refused_in_words() {
        let photo = palette(&[[0.5, 0.5, 0.5]]);
        for k in [0, 8, 9] {
            let e = choose(&inventory(), k, &photo, false, 0.96)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("«choose={k}»")) && e.contains("1 to 7"),
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
