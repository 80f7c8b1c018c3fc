//! `pixelpie stipple`: an image in, a stipple drawing (SVG or PNG) out.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use clap::Args;
use serde::Serialize;

use pixelpie::backend::BackendChoice;
use pixelpie::importance::{Mapping, Prepared, RadiusRange, fit_size};
use pixelpie::io;
use pixelpie::sampler::{self, Params, Point};
use pixelpie::stipple::{DotSize, raster, relax, svg, tsp};

use super::importance::{ImportanceOpts, RunOpts};
use super::sample::{GpuPath, PolicyArg, progress_bar};

/// The default number of dots.
pub const DEFAULT_POINTS: usize = 10_000;
/// The white dots' radius as a fraction of the black dots' (`--dot sized`):
/// the best of 0.3, 0.4 and 0.5 by the fidelity measure on the bundled
/// photos (StippleGen's default dot sizes, 2 and 5, make 0.4).
pub const DEFAULT_DOT_RATIO: f32 = 0.3;
/// The default domain's longer side is at least this many pixels.
pub const MIN_DOMAIN_SIDE: u32 = 1024;

/// Arguments of `pixelpie stipple`.
#[derive(Args, Debug, Serialize)]
pub struct StippleArgs {
    /// The picture: PNG, JPEG, TIFF, BMP, WebP or OpenEXR.
    #[arg(id = "importance", value_name = "IMAGE")]
    image: PathBuf,
    /// Output drawing: .svg or .png.
    #[arg(long, short)]
    output: PathBuf,
    /// Number of dots (±3%) [default: 10000 unless --min-radius is given].
    #[arg(long)]
    points: Option<usize>,
    /// Domain width in px [default: the image scaled so that its longer side
    /// is max(1024, 10·√points)].
    #[arg(long)]
    width: Option<u32>,
    /// Domain height in px [default: from the width and the image's aspect].
    #[arg(long)]
    height: Option<u32>,
    #[command(flatten)]
    importance_opts: ImportanceOpts,
    /// Dot size. fixed: all dots alike; sized: small dots in light areas,
    /// larger ones in dark areas (StippleGen's min/max dot size). Both are
    /// calibrated: once blurred, the ink equals the grey of the picture.
    /// proportional: dot radius = factor × the sample's radius; it covers the
    /// same fraction everywhere, so it does NOT reproduce tones (a texture).
    /// [default: sized; fixed with --pen-mm, since dots narrower than the
    /// pen cannot be drawn]
    #[arg(long, value_enum)]
    dot: Option<DotArg>,
    /// Dot radius factor: × the calibrated radius (fixed, sized: 1
    /// reproduces the tones, more darkens, less lightens) or × each sample's
    /// radius (proportional; 0.5 makes the closest dots touch) [default: 1
    /// fixed/sized, 0.5 proportional].
    #[arg(long)]
    dot_factor: Option<f32>,
    /// With --dot sized: the lightest dots' radius as a fraction of the
    /// darkest dots' (0..1].
    #[arg(long, default_value_t = DEFAULT_DOT_RATIO)]
    dot_ratio: f32,
    /// Radius in domain px of the darkest dots; the sample radii follow from
    /// it, so the dot count does too (instead of --points).
    #[arg(long, conflicts_with_all = ["points", "min_radius"])]
    dot_radius: Option<f32>,
    /// Weighted Lloyd (Voronoi) relaxation steps after sampling: moves each
    /// dot to the centroid of its Voronoi cell, weighted to keep the
    /// calibrated density. A few steps make the spacing more even.
    #[arg(long, default_value_t = 0)]
    relax: u32,
    /// Drawing order: as sampled, or a short pen-plotter path (2-opt).
    #[arg(long, value_enum, default_value_t = OrderArg::None)]
    order: OrderArg,
    /// PNG pixels per domain pixel.
    #[arg(long, default_value_t = 1.0)]
    scale: f32,
    /// SVG page width in millimetres (height follows the aspect) [default: px].
    #[arg(long)]
    width_mm: Option<f64>,
    /// Pen width in mm (needs --width-mm): each dot is drawn as a pen draws
    /// it, in mm, on one Inkscape layer: a dot no wider than the pen is one
    /// pen touch (a two-point path), a bigger one a spiral filled at pen
    /// pitch. Without --points, --dot-radius or --min-radius the darkest
    /// dots are one pen wide, so that the tones are calibrated for the pen.
    #[arg(long)]
    pen_mm: Option<f64>,
    /// Also write the dots' centres and radii (.csv or .json), in drawing order.
    #[arg(long)]
    save_points: Option<PathBuf>,
    /// Disk policy for varying radii (paper §3.4); the paper stipples with
    /// the smaller disk, which keeps large light-area disks out of dark areas.
    #[arg(long, value_enum, default_value_t = PolicyArg::Smaller)]
    policy: PolicyArg,
    /// Seed of the dart hash.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Sub-pixel bits per axis of dart positions (0 = pixel centres, at most 7).
    #[arg(long, default_value_t = sampler::DEFAULT_SUBPIXEL_BITS)]
    subpixel_bits: u32,
    /// Wrap distances around the domain, so that tiled copies of the drawing
    /// keep the dot spacing across their seams.
    #[arg(long)]
    periodic: bool,
    /// Exact mode: dots exactly the disk distance apart with no gaps between
    /// them (runs on the CPU).
    #[arg(long)]
    exact: bool,
    /// Backend.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    backend: BackendChoice,
    /// How the GPU rasterizes darts (S1): by measurement, the depth-tested
    /// draw, or the compute pass.
    #[arg(long, value_enum, default_value_t = GpuPath::Auto)]
    gpu_path: GpuPath,
    /// No progress bar and no report on stderr.
    #[arg(long, short)]
    quiet: bool,
    /// Print the backend, radii and timings on stderr.
    #[arg(long, short)]
    verbose: bool,
}

/// Dot sizing on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DotArg {
    /// All dots the same size (calibrated).
    Fixed,
    /// Dots sized by tone, small in light areas (calibrated).
    Sized,
    /// Dot radius proportional to the sample's radius (does not reproduce tones).
    Proportional,
}

/// Drawing order on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum OrderArg {
    /// The sampler's acceptance order.
    None,
    /// Nearest-neighbour tour improved by 2-opt.
    Tsp,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Drawing {
    Svg,
    Png,
}

fn drawing_format(path: &Path) -> Result<Drawing> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("svg") => Ok(Drawing::Svg),
        Some("png") => Ok(Drawing::Png),
        _ => bail!(
            "unknown output extension of '{}': use .svg or .png",
            path.display()
        ),
    }
}

/// The default domain: the image scaled so its longer side is
/// max(1024, 10 √N) px, about ten pixels between dots or more.
fn default_domain(w: u32, h: u32, points: usize) -> (u32, u32) {
    let side = f64::from(MIN_DOMAIN_SIDE)
        .max(10.0 * (points as f64).sqrt())
        .ceil();
    let s = side / f64::from(w.max(h));
    (
        ((f64::from(w) * s).round() as u32).max(1),
        ((f64::from(h) * s).round() as u32).max(1),
    )
}

pub fn run(a: &StippleArgs) -> Result<()> {
    let format = drawing_format(&a.output)?;
    if let Some(p) = &a.save_points {
        io::PointFormat::from_path(p)?;
    }
    if format == Drawing::Svg && a.scale != 1.0 {
        bail!("--scale applies to PNG output; use --width-mm to size an SVG");
    }
    if format == Drawing::Png && (a.width_mm.is_some() || a.pen_mm.is_some()) {
        bail!("--width-mm and --pen-mm apply to SVG output; use --scale to size a PNG");
    }
    if let Some(pen) = a.pen_mm {
        if !(pen.is_finite() && pen > 0.0) {
            bail!("--pen-mm {pen} must be a positive number");
        }
        if a.width_mm.is_none() {
            bail!("--pen-mm needs --width-mm: the page size turns pixels into millimetres");
        }
    }
    if !(a.dot_ratio.is_finite() && a.dot_ratio > 0.0 && a.dot_ratio <= 1.0) {
        bail!("--dot-ratio {} must be in (0, 1]", a.dot_ratio);
    }
    if let Some(r) = a.dot_radius
        && !(r.is_finite() && r > 0.0)
    {
        bail!("--dot-radius {r} must be a positive number");
    }
    // The dots' own radius sets the sample radii, or the count does; a pen
    // alone sets the darkest dots to its width.
    let pen_sized =
        a.pen_mm.is_some() && a.points.is_none() && a.importance_opts.min_radius.is_none();
    let by_dot = a.dot_radius.is_some() || pen_sized;
    let points = match (a.points, a.importance_opts.min_radius) {
        (Some(n), _) => Some(n),
        _ if by_dot => None,
        (None, Some(_)) => None,
        (None, None) => Some(DEFAULT_POINTS),
    };
    if a.backend != BackendChoice::Cpu && a.gpu_path != GpuPath::Auto {
        a.gpu_path.apply();
    }
    let dot = a.dot.unwrap_or(if a.pen_mm.is_some() {
        DotArg::Fixed
    } else {
        DotArg::Sized
    });
    let mapping = match dot {
        DotArg::Sized => Mapping::ToneSized(a.dot_ratio),
        DotArg::Fixed | DotArg::Proportional => Mapping::Tone,
    };
    let t0 = Instant::now();
    let mut prepared = a.importance_opts.prepare(
        &a.image,
        |w, h| match (a.width, a.height) {
            (None, None) => default_domain(w, h, points.unwrap_or(DEFAULT_POINTS)),
            (wd, hd) => fit_size((w, h), wd, hd),
        },
        mapping,
        points.is_some() || by_dot,
    )?;
    let (width, height) = (prepared.map.width(), prepared.map.height());
    let pen_dot = match (a.pen_mm, a.width_mm) {
        (Some(pen), Some(mm)) if pen_sized && a.dot_radius.is_none() => {
            Some((pen / 2.0 * f64::from(width) / mm) as f32)
        }
        _ => None,
    };
    if let Some(rho) = a.dot_radius.or(pen_dot) {
        let min = Mapping::range_for_dot(rho, 1.0)?.min;
        let max = a
            .importance_opts
            .max_radius
            .unwrap_or(min * super::importance::DEFAULT_RADIUS_RATIO);
        prepared.range = RadiusRange::new(min, max.max(min))?;
    }
    let t_load = t0.elapsed().as_secs_f64();
    let bar = progress_bar(a.quiet);
    let opts = RunOpts {
        base: Params::new(width, height)
            .with_policy(a.policy.into())
            .with_seed(a.seed)
            .with_subpixel_bits(a.subpixel_bits)
            .with_periodic(a.periodic)
            .with_exact(a.exact),
        points,
        backend: a.backend,
        bar: &bar,
        quiet: a.quiet,
        verbose: a.verbose,
    };
    let (mut set, range) = super::importance::sample(&prepared, &opts)?;
    bar.finish_and_clear();
    let t_sample = t0.elapsed().as_secs_f64() - t_load;
    if a.relax > 0 {
        set.points = relax_points(&prepared, range, &set.points, a)?;
    }
    let t_relax = t0.elapsed().as_secs_f64() - t_load - t_sample;
    let size = match dot {
        DotArg::Fixed | DotArg::Sized => DotSize::Calibrated(a.dot_factor.unwrap_or(1.0)),
        DotArg::Proportional => DotSize::Proportional(a.dot_factor.unwrap_or(0.5)),
    };
    size.validate()?;
    let points = match a.order {
        OrderArg::None => set.points.clone(),
        OrderArg::Tsp => order_tsp(&set.points, a.quiet),
    };
    let dots = size.dots(&points, |p| prepared.dot_radius(p, range));
    match format {
        Drawing::Svg => {
            let mut opts = match a.width_mm {
                Some(mm) => svg::SvgOptions::with_width_mm((width, height), mm)?,
                None => svg::SvgOptions::new((width, height)),
            };
            if let Some(pen) = a.pen_mm {
                opts = opts.with_pen_mm(pen)?;
            }
            io::write_atomic(&a.output, |w| Ok(svg::write(w, &dots, &opts)?))?;
        }
        Drawing::Png => {
            let img = raster::render(&dots, (width, height), a.scale)?;
            io::write_atomic(&a.output, |w| Ok(raster::write_png(w, &img, dots.len())?))?;
        }
    }
    if let Some(path) = &a.save_points {
        let out = set.clone().with_points(points);
        io::write_points(path, &out, a)?;
    }
    if a.verbose {
        let (lo, hi) = dots.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), d| {
            (lo.min(d.radius), hi.max(d.radius))
        });
        eprintln!(
            "{} dots on a {width}x{height} domain, sample radii {:.2}..{:.2} px, dot radii \
             {lo:.2}..{hi:.2} px; load {t_load:.3} s, sampling {t_sample:.3} s, relax \
             {t_relax:.3} s, total {:.3} s",
            dots.len(),
            range.min,
            range.max,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// `--relax`: weighted Lloyd steps with a progress bar
/// ([`pixelpie::stipple::relax_points`]).
fn relax_points(
    prepared: &Prepared,
    range: RadiusRange,
    points: &[Point],
    a: &StippleArgs,
) -> Result<Vec<Point>> {
    let bar = progress_bar(a.quiet);
    bar.set_length(u64::from(a.relax));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} relaxing [{bar:30}] {pos}/{len}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let options = relax::RelaxOptions {
        iterations: a.relax,
        periodic: a.periodic,
    };
    let moved = pixelpie::stipple::relax_points(prepared, range, points, options, |done| {
        bar.set_position(u64::from(done));
        true
    })?;
    bar.finish_and_clear();
    Ok(moved)
}

/// Orders `points` for a pen plotter and reports the pen travel on stderr.
fn order_tsp(points: &[Point], quiet: bool) -> Vec<Point> {
    let t = Instant::now();
    let xy: Vec<[f64; 2]> = points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let tour = tsp::plan(&xy, tsp::TspOptions::default());
    if !quiet {
        let saved = if tour.nearest_neighbour_length > 0.0 {
            100.0 * (1.0 - tour.length / tour.nearest_neighbour_length)
        } else {
            0.0
        };
        eprintln!(
            "tsp: pen travel {:.0} px (nearest neighbour) -> {:.0} px (2-opt, {} moves, -{saved:.1}%) in {:.2} s",
            tour.nearest_neighbour_length,
            tour.length,
            tour.moves,
            t.elapsed().as_secs_f64()
        );
    }
    tour.order.iter().map(|&i| points[i]).collect()
}
