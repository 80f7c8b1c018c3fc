//! The app's controls, persisted between runs through eframe storage.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::backend::BackendChoice;
use crate::importance::Tones;
use crate::sampler::Policy;
pub use crate::stipple::DotMode;

/// What is drawn behind the dots.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Background {
    /// White paper.
    #[default]
    Paper,
    /// The importance map after adjustments (grey levels).
    Importance,
    /// The original picture.
    Photo,
}

/// Every control of the side panel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// The loaded image, reopened at start.
    pub image: Option<PathBuf>,
    /// Target a point count (true) or use the radius range as is.
    pub use_count: bool,
    /// The point count to target.
    pub points: u32,
    /// Smallest radius in pixels (for black); scaled in count mode.
    pub r_min: f32,
    /// Largest radius in pixels (for white); scaled in count mode.
    pub r_max: f32,
    /// Tone mapping (true) or the paper's linear ramp.
    pub tone: bool,
    /// The grey the drawing reproduces.
    pub tones: Tones,
    /// The disk policy.
    pub policy: Policy,
    /// Gamma applied after the levels.
    pub gamma: f32,
    /// Black level.
    pub black: f32,
    /// White level.
    pub white: f32,
    /// Light parts become the important ones.
    pub invert: bool,
    /// No dots where the importance is above this (1 = off).
    pub cutoff: f32,
    /// Sub-pixel bits of dart positions.
    pub subpixel_bits: u32,
    /// The seed.
    pub seed: u64,
    /// Wrap-around domain.
    pub periodic: bool,
    /// Exact mode: no sub-pixel slack in the spacing, no gaps.
    pub exact: bool,
    /// The backend.
    pub backend: BackendChoice,
    /// How the dots are sized.
    pub dot_mode: DotMode,
    /// Dot radius as a fraction of the sample radius (proportional dots).
    pub dot_scale: f32,
    /// Dot radius as a fraction of the calibrated radius (fixed and sized dots).
    pub dot_factor: f32,
    /// The lightest dots' radius as a fraction of the darkest's (sized dots).
    pub dot_ratio: f32,
    /// Weighted Lloyd relaxation steps after sampling.
    pub relax: u32,
    /// Dot colour.
    pub dot_color: [u8; 3],
    /// What is drawn behind the dots.
    pub background: Background,
    /// Show the coverage disks of the samples (paper Figure 4).
    pub show_coverage: bool,
    /// PNG export: image pixels per domain pixel.
    pub png_scale: f32,
    /// The folder of the last file opened or exported (the dialogs start there).
    pub last_dir: Option<PathBuf>,
    /// With a periodic domain, show the drawing tiled 2×2.
    pub tile: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            image: None,
            use_count: true,
            points: 10_000,
            r_min: 1.5,
            r_max: 12.0,
            tone: true,
            tones: Tones::Display,
            policy: Policy::Smaller,
            gamma: 1.0,
            black: 0.0,
            white: 1.0,
            invert: false,
            cutoff: 1.0,
            subpixel_bits: crate::sampler::DEFAULT_SUBPIXEL_BITS,
            seed: 1,
            periodic: false,
            exact: false,
            backend: BackendChoice::Auto,
            dot_mode: DotMode::Sized,
            dot_scale: 0.35,
            dot_factor: 1.0,
            dot_ratio: 0.3,
            relax: 0,
            dot_color: [20, 20, 20],
            background: Background::Paper,
            show_coverage: false,
            png_scale: 1.0,
            last_dir: None,
            tile: true,
        }
    }
}

/// The settings that change the points (a change re-samples).
#[derive(Clone, Debug, PartialEq)]
pub struct SamplingKey {
    use_count: bool,
    points: u32,
    range: (u32, u32),
    tone: bool,
    tones: Tones,
    sized: Option<u32>,
    relax: u32,
    policy: Policy,
    levels: (u32, u32, u32, u32),
    invert: bool,
    subpixel_bits: u32,
    seed: u64,
    periodic: bool,
    exact: bool,
    backend: BackendChoice,
}

impl Settings {
    /// The part of the settings that the points depend on.
    #[must_use]
    pub fn sampling_key(&self) -> SamplingKey {
        SamplingKey {
            use_count: self.use_count,
            points: self.points,
            range: (self.r_min.to_bits(), self.r_max.to_bits()),
            tone: self.tone,
            tones: self.tones,
            sized: (self.dot_mode == DotMode::Sized).then_some(self.dot_ratio.to_bits()),
            relax: self.relax,
            policy: self.policy,
            levels: (
                self.gamma.to_bits(),
                self.black.to_bits(),
                self.white.to_bits(),
                self.cutoff.to_bits(),
            ),
            invert: self.invert,
            subpixel_bits: self.subpixel_bits,
            seed: self.seed,
            periodic: self.periodic,
            exact: self.exact,
            backend: self.backend,
        }
    }
}
