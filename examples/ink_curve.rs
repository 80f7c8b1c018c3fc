//! Measures the tone-reproduction curve of the stipple drawings and writes it
//! as `src/importance/ink_table.rs`.
//!
//! ```text
//! cargo run --release --example ink_curve > src/importance/ink_table.rs
//! ```
//!
//! For each sample radius r of [`RADII`] it samples maximal sets of that
//! radius with the project's sampler (periodic domain, default sub-pixel
//! darts), and measures the ink of dots of radius t·r drawn on them: the
//! fraction of the domain within t·r of a sample, the area of the union of
//! the dots. That is the contact distribution of the set, measured on a fine
//! jittered lattice of probe points (r/12 apart) for every t at once. The
//! ink depends on t alone up to the pixel-resolution slack of the sampler,
//! which matters at small r; hence one curve per radius.

use pixelpie::sampler::{Control, Params, cpu};

/// The sample radii measured, in pixels.
const RADII: [f64; 11] = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0];
/// Steps of t = dot radius / sample radius.
const T_STEPS: usize = 61;
/// The t step.
const T_STEP: f64 = 0.02;
/// Probe points wanted per radius.
const PROBES: f64 = 6.0e6;

fn main() -> anyhow::Result<()> {
    println!("//! The measured tone-reproduction curve: written by");
    println!("//! `cargo run --release --example ink_curve`; do not edit by hand.");
    println!("//!");
    println!("//! `INK[i][j]` is the ink (area fraction of the paper under dots) of");
    println!("//! dots of radius `j · T_STEP · r` on a maximal set of radius");
    println!("//! `r = RADII[i]` px, sampled with the default sub-pixel darts.");
    println!();
    println!("/// Sample radii of the rows, in pixels.");
    println!("pub const RADII: [f64; {}] = {RADII:?};", RADII.len());
    println!("/// The step of t = dot radius / sample radius between columns.");
    println!("pub const T_STEP: f64 = {T_STEP:?};");
    println!("/// Ink per radius (rows) and t (columns).");
    println!("pub const INK: [[f64; {T_STEPS}]; {}] = [", RADII.len());
    for &r in &RADII {
        let side = (48.0 * r).round().clamp(256.0, 1536.0) as u32;
        let h = r / 12.0;
        let per_set = (f64::from(side) / h).powi(2);
        let sets = (PROBES / per_set).ceil().max(1.0) as u64;
        let mut hist = vec![0u64; T_STEPS];
        let mut total = 0u64;
        let mut points = 0usize;
        for seed in 0..sets {
            let params = Params::new(side, side)
                .with_radius(r as f32)
                .with_periodic(true)
                .with_seed(1000 + seed);
            let set = cpu::sample(&params, Control::default())?;
            points += set.points.len();
            let xy: Vec<[f64; 2]> = set
                .points
                .iter()
                .map(|p| [f64::from(p.x), f64::from(p.y)])
                .collect();
            total += contact(&xy, f64::from(side), r, h, seed, &mut hist);
        }
        let mut cum = 0u64;
        let row: Vec<String> = hist
            .iter()
            .map(|&c| {
                cum += c;
                format!("{:.5}", cum as f64 / total as f64)
            })
            .collect();
        eprintln!(
            "r = {r}: {sets} sets of {side}², {points} points, coverage density {:.4}",
            points as f64 * std::f64::consts::PI * r * r
                / 4.0
                / f64::from(side).powi(2)
                / sets as f64
        );
        println!("    // r = {r} px");
        println!("    [{}],", row.join(", "));
    }
    println!("];");
    Ok(())
}

/// Adds to `hist[j]` the probes whose nearest sample lies in
/// [(j−1)·T_STEP·r, j·T_STEP·r) (j = 0: exactly on a sample), on a lattice
/// of spacing `h` jittered per probe; returns the number of probes.
fn contact(xy: &[[f64; 2]], side: f64, r: f64, h: f64, seed: u64, hist: &mut [u64]) -> u64 {
    let reach = T_STEP * (T_STEPS - 1) as f64 * r;
    let cells = ((side / reach).floor() as usize).max(1);
    let cell = side / cells as f64;
    let mut grid = vec![Vec::new(); cells * cells];
    for p in xy {
        let cx = ((p[0] / cell) as usize).min(cells - 1);
        let cy = ((p[1] / cell) as usize).min(cells - 1);
        grid[cy * cells + cx].push(*p);
    }
    let n = (side / h).floor() as u64;
    let mut probes = 0;
    for iy in 0..n {
        for ix in 0..n {
            let k = hash(seed, iy * n + ix);
            let jx = (k & 0xffff) as f64 / 65536.0;
            let jy = (k >> 16 & 0xffff) as f64 / 65536.0;
            let (x, y) = ((ix as f64 + jx) * h, (iy as f64 + jy) * h);
            let d = nearest(&grid, cells, cell, side, x, y);
            probes += 1;
            let j = (d / (T_STEP * r)).ceil();
            if j < T_STEPS as f64 {
                hist[j as usize] += 1;
            }
        }
    }
    probes
}

/// The distance from (x, y) to the nearest point in the 3×3 cells around it,
/// on the torus (infinite if none).
fn nearest(grid: &[Vec<[f64; 2]>], cells: usize, cell: f64, side: f64, x: f64, y: f64) -> f64 {
    let cx = ((x / cell) as usize).min(cells - 1) as isize;
    let cy = ((y / cell) as usize).min(cells - 1) as isize;
    let n = cells as isize;
    let mut best = f64::INFINITY;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let c = ((cy + dy).rem_euclid(n) * n + (cx + dx).rem_euclid(n)) as usize;
            for p in &grid[c] {
                let mut ddx = (p[0] - x).abs();
                let mut ddy = (p[1] - y).abs();
                ddx = ddx.min(side - ddx);
                ddy = ddy.min(side - ddy);
                best = best.min(ddx * ddx + ddy * ddy);
            }
        }
    }
    best.sqrt()
}

/// splitmix64 of (seed, i): the probes' jitter.
fn hash(seed: u64, i: u64) -> u64 {
    let mut z = seed
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(i)
        .wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
