//! `pixelpie bench --stipple`: what a drawing costs beside the sampling of
//! as many uniform points, in the same run. For each dot count: the whole
//! `stipple` process to SVG and to PNG, and `sample` of uniform points on
//! the same domain (a radius predicted to give the count, one run) to CSV,
//! each run as a child process `reps` times (median wall time, largest
//! peak memory), and the SVG drawing's stages timed in this process.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use pixelpie::backend::BackendChoice;
use pixelpie::importance::ink;
use pixelpie::job::{Job, Stage, default_domain};
use pixelpie::sampler::RSA_DENSITY;

/// The environment variable that makes `pixelpie` print its peak memory
/// (`peak-rss-kb: N`, from /proc/self/status) on stderr as it exits.
pub const PEAK_ENV: &str = "PIXELPIE_PRINT_PEAK";

/// Prints the process's peak resident memory when [`PEAK_ENV`] is set.
pub fn print_peak() {
    if std::env::var_os(PEAK_ENV).is_none() {
        return;
    }
    if let Ok(status) = std::fs::read_to_string("/proc/self/status")
        && let Some(kb) = status
            .lines()
            .find_map(|l| l.strip_prefix("VmHWM:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
    {
        eprintln!("peak-rss-kb: {kb}");
    }
}

/// One child run: wall seconds and peak memory (MB, 0 where unknown).
fn child(args: &[&str]) -> Result<(f64, f64)> {
    let exe = std::env::current_exe()?;
    let t = Instant::now();
    let out = Command::new(exe)
        .args(args)
        .env(PEAK_ENV, "1")
        .output()
        .context("running pixelpie")?;
    let secs = t.elapsed().as_secs_f64();
    let err = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        bail!("pixelpie {}: {}", args.join(" "), err.trim());
    }
    let peak = err
        .lines()
        .find_map(|l| l.strip_prefix("peak-rss-kb: "))
        .and_then(|v| v.trim().parse::<f64>().ok())
        .map_or(0.0, |kb| kb / 1024.0);
    Ok((secs, peak))
}

/// Median seconds and largest peak over `reps` runs of `args`.
fn measure(reps: u32, args: &[&str]) -> Result<(f64, f64)> {
    let mut runs = Vec::new();
    for _ in 0..reps.max(1) {
        runs.push(child(args)?);
    }
    let mut secs: Vec<f64> = runs.iter().map(|r| r.0).collect();
    secs.sort_by(f64::total_cmp);
    let peak = runs.iter().map(|r| r.1).fold(0.0, f64::max);
    Ok((secs[secs.len() / 2], peak))
}

/// The uniform radius whose maximal set on `domain` holds about `n` points
/// (the RSA density corrected by the pixel-mode density, as the count fit).
fn uniform_radius(domain: (u32, u32), n: usize) -> f64 {
    let area = f64::from(domain.0) * f64::from(domain.1);
    let mut r = (area * RSA_DENSITY * 4.0 / (std::f64::consts::PI * n as f64)).sqrt();
    for _ in 0..8 {
        r = (area * RSA_DENSITY * ink::density(r) * 4.0 / (std::f64::consts::PI * n as f64)).sqrt();
    }
    r
}

/// `--backend`'s value for `choice`.
fn choice_arg(choice: BackendChoice) -> &'static str {
    match choice {
        BackendChoice::Auto => "auto",
        BackendChoice::Cpu => "cpu",
        BackendChoice::Gpu => "gpu",
    }
}

/// The backend in the table's heading.
fn backend_name(choice: BackendChoice) -> &'static str {
    match choice {
        BackendChoice::Auto => "backend auto",
        BackendChoice::Cpu => "CPU backend",
        BackendChoice::Gpu => "GPU backend",
    }
}

/// Samples `params` on `choice` in this process (the stages' timings).
fn sample(
    params: &pixelpie::sampler::Params,
    choice: BackendChoice,
) -> pixelpie::Result<pixelpie::sampler::SampleSet> {
    Ok(pixelpie::backend::sample(
        params,
        choice,
        Default::default(),
        &mut |_| {},
    )?)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap_or_default()
}

/// Runs the drawing benchmark on `image` for each of `counts` and prints
/// its table.
pub fn run(image: &Path, counts: &[usize], reps: u32, backend: BackendChoice) -> Result<()> {
    let dir = tempfile::tempdir()?;
    let (svg, png, csv): (PathBuf, PathBuf, PathBuf) = (
        dir.path().join("d.svg"),
        dir.path().join("d.png"),
        dir.path().join("u.csv"),
    );
    let (iw, ih) = image::image_dimensions(image)
        .with_context(|| format!("cannot read '{}'", image.display()))?;
    println!(
        "{} ({iw}×{ih}), {} ({} CPU threads), whole processes, median of {reps}; \
         uniform: the same domain and count, one run\n",
        image.display(),
        backend_name(backend),
        rayon::current_num_threads()
    );
    println!(
        "| dots | domain | uniform CSV s | SVG s | SVG ÷ uniform | PNG s | PNG ÷ uniform | peak MB (uniform / SVG / PNG) | SVG stages: load, fit+sample, dots+write s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &n in counts {
        let domain = default_domain(iw, ih, n);
        let r = format!("{:.4}", uniform_radius(domain, n));
        let (w, h) = (domain.0.to_string(), domain.1.to_string());
        let points = n.to_string();
        let img = s(image);
        let uniform = measure(
            reps,
            &[
                "sample",
                "--width",
                &w,
                "--height",
                &h,
                "--radius",
                &r,
                "-o",
                s(&csv),
                "--backend",
                choice_arg(backend),
                "-q",
            ],
        )?;
        let stipple = |out: &Path| {
            measure(
                reps,
                &[
                    "stipple",
                    img,
                    "-o",
                    s(out),
                    "--points",
                    &points,
                    "--backend",
                    choice_arg(backend),
                    "-q",
                ],
            )
        };
        let svg_t = stipple(&svg)?;
        let png_t = stipple(&png)?;
        // The stages, in this process.
        let mut job = Job::default();
        job.points = Some(n);
        let t = Instant::now();
        let drawing = job.run(image, |p| sample(p, backend), |_| true)?;
        let t_run = t.elapsed().as_secs_f64();
        job.write(&drawing, &svg)?;
        let t_write = t.elapsed().as_secs_f64() - t_run;
        let (load, sample) = (
            drawing.seconds(Stage::Prepare),
            drawing.seconds(Stage::Sample),
        );
        println!(
            "| {:.0}K | {}×{} | {:.2} | {:.2} | **{:.2}** | {:.2} | **{:.2}** | {:.0} / {:.0} / {:.0} | {load:.2}, {sample:.2}, {:.2} |",
            drawing.dots.len() as f64 / 1e3,
            domain.0,
            domain.1,
            uniform.0,
            svg_t.0,
            svg_t.0 / uniform.0,
            png_t.0,
            png_t.0 / uniform.0,
            uniform.1,
            svg_t.1,
            png_t.1,
            t_run - load - sample + t_write,
        );
    }
    Ok(())
}

/// Runs the colour benchmark on `image` for each of `counts`: the 4-pen
/// drawing (`--pens cmyk`) and the grey one of the same count to SVG, whole
/// processes run in turn `reps` times (the median of the pairs' ratios,
/// the largest peaks), and the colour run's stages timed in this process.
pub fn run_colour(image: &Path, counts: &[usize], reps: u32, backend: BackendChoice) -> Result<()> {
    let dir = tempfile::tempdir()?;
    let svg = dir.path().join("d.svg");
    println!(
        "{}, {} ({} CPU threads), whole processes to SVG, run in turn, median of {reps}\n",
        image.display(),
        backend_name(backend),
        rayon::current_num_threads()
    );
    println!(
        "| dots | grey s | cmyk s | cmyk ÷ grey | peak MB (grey / cmyk) | cmyk stages s: prepare, sample, order, size |"
    );
    println!("|---|---|---|---|---|---|");
    for &n in counts {
        let points = n.to_string();
        let args = |pens: bool| {
            let mut v = vec![
                "stipple",
                s(image),
                "-o",
                s(&svg),
                "--points",
                &points,
                "--backend",
                choice_arg(backend),
                "-q",
            ];
            if pens {
                v.extend(["--pens", "cmyk"]);
            }
            v
        };
        let (mut grey, mut colour, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..reps.max(1) {
            let g = child(&args(false))?;
            let c = child(&args(true))?;
            ratios.push(c.0 / g.0);
            grey.push(g);
            colour.push(c);
        }
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let peak = |v: &[(f64, f64)]| v.iter().map(|r| r.1).fold(0.0, f64::max);
        let mut job = Job::default();
        job.points = Some(n);
        job.pens = Some(pixelpie::colour::PenSet::cmyk());
        let drawing = job.run(image, |p| sample(p, backend), |_| true)?;
        println!(
            "| {:.0}K | {:.2} | {:.2} | **{:.2}** | {:.0} / {:.0} | {:.2}, {:.2}, {:.2}, {:.2} |",
            drawing.dots.len() as f64 / 1e3,
            median(grey.iter().map(|r| r.0).collect()),
            median(colour.iter().map(|r| r.0).collect()),
            median(ratios),
            peak(&grey),
            peak(&colour),
            drawing.seconds(Stage::Prepare),
            drawing.seconds(Stage::Sample),
            drawing.seconds(Stage::Order),
            drawing.seconds(Stage::Size),
        );
    }
    Ok(())
}
