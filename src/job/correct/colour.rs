//! The colour drawing's correction: its calibrated dots resized toward
//! the separation's colours under the pens' render model, on the plan's
//! [`Grid`].

use rayon::prelude::*;

use super::{ERROR_BLUR, Grid, Schedule, blur_sigmas, damping, momentum, step};
use crate::colour::pens::MAX_PENS;
use crate::colour::{RenderModel, Separation, det3};
use crate::importance::ColourMap;
use crate::sampler::Point;

use super::super::Stage;

/// The correction of the calibrated dots toward the separation's colours,
/// closing the loop that the render model leaves open: pens placed apart
/// by the cross spacing overlap less than independent ones (the model's
/// assumption), and calibration is exact only on average. The drawing is
/// rendered at about the photo's resolution, blurred by the measure's σ
/// (the mean dot spacing) and compared with the photo's colours where the
/// pens make them (the separation's nearest colours elsewhere), blurred
/// alike; the error is turned into ink changes per pen by the
/// model's Jacobian (damped least norm), and each dot is resized by the ink
/// curve to put down its pen's new ink, in the rounds of
/// [`Schedule::colour`].
pub(crate) struct ColourCorrection {
    /// The render and work grids.
    grid: Grid,
    /// Pens.
    pens: usize,
    /// At every cell of the `src` grid, the ink change per pen for a unit
    /// error in each channel ([`gain`]): pens × 3 values per cell.
    gains: Vec<f32>,
    /// The gains' grid: the `src` grid in blocks of [`GAIN_BLOCK`].
    gain_grid: (u32, u32),
    /// The grid the target and the gains' inks are made on: the work grid,
    /// or the photo's size when smaller.
    src: (u32, u32),
    /// The target, blurred, one plane per channel (work grid).
    target: [crate::analyze::fidelity::Grey; 3],
    /// The render model.
    model: RenderModel,
}

/// The most pens whose one-partial mixes are tabulated (64 × 6 × 256
/// colours; 8 pens would take 512K).
const SINGLE_MAX_PENS: usize = 6;
/// The ink below which a pen is taken to have no dots in a correction.
const MIN_INK: f64 = 0.005;
/// The side, in `src` cells, of the blocks the gains are made on.
const GAIN_BLOCK: u32 = 2;

impl ColourCorrection {
    pub(crate) fn new(
        picture: &ColourMap,
        separation: &Separation,
        grid: Grid,
    ) -> crate::Result<Self> {
        use crate::analyze::fidelity::{Grey, blur};
        let work = grid.work;
        // The photo has no more detail than its own pixels: the target and
        // the gains are made at the smaller of its size and the work grid's,
        // and read off it at each work cell.
        let src = (
            work.0.min(picture.width()).max(1),
            work.1.min(picture.height()).max(1),
        );
        let photo = picture.resized(src.0, src.1)?;
        let inks = separation.image(photo.rgb());
        let model = separation.model().clone();
        let n = (src.0 * src.1) as usize;
        // The photo's own colour where the pens make it (the separation's
        // table is exact only at its nodes), the separation's nearest colour
        // where they do not, blended between ΔE00 2 and 4.
        let colours: Vec<[f32; 3]> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut a = [0f64; MAX_PENS];
                for (k, p) in inks.iter().enumerate() {
                    a[k] = f64::from(p[i]);
                }
                let made = model.mix(&a[..inks.len()]);
                let linear = photo.rgb()[i].map(f64::from);
                let photo = model.from_linear(linear);
                let (lab_made, lab_photo) =
                    (model.lab(made), crate::colour::Lab::from_linear(linear));
                // ΔE00 ≤ 2.12 ΔE76 (the a* stretch at most 1.5, the
                // rotation term at most the sum of squares): under 0.94 in
                // Lab the photo's colour is made, without the costlier
                // CIEDE2000.
                let e76 = ((lab_made.l - lab_photo.l).powi(2)
                    + (lab_made.a - lab_photo.a).powi(2)
                    + (lab_made.b - lab_photo.b).powi(2))
                .sqrt();
                let w = if e76 < 0.94 {
                    0.0
                } else {
                    let off = crate::colour::delta_e00(lab_made, lab_photo);
                    ((off - 2.0) / 2.0).clamp(0.0, 1.0)
                };
                std::array::from_fn(|k| ((1.0 - w) * photo[k] + w * made[k]) as f32)
            })
            .collect();
        let pens = inks.len();
        let damping = damping(grid.sigma);
        // The gains vary with the inks more smoothly than the colours do:
        // made on blocks of GAIN_BLOCK² cells (the blocks' mean inks).
        let gain_grid = (src.0.div_ceil(GAIN_BLOCK), src.1.div_ceil(GAIN_BLOCK));
        let mut gains = vec![0f32; (gain_grid.0 * gain_grid.1) as usize * pens * 3];
        gains
            .par_chunks_mut(pens * 3)
            .enumerate()
            .for_each(|(i, out)| {
                let (bx, by) = (i as u32 % gain_grid.0, i as u32 / gain_grid.0);
                let mut a = [0f64; MAX_PENS];
                let mut n = 0.0;
                for y in by * GAIN_BLOCK..((by + 1) * GAIN_BLOCK).min(src.1) {
                    for x in bx * GAIN_BLOCK..((bx + 1) * GAIN_BLOCK).min(src.0) {
                        let j = (y * src.0 + x) as usize;
                        for (k, p) in inks.iter().enumerate() {
                            a[k] += f64::from(p[j]);
                        }
                        n += 1.0;
                    }
                }
                for v in &mut a[..pens] {
                    *v /= n;
                }
                let g = gain(&model, &a[..pens], damping);
                for (k, o) in out.chunks_mut(3).enumerate() {
                    for c in 0..3 {
                        o[c] = g[k][c] as f32;
                    }
                }
            });
        let src_sigma =
            blur_sigmas(grid.px_per_spacing()) * grid.sigma * f64::from(src.0) / f64::from(work.0);
        let mut target = Vec::with_capacity(3);
        for k in 0..3 {
            let blurred = blur(
                &Grey {
                    width: src.0,
                    height: src.1,
                    values: colours.iter().map(|c| c[k]).collect(),
                },
                src_sigma,
            );
            target.push(if src == work {
                blurred
            } else {
                let up =
                    crate::importance::ImportanceMap::from_values(src.0, src.1, blurred.values)?
                        .resized(work.0, work.1)?;
                Grey {
                    width: work.0,
                    height: work.1,
                    values: up.values().to_vec(),
                }
            });
        }
        let target: [Grey; 3] = target
            .try_into()
            .map_err(|_| crate::stipple::Error::InvalidParameter("three channels".into()))?;
        Ok(Self {
            grid,
            gain_grid,
            pens,
            gains,
            src,
            target,
            model,
        })
    }

    /// Corrects `calibrated` (the dots' radii) of `points`, whose pens were
    /// to put down `inks` at the spacing of maximal sets of radii `spacing`,
    /// in the rounds of [`Schedule::colour`].
    pub(crate) fn apply(
        &self,
        points: &[Point],
        inks: &[f64],
        spacing: &[f64],
        calibrated: &mut [f32],
        pens: usize,
        stage: &mut dyn FnMut(Stage) -> crate::Result<()>,
    ) -> crate::Result<()> {
        let grid = &self.grid;
        let (ww, wh) = grid.work;
        let mut assumed = inks.to_vec();
        // The dot ratios tabulated over the spacings' range, as the grey
        // correction reads them.
        let (lo, hi) = spacing
            .iter()
            .fold((f64::INFINITY, 0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        let ratios = super::super::density::Ratios::new(lo, hi);
        // The mix where one pen covers a render pixel in part and each
        // other wholly or not at all (most such pixels), by the mask of the
        // whole ones, that pen and its byte: made by `mix` itself, so the
        // same values. Up to [`SINGLE_MAX_PENS`] pens.
        let single: Vec<[f64; 3]> = if pens <= SINGLE_MAX_PENS {
            (0..(1usize << pens) * pens * 256)
                .into_par_iter()
                .map(|i| {
                    let (whole, k, v) = (i / (pens * 256), i / 256 % pens, i % 256);
                    let mut a = [0f64; MAX_PENS];
                    for (j, a) in a.iter_mut().enumerate().take(pens) {
                        *a = if whole >> j & 1 == 1 { 1.0 } else { 0.0 };
                    }
                    a[k] = 1.0 - v as f64 / 255.0;
                    self.model.mix(&a[..pens])
                })
                .collect()
        } else {
            Vec::new()
        };
        // Each dot's work cell, the block of its gains and its spacing's
        // place among the ratios' rows: the same every round.
        let at: Vec<(u32, u32, f64)> = points
            .par_iter()
            .zip(spacing.par_iter())
            .map(|(p, &r)| {
                let g = grid.cell(p);
                let (gx, gy) = (g as u32 % ww, g as u32 / ww);
                let (sx, sy) = (gx * self.src.0 / ww, gy * self.src.1 / wh);
                let s = (sy / GAIN_BLOCK) * self.gain_grid.0 + sx / GAIN_BLOCK;
                (g as u32, s, ratios.place(r))
            })
            .collect();
        let of = Schedule::colour(grid.sigma).rounds;
        // Each dot's last ink change (momentum).
        let mut change = vec![0f64; points.len()];
        for round in 1..=of {
            stage(Stage::Correct { round, of })?;
            let layers = (0..pens as u32)
                .into_par_iter()
                .map(|k| grid.render(points, calibrated, |p| p.class == k))
                .collect::<Result<Vec<_>, _>>()?;
            // What the drawing shows, in the model's space, averaged over
            // each work-grid cell (the render pixels' colours, so that the
            // overlaps within a cell count).
            let shown = grid.cell_means(|i| {
                // Where every pen covers the pixel wholly or not at all
                // (most pixels), the mix is that overlap's colour itself,
                // exactly.
                let mut whole = 0usize;
                let mut partial = None;
                let mut several = false;
                for (k, l) in layers.iter().enumerate() {
                    match l.as_raw()[i] {
                        0 => whole |= 1 << k,
                        255 => {}
                        v => {
                            several |= partial.is_some();
                            partial = Some((k, usize::from(v)));
                        }
                    }
                }
                if let (Some((k, v)), false, false) = (partial, several, single.is_empty()) {
                    single[(whole * pens + k) * 256 + v]
                } else if partial.is_some() {
                    let mut a = [0f64; MAX_PENS];
                    for (k, l) in layers.iter().enumerate() {
                        a[k] = 1.0 - f64::from(l.as_raw()[i]) / 255.0;
                    }
                    self.model.mix(&a[..pens])
                } else {
                    self.model.primary(whole)
                }
            });
            let sigmas = blur_sigmas(grid.px_per_spacing());
            let drawn =
                [0, 1, 2].map(|k| grid.blurred(shown.iter().map(|c| c[k]).collect(), sigmas));
            // The error, smoothed once more: corrections follow the local
            // bias, not each dot's own noise.
            let error = [0, 1, 2].map(|k| {
                let values = self.target[k]
                    .values
                    .iter()
                    .zip(&drawn[k].values)
                    .map(|(t, d)| t - d)
                    .collect();
                grid.blurred(values, ERROR_BLUR * sigmas)
            });
            let beta = momentum(round);
            // Each dot's own update: in parallel, the same values.
            points
                .par_iter()
                .zip(calibrated.par_iter_mut())
                .zip(assumed.par_iter_mut())
                .zip(at.par_iter())
                .zip(change.par_iter_mut())
                .for_each(|((((p, cal), assumed), &(g, s, place)), change)| {
                    let (g, s) = (g as usize, s as usize);
                    let k = p.class as usize;
                    // The ink change of the dot's pen at its work cell.
                    let e = [0, 1, 2].map(|c| error[c].values[g]);
                    let gain = &self.gains[(s * self.pens + k) * 3..(s * self.pens + k + 1) * 3];
                    let delta = gain[0] * e[0] + gain[1] * e[1] + gain[2] * e[2];
                    let (before, last) = (*assumed, std::mem::take(change));
                    let Some(s) = step(&ratios, place, before, f64::from(delta), beta * last)
                    else {
                        return;
                    };
                    *cal *= s.factor as f32;
                    *assumed = s.after;
                    // A dot held by the clamp did not put down the change:
                    // none of it is carried.
                    if !s.held {
                        *change = s.after - before;
                    }
                });
        }
        Ok(())
    }
}

/// The damped least-norm ink change Δa = G·e with J·Δa = e, J the model's
/// Jacobian at inks `a` (3 × pens): G = DAMPING · Jᵀ (J Jᵀ + λI)⁻¹, one
/// row of 3 per pen.
fn gain(model: &RenderModel, a: &[f64], damping: f64) -> [[f64; 3]; MAX_PENS] {
    let n = a.len();
    let base = model.mix(a);
    let mut jac = [[0f64; 3]; MAX_PENS];
    let mut b = [0f64; MAX_PENS];
    b[..n].copy_from_slice(a);
    for k in 0..n {
        // A pen without dots here cannot change: no column.
        if a[k] < MIN_INK {
            continue;
        }
        let h = if a[k] > 0.5 { -1e-3 } else { 1e-3 };
        b[k] = a[k] + h;
        let c = model.mix(&b[..n]);
        b[k] = a[k];
        for i in 0..3 {
            jac[k][i] = (c[i] - base[i]) / h;
        }
    }
    // (J Jᵀ + λI) y = e, Δa = Jᵀ y: the inverse's columns solved for.
    let lambda = 1e-2;
    let mut m = [[0f64; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = jac[..n].iter().map(|c| c[i] * c[j]).sum::<f64>()
                + if i == j { lambda } else { 0.0 };
        }
    }
    let inv = [0, 1, 2].map(|c| solve3(m, std::array::from_fn(|r| f64::from(u8::from(r == c)))));
    let mut g = [[0f64; 3]; MAX_PENS];
    for k in 0..n {
        for c in 0..3 {
            g[k][c] = damping * (0..3).map(|i| jac[k][i] * inv[c][i]).sum::<f64>();
        }
    }
    g
}

/// Solves the 3×3 system `m`·x = `b` (Cramer's rule; `m` is positive
/// definite here).
fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let d = det3(m);
    if d.abs() < 1e-12 {
        return [0.0; 3];
    }
    std::array::from_fn(|c| {
        let mut mc = m;
        for r in 0..3 {
            mc[r][c] = b[r];
        }
        det3(mc) / d
    })
}
