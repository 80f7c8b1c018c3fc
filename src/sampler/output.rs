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
    /// The sample's class (0 without classes, [`super::classes`]).
    #[serde(skip)]
    pub class: u32,
}

/// The backend that ran a set (its name in statistics: `cpu`,
/// `gpu-raster`, `gpu-compute`, `gpu-coalesced`, `gpu-exact`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[non_exhaustive]
pub enum BackendKind {
    /// The CPU reference backend.
    #[default]
    #[serde(rename = "cpu")]
    Cpu,
    /// The GPU, S1 as an instanced depth-tested draw (the paper's way).
    #[serde(rename = "gpu-raster")]
    GpuRaster,
    /// The GPU, S1 as a compute pass.
    #[serde(rename = "gpu-compute")]
    GpuCompute,
    /// The GPU, S1 as a compute pass with coalesced writes.
    #[serde(rename = "gpu-coalesced")]
    GpuCoalesced,
    /// The GPU in exact mode.
    #[serde(rename = "gpu-exact")]
    GpuExact,
}

impl BackendKind {
    /// The name in statistics.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Cpu => "cpu",
            Self::GpuRaster => "gpu-raster",
            Self::GpuCompute => "gpu-compute",
            Self::GpuCoalesced => "gpu-coalesced",
            Self::GpuExact => "gpu-exact",
        }
    }
}

impl std::fmt::Display for BackendKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Timings and sizes of a run. The point count is the [`SampleSet`]'s own
/// (`points.len()`); [`SampleSet::report`] writes both.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Stats {
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
    /// Exact mode: samples taken back to repair voids finer than the
    /// position grid (each re-filled by new darts); 0 in pixel mode.
    pub repaired: usize,
    /// The backend that ran.
    pub backend: BackendKind,
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
#[non_exhaustive]
pub struct SampleSet {
    /// Domain width in pixels.
    pub width: u32,
    /// Domain height in pixels.
    pub height: u32,
    /// Points in acceptance order.
    pub points: Vec<Point>,
    /// The run's statistics (whether it was maximal, iterations, timings).
    pub stats: Stats,
}

/// A set's statistics with its point count, as `--stats` writes them.
#[derive(Serialize)]
pub struct Report<'a> {
    /// Points in the set.
    pub points: usize,
    /// The run's statistics.
    #[serde(flatten)]
    pub stats: &'a Stats,
}

impl SampleSet {
    /// A finished run of a `width`×`height` domain.
    #[must_use]
    pub(crate) fn finish(
        (width, height): (u32, u32),
        points: Vec<Point>,
        iterations: u32,
        maximal: bool,
        mut stats: Stats,
    ) -> Self {
        stats.iterations = iterations;
        stats.maximal = maximal;
        Self {
            width,
            height,
            points,
            stats,
        }
    }

    /// Whether the run ended maximal.
    #[must_use]
    pub fn maximal(&self) -> bool {
        self.stats.maximal
    }

    /// Iterations run.
    #[must_use]
    pub fn iterations(&self) -> u32 {
        self.stats.iterations
    }

    /// The same run with other points (a cutoff, an order, a relaxation).
    #[must_use]
    pub fn with_points(self, points: Vec<Point>) -> Self {
        Self { points, ..self }
    }

    /// The statistics with the point count, for JSON.
    #[must_use]
    pub fn report(&self) -> Report<'_> {
        Report {
            points: self.points.len(),
            stats: &self.stats,
        }
    }
}
