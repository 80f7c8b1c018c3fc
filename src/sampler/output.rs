//! A run's result: the points in acceptance order and the run's statistics.

use serde::Serialize;

/// One accepted sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Point {
    /// x in pixels (0 = left edge).
    pub x: f32,
    /// y in pixels (0 = top edge).
    pub y: f32,
    /// The radius at the sample, in pixels.
    pub radius: f32,
}

/// Timings and sizes of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Stats {
    /// Points accepted.
    pub points: usize,
    /// Iterations run.
    pub iterations: u32,
    /// Whether every pixel ended covered (in exact mode: every point of the
    /// domain).
    pub maximal: bool,
    /// Whether the run was in exact mode.
    pub exact: bool,
    /// What was left empty at the end: pixels in pixel mode; in exact mode,
    /// active cells, or after a finished run the voids finer than the
    /// position grid that no dart can fill.
    pub empty_left: u64,
    /// `"cpu"` or `"gpu"`.
    pub backend: String,
    /// The GPU adapter's name, or the CPU's thread count.
    pub device: String,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
    /// Seconds per stage: `throw` (the paper's S1), `cull` (S2: conflict
    /// removal and coverage), `compact` (PP), and in exact mode `refine`.
    #[serde(flatten)]
    pub stages: super::StageTimes,
    /// Peak working memory divided by the number of pixels.
    pub bytes_per_pixel: f64,
    /// Whether stage timings come from GPU timestamp queries.
    pub gpu_timestamps: bool,
}

/// The output of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SampleSet {
    /// Domain width in pixels.
    pub width: u32,
    /// Domain height in pixels.
    pub height: u32,
    /// Points in acceptance order.
    pub points: Vec<Point>,
    /// Whether the set is maximal (no pixel left uncovered).
    pub maximal: bool,
    /// Iterations run.
    pub iterations: u32,
    /// The run's statistics.
    pub stats: Stats,
}

impl SampleSet {
    /// A finished run of a `width`×`height` domain; the statistics' counts are
    /// taken from the run itself.
    #[must_use]
    pub fn finish(
        (width, height): (u32, u32),
        points: Vec<Point>,
        iterations: u32,
        maximal: bool,
        mut stats: Stats,
    ) -> Self {
        stats.points = points.len();
        stats.iterations = iterations;
        stats.maximal = maximal;
        Self {
            width,
            height,
            points,
            maximal,
            iterations,
            stats,
        }
    }
}
