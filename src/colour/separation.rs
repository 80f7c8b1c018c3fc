//! The render model of a colour drawing, and the separation of a photo into
//! the inks of a pen set under it.
//!
//! # Render model
//!
//! White paper; each pen's ink is the union of its dots; where dots of
//! several pens overlap their inks multiply (transmittance in linear light):
//! a point under the pens of set S has the linear colour Π_{k∈S} t_k, t_k the
//! pen's colour decoded from sRGB. A region where pen k covers the fraction
//! a_k of the paper, the pens placed independently of each other (Demichel),
//! shows the pens of S together on w_S = Π_{k∈S} a_k Π_{k∉S} (1 − a_k) of
//! it. Its average colour is Σ_S w_S·c_S (Neugebauer), with c_S the sRGB
//! encoding of Π_{k∈S} t_k under the display convention (a region's colour
//! averages sRGB values, as the grey measure does) or the linear value itself
//! under the linear convention.
//!
//! # Separation
//!
//! For a colour, the inks a ∈ [0, a_max]^n minimize
//! ΔE00(model(a), colour)² + λ·Σ a_k, in CIELAB D65: inside the pens' gamut
//! the colour itself, outside it the nearest colour the pens make by the
//! CIEDE2000 measure; λ = [`INK_COST`] breaks ties towards less ink (black
//! rather than three colours over each other). The minimum is found by a
//! pattern search (the best coordinate step, steps halving from ¼ to
//! 1/512; CIE76 down to 1/32, then CIEDE2000) from no ink, and again from half of every ink where that ends
//! more than ΔE00 0.5 off. An image is separated through a 17³ table over sRGB-encoded RGB,
//! solved at the nodes its pixels need and interpolated tetrahedrally (a
//! grey reads grey nodes only).

use rayon::prelude::*;

use super::{Lab, PenSet, decode, delta_e00, encode};

/// The cost of a whole pen's ink, in ΔE00²: the tie-break towards less ink.
pub const INK_COST: f64 = 0.25;
/// The search's steps below this use CIEDE2000, the coarser ones CIE76.
const FINE_STEP: f64 = 1.0 / 32.0;
/// Nodes per axis of the separation table.
pub const TABLE_NODES: usize = 17;

/// The render model of a pen set under a tone convention.
#[derive(Clone, Debug)]
pub struct RenderModel {
    /// The colour of each overlap set S (bit k = pen k), in the convention's
    /// space: sRGB-encoded (display) or linear.
    primaries: Vec<[f64; 3]>,
    /// Whether the convention is linear light.
    linear: bool,
    /// Pens.
    pens: usize,
}

impl RenderModel {
    /// The model of `pens` on white paper, averaging linear light when
    /// `linear`, else sRGB-encoded values.
    #[must_use]
    pub fn new(pens: &PenSet, linear: bool) -> Self {
        let order: Vec<usize> = (0..pens.len()).collect();
        Self::on_paper(pens, linear, [255; 3], &order)
    }

    /// The model of `pens` laid on paper of colour `paper` (sRGB) in the
    /// plotting order `order` (pen indices; any other list means the pens'
    /// own order): where the pens of a set S overlap, each pen k of S in
    /// turn turns the colour c below it into (1 − o_k)·c·t_k + o_k·t_k, o_k
    /// its opacity ([`super::Pen::opacity_on`]): a transparent ink
    /// multiplies, an opaque one covers.
    #[must_use]
    pub fn on_paper(pens: &PenSet, linear: bool, paper: [u8; 3], order: &[usize]) -> Self {
        let lin = |c: [u8; 3]| c.map(|v| decode(f64::from(v) / 255.0));
        let t: Vec<([f64; 3], f64)> = pens
            .pens()
            .iter()
            .map(|p| (lin(p.colour), p.opacity_on(paper)))
            .collect();
        let n = t.len();
        let mut sorted = order.to_vec();
        sorted.sort_unstable();
        let order: Vec<usize> = if sorted == (0..n).collect::<Vec<_>>() {
            order.to_vec()
        } else {
            (0..n).collect()
        };
        let base = lin(paper);
        let primaries = (0..1usize << n)
            .map(|s| {
                let mut c = base;
                for &k in &order {
                    if s >> k & 1 == 1 {
                        let (tk, o) = t[k];
                        for i in 0..3 {
                            c[i] = (1.0 - o) * c[i] * tk[i] + o * tk[i];
                        }
                    }
                }
                if linear { c } else { c.map(encode) }
            })
            .collect();
        Self {
            primaries,
            linear,
            pens: n,
        }
    }

    /// The number of pens.
    #[must_use]
    pub fn pens(&self) -> usize {
        self.pens
    }

    /// Whether the model averages linear light.
    #[must_use]
    pub fn linear(&self) -> bool {
        self.linear
    }

    /// The average colour, in the convention's space, of a region where
    /// pen k covers `a[k]` of the paper.
    #[must_use]
    pub fn mix(&self, a: &[f64]) -> [f64; 3] {
        // The weights on the stack at the size the pens need (clearing all
        // 2^MAX_PENS of them cost more than the mix of four pens).
        match self.pens {
            0..=4 => self.mix_in::<16>(a),
            5..=6 => self.mix_in::<64>(a),
            _ => self.mix_in::<{ 1 << super::pens::MAX_PENS }>(a),
        }
    }

    /// [`Self::mix`] with room for `M` ≥ 2^pens weights.
    fn mix_in<const M: usize>(&self, a: &[f64]) -> [f64; 3] {
        let mut w = [0f64; M];
        w[0] = 1.0;
        for (k, &ak) in a.iter().enumerate().take(self.pens) {
            let half = 1usize << k;
            for s in 0..half {
                w[s | half] = w[s] * ak;
                w[s] *= 1.0 - ak;
            }
        }
        let mut c = [0f64; 3];
        for (ws, p) in w.iter().zip(&self.primaries) {
            for i in 0..3 {
                c[i] += ws * p[i];
            }
        }
        c
    }

    /// The colour of the pens of set `s` (bit k = pen k) over each other, in
    /// the convention's space.
    #[must_use]
    pub fn primary(&self, s: usize) -> [f64; 3] {
        self.primaries[s]
    }

    /// The CIELAB colour of a value in the convention's space.
    #[must_use]
    pub fn lab(&self, c: [f64; 3]) -> Lab {
        if self.linear {
            Lab::from_linear(c)
        } else {
            Lab::from_srgb(c)
        }
    }

    /// The convention's value of a linear colour.
    #[must_use]
    pub fn from_linear(&self, rgb: [f64; 3]) -> [f64; 3] {
        if self.linear { rgb } else { rgb.map(encode) }
    }
}

/// The separation of colours into a pen set's inks.
#[derive(Debug)]
pub struct Separation {
    model: RenderModel,
    /// The most ink a pen may put down.
    max_ink: f64,
    /// The table's nodes, solved on first use.
    table: Vec<std::sync::OnceLock<[f32; super::pens::MAX_PENS]>>,
}

impl Separation {
    /// A separation under `model`, each ink at most `max_ink`.
    #[must_use]
    pub fn new(model: RenderModel, max_ink: f64) -> Self {
        Self {
            model,
            max_ink,
            table: (0..TABLE_NODES.pow(3))
                .map(|_| std::sync::OnceLock::new())
                .collect(),
        }
    }

    /// The render model.
    #[must_use]
    pub fn model(&self) -> &RenderModel {
        &self.model
    }

    /// The inks for the colour of CIELAB `target`.
    #[must_use]
    pub fn inks(&self, target: Lab) -> Vec<f64> {
        self.inks_to(target, 1.0 / 512.0)
    }

    /// [`Self::inks`], the search's steps halving down to `finest`.
    #[must_use]
    pub fn inks_to(&self, target: Lab, finest: f64) -> Vec<f64> {
        let n = self.model.pens;
        // CIE76 (Lab distance, cheap) while the steps are coarse, CIEDE2000
        // for the fine ones.
        let cost = |a: &[f64], fine: bool| {
            let lab = self.model.lab(self.model.mix(a));
            let e2 = if fine {
                delta_e00(lab, target).powi(2)
            } else {
                (lab.l - target.l).powi(2) + (lab.a - target.a).powi(2) + (lab.b - target.b).powi(2)
            };
            e2 + INK_COST * a.iter().sum::<f64>()
        };
        // The second start only where the first ends off the colour (out
        // of gamut, or a local minimum).
        let starts = [vec![0.0; n], vec![0.5 * self.max_ink; n]];
        let mut best: Option<(f64, Vec<f64>)> = None;
        for mut a in starts {
            if best
                .as_ref()
                .is_some_and(|(e, a)| *e - INK_COST * a.iter().sum::<f64>() < 0.25)
            {
                break;
            }
            let mut step = 0.25;
            let mut fine = false;
            let mut e = cost(&a, fine);
            // The point the last move came from (pen, ink): its cost is
            // higher than the current one's, so it is never picked again.
            let mut came_from: Option<(usize, f64)> = None;
            while step > finest {
                if !fine && step < FINE_STEP {
                    fine = true;
                    e = cost(&a, fine);
                    came_from = None;
                }
                // The best of the 2n coordinate steps, if any improves.
                let mut pick: Option<(f64, usize, f64)> = None;
                for k in 0..n {
                    for dir in [1.0, -1.0] {
                        let t = (a[k] + dir * step).clamp(0.0, self.max_ink);
                        if t == a[k] || came_from == Some((k, t)) {
                            continue;
                        }
                        let old = a[k];
                        a[k] = t;
                        let e2 = cost(&a, fine);
                        a[k] = old;
                        if e2 < pick.map_or(e, |p| p.0) {
                            pick = Some((e2, k, t));
                        }
                    }
                }
                match pick {
                    Some((e2, k, t)) => {
                        e = e2;
                        came_from = Some((k, a[k]));
                        a[k] = t;
                    }
                    None => step *= 0.5,
                }
            }
            if best.as_ref().is_none_or(|(b, _)| e < *b) {
                best = Some((e, a));
            }
        }
        best.map(|(_, a)| a).unwrap_or_default()
    }

    /// The inks of every pixel of a linear-RGB image, one plane per pen,
    /// through the table ([`TABLE_NODES`]³ over sRGB-encoded RGB, solved
    /// at the nodes the pixels need).
    #[must_use]
    pub fn image(&self, linear_rgb: &[[f32; 3]]) -> Vec<Vec<f32>> {
        const N: usize = TABLE_NODES;
        let step = (N - 1) as f32;
        // sRGB encoding through a table: 2^16 steps of linear light, made
        // once in the process.
        const STEPS: usize = 1 << 16;
        static ENCODE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
        let enc = ENCODE.get_or_init(|| {
            (0..=STEPS)
                .into_par_iter()
                .map(|i| encode(i as f64 / STEPS as f64) as f32)
                .collect()
        });
        let axis = |v: f32| {
            let t = v.clamp(0.0, 1.0) * STEPS as f32;
            let i = (t as usize).min(STEPS - 1);
            let e = enc[i] + (t - i as f32) * (enc[i + 1] - enc[i]);
            let x = e * step;
            let i = (x as usize).min(N - 2);
            (i, x - i as f32)
        };
        // Tetrahedral: the cell's corners along the path that adds the axes
        // in the order of their fractions, so that a grey reads grey nodes
        // only; the four nodes and their weights.
        let tetrahedron = |p: &[f32; 3]| -> ([usize; 4], [f32; 4]) {
            let c = [axis(p[0]), axis(p[1]), axis(p[2])];
            // The axes by falling fraction, ties in axis order (the stable
            // sort of three, by hand).
            let mut axes = [0usize, 1, 2];
            let before = |a: usize, b: usize| c[b].1.total_cmp(&c[a].1).is_lt();
            if before(axes[1], axes[0]) {
                axes.swap(0, 1);
            }
            if before(axes[2], axes[1]) {
                axes.swap(1, 2);
                if before(axes[1], axes[0]) {
                    axes.swap(0, 1);
                }
            }
            let mut node = [c[0].0, c[1].0, c[2].0];
            let f = axes.map(|a| c[a].1);
            let weights = [1.0 - f[0], f[0] - f[1], f[1] - f[2], f[2]];
            let nodes = std::array::from_fn(|step| {
                if step > 0 {
                    node[axes[step - 1]] += 1;
                }
                node[0] * N * N + node[1] * N + node[2]
            });
            (nodes, weights)
        };
        // A node's inks, solved where a pixel first reads it (once for this
        // separation; a thread that reads a node being solved waits for it),
        // so that only the nodes the pixels read are solved.
        let n = self.model.pens;
        let node = |i: usize| {
            self.table[i].get_or_init(|| {
                let rgb = [i / (N * N), i / N % N, i % N].map(|v| v as f64 / f64::from(step));
                let a = self.inks(Lab::from_srgb(rgb));
                let mut out = [0f32; super::pens::MAX_PENS];
                for (o, v) in out.iter_mut().zip(a) {
                    *o = v as f32;
                }
                out
            })
        };
        let mut planes = vec![vec![0f32; linear_rgb.len()]; n];
        // Each chunk of pixels writes its part of every plane.
        const CHUNK: usize = 1 << 12;
        let mut parts: Vec<Vec<&mut [f32]>> = Vec::new();
        for plane in &mut planes {
            for (c, part) in plane.chunks_mut(CHUNK).enumerate() {
                if parts.len() <= c {
                    parts.push(Vec::with_capacity(n));
                }
                parts[c].push(part);
            }
        }
        parts.into_par_iter().enumerate().for_each(|(c, mut out)| {
            let pixels = &linear_rgb[c * CHUNK..(c * CHUNK + CHUNK).min(linear_rgb.len())];
            for (j, p) in pixels.iter().enumerate() {
                let (nodes, weights) = tetrahedron(p);
                let mut sum = [0f32; super::pens::MAX_PENS];
                for (i, w) in nodes.into_iter().zip(weights) {
                    for (o, v) in sum.iter_mut().zip(node(i)).take(n) {
                        *o += w * v;
                    }
                }
                for (plane, v) in out.iter_mut().zip(sum) {
                    plane[j] = v;
                }
            }
        });
        planes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_mixes_paper_inks_and_overlaps() {
        let m = RenderModel::new(&PenSet::cmyk(), true);
        assert_eq!(m.mix(&[0.0; 4]), [1.0, 1.0, 1.0]);
        // Full cyan and yellow: green, their product.
        let g = m.mix(&[1.0, 0.0, 1.0, 0.0]);
        assert!(g[0].abs() < 1e-12 && (g[1] - 1.0).abs() < 1e-12 && g[2].abs() < 1e-12);
        // Half black in linear light: half the light.
        assert!((m.mix(&[0.0, 0.0, 0.0, 0.5])[1] - 0.5).abs() < 1e-12);
        // Under the display convention half black averages sRGB 1 and 0.
        let d = RenderModel::new(&PenSet::cmyk(), false);
        assert!((d.mix(&[0.0, 0.0, 0.0, 0.5])[1] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn inks_lie_on_the_paper_in_plotting_order() {
        let pens = PenSet::from_toml(
            "[[pen]]\nname = \"black\"\ncolour = \"#000000\"\n\
             [[pen]]\nname = \"white\"\ncolour = \"#ffffff\"\nopacity = 1\n",
        )
        .unwrap();
        let grey = [0x80; 3];
        let g = decode(128.0 / 255.0);
        // Black, then white over it: where both are, white covers black.
        let m = RenderModel::on_paper(&pens, true, grey, &[0, 1]);
        assert!((m.mix(&[0.0, 0.0])[1] - g).abs() < 1e-12, "the paper");
        assert!(m.mix(&[1.0, 0.0])[1].abs() < 1e-12, "black multiplies");
        assert!((m.mix(&[0.0, 1.0])[1] - 1.0).abs() < 1e-12, "white covers");
        assert!((m.mix(&[1.0, 1.0])[1] - 1.0).abs() < 1e-12, "white last");
        // White first, then black over it: black.
        let m = RenderModel::on_paper(&pens, true, grey, &[1, 0]);
        assert!(m.mix(&[1.0, 1.0])[1].abs() < 1e-12, "black last");
        // A transparent white ink on grey paper shows nothing; unset, an
        // ink lighter than the paper covers.
        let felt = PenSet::parse("#ffffff").unwrap();
        assert_eq!(felt.pens()[0].opacity_on(grey), 1.0);
        assert_eq!(felt.pens()[0].opacity_on([255; 3]), 0.0);
        // On white paper the model is the multiplying one.
        let cmyk = PenSet::cmyk();
        let (a, b) = (
            RenderModel::new(&cmyk, false),
            RenderModel::on_paper(&cmyk, false, [255; 3], &[3, 2, 1, 0]),
        );
        for s in 0..16 {
            for i in 0..3 {
                assert!((a.primary(s)[i] - b.primary(s)[i]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn colours_inside_the_gamut_separate_exactly() {
        for linear in [false, true] {
            let sep = Separation::new(RenderModel::new(&PenSet::cmyk(), linear), 0.96);
            for rgb in [
                [0.8, 0.3, 0.2],
                [0.2, 0.5, 0.7],
                [0.5, 0.5, 0.5],
                [0.9, 0.85, 0.4],
            ] {
                let target = Lab::from_srgb(rgb);
                let a = sep.inks(target);
                let got = sep.model().lab(sep.model().mix(&a));
                assert!(
                    delta_e00(got, target) < 0.5,
                    "{rgb:?} linear {linear}: {a:?}"
                );
            }
        }
    }

    /// A pixel on a node of the table takes that node's inks; any pixel
    /// takes the same inks whatever else was separated before and on any
    /// number of threads (nodes are solved where first read).
    #[test]
    fn image_inks_come_from_the_table_the_same_on_any_threads() {
        let model = RenderModel::new(&PenSet::cmyk(), false);
        let step = (TABLE_NODES - 1) as f64;
        // sRGB 8/16, 4/16 and 12/16 of the way: a node; then a ramp.
        let on_node = [[8.0 / step, 4.0 / step, 12.0 / step]
            .map(decode)
            .map(|v| v as f32)];
        let ramp: Vec<[f32; 3]> = (0..500)
            .map(|i| {
                let t = i as f32 / 499.0;
                [t, (1.0 - t) * 0.7, (t * 7.0).fract()]
            })
            .collect();
        let sep = Separation::new(model.clone(), 0.96);
        let planes = sep.image(&on_node);
        let want = sep.inks(Lab::from_srgb([8.0 / step, 4.0 / step, 12.0 / step]));
        for (p, w) in planes.iter().zip(&want) {
            assert!((f64::from(p[0]) - w).abs() < 1e-6, "{p:?} {want:?}");
        }
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let four = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let alone = one.install(|| Separation::new(model.clone(), 0.96).image(&ramp));
        let after = four.install(|| sep.image(&ramp));
        assert_eq!(alone, after);
        assert!(alone.iter().any(|p| p.iter().any(|&a| a > 0.1)));
    }

    #[test]
    fn greys_take_black_ink_only() {
        let sep = Separation::new(RenderModel::new(&PenSet::cmyk(), false), 0.96);
        for v in [0.2, 0.5, 0.8] {
            let a = sep.inks(Lab::from_srgb([v; 3]));
            assert!(a[..3].iter().all(|&x| x < 0.01), "{v}: {a:?}");
            assert!((a[3] - (1.0 - v)).abs() < 0.01, "{v}: {a:?}");
        }
    }

    #[test]
    fn out_of_gamut_colours_get_the_nearest_colour_the_pens_make() {
        // Black and red pens cannot make blue: the nearest is a dark grey
        // or red, not nothing.
        let pens = PenSet::parse("#000000,#d62728").unwrap();
        let sep = Separation::new(RenderModel::new(&pens, false), 0.96);
        let target = Lab::from_srgb([0.1, 0.2, 0.8]);
        let a = sep.inks(target);
        let got = sep.model().lab(sep.model().mix(&a));
        let paper = sep.model().lab(sep.model().mix(&[0.0, 0.0]));
        assert!(delta_e00(got, target) < delta_e00(paper, target));
        // And no pen combination on a 1/16 grid beats it by more than 0.5.
        let mut best = f64::MAX;
        for i in 0..=16 {
            for j in 0..=16 {
                let m = [i as f64 * 0.06, j as f64 * 0.06];
                best = best.min(delta_e00(sep.model().lab(sep.model().mix(&m)), target));
            }
        }
        assert!(delta_e00(got, target) < best + 0.5);
    }
}
