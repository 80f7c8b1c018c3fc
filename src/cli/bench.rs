//! `pixelpie bench`: the paper's Table 1 (r = 8.5 px, batch N/2) with the GPU
//! and CPU backends side by side, pixel mode and exact mode, as a Markdown
//! table on stdout.

use anyhow::Result;
use clap::Args;

use pixelpie::backend::SharedGpu;
use pixelpie::gpu::S1Path;
use pixelpie::sampler::{self, Control, Params, SampleSet};

/// Arguments of `pixelpie bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Domain sides (default: 1024 to 10240 in steps of 1024, as in the paper).
    #[arg(long, value_delimiter = ',')]
    sizes: Vec<u32>,
    /// Disk radius in pixels.
    #[arg(long, default_value_t = 8.5)]
    radius: f32,
    /// Runs per row; the fastest is reported.
    #[arg(long, default_value_t = 3)]
    reps: u32,
    /// Skip the CPU backend.
    #[arg(long)]
    no_cpu: bool,
    /// Skip the GPU backend.
    #[arg(long)]
    no_gpu: bool,
    /// Skip exact mode (its GPU pixel pass with the CPU's refinement, and
    /// the CPU alone).
    #[arg(long)]
    no_exact: bool,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Instead of Table 1: the drawing's cost (`stipple` to SVG and PNG)
    /// beside uniform sampling of as many points, whole processes.
    #[arg(long)]
    stipple: bool,
    /// With --stipple: a 4-pen drawing (`--pens cmyk`) against the grey
    /// drawing of the same count, to SVG, whole processes run in turn.
    #[arg(long, requires = "stipple")]
    colour: bool,
    /// The picture for --stipple.
    #[arg(long, default_value = "assets/default.png", requires = "stipple")]
    image: std::path::PathBuf,
    /// Dot counts for --stipple.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "100000,1000000",
        requires = "stipple"
    )]
    points: Vec<usize>,
    /// With --stipple: the backend the drawings (and the uniform sampling
    /// beside them) sample on, in every process and in this one.
    #[arg(long, value_enum, default_value = "cpu", requires = "stipple")]
    backend: pixelpie::backend::BackendChoice,
}

fn best(reps: u32, mut run: impl FnMut() -> sampler::Result<SampleSet>) -> Result<SampleSet> {
    let mut best: Option<SampleSet> = None;
    for _ in 0..reps.max(1) {
        let s = run()?;
        if best
            .as_ref()
            .is_none_or(|b| s.stats.seconds < b.stats.seconds)
        {
            best = Some(s);
        }
    }
    best.ok_or_else(|| anyhow::anyhow!("no run"))
}

fn row(label: &str, side: u32, batch: u32, s: &SampleSet) {
    let st = &s.stats;
    let px = f64::from(side) * f64::from(side);
    println!(
        "| {label} | {side}² | {:.2}K | {:.2}K | {} | {:.1} | {:.1} | {:.1} | {} | {:.1} | {:.2}M | {:.1} | {} |",
        f64::from(batch) / 1e3,
        s.points.len() as f64 / 1e3,
        st.iterations,
        st.stages.get("throw") * 1e3,
        st.stages.get("cull") * 1e3,
        st.stages.get("compact") * 1e3,
        if st.exact {
            format!(
                "{:.1}",
                (st.stages.get("refine") + st.stages.get("repair")) * 1e3
            )
        } else {
            "–".into()
        },
        st.seconds * 1e3,
        s.points.len() as f64 / st.seconds / 1e6,
        st.bytes_per_pixel * px / (1 << 20) as f64,
        if st.maximal { "yes" } else { "no" },
    );
}

pub fn run(a: &BenchArgs) -> Result<()> {
    if a.stipple && a.colour {
        return super::bench_stipple::run_colour(&a.image, &a.points, a.reps, a.backend);
    }
    if a.stipple {
        return super::bench_stipple::run(&a.image, &a.points, a.reps, a.backend);
    }
    let gpu = if a.no_gpu {
        None
    } else {
        match SharedGpu::get() {
            Ok(g) => Some(g),
            Err(e) => {
                eprintln!("no usable GPU ({e}); CPU rows only");
                None
            }
        }
    };
    let sizes = if a.sizes.is_empty() {
        (1..=10).map(|i| i * 1024).collect()
    } else {
        a.sizes.clone()
    };
    println!(
        "r = {} px, batch N/2, best of {}; GPU: {}; CPU: {} threads\n",
        a.radius,
        a.reps,
        gpu.map_or("none", |g| g.adapter()),
        rayon::current_num_threads()
    );
    println!(
        "| backend | domain | batch | points | iter | S1 ms | S2 ms | PP ms | refine ms | total ms | rate (samples/s) | MB | maximal |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for side in sizes {
        let params = Params::new(side, side)
            .with_radius(a.radius)
            .with_seed(a.seed);
        let batch = params.plan()?.batch();
        if let Some(g) = gpu {
            for (label, path) in [
                ("GPU raster", S1Path::Raster),
                ("GPU compute", S1Path::Compute),
                ("GPU coalesced", S1Path::Coalesced),
            ] {
                match best(a.reps, || {
                    g.sample_on(&params, Some(path), Control::default())
                }) {
                    Ok(s) => row(label, side, batch, &s),
                    Err(e) => eprintln!("{label} {side}²: {e:#}"),
                }
            }
        }
        if !a.no_cpu {
            let s = best(a.reps, || sampler::cpu::sample(&params, Control::default()))?;
            row("CPU", side, batch, &s);
        }
        if a.no_exact {
            continue;
        }
        // Exact mode: on the GPU, S2 is throw and acceptance, PP the
        // coverage and scans, and "refine" the CPU's part after the pixel
        // pass.
        let exact = params.clone().with_exact(true);
        if let Some(g) = gpu {
            match best(a.reps, || g.sample_on(&exact, None, Control::default())) {
                Ok(s) => row("GPU exact", side, batch, &s),
                Err(e) => eprintln!("GPU exact {side}²: {e:#}"),
            }
        }
        if !a.no_cpu {
            let s = best(a.reps, || sampler::cpu::sample(&exact, Control::default()))?;
            row("CPU exact", side, batch, &s);
        }
    }
    Ok(())
}
