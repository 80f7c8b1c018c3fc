//! Colour drawings (`--pens`): the photo separated into the pens' inks
//! under the render model ([`crate::colour::separation`]), one importance
//! map per pen, all pens sampled together in one multi-class run
//! ([`crate::sampler::classes`]) so that they interleave, each pen's dots
//! calibrated to its own ink, and the outputs: one Inkscape layer per pen,
//! the composite PNG, a `pen` column in CSV and JSON.

use std::path::Path;

use super::{Format, Job, Stage, Stipple};
use crate::stipple::{Dot, svg};
use rayon::prelude::*;

use crate::colour::pens::MAX_PENS;
use crate::colour::{RenderModel, Separation};
use crate::importance::ink::{self, K_MAX};
use crate::importance::{Adjust, ColourMap, Mapping, MappingKind, Prepared, RadiusRange, Tones};
use crate::sampler::Point;

use super::correct::{ERROR_BLUR, Grid, MAX_INK, damping, rounds};

/// A colour picture prepared for drawing: one map per pen, and what the
/// size stage's correction compares the drawing with.
pub(crate) struct Separated {
    /// One prepared map per pen, at the domain's size.
    pub maps: Vec<Prepared>,
    /// The picture, tones adjusted, at the size it was separated at.
    pub picture: ColourMap,
    /// The separation (its table solved where the picture needed it).
    pub separation: Separation,
}

impl Job {
    /// The render model of this job's pens, under its tone convention.
    #[must_use]
    pub fn render_model(&self) -> Option<RenderModel> {
        let linear = self.importance.tones == Tones::Linear;
        self.pens.as_ref().map(|p| RenderModel::new(p, linear))
    }

    /// The prepare stage of a colour drawing: the picture at the domain's
    /// size (`domain`), its tones adjusted as the grey drawing's are
    /// ([`ColourMap::adjusted`]: levels, gamma and invert on the
    /// lightness, hue kept), separated into the pens' inks, one map per
    /// pen, no ink where `--white-cutoff` drops dots. The separation is
    /// solved at the smaller of the picture's and the domain's sizes, and
    /// the inks resized (triangle filter) to the domain when it is larger.
    pub(crate) fn separate(
        &self,
        picture: &ColourMap,
        domain: (u32, u32),
        count_target: bool,
    ) -> crate::Result<Separated> {
        let Some(model) = self.render_model() else {
            return Err(crate::stipple::Error::InvalidParameter(
                "a colour drawing needs --pens".into(),
            )
            .into());
        };
        let (width, height) = domain;
        let imp = &self.importance;
        imp.check()?;
        let source = u64::from(picture.width()) * u64::from(picture.height());
        let upscaled = source < u64::from(width) * u64::from(height);
        let at = if upscaled {
            picture.clone()
        } else {
            picture.resized(width, height)?
        };
        let adjust = imp.adjust();
        let (at, tone) = if adjust == Adjust::default() && imp.white_cutoff.is_none() {
            (at, None)
        } else {
            let (a, t) = at.adjusted(imp.tones, &adjust)?;
            (a, Some(t))
        };
        let separation = Separation::new(model, K_MAX);
        let mut inks = at.separate(&separation);
        if let (Some(cut), Some(tone)) = (imp.white_cutoff, &tone) {
            // No ink, hence no dots, where the grey drawing drops them.
            inks = inks
                .into_iter()
                .map(|map| map.with_values_where(|i| tone[i] > cut, 1.0))
                .collect();
        }

        let mapping = match imp.mapping {
            Some(MappingKind::Linear) => Mapping::Linear,
            _ => self.dot_mode().mapping(self.dot_ratio),
        };
        let range = self.dot_range(imp.radius_range(count_target)?, domain)?;
        let maps = inks
            .into_iter()
            .map(|map| Prepared::new(map, mapping, range, None).stretched(domain))
            .collect();
        Ok(Separated {
            maps,
            picture: at,
            separation,
        })
    }

    /// The size stage of a colour drawing: each dot calibrated to its pen's
    /// ink at the spacing its pen's dots have (each pen holds its share of
    /// the union sample's points: its own density, [`super::assign`], up to
    /// the sampler's packing, measured once over the drawing), then corrected toward the picture's colours ([`Correction`]); with
    /// `--dot fixed`, one radius per pen (the root mean square of its
    /// calibrated dots'); with `--mapping linear`, the mapping's dots.
    pub(crate) fn colour_sizes(
        &self,
        separated: &Separated,
        points: &[Point],
        range: RadiusRange,
        grid: Option<Grid>,
        stage: &mut dyn FnMut(Stage) -> crate::Result<()>,
    ) -> crate::Result<Vec<f32>> {
        let maps = &separated.maps;
        if maps.first().is_some_and(|m| m.mapping == Mapping::Linear) {
            return Ok(points
                .iter()
                .map(|p| maps[p.class as usize].dot_radius(p, range))
                .collect());
        }
        stage(Stage::Calibrate)?;
        let inks: Vec<f64> = points
            .par_iter()
            .map(|p| f64::from(1.0 - maps[p.class as usize].value_at(p.x, p.y)))
            .collect();
        // Each pen's dots lie at the spacing of a maximal set of that pen
        // alone, up to how much more tightly the union packs than the
        // count's prediction: one factor k over the whole drawing.
        let scale = f64::from(range.max) / f64::from(maps[0].range.max);
        let expected: f64 = maps.iter().map(|m| m.predicted_points(scale)).sum();
        let k = if expected > 0.0 {
            (points.len() as f64 / expected).clamp(0.25, 4.0)
        } else {
            1.0
        };
        let spacing: Vec<f64> = points
            .par_iter()
            .map(|p| f64::from(p.radius) / k.sqrt())
            .collect();
        // Each pen's calibrated dot radius as a function of its value, made
        // once (the black dots' radius inverts the ink curve).
        let dot_radius: Vec<_> = maps.iter().map(|m| m.mapping.dot_radii(range)).collect();
        let ratios =
            super::density::Ratios::new(f64::from(range.min) * 0.5, f64::from(range.max) * 3.2);
        let mut calibrated: Vec<f32> = points
            .par_iter()
            .zip(&inks)
            .zip(&spacing)
            .map(|((p, &ink), &r_eff)| {
                let c = p.class as usize;
                dot_radius[c](maps[c].value_at(p.x, p.y))
                    * ratios.factor(ink, f64::from(p.radius), r_eff)
            })
            .collect();
        if let Some(grid) = grid {
            Correction::new(&separated.picture, &separated.separation, grid)?.apply(
                points,
                &inks,
                &spacing,
                &mut calibrated,
                maps.len(),
                stage,
            )?;
        }
        if self.dot_mode() == super::DotMode::Fixed {
            let mut sums = vec![(0f64, 0usize); maps.len()];
            for (p, &r) in points.iter().zip(&calibrated) {
                let s = &mut sums[p.class as usize];
                s.0 += f64::from(r) * f64::from(r);
                s.1 += 1;
            }
            let radius: Vec<f32> = sums
                .iter()
                .map(|&(sq, n)| (sq / n.max(1) as f64).sqrt() as f32)
                .collect();
            for (p, r) in points.iter().zip(&mut calibrated) {
                *r = radius[p.class as usize];
            }
        }
        Ok(calibrated)
    }

    /// Writes the SVG of a drawing in layers to `out`: one Inkscape layer
    /// per pen (or per part of a pen's drawing, with `refill_mm`), in the
    /// plotting order ([`Job::layers`]).
    pub(crate) fn write_layered_svg(
        &self,
        drawing: &Stipple,
        out: &mut dyn std::io::Write,
    ) -> crate::Result<()> {
        let layers = self.layers(drawing)?;
        let opts = self.svg_options(drawing.domain)?;
        let svg_layers: Vec<svg::Layer<'_>> = layers
            .iter()
            .map(|l| svg::Layer {
                name: &l.name,
                ink: l.ink,
                pen_mm: l.pen_mm,
                dots: &l.dots,
            })
            .collect();
        svg::write_layers(out, &svg_layers, &opts)?;
        Ok(())
    }

    /// Writes a colour drawing (its `pens` set) in `format` to `path`: one
    /// layer per pen in SVG, the composite in PNG, a pen column in CSV and
    /// JSON.
    pub(crate) fn write_colour(
        &self,
        drawing: &Stipple,
        format: Format,
        path: &Path,
    ) -> crate::Result<()> {
        let Some(pens) = &drawing.pens else {
            return Err(
                crate::stipple::Error::InvalidParameter("not a colour drawing".into()).into(),
            );
        };
        let layers = self.pen_dots(drawing);
        let dots = layers.iter().map(Vec::len).sum::<usize>();
        match format {
            Format::Svg => {
                let text = self.svg(drawing)?;
                crate::io::write_atomic(path, |w| Ok(w.write_all(&text)?))?;
            }
            Format::Png => {
                let papers = layers
                    .iter()
                    .map(|d| crate::stipple::raster::render(d, drawing.domain, self.scale))
                    .collect::<Result<Vec<_>, _>>()?;
                let linear = self.importance.tones == Tones::Linear;
                let img =
                    crate::stipple::raster::composite(&papers, &RenderModel::new(pens, linear))?;
                crate::io::write_atomic(path, |w| {
                    Ok(crate::stipple::raster::write_png_rgb(w, &img, dots)?)
                })?;
            }
            Format::Csv | Format::Json => {
                let set = drawing.set.clone().with_points(drawing.points.clone());
                crate::io::write_points_pens(path, &set, self, pens)?;
            }
        }
        Ok(())
    }
}

/// The correction of the calibrated dots toward the separation's colours,
/// closing the loop that the render model leaves open: pens placed apart
/// by the cross spacing overlap less than independent ones (the model's
/// assumption), and calibration is exact only on average. The drawing is
/// rendered at about the photo's resolution, blurred by the measure's σ
/// (the mean dot spacing) and compared with the photo's colours where the
/// pens make them (the separation's nearest colours elsewhere), blurred
/// alike; the error is turned into ink changes per pen by the
/// model's Jacobian (damped least norm), and each dot is resized by the ink
/// curve to put down its pen's new ink, in [`rounds`].
struct Correction {
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

/// The ink below which a pen is taken to have no dots in a correction.
const MIN_INK: f64 = 0.005;
/// The side, in `src` cells, of the blocks the gains are made on.
const GAIN_BLOCK: u32 = 2;

impl Correction {
    fn new(picture: &ColourMap, separation: &Separation, grid: Grid) -> crate::Result<Self> {
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
        let src_sigma = grid.sigma * f64::from(src.0) / f64::from(work.0);
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
    /// in [`rounds`].
    fn apply(
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
        let of = rounds(grid.sigma);
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
                let mut partial = false;
                for (k, l) in layers.iter().enumerate() {
                    match l.as_raw()[i] {
                        0 => whole |= 1 << k,
                        255 => {}
                        _ => partial = true,
                    }
                }
                if partial {
                    let mut a = [0f64; MAX_PENS];
                    for (k, l) in layers.iter().enumerate() {
                        a[k] = 1.0 - f64::from(l.as_raw()[i]) / 255.0;
                    }
                    self.model.mix(&a[..pens])
                } else {
                    self.model.primary(whole)
                }
            });
            let drawn = [0, 1, 2].map(|k| grid.blurred(shown.iter().map(|c| c[k]).collect(), 1.0));
            // The error, smoothed once more: corrections follow the local
            // bias, not each dot's own noise.
            let error = [0, 1, 2].map(|k| {
                let values = self.target[k]
                    .values
                    .iter()
                    .zip(&drawn[k].values)
                    .map(|(t, d)| t - d)
                    .collect();
                grid.blurred(values, ERROR_BLUR)
            });
            // Each dot's own update: in parallel, the same values.
            points
                .par_iter()
                .zip(calibrated.par_iter_mut())
                .zip(assumed.par_iter_mut())
                .zip(spacing.par_iter())
                .for_each(|(((p, cal), assumed), &r)| {
                    let g = grid.cell(p);
                    let (gx, gy) = (g as u32 % ww, g as u32 / ww);
                    let k = p.class as usize;
                    // The ink change of the dot's pen at its work cell.
                    let e = [0, 1, 2].map(|c| error[c].values[g]);
                    let (sx, sy) = (gx * self.src.0 / ww, gy * self.src.1 / wh);
                    let s = ((sy / GAIN_BLOCK) * self.gain_grid.0 + sx / GAIN_BLOCK) as usize;
                    let gain = &self.gains[(s * self.pens + k) * 3..(s * self.pens + k + 1) * 3];
                    let delta = gain[0] * e[0] + gain[1] * e[1] + gain[2] * e[2];
                    let before = *assumed;
                    if before < 1e-3 {
                        return;
                    }
                    let after = (before + f64::from(delta)).clamp(0.5 * before, MAX_INK);
                    let had = ink::dot_ratio(before, r);
                    if had <= 0.0 {
                        return;
                    }
                    let factor = (ink::dot_ratio(after, r) / had).clamp(0.6, 1.6);
                    *cal *= factor as f32;
                    *assumed = after;
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
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    if d.abs() < 1e-12 {
        return [0.0; 3];
    }
    std::array::from_fn(|c| {
        let mut mc = m;
        for r in 0..3 {
            mc[r][c] = b[r];
        }
        det(mc) / d
    })
}

impl Job {
    /// How `drawing` looks at `size` pixels, as the PNG shows it: each
    /// pen's dots (this job's [`Job::dots`]) in its colour, overlapping inks
    /// multiplied, a pixel's partial inks averaged under the job's render
    /// model (sRGB values, or linear light with `--tones linear`). A grey
    /// drawing is one pen in the job's ink.
    pub fn picture(&self, drawing: &Stipple, size: (u32, u32)) -> crate::Result<image::RgbImage> {
        let pens = match &drawing.pens {
            Some(p) => p.clone(),
            None => crate::colour::PenSet::from_colours([
                crate::colour::pens::hex_of(self.ink.0).as_str()
            ])?,
        };
        let view = (f64::from(drawing.domain.0), f64::from(drawing.domain.1));
        let layers = self
            .pen_dots(drawing)
            .iter()
            .map(|layer| crate::stipple::raster::render_view(layer, view, size))
            .collect::<Result<Vec<_>, _>>()?;
        let linear = self.importance.tones == Tones::Linear;
        Ok(crate::stipple::raster::composite(
            &layers,
            &RenderModel::new(&pens, linear),
        )?)
    }
}

impl Job {
    /// The dots of `drawing` as this job draws them ([`Job::dots`]), pen by
    /// pen in the pens' order (one layer for a grey drawing), each layer in
    /// drawing order.
    #[must_use]
    pub fn pen_dots(&self, drawing: &Stipple) -> Vec<Vec<Dot>> {
        let pens = drawing.pens.as_ref().map_or(1, crate::colour::PenSet::len);
        let mut layers = vec![Vec::new(); pens];
        for (p, d) in drawing.points.iter().zip(self.dots(drawing)) {
            if let Some(layer) = layers.get_mut(p.class as usize) {
                layer.push(d);
            }
        }
        layers
    }
}
