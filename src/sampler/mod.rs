//! The PixelPie sampler: maximal Poisson-disk sampling by rasterization and
//! occlusion culling (Ip, Yalçın, Luebke & Varshney 2013), headless.
//!
//! This module is the contract. Every backend (the CPU reference in [`cpu`],
//! the wgpu backend in `crate::gpu`) produces exactly the points defined here,
//! bit for bit, for the same [`Params`].
//!
//! # Semantics
//!
//! * **Domain.** W×H pixels, origin top left; pixel (i, j) has its centre at
//!   (i + ½, j + ½). Positions are integers in 1/256 px, radii in 1/64 px
//!   ([`fixed`]); every distance test is `dx² + dy² < r²` on 64-bit integers.
//! * **Radius map.** r(p) for every pixel, at least 1 px, quantized to 1/64 px.
//! * **Darts.** Iteration `t` throws `b = min(batch, empty, max_batch)` darts.
//!   Dart `k` takes hash `h = dart_hash(iteration_key(seed_key(seed), t), k)`,
//!   lands on empty pixel `empty[pick(h, empty.len())]` and is offset inside it
//!   by `offset_hash(h)`: `subpixel_bits` bits per axis, at sub-cell centres,
//!   so 0 bits give the paper's pixel-centred darts. Its radius is r at its pixel.
//! * **Depth keys.** Dart `k` has key `k` (Prior: Less wins; Current: Greater
//!   wins) or `(r - r_min) << index_bits | k` (Bigger: Greater wins; Smaller:
//!   Less wins). Keys have [`fixed::KEY_BITS`] = 29 bits, so a batch holds at
//!   most min(2^(29 - radius_bits), 2^22) darts ([`KeyLayout::max_batch`]); a
//!   larger batch is split over successive iterations.
//! * **Conflicts within a batch** (paper §3.1–3.2). Dart j survives iff no dart
//!   i of the batch whose key beats j's has `|c_i - p_j| < r_i`, with p_j the
//!   centre of j's pixel: the depth test at j's pixel.
//! * **Coverage across iterations.** Pixel p is covered when an accepted sample
//!   i has `|p - c_i| < f(r_i, r_p)`, f = r_i (Prior), r_p (Current), max
//!   (Bigger) or min (Smaller). Darts land only on uncovered pixels.
//! * **Compaction and stopping.** The empty-pixel list (all pixels in index
//!   order at first) keeps its order when covered pixels leave it. The run
//!   stops when it is empty (maximal) or after `max_iterations` (not maximal).
//! * **Periodic domain.** Distances take the short way round; disks wrap. The
//!   largest radius may then be at most half the domain's smaller side.
//! * **Output.** Points in acceptance order (iteration, then dart index), each
//!   with x, y and radius in pixels, all exact in `f32`.
//! * **Batch size.** By default half the expected count, the sum over pixels of
//!   0.547 / (π r²/4), RSA's saturation density (paper §5.1).
//! * **The loop.** [`run::run`] drives a backend's [`Stepper`], one iteration
//!   at a time; cancellation is checked before every iteration, and the CPU
//!   backend's stages poll it inside (throw, grid, cull, cover; exact mode's
//!   phases), so that a cancel lands within milliseconds of being set. A
//!   cancelled stage's unfinished work is thrown away: a run that is not
//!   cancelled gives the same points.
//!
//! # Exact mode
//!
//! With [`Params::exact`] the run follows [`exact`]'s semantics instead: the
//! same darts and iterations, with the disk condition tested between dart
//! centres with no slack, coverage by cells (a pixel, then quarters of it
//! down to one position) that one disk holds whole, acceptance in dart
//! order (unbiased random sequential addition), and maximality in the
//! continuous domain. It runs on the CPU.

pub mod classes;
pub mod coverage;
pub mod cpu;
// Exact mode's and the fixed-point rules are the contract's own; the tests
// read them, users need not.
#[doc(hidden)]
pub mod exact;
#[doc(hidden)]
pub mod fixed;
mod options;
mod output;
mod params;
mod radius_map;
pub(crate) mod run;

use std::sync::atomic::{AtomicBool, Ordering};

pub use classes::ClassRadii;
pub use options::SamplerOptions;
pub use output::{BackendKind, Point, Report as StatsReport, SampleSet, Stats};
pub use params::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_POLICY, DEFAULT_SUBPIXEL_BITS, KeyLayout, Params, Plan, Policy,
    RSA_DENSITY, Radius,
};
pub use radius_map::{MAX_PIXELS, RadiusMap};
pub(crate) use run::Dart;
pub use run::StageTimes;

/// What can go wrong in the sampler.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A width or height that is zero or too large.
    #[error("invalid domain size {0}")]
    InvalidSize(String),
    /// A radius that is not a number, too small or too large.
    #[error("invalid radius: {0}")]
    InvalidRadius(String),
    /// A radius map whose size is not the domain's.
    #[error("radius map has {len} values, the {}x{} domain needs {}", expected.0, expected.1, u64::from(expected.0) * u64::from(expected.1))]
    RadiusMapSize {
        /// The domain size.
        expected: (u32, u32),
        /// The number of values given.
        len: usize,
    },
    /// Another parameter out of range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// The caller cancelled the run.
    #[error("cancelled")]
    Cancelled,
    /// A backend could not run, or failed: its own error inside (the GPU
    /// backend's, say). The CPU reference backend never fails so.
    #[error(transparent)]
    Backend(Box<dyn std::error::Error + Send + Sync>),
}

impl Error {
    /// A backend's own error.
    pub fn backend(e: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self::Backend(Box::new(e))
    }

    /// Whether a backend failed (as opposed to bad parameters or a cancel).
    #[must_use]
    pub fn is_backend(&self) -> bool {
        matches!(self, Self::Backend(_))
    }
}

/// The sampler's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Progress after an iteration.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// Iterations done.
    pub iteration: u32,
    /// Points accepted so far.
    pub points: usize,
    /// Pixels still empty.
    pub empty_pixels: u64,
    /// Pixels in the domain.
    pub pixels: u64,
}

/// Progress reporting and cancellation, shared by every backend.
///
/// ```
/// use std::sync::atomic::AtomicBool;
/// use pixelpie::sampler::{Control, Params, Progress};
/// let cancel = AtomicBool::new(false);
/// let progress = |p: Progress| eprintln!("{} points", p.points);
/// let ctl = Control::new().with_progress(&progress).with_cancel(&cancel);
/// let set = Params::new(64, 64).with_radius(4.0).generate_with(ctl).unwrap();
/// assert!(set.maximal());
/// ```
#[derive(Default, Clone, Copy)]
#[non_exhaustive]
pub struct Control<'a> {
    /// Called after every iteration.
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
    /// Checked before every iteration, the first included, and polled
    /// inside the CPU backend's stages; when set the run ends with
    /// [`Error::Cancelled`].
    pub cancel: Option<&'a AtomicBool>,
}

impl<'a> Control<'a> {
    /// No progress and no cancellation.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Calls `progress` after every iteration.
    #[must_use]
    pub fn with_progress(mut self, progress: &'a (dyn Fn(Progress) + Sync)) -> Self {
        self.progress = Some(progress);
        self
    }

    /// Ends the run with [`Error::Cancelled`] before the next iteration once
    /// `cancel` is set.
    #[must_use]
    pub fn with_cancel(mut self, cancel: &'a AtomicBool) -> Self {
        self.cancel = Some(cancel);
        self
    }

    /// [`Error::Cancelled`] when the cancel flag is set.
    pub fn check(&self) -> Result<()> {
        if self.cancelled() {
            return Err(Error::Cancelled);
        }
        Ok(())
    }

    /// Whether the cancel flag is set: long loops inside a stage poll it
    /// and stop early (their work is then thrown away, so the results of a
    /// run that is not cancelled are the same).
    #[must_use]
    pub fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }

    /// Reports progress.
    pub fn report(&self, p: Progress) {
        if let Some(f) = self.progress {
            f(p);
        }
    }
}
