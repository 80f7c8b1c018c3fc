//! The guarantee table of the README: what each sampler promises, measured
//! by the same independent checks in one run.
//!
//! For the pixel mode, the exact mode, `fast_poisson` (Bridson) and the
//! `poisson` crate (Ebeida et al. 2011, as published), on a
//! bounded 1024² domain at r = 8.5 px and on a 1024² torus (ours only):
//! the closest pair, the largest empty circle (Delaunay, boundary mirrored
//! or wrapped), the coverage density N·π(r/2)²/A, whether the disks cover
//! the domain in the continuous sense, and the samples per second at 4096²
//! (median of 3), with the ratio to the pixel mode.
//!
//! `cargo run --release --example guarantees`

use std::time::Instant;

use fast_poisson::Poisson2D;
use pixelpie::analyze::{CoverRadius, Domain, gaps, metrics};
use pixelpie::sampler::{Control, Params, cpu};

const R: f64 = 8.5;

/// A sampler of the table: periodic or not, to points.
type Sampler<'a> = dyn Fn(bool) -> Vec<[f64; 2]> + 'a;

fn ours(side: u32, exact: bool, periodic: bool) -> Vec<[f64; 2]> {
    let p = Params::new(side, side)
        .with_radius(R as f32)
        .with_seed(1)
        .with_periodic(periodic)
        .with_exact(exact);
    let set = cpu::sample(&p, Control::default()).expect("sample");
    set.points
        .iter()
        .map(|q| [f64::from(q.x), f64::from(q.y)])
        .collect()
}

fn bridson(side: u32) -> Vec<[f64; 2]> {
    Poisson2D::new()
        .with_dimensions([f64::from(side), f64::from(side)], R)
        .with_seed(1)
        .generate()
}

/// The `poisson` crate: its radius is half the minimum distance, in the unit
/// square.
fn ebeida(side: u32) -> Vec<[f64; 2]> {
    use nalgebra017 as na;
    use poisson::{Builder, Type, algorithm};
    use rand06::{SeedableRng, rngs::SmallRng};
    let s = f64::from(side);
    Builder::<_, na::Vector2<f64>>::with_radius(R / (2.0 * s), Type::Normal)
        .build(SmallRng::seed_from_u64(1), algorithm::Ebeida)
        .into_iter()
        .map(|p| [p.x * s, p.y * s])
        .collect()
}

fn rate(f: &dyn Fn() -> usize) -> f64 {
    let mut runs: Vec<f64> = (0..3)
        .map(|_| {
            let t = Instant::now();
            let n = f();
            n as f64 / t.elapsed().as_secs_f64()
        })
        .collect();
    runs.sort_by(f64::total_cmp);
    runs[1]
}

fn main() {
    let side = 1024u32;
    println!(
        "| sampler | domain | points | closest pair | largest gap | density | maximal (continuous) | samples/s at 4096² | vs pixel mode |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let pixel_rate = rate(&|| ours(4096, false, false).len());
    let rows: [(&str, bool, &Sampler<'_>, f64); 4] = [
        (
            "PixelPie pixel mode",
            true,
            &|p| ours(side, false, p),
            pixel_rate,
        ),
        (
            "PixelPie `--exact`",
            true,
            &|p| ours(side, true, p),
            rate(&|| ours(4096, true, false).len()),
        ),
        (
            "fast_poisson 1.0 (Bridson)",
            false,
            &|_| bridson(side),
            rate(&|| bridson(4096).len()),
        ),
        (
            "poisson 0.10 (Ebeida)",
            false,
            &|_| ebeida(side),
            rate(&|| ebeida(4096).len()),
        ),
    ];
    for (name, has_periodic, make, speed) in rows {
        for periodic in [false, true] {
            if periodic && !has_periodic {
                continue;
            }
            let pts = make(periodic);
            let d = Domain {
                width: f64::from(side),
                height: f64::from(side),
                periodic,
            };
            let closest = metrics::min_distance(&pts, d).unwrap_or(f64::NAN);
            let gap = gaps::largest_gap(&pts, d).map_or(f64::NAN, |g| g.radius);
            let density = pts.len() as f64 * std::f64::consts::PI * (R / 2.0).powi(2) / d.area();
            let maximal =
                gaps::uncovered_cells(&pts, CoverRadius::Uniform(R), d).expect("cells") == 0;
            println!(
                "| {name} | {side}² {} | {} | {closest:.4} | {gap:.4} | {density:.4} | {} | {:.2}M | {:.2}× |",
                if periodic { "torus" } else { "bounded" },
                pts.len(),
                if maximal { "yes" } else { "no" },
                speed / 1e6,
                speed / pixel_rate
            );
        }
    }
}
