//! CPU benchmark at the paper's Table 1 setting (r = 8.5 px, batch N/2),
//! with the `fast_poisson` crate (Bridson's algorithm) in the same run.
//!
//! `cargo bench --bench sampler` prints a Markdown table. Set
//! `PIXELPIE_BENCH_SIZES=1024,2048` to choose the sides and
//! `PIXELPIE_BENCH_REPS` for the repetitions (the median is reported).

use std::time::Instant;

use fast_poisson::Poisson2D;
use pixelpie::sampler::{Control, Params, cpu};

const RADIUS: f32 = 8.5;

fn main() {
    let sizes: Vec<u32> = std::env::var("PIXELPIE_BENCH_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1024, 2048, 4096]);
    let reps: usize = std::env::var("PIXELPIE_BENCH_REPS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    println!(
        "CPU, {} threads, r = {RADIUS} px, batch N/2, median of {reps}\n",
        rayon::current_num_threads()
    );
    println!(
        "| domain | points | iter | S1 ms | S2 ms | PP ms | total ms | samples/s | maximal | fast_poisson points | fast_poisson ms | fast_poisson samples/s | speed-up |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for side in sizes {
        let params = Params::new(side, side).with_radius(RADIUS).with_seed(1);
        let mut runs: Vec<_> = (0..reps)
            .map(|_| cpu::sample(&params, Control::default()).expect("sampling"))
            .collect();
        runs.sort_by(|a, b| a.stats.seconds.total_cmp(&b.stats.seconds));
        let n = runs[reps / 2].points.len();
        let s = &runs[reps / 2].stats;
        let t = Instant::now();
        let bridson = Poisson2D::new()
            .with_dimensions([f64::from(side), f64::from(side)], f64::from(RADIUS))
            .with_seed(1)
            .generate();
        let fp = t.elapsed().as_secs_f64();
        let rate = n as f64 / s.seconds;
        let fp_rate = bridson.len() as f64 / fp;
        println!(
            "| {side}² | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2}M | {} | {} | {:.0} | {:.1}K | {:.0}× |",
            n,
            s.iterations,
            s.stages.get("throw") * 1e3,
            s.stages.get("cull") * 1e3,
            s.stages.get("compact") * 1e3,
            s.seconds * 1e3,
            rate / 1e6,
            s.maximal,
            bridson.len(),
            fp * 1e3,
            fp_rate / 1e3,
            rate / fp_rate,
        );
    }
}
