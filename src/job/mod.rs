//! The pipeline: the drawing job ([`Job`], `pixelpie stipple`) and the
//! point-set job ([`SampleJob`], `pixelpie sample`). `Job → Plan → run`:
//! the job is what the user asked for (its options and defaults, here; its
//! checks in `check.rs`; its sizes, domain and page in `radii.rs`); the
//! plan makes every decision once (`plan.rs`, [`Job::plan`]); the run
//! executes it (prepare → sample → relax → order → size; `run.rs`, the
//! count's fit in [`count`], the colour stages in `colour.rs`, the
//! correction in `correct/`); the writers put out SVG, PNG, CSV or JSON
//! (`write.rs`, through [`crate::stipple`]'s formats).
//!
//! Every front end runs these jobs: the CLI parses them from its arguments,
//! the Python package deserializes them from keyword arguments, and the
//! app's settings hold one [`Job`] (plus what only the view needs). The same
//! job therefore gives the same drawing and the same files, byte for byte,
//! from all three. Nothing below it (the sampler, maps, colour science,
//! the formats) imports it.

use serde::{Deserialize, Serialize};

mod assign;
mod check;
mod colour;
mod correct;
pub mod count;
mod density;
pub mod file;
mod layers;
mod line;
mod options;
mod plan;
mod plot;
mod poster;
mod preview;
mod radii;
mod ramp;
mod run;
mod sample;
mod write;

pub use layers::{LayerPaths, PageTransform, PenLayer};
pub use options::{
    Correction, DotMode, Format, Ink, LayerOrder, Order, PaperColour, Spacing, Style,
};
pub use plan::{PenChoice, Plan, Planned};
pub use poster::{Manifest, ManifestSheet, Poster, PosterPlan, Sheet, SheetGrid};
pub use preview::{PenCheck, PlotPen, plotted_dot, short_of};
pub use radii::default_domain;
pub use ramp::{RampError, ramp_error, ramp_error_sized};
pub use run::{Decoded, Picture, Stage, Step, Stipple};
pub use sample::{Radii, SampleJob, Sampled, not_maximal};

use crate::colour::PenSet;
use crate::importance::{Crop, ImportanceOptions};
use crate::sampler::{DEFAULT_POLICY, Policy, SamplerOptions};
use crate::stipple::paper::Paper;
use crate::stipple::svg::DotPath;

/// Lloyd steps a drawing takes by default ([`Job::plan`]), each
/// over-relaxed by [`crate::stipple::relax::OVER_RELAX`]: two lift the
/// default drawing's SSIM by 0.02–0.05 on five photos at 10K dots, and
/// make it closer to the photo than three plain steps did (docs/quality.md).
pub const AUTO_RELAX_STEPS: u32 = 2;
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
    #[cfg_attr(feature = "cli", arg(long, value_name = "MM"))]
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
    /// dot 1.6 times the way to the centroid of its Voronoi cell
    /// (over-relaxed), weighted to keep the calibrated density; a few steps
    /// make the spacing more even, each pen's dots on their own in colour
    /// [default: 2 for corrected dots (sized, --correction on) up to
    /// 200 000 dots, else none (a step costs about 0.45 s at 1M dots on
    /// two cores)].
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relax: Option<u32>,
    /// Drawing order: along a Hilbert curve, or a short pen-plotter path (2-opt).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Order::None))]
    pub order: Order,
    /// What the pen draws: dots, or one continuous line per pen through
    /// the points (TSP art), whose ink reproduces the tones; its count
    /// follows from the pen and the page as the dots' does.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Style::Dots))]
    #[serde(skip_serializing_if = "Style::is_default")]
    pub style: Style,
    /// With --style line: the line as smooth curves through its points
    /// (centripetal Catmull-Rom, written as cubic Béziers).
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub line_smooth: bool,
    /// PNG pixels per domain pixel (PNG output only).
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 1.0))]
    pub scale: f32,
    /// SVG page width in millimetres (height follows the aspect) [default: px].
    #[cfg_attr(feature = "cli", arg(long))]
    pub width_mm: Option<f64>,
    /// Paper for the SVG: a1 to a6, letter, legal, tabloid or WxHmm. The
    /// drawing fits inside the margins, centred, keeping its aspect; the
    /// SVG is the whole sheet, in mm.
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paper: Option<Paper>,
    /// Margin around the drawing on the paper, mm [default: 10 with --paper].
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// Turn the paper to landscape (wider than tall); portrait by default.
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub landscape: bool,
    /// A poster of WxH mm (or a paper name) plotted sheet by sheet: the
    /// drawing is made whole at the poster's size, then each dot goes to
    /// one --paper sheet (inside its --margin; the sheets overlap where
    /// they meet), with registration crosses on the seams; -o names a
    /// folder of one SVG a sheet and poster.json (docs/plotter.md).
    #[cfg_attr(feature = "cli", arg(long, value_name = "WxH"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub poster: Option<Paper>,
    /// The sheet of a poster this job writes (set by [`Job::poster`]).
    #[cfg_attr(feature = "cli", arg(skip))]
    #[serde(skip)]
    pub(crate) sheet: Option<poster::SheetPage>,
    /// Write the SVG's width and height in CSS px (96 per inch) instead of
    /// mm: the same page, for tools that drop units (saxi's command line).
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub size_px: bool,
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
    #[cfg_attr(feature = "cli", arg(long, value_name = "MM"))]
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
    /// Choose this many of --pens (an inventory, up to 64 pens) for the
    /// picture: the K whose drawing the render model predicts closest to
    /// its colours (docs/colour.md). The drawing, and --save-job, use the
    /// pens chosen.
    #[cfg_attr(feature = "cli", arg(long, value_name = "K"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub choose: Option<usize>,
    /// The paper's colour: white (the default), black, kraft, grey or
    /// #rrggbb, under the pens' inks. A pen file's `opacity` says how each
    /// ink lies on it (0 multiplies like felt-tip ink; 1 covers like a gel
    /// or paint pen; unset, an ink lighter than the paper covers). The
    /// separation, the correction, the PNG, the preview and the SVG (on a
    /// layer of its own that plotters skip) follow. One ink on a coloured
    /// paper draws the picture it makes: --ink "#ffffff" --paper-colour
    /// black draws stars as white dots.
    #[cfg_attr(feature = "cli", arg(long, value_name = "COLOUR"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paper_colour: Option<PaperColour>,
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
            style: Style::Dots,
            line_smooth: false,
            scale: 1.0,
            width_mm: None,
            paper: None,
            margin: None,
            landscape: false,
            poster: None,
            sheet: None,
            size_px: false,
            pen_mm: None,
            dot_path: DotPath::Spiral,
            refill_mm: None,
            layer_order: LayerOrder::LightFirst,
            spacing: Spacing::Local,
            ink: Ink::BLACK,
            pens: None,
            choose: None,
            paper_colour: None,
            policy: DEFAULT_POLICY,
            sampler: SamplerOptions::default(),
        }
    }
}

impl Job {
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
        key.size_px = false;
        key.line_smooth = false;
        // The pen sets the radii only when nothing else does.
        let pen_sized = self.pen_sized();
        key.dot_path = DotPath::Spiral;
        // Dots sized in mm take their radii from the page's size.
        if !pen_sized && self.dot_mm.is_none() && self.style == Style::Dots {
            key.pen_mm = None;
            key.width_mm = None;
            key.paper = None;
            key.margin = None;
            key.landscape = false;
            key.poster = None;
        }
        key.sheet = None;
        key
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

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
