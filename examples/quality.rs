//! Reproduces the paper's quality section (§4.2–4.3, Figures 7, 9 and 10):
//! 1024² domain, radius 8.5 px (the paper's r = 0.0083, N ≈ 10K), darts at
//! pixel centres (`subpixel_bits` 0) against sub-pixel darts, and against
//! continuous dart throwing as an exact, unbiased reference.
//!
//! ```text
//! cargo run --release --example quality -- [OUT_DIR] [SETS]
//! ```
//!
//! For each configuration it samples SETS sets (seeds 0…SETS−1, default 10,
//! as PSA averages 10), prints the mean angle-histogram std and ρ, averages
//! the periodograms, and writes the plots of `pixelpie analyze` into
//! OUT_DIR/<config>/ (default `docs/quality`) and the numbers into
//! OUT_DIR/results.json. The CPU backend is used: the GPU gives the same points.

use std::path::{Path, PathBuf};

use anyhow::Result;
use pixelpie::analyze::{self, Domain, angles, plots, spectrum};
use pixelpie::io::write_atomic;
use pixelpie::sampler::{Params, cpu};
use serde::Serialize;

const SIDE: u32 = 1024;
const RADIUS: f32 = 8.5;

/// splitmix64: the reference sampler's random numbers.
struct SplitMix(u64);

impl SplitMix {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Continuous dart throwing (random sequential adsorption) with exact
/// distances: darts uniform in the domain, kept when no kept point is
/// closer than `r`. `darts_per_point` × the expected count darts bring it
/// close to saturation; it is unbiased in angle, but not exactly maximal.
fn continuous_rsa(side: f64, r: f64, darts_per_point: f64, seed: u64) -> Vec<[f64; 2]> {
    let mut rng = SplitMix(seed ^ 0x5EED);
    // Cells of side r/√2 hold at most one point; neighbours lie within 2 cells.
    let cell = r / std::f64::consts::SQRT_2;
    let n = (side / cell).ceil() as usize;
    let mut grid: Vec<Option<[f64; 2]>> = vec![None; n * n];
    let expected = 0.547 * side * side / (std::f64::consts::PI * r * r / 4.0);
    let mut out = Vec::new();
    for _ in 0..(darts_per_point * expected) as usize {
        let p = [rng.next_f64() * side, rng.next_f64() * side];
        let (cx, cy) = ((p[0] / cell) as usize, (p[1] / cell) as usize);
        if grid[cy * n + cx].is_some() {
            continue;
        }
        let mut free = true;
        'check: for y in cy.saturating_sub(2)..(cy + 3).min(n) {
            for x in cx.saturating_sub(2)..(cx + 3).min(n) {
                if let Some(q) = grid[y * n + x]
                    && (p[0] - q[0]).hypot(p[1] - q[1]) < r
                {
                    free = false;
                    break 'check;
                }
            }
        }
        if free {
            grid[cy * n + cx] = Some(p);
            out.push(p);
        }
    }
    out
}

fn pixelpie(bits: u32, seed: u64) -> Result<Vec<[f64; 2]>> {
    let params = Params::new(SIDE, SIDE)
        .with_radius(RADIUS)
        .with_subpixel_bits(bits)
        .with_seed(seed);
    let set = cpu::sample(&params, Default::default())?;
    anyhow::ensure!(set.maximal(), "not maximal");
    Ok(set
        .points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect())
}

#[derive(Serialize)]
struct ConfigResult {
    name: String,
    description: String,
    sets: usize,
    mean_count: f64,
    mean_rho: f64,
    mean_density: f64,
    angle_std_mean: f64,
    angle_std_sd: f64,
    /// sqrt(mean bin count): the std of independent, isotropic edges.
    angle_std_poisson: f64,
    spectrum: spectrum::SpectrumSummary,
    plots: Vec<PathBuf>,
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

fn write_png(path: &Path, img: &image::RgbImage) -> Result<()> {
    Ok(write_atomic(path, |w| Ok(plots::write_png(w, img)?))?)
}

fn run_config(
    out: &Path,
    name: &str,
    description: &str,
    sets: usize,
    with_plots: bool,
    make: &dyn Fn(u64) -> Result<Vec<[f64; 2]>>,
) -> Result<ConfigResult> {
    let side = f64::from(SIDE);
    let domain = Domain {
        width: side,
        height: side,
        periodic: false,
    };
    let (mut counts, mut rhos, mut stds, mut poisson, mut dens) =
        (vec![], vec![], vec![], vec![], vec![]);
    let mut periodograms = Vec::new();
    let mut first: Option<Vec<[f64; 2]>> = None;
    let k = spectrum::default_max_frequency(10_000);
    for seed in 0..sets as u64 {
        let pts = make(seed)?;
        let r = analyze::report(
            &pts,
            domain,
            Some(analyze::CoverRadius::Uniform(f64::from(RADIUS))),
        )?;
        counts.push(r.count as f64);
        rhos.push(r.rho.unwrap_or(f64::NAN));
        stds.push(r.angle_std.unwrap_or(f64::NAN));
        dens.push(r.density.unwrap_or(f64::NAN));
        poisson.push((2.0 * r.angle_edges as f64 / 360.0).sqrt());
        periodograms.push(spectrum::periodogram(&pts, (side, side), k));
        first.get_or_insert(pts);
        eprint!(".");
    }
    eprintln!(" {name}");
    let mean = spectrum::average(&periodograms).ok_or_else(|| anyhow::anyhow!("no sets"))?;
    let radial = spectrum::radial(&mean);
    let (angle_std_mean, angle_std_sd) = mean_sd(&stds);
    let mut result = ConfigResult {
        name: name.into(),
        description: description.into(),
        sets,
        mean_count: mean_sd(&counts).0,
        mean_rho: mean_sd(&rhos).0,
        mean_density: mean_sd(&dens).0,
        angle_std_mean,
        angle_std_sd,
        angle_std_poisson: mean_sd(&poisson).0,
        spectrum: spectrum::summary(&radial),
        plots: Vec::new(),
    };
    if !with_plots {
        return Ok(result);
    }
    let dir = out.join(name);
    std::fs::create_dir_all(&dir)?;
    let pts = first.unwrap_or_default();
    // The points plot shows a 256² corner, as the paper's figures zoom in.
    let corner: Vec<[f64; 2]> = pts
        .iter()
        .copied()
        .filter(|p| p[0] < 256.0 && p[1] < 256.0)
        .collect();
    let figures = [
        ("points.png", plots::points(&corner, (256.0, 256.0))?),
        ("periodogram.png", plots::periodogram(&mean)?),
        ("radial_power.png", plots::radial_power(&radial)?),
        ("anisotropy.png", plots::anisotropy(&radial)?),
        (
            "angles.png",
            plots::angle_histogram(&angles::histogram(&angles::delaunay_angles(&pts), 360))?,
        ),
    ];
    for (file, img) in figures {
        let path = dir.join(file);
        write_png(&path, &img)?;
        result.plots.push(path);
    }
    Ok(result)
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "docs/quality".into()));
    let sets: usize = args.next().map_or(Ok(10), |s| s.parse())?;
    let mut results = Vec::new();
    for bits in [0u32, 1, 2, 3, 7] {
        let name = format!("bits{bits}");
        let desc = format!(
            "PixelPie, {0}×{0} dart positions per pixel (--subpixel-bits {bits})",
            1 << bits
        );
        // Plots for the paper's two cases; numbers for all.
        let with_plots = bits == 0 || bits == 3;
        results.push(run_config(&out, &name, &desc, sets, with_plots, &|seed| {
            pixelpie(bits, seed)
        })?);
    }
    results.push(run_config(
        &out,
        "continuous",
        "continuous dart throwing, exact distances (200 darts per point)",
        sets,
        true,
        &|seed| {
            Ok(continuous_rsa(
                f64::from(SIDE),
                f64::from(RADIUS),
                200.0,
                seed,
            ))
        },
    )?);
    println!(
        "| configuration | N | ρ | density | angle std | Poisson std | RAPS peak (f, P) | anisotropy |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for r in &results {
        println!(
            "| {} | {:.0} | {:.3} | {:.3} | {:.1} ± {:.1} | {:.1} | {:.0}, {:.2} | {:.1} dB |",
            r.description,
            r.mean_count,
            r.mean_rho,
            r.mean_density,
            r.angle_std_mean,
            r.angle_std_sd,
            r.angle_std_poisson,
            r.spectrum.peak_frequency,
            r.spectrum.peak_power,
            r.spectrum.mean_anisotropy_db
        );
    }
    let json = out.join("results.json");
    write_atomic(&json, |w| {
        serde_json::to_writer_pretty(&mut *w, &results)?;
        writeln!(w)?;
        Ok(())
    })?;
    Ok(())
}
