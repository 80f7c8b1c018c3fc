//! The CPU reference backend: the paper's loop (Figure 3) with one module per
//! stage, [`throw`] (S1), [`cull`] and [`cover`] (S2), [`compact`] (PP), each
//! the mirror of the WGSL shader of the same name. Parallel with rayon and
//! deterministic for any number of threads.

pub mod compact;
pub mod cover;
pub mod cull;
pub mod throw;

use std::time::Instant;

use compact::EmptyList;

use super::{Control, Params, Progress, Result, SampleSet, Stats};
use throw::Dart;

/// Runs the sampler on the CPU.
///
/// ```
/// use pixelpie::sampler::{Params, Control, cpu};
/// let set = cpu::sample(&Params::new(64, 64).with_radius(4.0).with_seed(1), Control::default()).unwrap();
/// assert!(set.maximal && !set.points.is_empty());
/// ```
pub fn sample(params: &Params, ctl: Control<'_>) -> Result<SampleSet> {
    let start = Instant::now();
    let plan = params.plan()?;
    let pixels = plan.pixels();
    let mut coverage = cover::new_map(pixels);
    let mut empty = EmptyList::all(pixels, plan.width);
    let mut points = Vec::new();
    let mut stats = Stats {
        backend: "cpu".into(),
        device: format!("{} threads", rayon::current_num_threads()),
        ..Stats::default()
    };
    let map_bytes = plan.map.as_ref().map_or(0, |m| 4 * m.radii_fx().len());
    let mut peak_bytes = 0usize;
    let mut iteration = 0;
    // Buffers reused by every iteration.
    let (mut darts, mut survivors) = (Vec::new(), Vec::new());
    let mut grid = throw::DartGrid::default();
    let mut culler = cull::Culler::default();
    while !empty.is_empty() && iteration < plan.max_iterations {
        let t0 = Instant::now();
        throw::throw(
            &plan,
            iteration,
            plan.darts_for(empty.len()),
            &empty,
            &mut darts,
        );
        grid.rebuild(&plan, &darts);
        let t1 = Instant::now();
        culler.survivors(&plan, &darts, &grid, &mut survivors);
        cover::cover(&plan, &survivors, &mut coverage);
        let t2 = Instant::now();
        empty.compact(&coverage);
        let t3 = Instant::now();
        peak_bytes = peak_bytes.max(
            empty.bytes()
                + grid.bytes()
                + culler.bytes()
                + 16 * (darts.capacity() + survivors.capacity()),
        );
        stats.throw_seconds += (t1 - t0).as_secs_f64();
        stats.cull_seconds += (t2 - t1).as_secs_f64();
        stats.compact_seconds += (t3 - t2).as_secs_f64();
        points.extend(survivors.iter().map(Dart::point));
        iteration += 1;
        ctl.step(Progress {
            iteration,
            points: points.len(),
            empty_pixels: u64::from(empty.len()),
            pixels: u64::from(pixels),
        })?;
    }
    stats.seconds = start.elapsed().as_secs_f64();
    stats.bytes_per_pixel =
        (8 * coverage.len() + map_bytes + peak_bytes) as f64 / f64::from(pixels.max(1));
    Ok(SampleSet::finish(
        (plan.width, plan.height),
        points,
        iteration,
        empty.is_empty(),
        stats,
    ))
}
