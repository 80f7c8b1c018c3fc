//! The pipeline: the drawing job ([`Job`], `pixelpie stipple`) and the
//! point-set job ([`SampleJob`], `pixelpie sample`), their options,
//! defaults and validation, the point-count fit ([`count`], written once),
//! and one staged run for grey and colour drawings ([`Job::draw`]: prepare
//! → sample → relax → order → size, in `run.rs`; the colour stages in
//! `colour.rs`), then the SVG, PNG, CSV or JSON output through
//! [`crate::stipple`]'s writers.
//!
//! Every front end runs these jobs: the CLI parses them from its arguments,
//! the Python package deserializes them from keyword arguments, and the
//! app's settings hold a [`Job`] (plus what only the view needs). The same
//! job therefore gives the same drawing and the same files, byte for byte,
//! from all three. Nothing below it (the sampler, maps, colour science,
//! the formats) imports it.

use std::path::Path;

use serde::{Deserialize, Serialize};

mod assign;
mod colour;
mod correct;
pub mod count;
mod density;
pub mod file;
mod layers;
mod options;
mod plan;
mod plot;
mod preview;
mod ramp;
mod run;
mod sample;

pub use layers::PenLayer;
pub use options::{Correction, DotMode, Format, Ink, LayerOrder, Order, Spacing};
pub use plan::{Plan, Planned};
pub use preview::{PenCheck, PlotPen, plotted_dot};
pub use ramp::{RampError, ramp_error, ramp_error_sized};
pub use run::{Decoded, Picture, Stage, Step, Stipple};
pub use sample::{Radii, SampleJob, Sampled};

use crate::colour::PenSet;
use crate::importance::{
    Crop, DEFAULT_RADIUS_RATIO, ImportanceOptions, Mapping, RadiusRange, fit_size,
};
use crate::sampler::{DEFAULT_POLICY, Policy, SamplerOptions};
use crate::stipple::paper::{DEFAULT_MARGIN_MM, Paper, Placement};
use crate::stipple::svg::DotPath;
use crate::stipple::{Dot, DotSize, Error, svg};

/// Lloyd steps a drawing takes by default ([`Job::plan`]): three
/// lift the default drawing's SSIM by 0.02–0.05 on five photos at 10K dots
/// (docs/quality.md).
pub const AUTO_RELAX_STEPS: u32 = 3;
/// The most dots a drawing relaxes by default: past them a step costs more
/// than sampling does (0.45 s at 1M dots on two cores).
pub const AUTO_RELAX_DOTS: usize = 200_000;

/// The default number of dots.
pub const DEFAULT_POINTS: usize = 10_000;
/// The white dots' radius as a fraction of the black dots' (`--dot sized`):
/// the best of 0.3, 0.4 and 0.5 by the fidelity measure on the bundled
/// photos (StippleGen's default dot sizes, 2 and 5, make 0.4).
pub const DEFAULT_DOT_RATIO: f32 = 0.3;
/// Pixels across the pen's plotted dot, at least, in a domain the pen sizes
/// (`--pen-mm` without a count): below about 3 the sampler's 1 px radius
/// floor refuses the dots.
pub const PEN_DOT_PX: f64 = 4.0;
/// The default domain's longer side is at least this many pixels.
pub const MIN_DOMAIN_SIDE: u32 = 1024;
/// The default domain holds at most this many pixels (4096²): past about
/// 240K dots (3:2) the dots come closer than ten pixels apart rather than
/// the domain growing, so that a million dots cost what the points need
/// (the smallest sample radius stays near 3 px, where the ink curve is
/// measured).
pub const MAX_DOMAIN_PIXELS: u64 = 4096 * 4096;

/// The drawing job: how a picture becomes a stipple drawing, and how the
/// drawing is written. Its fields are the options of `pixelpie stipple`,
/// the keyword arguments of Python's `pixelpie.stipple` and the app's
/// controls, under the same names; [`Job::default`] holds every default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default)]
#[non_exhaustive]
pub struct Job {
    /// Number of dots (±3%) [default: 10000 unless --min-radius or
    /// --dot-radius is given].
    #[cfg_attr(feature = "cli", arg(long))]
    pub points: Option<usize>,
    /// Domain width in px [default: the image scaled so that its longer side
    /// is max(1024, 10·√points), at most 4096² pixels].
    #[cfg_attr(feature = "cli", arg(long))]
    pub width: Option<u32>,
    /// Domain height in px [default: from the width and the image's aspect].
    #[cfg_attr(feature = "cli", arg(long))]
    pub height: Option<u32>,
    /// Crop the picture to x,y,w,h (its pixels, upright) before drawing.
    #[cfg_attr(feature = "cli", arg(long, value_name = "X,Y,W,H"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crop: Option<Crop>,
    /// Turn the picture clockwise by 90, 180 or 270 degrees (after the
    /// crop) before drawing.
    #[cfg_attr(feature = "cli", arg(long, value_name = "DEGREES", value_parser = clap::builder::TypedValueParser::map(clap::builder::PossibleValuesParser::new(["90", "180", "270"]), |s| s.parse::<u16>().unwrap_or(0))))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotate: Option<u16>,
    /// How the picture's tones become radii.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[serde(flatten)]
    pub importance: ImportanceOptions,
    /// Dot size. fixed: all dots alike; sized: small dots in light areas,
    /// larger ones in dark areas (StippleGen's min/max dot size). Both are
    /// calibrated: once blurred, the ink equals the grey of the picture.
    /// proportional: dot radius = factor × the sample's radius; it covers the
    /// same fraction everywhere, so it does NOT reproduce tones (a texture).
    /// [default: sized; fixed with --pen-mm, since dots narrower than the
    /// pen cannot be drawn]
    #[cfg_attr(feature = "cli", arg(long, value_enum))]
    pub dot: Option<DotMode>,
    /// Dot radius factor: × the calibrated radius (fixed, sized: 1
    /// reproduces the tones, more darkens, less lightens) or × each sample's
    /// radius (proportional; 0.5 makes the closest dots touch) [default: 1
    /// fixed/sized, 0.5 proportional].
    #[cfg_attr(feature = "cli", arg(long))]
    pub dot_factor: Option<f32>,
    /// With --dot sized: the lightest dots' radius as a fraction of the
    /// darkest dots' (0..1].
    #[cfg_attr(feature = "cli", arg(long, default_value_t = DEFAULT_DOT_RATIO))]
    pub dot_ratio: f32,
    /// Radius in domain px of the darkest dots; the sample radii follow from
    /// it, so the dot count does too (instead of --points).
    #[cfg_attr(feature = "cli", arg(long))]
    pub dot_radius: Option<f32>,
    /// Diameter in mm of the darkest dots on the page (needs --width-mm or
    /// --paper); as --dot-radius, the radii and the count follow from it.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "MM", conflicts_with = "dot_radius")
    )]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dot_mm: Option<f64>,
    /// The spacing sized dots are calibrated for: local (the dots' own
    /// spacing around each, counted: edges and the Prior and Bigger
    /// policies thin dots out) or radius (a maximal set's at the sample
    /// radius: the drawings of earlier versions).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Spacing::Local))]
    #[serde(skip_serializing_if = "Spacing::is_default")]
    pub spacing: Spacing,
    /// Sized dots corrected toward the picture's tones by rendering the
    /// drawing (on), or by the calibration's curves alone (off: the
    /// drawings of earlier versions). Unrelaxed grey drawings too dense
    /// for the render (past about 207K dots) skip it (`--plan` says).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Correction::On))]
    #[serde(skip_serializing_if = "Correction::is_default")]
    pub correction: Correction,
    /// Weighted Lloyd (Voronoi) relaxation steps after sampling: moves each
    /// dot to the centroid of its Voronoi cell, weighted to keep the
    /// calibrated density; a few steps make the spacing more even
    /// [default: 3 for corrected dots (sized, --correction on) up to 200 000
    /// dots, else none (a step costs about 0.45 s at 1M dots on two
    /// cores)].
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relax: Option<u32>,
    /// Drawing order: as sampled, or a short pen-plotter path (2-opt).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Order::None))]
    pub order: Order,
    /// PNG pixels per domain pixel (PNG output only).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 1.0))]
    pub scale: f32,
    /// SVG page width in millimetres (height follows the aspect) [default: px].
    #[cfg_attr(feature = "cli", arg(long, conflicts_with = "paper"))]
    pub width_mm: Option<f64>,
    /// Paper for the SVG: a1 to a6, letter, legal, tabloid or WxHmm. The
    /// drawing fits inside the margins, centred, keeping its aspect; the
    /// SVG is the whole sheet, in mm.
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paper: Option<Paper>,
    /// Margin around the drawing on the paper, mm [default: 10 with --paper].
    #[cfg_attr(feature = "cli", arg(long, requires = "paper"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// Turn the paper to landscape (wider than tall); portrait by default.
    #[cfg_attr(feature = "cli", arg(long, requires = "paper"))]
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub landscape: bool,
    /// Pen width in mm (needs --width-mm): each dot is drawn as a pen draws
    /// it, in mm, on one Inkscape layer: a dot no wider than the pen is one
    /// pen touch (a two-point path), a bigger one a spiral filled at pen
    /// pitch. Without --points, --dot-radius or --min-radius the darkest
    /// dots are one pen wide, so that the tones are calibrated for the pen.
    #[cfg_attr(feature = "cli", arg(long))]
    pub pen_mm: Option<f64>,
    /// How the pen draws a dot wider than itself (with --pen-mm): spiral
    /// (filled), circle (its outline) or touch (every dot one pen touch).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = DotPath::Spiral))]
    #[serde(skip_serializing_if = "DotPath::is_default")]
    pub dot_path: DotPath,
    /// Pen-down length in mm after which a plotter's pen wants a refill:
    /// each pen's layer is split into sub-layers of at most this much
    /// drawing, labelled "L name k/n" with L the layer's place (vpype and
    /// plotter tools number layers by a label's first digits), in order, to
    /// change pens between them (needs --pen-mm).
    #[cfg_attr(feature = "cli", arg(long, value_name = "MM", requires = "pen_mm"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refill_mm: Option<f64>,
    /// The order of the pens' layers in the SVG, the order they plot in.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = LayerOrder::LightFirst))]
    #[serde(skip_serializing_if = "LayerOrder::is_default")]
    pub layer_order: LayerOrder,
    /// The ink's colour in the SVG and the PNG: black or #rrggbb.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = Ink::BLACK))]
    pub ink: Ink,
    /// Draw in colour with several pens, sampled together so that they
    /// interleave: cmyk, a list of #rrggbb colours ("#000000,#d62728"), or
    /// a .toml file of [[pen]] entries (name, colour, width_mm). --points
    /// counts the dots of all pens. [default: one pen in --ink]
    #[cfg_attr(feature = "cli", arg(long, conflicts_with = "ink"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pens: Option<PenSet>,
    /// Disk policy for varying radii (paper §3.4); the paper stipples with
    /// the smaller disk, which keeps large light-area disks out of dark areas.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = DEFAULT_POLICY))]
    pub policy: Policy,
    /// Seed, sub-pixel darts, periodic domain, exact mode.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[serde(flatten)]
    pub sampler: SamplerOptions,
}

impl Default for Job {
    fn default() -> Self {
        Self {
            points: None,
            width: None,
            height: None,
            crop: None,
            rotate: None,
            importance: ImportanceOptions::default(),
            dot: None,
            dot_factor: None,
            dot_ratio: DEFAULT_DOT_RATIO,
            dot_radius: None,
            dot_mm: None,
            relax: None,
            correction: Correction::On,
            order: Order::None,
            scale: 1.0,
            width_mm: None,
            paper: None,
            margin: None,
            landscape: false,
            pen_mm: None,
            dot_path: DotPath::Spiral,
            refill_mm: None,
            layer_order: LayerOrder::LightFirst,
            spacing: Spacing::Local,
            ink: Ink::BLACK,
            pens: None,
            policy: DEFAULT_POLICY,
            sampler: SamplerOptions::default(),
        }
    }
}

/// The default domain: the image scaled so its longer side is
/// max(1024, 10 √N) px, about ten pixels between dots or more, but at most
/// [`MAX_DOMAIN_PIXELS`] pixels.
///
/// ```
/// use pixelpie::job::default_domain;
/// assert_eq!(default_domain(600, 400, 10_000), (1024, 683));
/// assert_eq!(default_domain(600, 400, 100_000), (3163, 2109));
/// let (w, h) = default_domain(600, 400, 1_000_000);
/// assert!(u64::from(w) * u64::from(h) <= 4096 * 4096 && w == 5016);
/// ```
#[must_use]
pub fn default_domain(w: u32, h: u32, points: usize) -> (u32, u32) {
    let side = f64::from(MIN_DOMAIN_SIDE)
        .max(10.0 * (points as f64).sqrt())
        .ceil();
    let (lw, lh) = (f64::from(w.max(1)), f64::from(h.max(1)));
    let long = lw.max(lh);
    // The largest longer side whose domain stays within the pixel budget.
    let cap = (MAX_DOMAIN_PIXELS as f64 * long / lw.min(lh))
        .sqrt()
        .floor();
    let side = side.min(cap.max(f64::from(MIN_DOMAIN_SIDE)));
    let s = side / f64::from(w.max(h));
    (
        ((f64::from(w) * s).round() as u32).max(1),
        ((f64::from(h) * s).round() as u32).max(1),
    )
}

impl Job {
    /// Checks the options that do not depend on the picture, for an output
    /// of `format`.
    pub fn validate(&self, format: Format) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if format == Format::Svg && self.scale != 1.0 {
            return bad("--scale applies to PNG output; use --width-mm to size an SVG".into());
        }
        if format == Format::Png
            && (self.width_mm.is_some() || self.pen_mm.is_some() || self.paper.is_some())
        {
            return bad(
                "--width-mm, --paper and --pen-mm apply to SVG output; use --scale to size a PNG"
                    .into(),
            );
        }
        self.check()
    }

    /// Checks the options that depend on neither the picture nor the
    /// output's format.
    pub fn check(&self) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if let Some(pen) = self.pen_mm {
            if !(pen.is_finite() && pen > 0.0) {
                return bad(format!("--pen-mm {pen} must be a positive number"));
            }
            if self.width_mm.is_none() && self.paper.is_none() {
                return bad(
                    "--pen-mm needs --width-mm or --paper: the page size turns pixels into millimetres"
                        .into(),
                );
            }
        }
        if self.width_mm.is_some() && self.paper.is_some() {
            return bad(
                "--width-mm and --paper exclude each other: the paper sizes the drawing".into(),
            );
        }
        if self.paper.is_none() && (self.margin.is_some() || self.landscape) {
            return bad("--margin and --landscape need --paper".into());
        }
        if let Some(r) = self.rotate
            && !matches!(r, 90 | 180 | 270)
        {
            return bad(format!(
                "--rotate {r} must be 90, 180 or 270 (degrees clockwise)"
            ));
        }
        if let Some(l) = self.refill_mm {
            if self.pen_mm.is_none() {
                return bad("--refill-mm needs --pen-mm: it splits the pen's drawing".into());
            }
            if !(l.is_finite() && l > 0.0) {
                return bad(format!("--refill-mm {l} must be a positive number"));
            }
        }
        if self.dot_path != DotPath::Spiral && self.pen_mm.is_none() {
            return bad("--dot-path needs --pen-mm: it is how the pen draws each dot".into());
        }
        if let Some(paper) = &self.paper {
            // The margins must leave room whatever the drawing's aspect.
            paper.place((1, 1), self.landscape, self.margin())?;
        }
        if !(self.dot_ratio.is_finite() && self.dot_ratio > 0.0 && self.dot_ratio <= 1.0) {
            return bad(format!("--dot-ratio {} must be in (0, 1]", self.dot_ratio));
        }
        if let Some(r) = self.dot_radius {
            if !(r.is_finite() && r > 0.0) {
                return bad(format!("--dot-radius {r} must be a positive number"));
            }
            if self.points.is_some() || self.importance.min_radius.is_some() {
                return bad(
                    "--dot-radius excludes --points and --min-radius: it sets the radii itself"
                        .into(),
                );
            }
        }
        if let Some(d) = self.dot_mm {
            if !(d.is_finite() && d > 0.0) {
                return bad(format!("--dot-mm {d} must be a positive number"));
            }
            if self.width_mm.is_none() && self.paper.is_none() {
                return bad("--dot-mm needs --width-mm or --paper: the page's size in mm".into());
            }
            if self.points.is_some()
                || self.importance.min_radius.is_some()
                || self.dot_radius.is_some()
            {
                return bad(
                    "--dot-mm excludes --points, --min-radius and --dot-radius: it sets the radii \
                     itself"
                        .into(),
                );
            }
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return bad(format!("--scale {} must be a positive number", self.scale));
        }
        if let Some(mm) = self.width_mm
            && !(mm.is_finite() && mm > 0.0)
        {
            return bad(format!("--width-mm {mm} must be a positive number"));
        }
        self.dot_size().validate()
    }

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

    /// The part of the job that the points depend on: two jobs with equal
    /// keys sample the same points (a front end re-samples when it
    /// changes); the rest only changes how the dots are drawn and written.
    #[must_use]
    pub fn sampling_key(&self) -> Self {
        let mut key = self.clone();
        // Fixed and proportional dots sample the same calibrated map.
        key.dot = Some(match self.dot_mode() {
            DotMode::Proportional => DotMode::Fixed,
            d => d,
        });
        if key.dot != Some(DotMode::Sized) {
            key.dot_ratio = DEFAULT_DOT_RATIO;
        }
        key.dot_factor = None;
        key.scale = 1.0;
        key.ink = Ink::BLACK;
        // The pen sets the radii only when nothing else does.
        let pen_sized = self.pen_mm.is_some()
            && self.points.is_none()
            && self.importance.min_radius.is_none()
            && self.dot_radius.is_none()
            && self.dot_mm.is_none();
        key.dot_path = DotPath::Spiral;
        // Dots sized in mm take their radii from the page's size.
        if !pen_sized && self.dot_mm.is_none() {
            key.pen_mm = None;
            key.width_mm = None;
            key.paper = None;
            key.margin = None;
            key.landscape = false;
        }
        key
    }

    /// The dot mode: `dot`, or fixed with a pen, else sized.
    #[must_use]
    pub fn dot_mode(&self) -> DotMode {
        self.dot.unwrap_or(if self.pen_mm.is_some() {
            DotMode::Fixed
        } else {
            DotMode::Sized
        })
    }

    /// Whether the dots' own radius or the pen sets the sample radii (else
    /// the count does, or the minimum radius).
    fn pen_sized(&self) -> bool {
        self.pen_mm.is_some()
            && self.points.is_none()
            && self.importance.min_radius.is_none()
            && self.dot_mm.is_none()
    }

    /// The dot count to fit, if any, and whether something scales the
    /// radii (a count, the dots' radius or the pen): then a missing radius
    /// range may default.
    pub(crate) fn count(&self) -> (Option<usize>, bool) {
        // The dots' own radius sets the sample radii, or the count does; a
        // pen alone sets the darkest dots to its width.
        let by_dot = self.dot_radius.is_some() || self.dot_mm.is_some() || self.pen_sized();
        let points = match (self.points, self.importance.min_radius) {
            (Some(n), _) => Some(n),
            _ if by_dot => None,
            (None, Some(_)) => None,
            (None, None) => Some(DEFAULT_POINTS),
        };
        (points, points.is_some() || by_dot)
    }

    /// The domain for a picture of `size`: the asked size, or the default.
    pub(crate) fn domain_for(&self, size: (u32, u32), points: Option<usize>) -> (u32, u32) {
        match (self.width, self.height) {
            (None, None) => {
                let domain = default_domain(size.0, size.1, points.unwrap_or(DEFAULT_POINTS));
                self.pen_domain(domain).unwrap_or(domain)
            }
            (wd, hd) => fit_size(size, wd, hd),
        }
    }

    /// When the pen sizes the dots (no count, no radius given), `domain`
    /// enlarged so that the pen's plotted dot spans [`PEN_DOT_PX`] pixels
    /// (within [`MAX_DOMAIN_PIXELS`]): a fine pen on a large sheet is
    /// sampled, not refused. `None` when it spans that already.
    fn pen_domain(&self, domain: (u32, u32)) -> Option<(u32, u32)> {
        if !self.pen_sized() || self.dot_radius.is_some() {
            return None;
        }
        let mm = self.mm_per_px(domain).ok()??;
        let across = self.pen_width()? * self.dot_gain(0) / mm;
        if across >= PEN_DOT_PX {
            return None;
        }
        let (w, h) = (f64::from(domain.0), f64::from(domain.1));
        let grow = PEN_DOT_PX / across;
        let fit = (MAX_DOMAIN_PIXELS as f64 / (w * h)).sqrt();
        let s = grow.min(fit).max(1.0);
        Some((
            ((w * s).round() as u32).max(1),
            ((h * s).round() as u32).max(1),
        ))
    }

    /// `range`, or the range whose darkest dots have the asked dot radius
    /// (or the pen's, on a domain `width` px wide).
    pub(crate) fn dot_range(
        &self,
        range: RadiusRange,
        domain: (u32, u32),
    ) -> crate::Result<RadiusRange> {
        let pen_dot = match (self.pen_mm, self.mm_per_px(domain)?) {
            (Some(_), Some(mm)) if self.pen_sized() && self.dot_radius.is_none() => {
                let pen = self.pen_width().unwrap_or_default();
                // The dot as plotted: the pen's width times its gain.
                Some((pen * self.dot_gain(0) / 2.0 / mm) as f32)
            }
            _ => None,
        };
        // The darkest dots' diameter in mm, as a radius in domain px.
        let mm_dot = match (self.dot_mm, self.mm_per_px(domain)?) {
            (Some(d), Some(mm)) => Some((d / 2.0 / mm) as f32),
            _ => None,
        };
        let Some(rho) = self.dot_radius.or(mm_dot).or(pen_dot) else {
            return Ok(range);
        };
        let min = Mapping::range_for_dot(rho, 1.0)?.min;
        if pen_dot.is_some() && self.dot_radius.is_none() && min < 1.0 {
            return Err(Error::InvalidParameter(format!(
                "the pen's dots are {:.2} px wide on this {} px wide domain, too small to \
                 sample: give --points, or a wider domain with --width",
                2.0 * rho,
                domain.0
            ))
            .into());
        }
        let max = self
            .importance
            .max_radius
            .unwrap_or(min * DEFAULT_RADIUS_RATIO);
        Ok(RadiusRange::new(min, max.max(min))?)
    }

    /// The margin on the paper, mm: `--margin` or [`DEFAULT_MARGIN_MM`].
    #[must_use]
    pub fn margin(&self) -> f64 {
        self.margin.unwrap_or(DEFAULT_MARGIN_MM)
    }

    /// Where a drawing of `domain` px lies on the job's paper, if any.
    pub fn placement(&self, domain: (u32, u32)) -> crate::Result<Option<Placement>> {
        match &self.paper {
            Some(paper) => Ok(Some(paper.place(domain, self.landscape, self.margin())?)),
            None => Ok(None),
        }
    }

    /// Millimetres per domain pixel, when the drawing has a size in mm
    /// (`--width-mm` or `--paper`).
    pub fn mm_per_px(&self, domain: (u32, u32)) -> crate::Result<Option<f64>> {
        if let Some(p) = self.placement(domain)? {
            return Ok(Some(p.mm_per_px(domain.0)));
        }
        Ok(self.width_mm.map(|mm| mm / f64::from(domain.0.max(1))))
    }

    /// The dot gain of pen `class` (its plotted dot's diameter over the
    /// drawn one, from `pixelpie calibrate fit`), 1 when not calibrated. A
    /// one-ink drawing takes its single pen's.
    #[must_use]
    pub fn dot_gain(&self, class: u32) -> f64 {
        self.pens
            .as_ref()
            .and_then(|set| set.pens().get(class as usize))
            .and_then(|p| p.dot_gain)
            .unwrap_or(1.0)
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

    /// The grey drawing's pen width with `--pen-mm`: its one pen's own
    /// width if the pen file gives one.
    #[must_use]
    pub fn pen_width(&self) -> Option<f64> {
        self.pen_mm
            .map(|w| self.one_pen().and_then(|p| p.width_mm).unwrap_or(w))
    }

    /// [`Self::run`] on the chosen backend (the CLI's fallback policy,
    /// [`crate::backend::sample`]); `notice` hears which backend runs.
    pub fn run_on(
        &self,
        image: &Path,
        backend: crate::backend::BackendChoice,
        ctl: crate::sampler::Control<'_>,
        notice: &mut dyn FnMut(crate::backend::Notice),
    ) -> crate::Result<Stipple> {
        self.run(
            image,
            |params| Ok(crate::backend::sample(params, backend, ctl, &mut *notice)?),
            |_| ctl.check().is_ok(),
        )
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_job_reads_back_its_own_json_and_refuses_unknown_values() {
        let mut job = Job {
            points: Some(1234),
            ink: Ink([1, 2, 3]),
            ..Job::default()
        };
        job.importance.gamma = 1.5;
        job.sampler.seed = 9;
        let text = serde_json::to_string(&job).unwrap();
        assert!(text.contains(r##""ink":"#010203""##), "{text}");
        assert_eq!(serde_json::from_str::<Job>(&text).unwrap(), job);
        // Missing fields take the defaults; a bad enum name is refused.
        assert_eq!(serde_json::from_str::<Job>("{}").unwrap(), Job::default());
        assert!(serde_json::from_str::<Job>(r#"{"policy":"largest"}"#).is_err());
        assert_eq!(Job::default().policy, Policy::Smaller);
    }

    #[test]
    fn the_sampling_key_ignores_only_how_dots_are_drawn() {
        let job = Job::default();
        let mut drawn = job.clone();
        drawn.dot_factor = Some(1.3);
        drawn.scale = 2.0;
        drawn.ink = Ink([200, 0, 0]);
        drawn.width_mm = Some(100.0);
        drawn.dot = Some(DotMode::Sized);
        assert_eq!(drawn.sampling_key(), job.sampling_key());
        // Fixed and proportional dots share their samples; sized ones not.
        let fixed = Job {
            dot: Some(DotMode::Fixed),
            ..job.clone()
        };
        let proportional = Job {
            dot: Some(DotMode::Proportional),
            ..job.clone()
        };
        assert_eq!(fixed.sampling_key(), proportional.sampling_key());
        assert_ne!(fixed.sampling_key(), job.sampling_key());
        let mut seeded = job.clone();
        seeded.sampler.seed = 1;
        assert_ne!(seeded.sampling_key(), job.sampling_key());
        // A pen sizes the dots only when nothing else does.
        let pen = Job {
            width_mm: Some(100.0),
            pen_mm: Some(0.3),
            ..job.clone()
        };
        assert_ne!(pen.sampling_key().pen_mm, None);
        let counted = Job {
            points: Some(500),
            ..pen
        };
        assert_eq!(counted.sampling_key().pen_mm, None);
    }

    #[test]
    fn the_job_holds_every_exclusion() {
        let both = Job {
            dot_radius: Some(3.0),
            points: Some(100),
            ..Job::default()
        };
        assert!(both.check().is_err());
        let mut with_min = Job {
            dot_radius: Some(3.0),
            ..Job::default()
        };
        assert!(with_min.check().is_ok());
        with_min.importance.min_radius = Some(2.0);
        assert!(with_min.check().is_err());
        let pen = Job {
            pen_mm: Some(0.3),
            ..Job::default()
        };
        assert!(pen.check().is_err(), "a pen needs a page width");
        let scaled = Job {
            scale: 2.0,
            ..Job::default()
        };
        assert!(scaled.validate(Format::Svg).is_err());
        assert!(scaled.validate(Format::Png).is_ok());
        assert_eq!(
            Format::from_path(Path::new("photo.SVG")).unwrap(),
            Format::Svg
        );
        assert_eq!(
            Format::from_path(Path::new("dots.Json")).unwrap(),
            Format::Json
        );
    }
}
