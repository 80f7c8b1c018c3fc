//! The drawing as the pens will put it on paper (`stipple --preview`, the
//! app's view with a pen): each dot as its pen path inks it, by a pen of
//! its plotted width (the pen's width × its dot gain), the inks multiplied
//! where they overlap, on the sheet; and the warning when the pen cannot
//! draw the dots as small as the tones ask.
//!
//! A dot no wider than the pen (or every dot, with `--dot-path touch`) is
//! one touch: a disk of the pen's width. A spiral inks the dot's disk; a
//! circle its ring, drawn here as the disk of the ring's area (its ink).
//! Each, times the pen's gain. Without a pen (or a size in mm) the dots are
//! the drawing's own.

use std::path::Path;

use super::{Format, Job, Stipple};
use crate::colour::{PenSet, RenderModel};
use crate::importance::Tones;
use crate::stipple::svg::DotPath;
use crate::stipple::{Dot, raster};

/// The share of dots that may be wider on paper than their tone asks before
/// the plot is said to be too dark: the dots under the pen, beyond this,
/// make the warning.
const SMALL_SHARE: f64 = 0.05;
/// The least fall in mean grey that is worth a warning.
const GREY_DROP: f64 = 0.01;
/// The longer side in pixels of the renders the warning compares.
const CHECK_SIDE: f32 = 512.0;

/// One layer's pen as it plots: its name, width in mm and dot gain.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotPen {
    /// The pen's name.
    pub name: String,
    /// Its width in mm.
    pub width_mm: f64,
    /// Its dot gain (the plotted dot's diameter over the drawn one).
    pub gain: f64,
}

/// The dots that a pen draws larger than their tones ask, and what that
/// does to the plot.
#[derive(Clone, Debug, PartialEq)]
pub struct PenCheck {
    /// The pen whose dots are most often too small for it.
    pub pen: PlotPen,
    /// The share of that pen's dots narrower than it plots them.
    pub small: f64,
    /// The drawing's mean grey (0 black, 1 white) as the tones ask: its
    /// dots at their calibrated size, the inks multiplied.
    pub asked: f64,
    /// The mean grey as the pens plot it ([`Job::preview`]'s dots).
    pub plotted: f64,
    /// About the dot count at which the pen draws the tones true (its
    /// smallest dots, but for a few, one pen wide).
    pub true_count: usize,
    /// The drawing's dot count.
    pub count: usize,
}

impl PenCheck {
    /// The warning's text (one line).
    #[must_use]
    pub fn message(&self) -> String {
        format!(
            "{:.0}% of the dots are narrower than the {} mm {} pen can draw them: the plot \
             will be darker than the picture (mean grey {:.2}, not {:.2}: {:.0}% darker); \
             about {} dots draw its tones true",
            100.0 * self.small,
            self.pen.width_mm,
            self.pen.name,
            self.plotted,
            self.asked,
            100.0 * self.darker(),
            self.true_count
        )
    }

    /// How much darker the plot is than the tones ask, as a share of the
    /// asked mean grey.
    #[must_use]
    pub fn darker(&self) -> f64 {
        if self.asked > 0.0 {
            (self.asked - self.plotted) / self.asked
        } else {
            0.0
        }
    }
}

/// `dot` (domain px) as a pen `pen` px wide with dot gain `gain` inks it,
/// following `path`.
#[must_use]
pub fn plotted_dot(dot: Dot, pen: f32, gain: f32, path: DotPath) -> Dot {
    let r = dot.radius;
    let radius = if path == DotPath::Touch || 2.0 * r <= pen {
        pen / 2.0
    } else if path == DotPath::Circle {
        let inner = (r - pen).max(0.0);
        (r * r - inner * inner).sqrt()
    } else {
        r
    };
    Dot {
        radius: radius * gain,
        ..dot
    }
}

impl Job {
    /// The pen of each layer as it plots, and the drawing's mm per domain
    /// px: `None` without a pen width and a size in mm.
    pub fn plot_pens(&self, drawing: &Stipple) -> crate::Result<Option<(f64, Vec<PlotPen>)>> {
        let (Some(mm), Some(pen_mm)) = (self.mm_per_px(drawing.domain)?, self.pen_width()) else {
            return Ok(None);
        };
        let pens = match &drawing.pens {
            Some(set) => set
                .pens()
                .iter()
                .enumerate()
                .map(|(k, p)| PlotPen {
                    name: p.name.clone(),
                    width_mm: p.width_mm.unwrap_or(pen_mm),
                    gain: self.dot_gain(k as u32),
                })
                .collect(),
            None => vec![PlotPen {
                name: self.one_pen().map_or_else(
                    || crate::colour::pens::name_of(self.ink.0),
                    |p| p.name.clone(),
                ),
                width_mm: pen_mm,
                gain: self.dot_gain(0),
            }],
        };
        Ok(Some((mm, pens)))
    }

    /// Each dot's radius on paper (domain px), in drawing order: the dot as
    /// drawn ([`Self::dots`]) plotted by its pen ([`plotted_dot`]); `None`
    /// without a pen width and a size in mm.
    pub fn plotted_radii(&self, drawing: &Stipple) -> crate::Result<Option<Vec<f32>>> {
        let Some((mm, pens)) = self.plot_pens(drawing)? else {
            return Ok(None);
        };
        let pens: Vec<(f32, f32)> = pens
            .iter()
            .map(|p| ((p.width_mm / mm) as f32, p.gain as f32))
            .collect();
        Ok(Some(
            drawing
                .points
                .iter()
                .zip(self.dots(drawing))
                .map(|(p, d)| {
                    let (px, gain) = pens.get(p.class as usize).copied().unwrap_or(pens[0]);
                    plotted_dot(d, px, gain, self.dot_path).radius
                })
                .collect(),
        ))
    }

    /// The dots of `drawing` as the pens put them on paper, pen by pen
    /// ([`Self::pen_dots`]'s layers, each dot [`plotted_dot`]); the dots
    /// as drawn without a pen.
    pub fn plotted_layers(&self, drawing: &Stipple) -> crate::Result<Vec<Vec<Dot>>> {
        let Some(radii) = self.plotted_radii(drawing)? else {
            return Ok(self.pen_dots(drawing));
        };
        let pens = drawing.pens.as_ref().map_or(1, PenSet::len);
        let mut layers = vec![Vec::new(); pens];
        for (p, r) in drawing.points.iter().zip(radii) {
            if let Some(layer) = layers.get_mut(p.class as usize) {
                layer.push(Dot {
                    x: p.x,
                    y: p.y,
                    radius: r,
                });
            }
        }
        Ok(layers)
    }

    /// The render model of the drawing's inks: its pens', or the one ink's.
    fn ink_model(&self, drawing: &Stipple) -> crate::Result<RenderModel> {
        let linear = self.importance.tones == Tones::Linear;
        Ok(match &drawing.pens {
            Some(p) => self.model_of(p),
            None => {
                let one = match self.one_pen() {
                    Some(p) => PenSet::new(vec![p.clone()])?,
                    None => {
                        PenSet::from_colours(
                            [crate::colour::pens::hex_of(self.ink_rgb()).as_str()],
                        )?
                    }
                };
                RenderModel::on_paper(&one, linear, self.paper_rgb(), &[0])
            }
        })
    }

    /// The as-plotted preview of `drawing` ([`Self::plotted_layers`]): the
    /// drawing at one pixel per domain pixel, the inks mixed on the paper
    /// (`--paper-colour`), on its sheet of that paper with `--paper`.
    pub fn preview(&self, drawing: &Stipple) -> crate::Result<image::RgbImage> {
        let layers = self.plotted_layers(drawing)?;
        let papers = Self::pen_papers(drawing, &layers, 1.0, |d| {
            raster::render(d, drawing.domain, 1.0)
        })?;
        let picture = raster::composite(&papers, &self.ink_model(drawing)?)?;
        let Some(p) = self.placement(drawing.domain)? else {
            return Ok(picture);
        };
        // The sheet, in domain px, the drawing at its origin.
        let mm = p.mm_per_px(drawing.domain.0);
        let side = |v: f64| (v / mm).round().max(1.0) as u32;
        let (w, h) = (side(p.sheet_mm.0), side(p.sheet_mm.1));
        if u64::from(w) * u64::from(h) > raster::MAX_PIXELS {
            return Err(crate::stipple::Error::InvalidParameter(format!(
                "a {w}x{h} preview is too large (at most {} pixels)",
                raster::MAX_PIXELS
            ))
            .into());
        }
        let mut sheet = image::RgbImage::from_pixel(w, h, image::Rgb(self.paper_rgb()));
        let (x0, y0) = (
            (p.origin_mm.0 / mm).round() as i64,
            (p.origin_mm.1 / mm).round() as i64,
        );
        image::imageops::overlay(&mut sheet, &picture, x0, y0);
        Ok(sheet)
    }

    /// Writes [`Self::preview`] of `drawing` as a PNG to `path`, atomically.
    pub fn write_preview(&self, drawing: &Stipple, path: &Path) -> crate::Result<()> {
        if super::Format::from_path(path)? != super::Format::Png {
            return Err(crate::stipple::Error::InvalidParameter(format!(
                "the preview is a PNG: name it .png, not '{}'",
                path.display()
            ))
            .into());
        }
        let img = self.preview(drawing)?;
        crate::io::write_atomic(path, |w| {
            Ok(raster::write_png_rgb(w, &img, drawing.points.len())?)
        })?;
        Ok(())
    }

    /// Whether the pens draw `drawing`'s dots larger than its tones ask
    /// (dots narrower than a pen), and by how much: `None` when they draw
    /// it true, or without a pen.
    pub fn pen_check(&self, drawing: &Stipple) -> crate::Result<Option<PenCheck>> {
        let Some((mm, pens)) = self.plot_pens(drawing)? else {
            return Ok(None);
        };
        let asked = self.pen_dots(drawing);
        let plotted = self.plotted_layers(drawing)?;
        // The pen with the largest share of dots under it.
        let mut worst: Option<(f64, usize)> = None;
        for (k, (layer, pen)) in asked.iter().zip(&pens).enumerate() {
            if layer.is_empty() {
                continue;
            }
            let gain = pen.gain as f32;
            let small = layer
                .iter()
                .zip(&plotted[k])
                .filter(|(a, p)| p.radius > a.radius * gain * 1.001)
                .count() as f64
                / layer.len() as f64;
            if worst.is_none_or(|(s, _)| small > s) {
                worst = Some((small, k));
            }
        }
        let Some((small, k)) = worst else {
            return Ok(None);
        };
        let gains: Vec<f32> = pens.iter().map(|p| p.gain as f32).collect();
        let on_paper: Vec<Vec<Dot>> = asked
            .iter()
            .zip(&gains)
            .map(|(l, &g)| {
                l.iter()
                    .map(|d| Dot {
                        radius: d.radius * g,
                        ..*d
                    })
                    .collect()
            })
            .collect();
        let model = self.ink_model(drawing)?;
        let grey_asked = mean_grey(&on_paper, drawing.domain, &model)?;
        let grey_plotted = mean_grey(&plotted, drawing.domain, &model)?;
        if small <= SMALL_SHARE || grey_asked - grey_plotted < GREY_DROP {
            return Ok(None);
        }
        // The radii scale as 1/√count: the count whose dots, but for
        // SMALL_SHARE of them, are at least the pen's plotted dot.
        let pen = &pens[k];
        let pen_r = (pen.width_mm / mm * pen.gain / 2.0) as f32;
        let mut radii: Vec<f32> = on_paper[k].iter().map(|d| d.radius).collect();
        radii.sort_by(f32::total_cmp);
        let q = radii[((radii.len() as f64 * SMALL_SHARE) as usize).min(radii.len() - 1)];
        let count = drawing.points.len();
        let ratio = f64::from(q / pen_r).powi(2);
        let true_count = ((count as f64 * ratio * 0.95).floor() as usize).max(1);
        Ok(Some(PenCheck {
            pen: pen.clone(),
            small,
            asked: grey_asked,
            plotted: grey_plotted,
            true_count,
            count,
        }))
    }

    /// What a front end warns of after drawing `drawing` (to a file of
    /// `output` format, when written), in the CLI's words without its
    /// "warning: ": a count short of its target, a PNG too coarse for its
    /// dots, and dots that the pen covers.
    pub fn warnings(
        &self,
        drawing: &Stipple,
        output: Option<Format>,
    ) -> crate::Result<Vec<String>> {
        let mut out = Vec::new();
        if let Some(n) = drawing.short_of {
            out.push(short_of(n, drawing.set.points.len()));
        }
        if output == Some(Format::Png)
            && let Some(w) = self.png_check(drawing)
        {
            out.push(w);
        }
        if let Some(w) = self.line_count_warning(&drawing.plan) {
            out.push(w);
        }
        if let Some(check) = self.pen_check(drawing)? {
            out.push(format!(
                "{}: give «points={}»",
                check.message(),
                check.true_count
            ));
        }
        Ok(out)
    }
}

impl Job {
    /// A warning when the PNG's dots are too small to see: the dots that
    /// hold half the drawing's ink under one pixel across at `scale`, with
    /// the count at which they reach it; `None` when they are larger.
    #[must_use]
    pub fn png_check(&self, drawing: &Stipple) -> Option<String> {
        let mut radii: Vec<f32> = self.dots(drawing).iter().map(|d| d.radius).collect();
        if radii.is_empty() {
            return None;
        }
        radii.sort_by(f32::total_cmp);
        // The radius below which half the ink (Σ r²) lies.
        let total: f64 = radii.iter().map(|&r| f64::from(r * r)).sum();
        let mut sum = 0.0;
        let median = radii
            .iter()
            .find(|&&r| {
                sum += f64::from(r * r);
                sum >= total / 2.0
            })
            .copied()
            .unwrap_or(radii[radii.len() - 1]);
        let across = 2.0 * f64::from(median) * f64::from(self.scale);
        (across < 1.0).then(|| {
            let count = ((radii.len() as f64 * across * across).floor() as usize).max(1);
            format!(
                "the PNG's dots are {across:.2} px across at «scale={}» (half the ink in dots \
                 under 1 px: a grey haze); about {count} dots, or a larger «scale», draw them",
                self.scale
            )
        })
    }
}

/// The mean grey (0 black, 1 white; the mean of the display's R, G and B)
/// of `layers` (domain px, one per pen of `model`) over `domain`, rendered
/// with the inks multiplied at [`CHECK_SIDE`] pixels on the longer side
/// (dots thinner than a pixel count by their area).
fn mean_grey(layers: &[Vec<Dot>], domain: (u32, u32), model: &RenderModel) -> crate::Result<f64> {
    let scale = (CHECK_SIDE / domain.0.max(domain.1) as f32).min(1.0);
    let papers = layers
        .iter()
        .map(|d| raster::render(d, domain, scale))
        .collect::<Result<Vec<_>, _>>()?;
    let img = raster::composite(&papers, model)?;
    let raw = img.as_raw();
    Ok(raw.iter().map(|&v| f64::from(v)).sum::<f64>() / (255.0 * raw.len().max(1) as f64))
}

/// The warning of a count short of its target: `asked` points asked for,
/// `got` reached.
#[must_use]
pub fn short_of(asked: usize, got: usize) -> String {
    format!(
        "asked for {asked} points, got {got}: the radii are at the sampler's limits \
         (1 px at the darkest, the domain's size at the lightest); change «width»/«height»"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pen_inks_at_least_its_own_width() {
        let dot = Dot {
            x: 1.0,
            y: 2.0,
            radius: 0.5,
        };
        // Narrower than the pen: one touch, the pen's disk, times the gain.
        assert_eq!(plotted_dot(dot, 3.0, 1.0, DotPath::Spiral).radius, 1.5);
        assert_eq!(
            plotted_dot(dot, 3.0, 1.2, DotPath::Spiral).radius,
            1.5 * 1.2
        );
        let big = Dot { radius: 4.0, ..dot };
        assert_eq!(plotted_dot(big, 3.0, 1.0, DotPath::Spiral).radius, 4.0);
        assert_eq!(plotted_dot(big, 3.0, 1.0, DotPath::Touch).radius, 1.5);
        // A ring 3 px wide round a 4 px dot: the disk of its area.
        let ring = plotted_dot(big, 3.0, 1.0, DotPath::Circle).radius;
        assert!((ring * ring - (16.0 - 1.0)).abs() < 1e-4);
    }

    #[test]
    fn the_mean_grey_is_the_paper_left_by_sparse_dots() {
        let dots: Vec<Dot> = (0..100)
            .map(|i| Dot {
                x: (i % 10) as f32 * 64.0 + 32.0,
                y: (i / 10) as f32 * 64.0 + 32.0,
                radius: 8.0,
            })
            .collect();
        let model = RenderModel::new(&PenSet::black(), false);
        let want = 1.0 - 100.0 * std::f64::consts::PI * 64.0 / (640.0 * 640.0);
        let got = mean_grey(&[dots], (640, 640), &model).unwrap();
        assert!((got - want).abs() < 0.01, "{got} vs {want}");
    }
}
