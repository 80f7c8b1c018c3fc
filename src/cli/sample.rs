//! `pixelpie sample`: headless export of maximal Poisson-disk point sets.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use pixelpie::backend::{self, BackendChoice, Notice};
use pixelpie::gpu::S1Path;
use pixelpie::io;
use pixelpie::job::SampleJob;
use pixelpie::sampler::{self, Control, Params, Progress, SampleSet};

/// Arguments of `pixelpie sample`: the library's point-set job, where the
/// points go, and how the run goes.
#[derive(Args, Debug, Serialize)]
pub struct SampleArgs {
    #[command(flatten)]
    #[serde(flatten)]
    job: SampleJob,
    /// Output file: .csv or .json.
    #[arg(long, short)]
    output: PathBuf,
    /// Statistics as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    #[command(flatten)]
    #[serde(flatten)]
    run: RunArgs,
}

/// How a run goes, for `sample` and `stipple`: the backend, and what is
/// reported on stderr.
#[derive(Args, Debug, Serialize)]
pub struct RunArgs {
    /// Backend.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto)]
    pub backend: BackendChoice,
    /// How the GPU rasterizes darts (S1): by measurement, the depth-tested
    /// draw, or the compute pass.
    #[arg(long, value_enum, default_value_t = GpuPath::Auto)]
    pub gpu_path: GpuPath,
    /// No progress bar and no report on stderr.
    #[arg(long, short)]
    pub quiet: bool,
    /// Print the backend, adapter, radii and timings on stderr.
    #[arg(long, short)]
    pub verbose: bool,
    /// The memory a picture may take (4G, 512M, …): a picture whose
    /// drawing would need more, said from its header, is refused before
    /// it is decoded [default: 4G, or half the machine's memory when less]
    #[arg(long, value_name = "SIZE", value_parser = pixelpie::importance::budget::parse_size)]
    pub max_memory: Option<u64>,
}

impl RunArgs {
    /// Makes the process's GPU use the chosen S1 path.
    pub fn apply_gpu_path(&self) {
        if self.backend != BackendChoice::Cpu && self.gpu_path != GpuPath::Auto {
            self.gpu_path.apply();
        }
    }
}

/// The GPU's S1 path on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GpuPath {
    /// The faster on this adapter (measured once).
    Auto,
    /// An instanced depth-only draw (the paper's way).
    Raster,
    /// A compute pass with atomicMax, a thread per row of a disk.
    Compute,
    /// The compute pass with a warp's lanes along one disk's rows.
    Coalesced,
}

impl GpuPath {
    /// Makes the process's GPU use this path.
    pub fn apply(self) {
        let path = match self {
            Self::Auto => None,
            Self::Raster => Some(S1Path::Raster),
            Self::Compute => Some(S1Path::Compute),
            Self::Coalesced => Some(S1Path::Coalesced),
        };
        if let Ok(gpu) = backend::SharedGpu::get() {
            gpu.set_preferred_path(path);
        }
    }
}

/// Checks that a JSON side output has the right extension.
pub fn check_json_path(path: &Path) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()) != Some("json") {
        bail!("statistics file '{}' must end in .json", path.display());
    }
    Ok(())
}

/// A progress bar on stderr, hidden when quiet or not a terminal.
pub fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(100);
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {percent}% covered ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// [`progress_bar`] for the sampler's run: its spinner and clock move
/// between the sampler's iterations too (a large map's setup takes
/// seconds).
pub fn sampling_bar(quiet: bool) -> ProgressBar {
    let bar = progress_bar(quiet);
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    bar
}

/// Runs the sampler with a progress bar, on the chosen backend.
pub fn run_with_progress(
    params: &Params,
    choice: BackendChoice,
    bar: &ProgressBar,
    verbose: bool,
) -> sampler::Result<SampleSet> {
    let progress = |p: Progress| {
        bar.set_position(100 - 100 * p.empty_pixels / p.pixels.max(1));
        bar.set_message(format!("iteration {}, {} points", p.iteration, p.points));
    };
    let ctl = Control::new().with_progress(&progress);
    let set = backend::sample(params, choice, ctl, &mut |n| {
        let show = match n {
            // Sampling on the CPU is the normal course without a GPU: a
            // working run prints nothing unless asked.
            Notice::Adapter(_) | Notice::Fallback(_) => verbose,
        };
        if show {
            bar.suspend(|| eprintln!("{n}"));
        }
    })?;
    if verbose {
        eprintln!(
            "backend: {} ({}), {} points in {} iterations, {:.3} s",
            set.stats.backend,
            set.stats.device,
            set.points.len(),
            set.stats.iterations,
            set.stats.seconds
        );
    }
    Ok(set)
}

pub fn run(a: &SampleArgs) -> Result<()> {
    pixelpie::importance::budget::set_max_memory(a.run.max_memory);
    io::PointFormat::from_path(&a.output)?;
    if let Some(s) = &a.stats {
        check_json_path(s)?;
    }
    let _gpu = backend::open_early(a.run.backend);
    a.run.apply_gpu_path();
    let job = &a.job;
    let radii = match job.radii() {
        Err(e) => {
            return Err(match &job.radius_map {
                Some(path) => {
                    anyhow::Error::new(e).context(format!("radius map '{}'", path.display()))
                }
                None => e.into(),
            });
        }
        Ok(r) => r,
    };
    let bar = sampling_bar(a.run.quiet);
    let done = job.run(&radii, |p| {
        Ok(run_with_progress(p, a.run.backend, &bar, a.run.verbose)?)
    });
    let done = match (&job.radius_map, done) {
        (Some(path), Err(e)) => {
            return Err(anyhow::Error::new(e).context(format!("radius map '{}'", path.display())));
        }
        (_, done) => done?,
    };
    bar.finish_and_clear();
    let got = done.set.points.len();
    if let (Some(n), true) = (job.points, a.run.verbose) {
        eprintln!("count target {n}: {got} points after {} runs", done.runs);
    }
    if let Some(n) = done.short_of
        && !a.run.quiet
    {
        eprintln!("warning: {}", super::said(pixelpie::job::short_of(n, got)));
    }
    write_outputs(a, &done.set)
}

/// Writes the points, the statistics and the warning of a capped run.
fn write_outputs(a: &SampleArgs, set: &SampleSet) -> Result<()> {
    io::write_points(&a.output, set, a)?;
    if let Some(path) = &a.stats {
        io::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &set.report())?;
            writeln!(w)?;
            Ok(())
        })?;
    }
    if let Some(w) = pixelpie::job::not_maximal(set, a.job.max_iterations)
        && !a.run.quiet
    {
        eprintln!("warning: {}", super::said(w));
    }
    Ok(())
}
