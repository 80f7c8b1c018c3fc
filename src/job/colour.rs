//! Colour drawings (`--pens`): the photo separated into the pens' inks
//! under the render model ([`crate::colour::separation`]), one importance
//! map per pen, all pens sampled together in one multi-class run
//! ([`crate::sampler::classes`]) so that they interleave, each pen's dots
//! calibrated to its own ink, and the outputs: one Inkscape layer per pen,
//! the composite PNG, a `pen` column in CSV and JSON.

use super::{Job, Stage, Stipple};
use crate::stipple::{Dot, svg};
use rayon::prelude::*;

use super::Picture;
use crate::colour::choose::{Choice, Palette, choose};
use crate::colour::{RenderModel, Separation};
use crate::importance::ink::K_MAX;
use crate::importance::{Adjust, ColourMap, Mapping, MappingKind, Prepared, RadiusRange, Tones};
use crate::sampler::Point;

use super::correct::ColourCorrection;

/// A colour picture prepared for drawing: one map per pen, and what the
/// size stage's correction compares the drawing with.
pub(crate) struct Separated {
    /// One prepared map per pen, read at the domain's pixels.
    pub maps: Vec<Prepared>,
    /// The picture, tones adjusted, at the size it was separated at.
    pub picture: ColourMap,
    /// The separation (its table solved where the picture needed it).
    pub separation: Separation,
}

/// The longer side, in pixels, of the copy of the picture whose colours
/// `--choose` weighs.
const PALETTE_SIDE: u32 = 256;

impl Job {
    /// This job with `--choose K` resolved for `picture`: `--pens` is an
    /// inventory, and the job returned draws with the K of its pens whose
    /// drawing the render model predicts closest to the picture's colours,
    /// its tones adjusted as the drawing adjusts them
    /// ([`crate::colour::choose`]); with the choice. Without `--choose`,
    /// the job itself and `None`. Every front end draws and writes the job
    /// returned, and `--save-job` saves it.
    pub fn chosen(&self, picture: Picture<'_>) -> crate::Result<(Job, Option<Choice>)> {
        let (Some(k), Some(inventory)) = (self.choose, &self.pens) else {
            return Ok((self.clone(), None));
        };
        self.check()?;
        // Chosen for the picture as drawn: cropped and turned.
        let framed = self.frame(picture)?;
        let picture = framed.as_ref().map_or(picture, super::run::Framed::picture);
        let colours = picture.colour();
        let (w, h) = (colours.width(), colours.height());
        let f = (f64::from(PALETTE_SIDE) / f64::from(w.max(h))).min(1.0);
        let side = |v: u32| ((f64::from(v) * f).round() as u32).max(1);
        let small = colours.resized(side(w), side(h))?;
        let imp = &self.importance;
        let adjust = imp.adjust();
        let small = if adjust == Adjust::default() {
            small
        } else {
            small.adjusted(imp.tones, &adjust)?.0
        };
        let palette = Palette::of_linear(small.rgb());
        let linear = imp.tones == Tones::Linear;
        let choice = choose(inventory.pens(), k, &palette, linear, K_MAX)
            .map_err(|e| crate::stipple::Error::InvalidParameter(e.to_string()))?;
        let mut job = self.clone();
        job.pens = Some(choice.pens.clone());
        job.choose = None;
        Ok((job, Some(choice)))
    }

    /// The render model of this job's pens, under its tone convention.
    #[must_use]
    pub fn render_model(&self) -> Option<RenderModel> {
        self.pens.as_ref().map(|p| self.model_of(p))
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
        radii_scaled: bool,
    ) -> crate::Result<Separated> {
        let Some(model) = self.render_model() else {
            return Err(crate::stipple::Error::InvalidParameter(
                "a colour drawing needs «pens»".into(),
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
        let range = self.dot_range(imp.radius_range(radii_scaled)?, domain)?;
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
    /// the sampler's packing, measured once over the drawing), then
    /// corrected toward the picture's colours by `correction` (made while
    /// the dots were relaxed); with `--dot fixed`, one radius per pen (the
    /// root mean square of its calibrated dots'); with `--mapping linear`,
    /// the mapping's dots.
    pub(crate) fn colour_sizes(
        &self,
        separated: &Separated,
        points: &[Point],
        range: RadiusRange,
        correction: Option<&ColourCorrection>,
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
        if let Some(correction) = correction {
            correction.apply(points, &inks, &spacing, &mut calibrated, maps.len(), stage)?;
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
        let crosses = self.registration(drawing.domain)?;
        let first = layers.first();
        let mut svg_layers: Vec<svg::Layer<'_>> = Vec::with_capacity(layers.len() + 1);
        if !crosses.is_empty() {
            // A poster sheet's crosses: plotted first, by the first pen.
            svg_layers.push(svg::Layer {
                name: super::poster::REGISTRATION_LAYER,
                ink: first.map_or(self.ink_rgb(), |l| l.ink),
                pen_mm: first.and_then(|l| l.pen_mm),
                opaque: true,
                dots: &[],
                strokes: &crosses,
            });
        }
        svg_layers.extend(layers.iter().map(|l| svg::Layer {
            name: &l.name,
            ink: l.ink,
            pen_mm: l.pen_mm,
            opaque: l.opacity >= 0.5,
            dots: &l.dots,
            strokes: &l.strokes,
        }));
        svg::write_layers(out, &svg_layers, &opts)?;
        Ok(())
    }
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
        let scale = f64::from(size.0) / view.0;
        let layers = Self::pen_papers(drawing, &self.pen_dots(drawing), scale, |layer| {
            crate::stipple::raster::render_view_union(layer, view, size)
        })?;
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

    /// Each pen's paper of `drawing` (one for a grey drawing), in the
    /// pens' order: its dots of `layers` (one list per pen) drawn by
    /// `render`, its strokes over them at `scale` output pixels per domain
    /// pixel. What every picture of a drawing is made of: the PNG, the
    /// preview, the measures.
    pub(crate) fn pen_papers(
        drawing: &Stipple,
        layers: &[Vec<Dot>],
        scale: f64,
        render: impl Fn(&[Dot]) -> Result<image::GrayImage, crate::stipple::Error>,
    ) -> crate::Result<Vec<image::GrayImage>> {
        let mut papers = Vec::new();
        for (k, dots) in layers.iter().enumerate() {
            let mut paper = render(dots)?;
            if let Some(stroke) = drawing.strokes.get(k) {
                let line = crate::stipple::raster::render_strokes(
                    std::slice::from_ref(stroke),
                    drawing.domain,
                    scale,
                )?;
                for (a, b) in paper.iter_mut().zip(line.as_raw()) {
                    *a = (*a).min(*b);
                }
            }
            papers.push(paper);
        }
        Ok(papers)
    }
}
