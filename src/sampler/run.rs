//! The sampler's loop (paper Figure 3), written once for every backend.
//!
//! A backend implements [`Stepper`]: one iteration of throw, cull, cover and
//! compact, returning the survivors and the stage timings ([`Step`]). [`run`]
//! drives it: it sizes each batch, checks cancellation before every
//! iteration, reports progress after it, gathers the points and the timings,
//! and finishes the [`SampleSet`].

use std::time::Instant;

use super::fixed;
use super::{Control, Plan, Point, Progress, Result, SampleSet, Stats};

/// One dart, or one accepted sample, in the contract's fixed point. Mirrors
/// `struct Dart` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Dart {
    /// x in 1/256 px.
    pub x: u32,
    /// y in 1/256 px.
    pub y: u32,
    /// The index of the dart's pixel, `y * width + x`.
    pub pixel: u32,
    /// The radius at the dart's pixel, in 1/64 px.
    pub radius: u32,
}

impl Dart {
    /// The accepted sample this dart becomes, in pixels (exact).
    #[must_use]
    pub fn point(&self) -> Point {
        Point {
            x: fixed::fx_to_pos(self.x),
            y: fixed::fx_to_pos(self.y),
            radius: fixed::fx_to_radius(self.radius),
            class: 0,
        }
    }
}

/// Seconds spent in each stage, by name, in the order the stages first ran.
/// In JSON each stage is a field `<name>_seconds`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StageTimes(Vec<(&'static str, f64)>);

impl StageTimes {
    /// Adds `seconds` to stage `name`.
    pub fn add(&mut self, name: &'static str, seconds: f64) {
        match self.0.iter_mut().find(|(n, _)| *n == name) {
            Some((_, s)) => *s += seconds,
            None => self.0.push((name, seconds)),
        }
    }

    /// Adds every stage of `other`.
    pub fn merge(&mut self, other: &Self) {
        for &(n, s) in &other.0 {
            self.add(n, s);
        }
    }

    /// The seconds of stage `name` (0 when it never ran).
    #[must_use]
    pub fn get(&self, name: &str) -> f64 {
        self.0.iter().find(|(n, _)| *n == name).map_or(0.0, |p| p.1)
    }

    /// The stages and their seconds, in order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.0.iter().copied()
    }
}

impl serde::Serialize for StageTimes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, seconds) in &self.0 {
            map.serialize_entry(&format!("{name}_seconds"), seconds)?;
        }
        map.end()
    }
}

/// What one iteration returns.
#[derive(Clone, Debug, Default)]
pub struct Step {
    /// Pixels (or, in exact mode, cells) still empty after the iteration.
    pub empty: u64,
    /// The darts accepted, in acceptance order.
    pub accepted: Vec<Point>,
    /// Seconds per stage.
    pub stages: StageTimes,
    /// Whether the backend can do no more: the run ends after this step
    /// (maximal only if nothing is left empty).
    pub finished: bool,
    /// Samples taken back, by their index in acceptance order over the
    /// whole run (exact mode's repair of voids; see [`super::exact`]).
    pub removed: Vec<u32>,
    /// Samples accepted but not yet in `accepted`: the GPU holds them and
    /// hands them over in a later step, at the latest the run's last.
    pub held: usize,
}

/// A backend as the loop sees it: something that runs one iteration.
pub trait Stepper {
    /// Empty pixels (or cells) before the first iteration.
    fn empty(&self) -> u64;
    /// Runs iteration `iteration` with `darts` darts.
    fn step(&mut self, iteration: u32, darts: u32) -> Result<Step>;
    /// Darts for the next iteration when `empty` pixels (or cells) are empty.
    fn darts_for(&self, plan: &Plan, empty: u64) -> u32 {
        plan.darts_for(u32::try_from(empty).unwrap_or(u32::MAX))
    }
    /// Peak working memory in bytes, once the run is over.
    fn bytes(&self) -> usize;
}

/// Runs `stepper` until no pixel is empty or `plan.max_iterations` have run.
/// `stats` names the backend and device; the loop fills in the rest.
pub fn run(
    plan: &Plan,
    stepper: &mut dyn Stepper,
    mut stats: Stats,
    ctl: Control<'_>,
) -> Result<SampleSet> {
    let start = Instant::now();
    let pixels = plan.pixels();
    let mut points = Vec::new();
    let mut removed: Vec<u32> = Vec::new();
    let mut empty = stepper.empty();
    let mut iteration = 0;
    while empty > 0 && iteration < plan.max_iterations {
        ctl.check()?;
        let step = stepper.step(iteration, stepper.darts_for(plan, empty))?;
        stats.stages.merge(&step.stages);
        if points.is_empty() {
            points = step.accepted;
        } else {
            points.extend(step.accepted);
        }
        removed.extend(step.removed);
        empty = step.empty;
        iteration += 1;
        let finished = step.finished;
        ctl.report(Progress {
            iteration,
            points: points.len() - removed.len() + step.held,
            empty_pixels: empty,
            pixels: u64::from(pixels),
        });
        if finished {
            break;
        }
    }
    stats.seconds = start.elapsed().as_secs_f64();
    stats.exact = plan.exact;
    stats.empty_left = empty;
    stats.bytes_per_pixel = stepper.bytes() as f64 / f64::from(pixels.max(1));
    stats.repaired = removed.len();
    if !removed.is_empty() {
        let mut keep = vec![true; points.len()];
        for &i in &removed {
            keep[i as usize] = false;
        }
        let mut k = keep.iter();
        points.retain(|_| *k.next().unwrap_or(&true));
    }
    Ok(SampleSet::finish(
        (plan.width, plan.height),
        points,
        iteration,
        empty == 0,
        stats,
    ))
}
