//! `pixelpie analyze`: quality measures of a point set as JSON, and plots.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;

use pixelpie::analyze::{self, CoverRadius, Domain, angles, plots, spectrum};
use pixelpie::io;

/// Arguments of `pixelpie analyze`.
#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// Points: a CSV (or whitespace-separated) file with x and y columns.
    points: PathBuf,
    /// Domain width in the points' units (pixels).
    #[arg(long)]
    width: f64,
    /// Domain height in the points' units (pixels).
    #[arg(long)]
    height: f64,
    /// Covering radius for `uncovered_pixels` and `density` [default: the
    /// file's radius column, if any].
    #[arg(long)]
    radius: Option<f64>,
    /// Distances wrap around the domain (a periodic set).
    #[arg(long)]
    periodic: bool,
    /// Write PNG plots into this directory (created if missing).
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Largest frequency K of the spectrum [default: 2.5 √N, 16..512]; the
    /// exact periodogram costs N·K² (100K points at K = 512: about 40 s on 2 cores).
    #[arg(long)]
    max_frequency: Option<usize>,
}

#[derive(Serialize)]
struct Output {
    #[serde(flatten)]
    report: analyze::Report,
    #[serde(skip_serializing_if = "Option::is_none")]
    spectrum: Option<spectrum::SpectrumSummary>,
    #[serde(skip_serializing_if = "Option::is_none")]
    plots: Option<Vec<PathBuf>>,
}

pub fn run(a: &AnalyzeArgs) -> Result<()> {
    let text = std::fs::read_to_string(&a.points)
        .with_context(|| format!("cannot read points '{}'", a.points.display()))?;
    let table = analyze::csv::parse(&text)
        .with_context(|| format!("cannot read points '{}'", a.points.display()))?;
    let domain = Domain {
        width: a.width,
        height: a.height,
        periodic: a.periodic,
    };
    let radius = match (a.radius, &table.radii) {
        (Some(r), _) if !(r.is_finite() && r > 0.0) => {
            anyhow::bail!("--radius {r} must be a positive number")
        }
        (Some(r), _) => Some(CoverRadius::Uniform(r)),
        (None, Some(r)) => Some(CoverRadius::PerPoint(r)),
        (None, None) => None,
    };
    let report = analyze::report(&table.points, domain, radius)?;
    let mut out = Output {
        report,
        spectrum: None,
        plots: None,
    };
    if let Some(dir) = &a.plots {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create plot directory '{}'", dir.display()))?;
        let k = a
            .max_frequency
            .unwrap_or_else(|| spectrum::default_max_frequency(table.points.len()));
        let p = spectrum::periodogram(&table.points, (a.width, a.height), k);
        let r = spectrum::radial(&p);
        out.spectrum = Some(spectrum::summary(&r));
        let hist = angles::histogram(&angles::delaunay_angles(&table.points), 360);
        let figures = [
            (
                "points.png",
                plots::points(&table.points, (a.width, a.height))?,
            ),
            ("periodogram.png", plots::periodogram(&p)?),
            ("radial_power.png", plots::radial_power(&r)?),
            ("anisotropy.png", plots::anisotropy(&r)?),
            ("angles.png", plots::angle_histogram(&hist)?),
        ];
        let mut written = Vec::new();
        for (name, img) in figures {
            let path = dir.join(name);
            io::write_atomic(&path, |w| Ok(plots::write_png(w, &img)?))?;
            written.push(path);
        }
        out.plots = Some(written);
    }
    let stdout = std::io::stdout();
    let mut lock = stdout.lock();
    serde_json::to_writer_pretty(&mut lock, &out).context("cannot write the report")?;
    use std::io::Write;
    writeln!(lock).context("cannot write the report")?;
    Ok(())
}
