//! The job's writers: the dots as the job draws them, and the SVG, PNG,
//! CSV and JSON files.

use std::path::Path;

use super::{Format, Ink, Job, PaperColour, Stipple};
use crate::stipple::{Dot, DotSize, svg};

impl Job {
    /// How big the dots are drawn: the dot mode and its factor.
    #[must_use]
    pub fn dot_size(&self) -> DotSize {
        let dot = self.dot_mode();
        dot.size(self.dot_factor.unwrap_or(dot.default_factor()))
    }

    /// The dots of `drawing` as this job draws them (its dot mode and
    /// factor), in drawing order.
    #[must_use]
    pub fn dots(&self, drawing: &Stipple) -> Vec<Dot> {
        if !drawing.strokes.is_empty() {
            return Vec::new();
        }
        let size = self.dot_size();
        drawing
            .points
            .iter()
            .zip(&drawing.calibrated)
            .map(|(p, &c)| Dot {
                x: p.x,
                y: p.y,
                radius: size.radius(p.radius, c, self.dot_gain(p.class) as f32),
            })
            .collect()
    }

    /// The SVG writer's options for a drawing of `domain` px: the page (px,
    /// a width in mm, or a sheet of paper), the pen, its paths and the ink.
    pub fn svg_options(&self, domain: (u32, u32)) -> crate::Result<svg::SvgOptions> {
        let mut opts = match (self.placement(domain)?, self.width_mm) {
            (Some(p), _) => svg::SvgOptions::on_paper(domain, &p),
            (None, Some(mm)) => svg::SvgOptions::with_width_mm(domain, mm)?,
            (None, None) => svg::SvgOptions::new(domain),
        };
        if let Some(pen) = self.pen_width() {
            opts = opts.with_pen_mm(pen)?;
        }
        Ok(opts
            .with_dot_path(self.dot_path)
            .with_ink(self.ink_rgb())
            .with_size_px(self.size_px)
            .with_paper_if(self.paper_rgb())
            .with_multiply(self.ink_opacity() < 0.5))
    }

    /// Whether the job draws in colour: two pens or more. One pen draws the
    /// grey drawing in its ink ([`Self::one_pen`]), on its paper
    /// ([`Self::paper_levels`]).
    #[must_use]
    pub fn colour(&self) -> bool {
        self.pens.as_ref().is_some_and(|p| p.len() > 1)
    }

    /// The one ink's colour where it lies on the paper, sRGB: the ink
    /// itself where it covers the paper (opacity 1), the paper times the
    /// ink (in linear light) where it multiplies, between the two as its
    /// opacity says.
    #[must_use]
    pub fn ink_on_paper(&self) -> [u8; 3] {
        let (ink, paper) = (self.ink_rgb(), self.paper_rgb());
        let o = self.ink_opacity();
        let lin = |c: u8| crate::colour::decode(f64::from(c) / 255.0);
        std::array::from_fn(|i| {
            let (t, p) = (lin(ink[i]), lin(paper[i]));
            let c = (1.0 - o) * p * t + o * t;
            (crate::colour::encode(c) * 255.0).round().clamp(0.0, 255.0) as u8
        })
    }

    /// The one ink's opacity on the job's paper: its pen's
    /// ([`crate::colour::Pen::opacity_on`]), the same rule for `--ink`.
    #[must_use]
    pub fn ink_opacity(&self) -> f64 {
        let paper = self.paper_rgb();
        self.one_pen().map_or_else(
            || crate::colour::pens::default_opacity(self.ink.0, paper),
            |p| p.opacity_on(paper),
        )
    }

    /// The grey drawing's tones on a paper that is not white: the paper's
    /// grey P and the ink's grey Q on it (its luminance, in the drawing's
    /// tones), so that a pixel of grey v takes the ink's coverage
    /// (P − v)/(P − Q); `None` on white paper, or where the ink does not
    /// differ from the paper.
    #[must_use]
    pub fn paper_levels(&self) -> Option<(f32, f32)> {
        let paper = self.paper_rgb();
        if paper == PaperColour::WHITE.0 || self.colour() {
            return None;
        }
        let grey = |c: [u8; 3]| {
            self.importance
                .tones
                .tone(crate::colour::luminance(c) as f32)
        };
        let (p, q) = (grey(paper), grey(self.ink_on_paper()));
        ((p - q).abs() > 1e-3).then_some((p, q))
    }

    /// The paper's colour, sRGB (white by default).
    #[must_use]
    pub fn paper_rgb(&self) -> [u8; 3] {
        self.paper_colour.unwrap_or(PaperColour::WHITE).0
    }

    /// The single pen of a one-pen job (`--pens` with one colour or a pen
    /// file of one pen, e.g. from `pixelpie calibrate fit`).
    #[must_use]
    pub fn one_pen(&self) -> Option<&crate::colour::Pen> {
        self.pens
            .as_ref()
            .filter(|p| p.len() == 1)
            .and_then(|p| p.pens().first())
    }

    /// The grey drawing's ink: its one pen's colour, or `--ink`.
    #[must_use]
    pub fn ink_rgb(&self) -> [u8; 3] {
        self.one_pen().map_or(self.ink.0, |p| p.colour)
    }

    /// The SVG of `drawing` as this job writes it: circles, or pen paths
    /// with `pen_mm`; one Inkscape layer per pen in colour.
    pub fn svg(&self, drawing: &Stipple) -> crate::Result<Vec<u8>> {
        let mut out = Vec::new();
        if drawing.pens.is_some()
            || self.refill_mm.is_some()
            || !drawing.strokes.is_empty()
            || self.sheet.is_some()
        {
            self.write_layered_svg(drawing, &mut out)?;
        } else {
            let dots = self.dots(drawing);
            let opts = self.svg_options(drawing.domain)?;
            svg::write(&mut out, &dots, &opts)?;
        }
        Ok(out)
    }

    /// Writes `drawing` to `path` atomically, in the format of its
    /// extension: the dots as this job draws them ([`Self::dots`]) as SVG
    /// (circles, or pen paths with `pen_mm`) or PNG (at `scale`, in the
    /// ink's colour), or their sample points as CSV or JSON (with the job).
    /// Options of other formats are ignored ([`Self::validate`] refuses
    /// them up front).
    pub fn write(&self, drawing: &Stipple, path: &Path) -> crate::Result<()> {
        let bytes = self.encode(drawing, Format::from_path(path)?)?;
        crate::io::write_atomic(path, |w| Ok(w.write_all(&bytes)?))?;
        Ok(())
    }

    /// The bytes [`Self::write`] writes for `drawing` in `format`: the one
    /// encoder of grey and colour drawings, of dots and lines. SVG: one
    /// layer per pen (circles or pen paths, strokes); PNG: each pen's
    /// paper, one grey ink on its paper or the pens' composite; CSV and
    /// JSON: the sample points, with a pen column in colour.
    pub fn encode(&self, drawing: &Stipple, format: Format) -> crate::Result<Vec<u8>> {
        self.check()?;
        let mut out = Vec::new();
        match format {
            Format::Svg => return self.svg(drawing),
            Format::Png => {
                let layers = self.pen_dots(drawing);
                let papers = Self::pen_papers(drawing, &layers, f64::from(self.scale), |dots| {
                    crate::stipple::raster::render_exact(dots, drawing.domain, self.scale)
                })?;
                let dots = drawing.points.len();
                match (&drawing.pens, papers.as_slice()) {
                    (Some(pens), _) => {
                        let img = crate::stipple::raster::composite(&papers, &self.model_of(pens))?;
                        crate::stipple::raster::write_png_rgb(&mut out, &img, dots)?;
                    }
                    (None, [img]) => {
                        let (ink, paper) = (self.ink_on_paper(), self.paper_rgb());
                        if ink == Ink::BLACK.0 && paper == PaperColour::WHITE.0 {
                            crate::stipple::raster::write_png(&mut out, img, dots)?;
                        } else {
                            crate::stipple::raster::write_png_on(&mut out, img, ink, paper, dots)?;
                        }
                    }
                    (None, _) => {
                        return Err(crate::stipple::Error::InvalidParameter(
                            "a grey drawing has one pen".into(),
                        )
                        .into());
                    }
                }
            }
            Format::Csv | Format::Json => {
                let set = drawing.set.clone().with_points(drawing.points.clone());
                crate::io::points_to(&mut out, format.points(), &set, self, drawing.pens.as_ref())
                    .map_err(|e| crate::io::Error::Invalid(e.to_string()))?;
            }
        }
        Ok(out)
    }
}
