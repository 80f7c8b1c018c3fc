//! `pixelpie calibrate`: the pen-calibration loop (chart → plot → scan →
//! fit → pens.toml), and a synthetic plot-and-scan to try it without a
//! plotter. The work is the library's ([`pixelpie::stipple::calibrate`]).

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::{Args, Subcommand};

use pixelpie::colour::PenSet;
use pixelpie::stipple::Error;
use pixelpie::stipple::Paper;
use pixelpie::stipple::calibrate::{self, Chart, ChartSpec, ScanOptions, chart};

/// Arguments of `pixelpie calibrate`.
#[derive(Args, Debug)]
pub struct CalibrateArgs {
    #[command(subcommand)]
    command: CalibrateCommand,
}

#[derive(Subcommand, Debug)]
enum CalibrateCommand {
    /// Writes a calibration chart (SVG) to plot: per pen, patches of 0 to
    /// 100% ink made of the dots our stipples use at that pen's width.
    Chart(ChartArgs),
    /// Fits each pen's dot gain and ink colour from a scan or photo of the
    /// plotted chart, and writes the pen file that --pens reads.
    Fit(FitArgs),
    /// Renders a synthetic scan of the chart as plotted with known dot gains
    /// and inks (blur, noise, rotation, perspective): the loop without a
    /// plotter.
    Simulate(SimulateArgs),
}

#[derive(Args, Debug)]
struct ChartArgs {
    /// Output chart, .svg.
    #[arg(long, short)]
    output: PathBuf,
    /// The pens: black, cmyk, a list of #rrggbb colours or a .toml pen file.
    #[arg(long, default_value = "black")]
    pens: String,
    /// Width of the pens that have none, mm.
    #[arg(long, default_value_t = chart::DEFAULT_PEN_MM)]
    pen_mm: f64,
    /// Paper: a1 to a6, letter, legal, tabloid or WxHmm.
    #[arg(long, default_value = "a4")]
    paper: Paper,
    /// Margin, mm.
    #[arg(long, default_value_t = pixelpie::stipple::paper::DEFAULT_MARGIN_MM)]
    margin: f64,
    /// Landscape paper.
    #[arg(long)]
    landscape: bool,
    /// The paper's colour: white, black, kraft, grey or #rrggbb (the marks
    /// go to the pen that stands out most from it).
    #[arg(long, default_value = "white")]
    paper_colour: pixelpie::job::PaperColour,
    /// Seed of the patches' dots.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Args, Debug)]
struct FitArgs {
    /// The chart as written by `pixelpie calibrate chart`.
    #[arg(value_name = "CHART")]
    chart: PathBuf,
    /// The scan or photograph of the plotted chart.
    #[arg(value_name = "SCAN")]
    scan: PathBuf,
    /// Output pen file, .toml.
    #[arg(long, short)]
    output: PathBuf,
}

#[derive(Args, Debug)]
struct SimulateArgs {
    /// The chart as written by `pixelpie calibrate chart`.
    #[arg(value_name = "CHART")]
    chart: PathBuf,
    /// Output scan, .png.
    #[arg(long, short)]
    output: PathBuf,
    /// Each pen's dot gain, comma-separated (the last repeats).
    #[arg(long, value_delimiter = ',', default_value = "1.3")]
    gain: Vec<f64>,
    /// Each pen's real ink, comma-separated #rrggbb [default: the chart's].
    #[arg(long, value_delimiter = ',')]
    ink: Vec<String>,
    /// Gaussian blur, px.
    #[arg(long, default_value_t = ScanOptions::default().blur_px)]
    blur: f64,
    /// Noise, fraction of full scale.
    #[arg(long, default_value_t = ScanOptions::default().noise)]
    noise: f64,
    /// Rotation, degrees.
    #[arg(long, default_value_t = ScanOptions::default().rotate_deg)]
    rotate: f64,
    /// Perspective: corners move by up to this fraction of the sheet.
    #[arg(long, default_value_t = ScanOptions::default().perspective)]
    perspective: f64,
    /// Resolution, px per mm of the sheet.
    #[arg(long, default_value_t = ScanOptions::default().px_per_mm)]
    px_per_mm: f64,
    /// Seed of the noise and the warp.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

pub fn run(a: &CalibrateArgs) -> Result<()> {
    match &a.command {
        CalibrateCommand::Chart(c) => {
            let pens = PenSet::parse(&c.pens)?;
            let place = c.paper.place((1, 1), c.landscape, c.margin)?;
            let spec = ChartSpec::new(&pens, c.pen_mm, &place, c.seed)?;
            let chart = Chart::new(spec.with_paper(c.paper_colour.0))?;
            write_chart(&chart, &c.output)?;
            eprintln!(
                "chart {:04x}: {} pens × {} patches on {} paper; plot every pen's layer, then \
                 scan it and run pixelpie calibrate fit",
                chart.code,
                chart.spec.pens.len(),
                chart::FRACTIONS.len(),
                c.paper
            );
        }
        CalibrateCommand::Fit(f) => {
            let chart = read_chart(&f.chart)?;
            let scan = read_scan(&f.scan)?;
            let fit = calibrate::fit::fit(&chart, &scan)?;
            write_pens(&fit, &f.scan.display().to_string(), &f.output)?;
            println!("pen\tcolour\twidth mm\tdot gain\trms");
            for p in &fit.pens {
                println!(
                    "{}\t{}\t{}\t{:.3}\t{:.3}",
                    p.name,
                    pixelpie::colour::pens::hex_of(p.colour),
                    p.width_mm,
                    p.dot_gain,
                    p.rms
                );
            }
        }
        CalibrateCommand::Simulate(s) => {
            let chart = read_chart(&s.chart)?;
            let inks = s
                .ink
                .iter()
                .map(|c| pixelpie::colour::pens::parse_hex(c))
                .collect::<Result<Vec<_>, _>>()?;
            // The chart's paper where it names one (else off-white).
            let paper = chart.spec.paper.as_ref().map(|_| {
                chart
                    .spec
                    .paper_rgb()
                    .map(|c| pixelpie::colour::decode(f64::from(c) / 255.0))
            });
            let opts = ScanOptions {
                px_per_mm: s.px_per_mm,
                gains: s.gain.clone(),
                inks,
                paper: paper.unwrap_or(ScanOptions::default().paper),
                blur_px: s.blur,
                noise: s.noise,
                rotate_deg: s.rotate,
                perspective: s.perspective,
                seed: s.seed,
                ..ScanOptions::default()
            };
            let img = calibrate::simulate::scan(&chart, &opts)?;
            pixelpie::io::write_atomic(&s.output, |w| {
                img.write_with_encoder(image::codecs::png::PngEncoder::new(w))?;
                Ok(())
            })?;
        }
    }
    Ok(())
}

// The files of the loop: the chart, the scan and the pen file.

/// Reads the chart of the SVG file at `path`.
fn read_chart(path: &Path) -> pixelpie::Result<Chart> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::InvalidParameter(format!("cannot read chart '{}': {e}", path.display()))
    })?;
    Ok(Chart::read_svg(&text)?)
}

/// Reads a scan or photograph (PNG, JPEG, TIFF, BMP, WebP).
fn read_scan(path: &Path) -> pixelpie::Result<image::RgbImage> {
    let img = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| {
            Error::InvalidParameter(format!("cannot read scan '{}': {e}", path.display()))
        })?
        .decode()
        .map_err(|e| {
            Error::InvalidParameter(format!(
                "cannot decode scan '{}': {}",
                path.display(),
                pixelpie::one_line(&e)
            ))
        })?;
    Ok(img.to_rgb8())
}

/// Writes `chart` as SVG to `path`, atomically.
fn write_chart(chart: &Chart, path: &Path) -> pixelpie::Result<()> {
    pixelpie::io::write_atomic(path, |w| Ok(chart.write_svg(w)?))?;
    Ok(())
}

/// Writes `fit`'s pen file to `path`, atomically.
fn write_pens(fit: &calibrate::Fit, scan: &str, path: &Path) -> pixelpie::Result<()> {
    let text = calibrate::pen_toml(fit, scan)?;
    pixelpie::io::write_atomic(path, |w| Ok(std::io::Write::write_all(w, text.as_bytes())?))?;
    Ok(())
}
