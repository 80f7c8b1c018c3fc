//! The job's writers: the dots as the job draws them, and the SVG, PNG,
//! CSV and JSON files.

use std::path::Path;

use super::{Format, Ink, Job, Stipple};
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
        Ok(opts.with_dot_path(self.dot_path).with_ink(self.ink_rgb()))
    }

    /// Whether the job draws in colour: two pens or more. One pen draws the
    /// grey drawing in its ink ([`Self::one_pen`]).
    #[must_use]
    pub fn colour(&self) -> bool {
        self.pens.as_ref().is_some_and(|p| p.len() > 1)
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
        if drawing.pens.is_some() || self.refill_mm.is_some() {
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
        let format = Format::from_path(path)?;
        self.check()?;
        if drawing.pens.is_some() {
            return self.write_colour(drawing, format, path);
        }
        let domain = drawing.domain;
        match format {
            Format::Svg => {
                let text = self.svg(drawing)?;
                crate::io::write_atomic(path, |w| Ok(w.write_all(&text)?))?;
            }
            Format::Png => {
                let dots = self.dots(drawing);
                let img = crate::stipple::raster::render(&dots, domain, self.scale)?;
                let ink = self.ink_rgb();
                crate::io::write_atomic(path, |w| {
                    if ink == Ink::BLACK.0 {
                        Ok(crate::stipple::raster::write_png(w, &img, dots.len())?)
                    } else {
                        Ok(crate::stipple::raster::write_png_ink(
                            w,
                            &img,
                            ink,
                            dots.len(),
                        )?)
                    }
                })?;
            }
            Format::Csv | Format::Json => {
                let set = drawing.set.clone().with_points(drawing.points.clone());
                crate::io::write_points(path, &set, self)?;
            }
        }
        Ok(())
    }
}
