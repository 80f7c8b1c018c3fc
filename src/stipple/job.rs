//! The whole stipple pipeline, from a picture to a drawing: the options
//! `pixelpie stipple` takes (with the `cli` feature, its arguments), the
//! default domain, sampling to a dot count, relaxation, the drawing order,
//! dot sizes, and the SVG or PNG output. The CLI, the Python package and
//! library users run the same code, so the same options give the same
//! drawing byte for byte.

use std::path::Path;

use serde::Serialize;

use super::{Dot, DotSize, Error, relax, svg, tsp};
use crate::importance::{
    DEFAULT_RADIUS_RATIO, ImportanceMap, ImportanceOptions, Mapping, RadiusRange, fit_size,
};
use crate::sampler::{Params, Point, Policy, SampleSet, SamplerOptions};

/// The default number of dots.
pub const DEFAULT_POINTS: usize = 10_000;
/// The white dots' radius as a fraction of the black dots' (`--dot sized`):
/// the best of 0.3, 0.4 and 0.5 by the fidelity measure on the bundled
/// photos (StippleGen's default dot sizes, 2 and 5, make 0.4).
pub const DEFAULT_DOT_RATIO: f32 = 0.3;
/// The default domain's longer side is at least this many pixels.
pub const MIN_DOMAIN_SIDE: u32 = 1024;

/// Dot sizing (the CLI's `--dot`, the app's Dots control).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum DotMode {
    /// All dots the same size (calibrated).
    Fixed,
    /// Dots sized by tone, small in light areas (calibrated).
    #[default]
    Sized,
    /// Dot radius proportional to the sample's radius (does not reproduce tones).
    Proportional,
}

impl DotMode {
    /// The calibrated tone mapping for these dots: sized dots with the
    /// lightest dots `ratio` of the darkest's, else equal dots.
    #[must_use]
    pub fn mapping(self, ratio: f32) -> Mapping {
        match self {
            Self::Sized => Mapping::ToneSized(ratio),
            Self::Fixed | Self::Proportional => Mapping::Tone,
        }
    }

    /// How the dots are drawn: `factor` × the calibrated radius, or × the
    /// sample's radius for proportional dots.
    #[must_use]
    pub fn size(self, factor: f32) -> DotSize {
        match self {
            Self::Fixed | Self::Sized => DotSize::Calibrated(factor),
            Self::Proportional => DotSize::Proportional(factor),
        }
    }

    /// The default factor of [`Self::size`]: 1 reproduces the tones; 0.5
    /// makes the closest proportional dots touch.
    #[must_use]
    pub fn default_factor(self) -> f32 {
        match self {
            Self::Fixed | Self::Sized => 1.0,
            Self::Proportional => 0.5,
        }
    }
}

/// Drawing order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Order {
    /// The sampler's acceptance order.
    #[default]
    None,
    /// Nearest-neighbour tour improved by 2-opt.
    Tsp,
}

/// A drawing's file format, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// SVG: circles, or pen paths with `--pen-mm`.
    Svg,
    /// An anti-aliased greyscale PNG.
    Png,
}

impl Format {
    /// The format of `path`'s extension.
    pub fn from_path(path: &Path) -> Result<Self, Error> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Self::Svg),
            Some("png") => Ok(Self::Png),
            _ => Err(Error::InvalidParameter(format!(
                "unknown output extension of '{}': use .svg or .png",
                path.display()
            ))),
        }
    }
}

/// How a picture becomes a stipple drawing.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[non_exhaustive]
pub struct StippleOptions {
    /// Number of dots (±3%) [default: 10000 unless --min-radius is given].
    #[cfg_attr(feature = "cli", arg(long))]
    pub points: Option<usize>,
    /// Domain width in px [default: the image scaled so that its longer side
    /// is max(1024, 10·√points)].
    #[cfg_attr(feature = "cli", arg(long))]
    pub width: Option<u32>,
    /// Domain height in px [default: from the width and the image's aspect].
    #[cfg_attr(feature = "cli", arg(long))]
    pub height: Option<u32>,
    /// How the picture's tones become radii.
    #[cfg_attr(feature = "cli", command(flatten))]
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
    #[cfg_attr(feature = "cli", arg(long, conflicts_with_all = ["points", "min_radius"]))]
    pub dot_radius: Option<f32>,
    /// Weighted Lloyd (Voronoi) relaxation steps after sampling: moves each
    /// dot to the centroid of its Voronoi cell, weighted to keep the
    /// calibrated density. A few steps make the spacing more even.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub relax: u32,
    /// Drawing order: as sampled, or a short pen-plotter path (2-opt).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Order::None))]
    pub order: Order,
    /// PNG pixels per domain pixel.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 1.0))]
    pub scale: f32,
    /// SVG page width in millimetres (height follows the aspect) [default: px].
    #[cfg_attr(feature = "cli", arg(long))]
    pub width_mm: Option<f64>,
    /// Pen width in mm (needs --width-mm): each dot is drawn as a pen draws
    /// it, in mm, on one Inkscape layer: a dot no wider than the pen is one
    /// pen touch (a two-point path), a bigger one a spiral filled at pen
    /// pitch. Without --points, --dot-radius or --min-radius the darkest
    /// dots are one pen wide, so that the tones are calibrated for the pen.
    #[cfg_attr(feature = "cli", arg(long))]
    pub pen_mm: Option<f64>,
    /// Disk policy for varying radii (paper §3.4); the paper stipples with
    /// the smaller disk, which keeps large light-area disks out of dark areas.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = Policy::Smaller))]
    pub policy: Policy,
    /// Seed, sub-pixel darts, periodic domain, exact mode.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[serde(flatten)]
    pub sampler: SamplerOptions,
}

impl Default for StippleOptions {
    fn default() -> Self {
        Self {
            points: None,
            width: None,
            height: None,
            importance: ImportanceOptions::default(),
            dot: None,
            dot_factor: None,
            dot_ratio: DEFAULT_DOT_RATIO,
            dot_radius: None,
            relax: 0,
            order: Order::None,
            scale: 1.0,
            width_mm: None,
            pen_mm: None,
            policy: Policy::Smaller,
            sampler: SamplerOptions::default(),
        }
    }
}

/// A finished drawing: its dots in drawing order, and how it was made.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Stipple {
    /// The dots, in drawing order.
    pub dots: Vec<Dot>,
    /// The sample points under the dots, in drawing order.
    pub points: Vec<Point>,
    /// The sampler's run (its points after the white cutoff and relaxation,
    /// in acceptance order).
    pub set: SampleSet,
    /// The domain in pixels.
    pub domain: (u32, u32),
    /// The sample radius range used.
    pub range: RadiusRange,
    /// Sampler runs made to reach the dot count.
    pub runs: usize,
    /// The count asked for, when the domain could not hold it at radii of
    /// at least 1 px.
    pub short_of: Option<usize>,
    /// The pen-plotter tour, with `Order::Tsp`.
    pub tour: Option<tsp::Tour>,
    /// Seconds spent loading, sampling and relaxing.
    pub seconds: (f64, f64, f64),
}

/// The default domain: the image scaled so its longer side is
/// max(1024, 10 √N) px, about ten pixels between dots or more.
#[must_use]
pub fn default_domain(w: u32, h: u32, points: usize) -> (u32, u32) {
    let side = f64::from(MIN_DOMAIN_SIDE)
        .max(10.0 * (points as f64).sqrt())
        .ceil();
    let s = side / f64::from(w.max(h));
    (
        ((f64::from(w) * s).round() as u32).max(1),
        ((f64::from(h) * s).round() as u32).max(1),
    )
}

impl StippleOptions {
    /// Checks the options that do not depend on the picture, for an output
    /// of `format`.
    pub fn validate(&self, format: Format) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if format == Format::Svg && self.scale != 1.0 {
            return bad("--scale applies to PNG output; use --width-mm to size an SVG".into());
        }
        if format == Format::Png && (self.width_mm.is_some() || self.pen_mm.is_some()) {
            return bad(
                "--width-mm and --pen-mm apply to SVG output; use --scale to size a PNG".into(),
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
            if self.width_mm.is_none() {
                return bad(
                    "--pen-mm needs --width-mm: the page size turns pixels into millimetres".into(),
                );
            }
        }
        if !(self.dot_ratio.is_finite() && self.dot_ratio > 0.0 && self.dot_ratio <= 1.0) {
            return bad(format!("--dot-ratio {} must be in (0, 1]", self.dot_ratio));
        }
        if let Some(r) = self.dot_radius
            && !(r.is_finite() && r > 0.0)
        {
            return bad(format!("--dot-radius {r} must be a positive number"));
        }
        Ok(())
    }

    /// The dot mode, with its default.
    #[must_use]
    pub fn dot_mode(&self) -> DotMode {
        self.dot.unwrap_or(if self.pen_mm.is_some() {
            DotMode::Fixed
        } else {
            DotMode::Sized
        })
    }

    /// Draws `image` (a file) with `sample` running the sampler; `relaxed`
    /// hears each relaxation step done and returns false to stop.
    pub fn run(
        &self,
        image: &Path,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        relaxed: impl FnMut(u32) -> bool,
    ) -> crate::Result<Stipple> {
        let t0 = std::time::Instant::now();
        let map = ImportanceMap::open(image, self.importance.hdr_white)?;
        let opened = t0.elapsed().as_secs_f64();
        let mut drawing = self.run_map(map, sample, relaxed)?;
        drawing.seconds.0 += opened;
        Ok(drawing)
    }

    /// [`Self::run`] for a picture already in memory.
    pub fn run_map(
        &self,
        map: ImportanceMap,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        relaxed: impl FnMut(u32) -> bool,
    ) -> crate::Result<Stipple> {
        let t0 = std::time::Instant::now();
        self.check()?;
        // The dots' own radius sets the sample radii, or the count does; a
        // pen alone sets the darkest dots to its width.
        let pen_sized =
            self.pen_mm.is_some() && self.points.is_none() && self.importance.min_radius.is_none();
        let by_dot = self.dot_radius.is_some() || pen_sized;
        let points = match (self.points, self.importance.min_radius) {
            (Some(n), _) => Some(n),
            _ if by_dot => None,
            (None, Some(_)) => None,
            (None, None) => Some(DEFAULT_POINTS),
        };
        let dot = self.dot_mode();
        let mapping = dot.mapping(self.dot_ratio);
        let mut prepared = self.importance.prepare_map(
            map,
            |w, h| match (self.width, self.height) {
                (None, None) => default_domain(w, h, points.unwrap_or(DEFAULT_POINTS)),
                (wd, hd) => fit_size((w, h), wd, hd),
            },
            mapping,
            points.is_some() || by_dot,
        )?;
        let (width, height) = (prepared.map.width(), prepared.map.height());
        let pen_dot = match (self.pen_mm, self.width_mm) {
            (Some(pen), Some(mm)) if pen_sized && self.dot_radius.is_none() => {
                Some((pen / 2.0 * f64::from(width) / mm) as f32)
            }
            _ => None,
        };
        if let Some(rho) = self.dot_radius.or(pen_dot) {
            let min = Mapping::range_for_dot(rho, 1.0)?.min;
            let max = self
                .importance
                .max_radius
                .unwrap_or(min * DEFAULT_RADIUS_RATIO);
            prepared.range = RadiusRange::new(min, max.max(min))?;
        }
        let t_load = t0.elapsed().as_secs_f64();
        let base = self
            .sampler
            .apply(Params::new(width, height).with_policy(self.policy));
        let fitted = prepared.sample(&base, points, sample)?;
        let (mut set, range) = (fitted.set, fitted.range);
        let t_sample = t0.elapsed().as_secs_f64() - t_load;
        if self.relax > 0 {
            let options = relax::RelaxOptions {
                iterations: self.relax,
                periodic: self.sampler.periodic,
            };
            let moved = super::relax_points(&prepared, range, &set.points, options, relaxed)?;
            set = set.with_points(moved);
        }
        let t_relax = t0.elapsed().as_secs_f64() - t_load - t_sample;
        let size = dot.size(self.dot_factor.unwrap_or(dot.default_factor()));
        size.validate()?;
        let (points, tour) = match self.order {
            Order::None => (set.points.clone(), None),
            Order::Tsp => {
                let xy: Vec<[f64; 2]> = set
                    .points
                    .iter()
                    .map(|p| [f64::from(p.x), f64::from(p.y)])
                    .collect();
                let tour = tsp::plan(&xy, tsp::TspOptions::default());
                let ordered = tour.order.iter().map(|&i| set.points[i]).collect();
                (ordered, Some(tour))
            }
        };
        let dots = size.dots(&points, |p| prepared.dot_radius(p, range));
        Ok(Stipple {
            dots,
            points,
            set,
            domain: (width, height),
            range,
            runs: fitted.runs,
            short_of: fitted.short_of,
            tour,
            seconds: (t_load, t_sample, t_relax),
        })
    }

    /// Writes `drawing` to `path` (SVG or PNG by extension), atomically.
    pub fn write(&self, drawing: &Stipple, path: &Path) -> crate::Result<()> {
        let format = Format::from_path(path)?;
        self.validate(format)?;
        let (dots, domain) = (&drawing.dots, drawing.domain);
        match format {
            Format::Svg => {
                let mut opts = match self.width_mm {
                    Some(mm) => svg::SvgOptions::with_width_mm(domain, mm)?,
                    None => svg::SvgOptions::new(domain),
                };
                if let Some(pen) = self.pen_mm {
                    opts = opts.with_pen_mm(pen)?;
                }
                crate::io::write_atomic(path, |w| Ok(svg::write(w, dots, &opts)?))?;
            }
            Format::Png => {
                let img = super::raster::render(dots, domain, self.scale)?;
                crate::io::write_atomic(path, |w| {
                    Ok(super::raster::write_png(w, &img, dots.len())?)
                })?;
            }
        }
        Ok(())
    }
}
