//! The app's controls, persisted between runs through eframe storage: the
//! library's drawing job ([`Job`], the same one `pixelpie stipple` runs)
//! plus what only the app needs (the backend, the view, the last folder).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::backend::BackendChoice;
use crate::job::{DEFAULT_POINTS, Job};

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
    /// The drawing job, the one `pixelpie stipple` runs: every control that
    /// changes the drawing is one of its settings (the count, or the radius
    /// range, or the dots' size in mm, sets the radii).
    pub job: Job,
    /// The backend.
    pub backend: BackendChoice,
    /// What is drawn behind the dots.
    pub background: Background,
    /// Show the coverage disks of the samples (paper Figure 4).
    pub show_coverage: bool,
    /// Show the pen's travel: its moves between dots, in drawing order.
    pub show_travel: bool,
    /// The folder of the last file opened or exported (the dialogs start there).
    pub last_dir: Option<PathBuf>,
    /// With a periodic domain, show the drawing tiled 2×2.
    pub tile: bool,
    /// A colour drawing's pens hidden in the view (by index; the exports
    /// keep every pen).
    pub hidden_pens: Vec<bool>,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            image: None,
            job: Job {
                points: Some(DEFAULT_POINTS),
                ..Job::default()
            },
            backend: BackendChoice::Auto,
            background: Background::Paper,
            show_coverage: false,
            show_travel: false,
            last_dir: None,
            tile: true,
            hidden_pens: Vec::new(),
        }
    }
}

/// The most dots the app asks for: a photo on the largest domain (4096²
/// px) holds about 6 million dots of radius 1 px, the sampler's smallest;
/// past that the count cannot be met, and the sampler's buffers pass 1 GB.
pub const MAX_POINTS: u32 = 8_000_000;

/// The settings that change the points (a change re-samples).
#[derive(Clone, Debug, PartialEq)]
pub struct SamplingKey {
    job: Job,
    backend: BackendChoice,
}

impl Settings {
    /// These settings for a picture already cropped and turned: the job
    /// without its crop and turn.
    #[must_use]
    pub fn framed(&self) -> Self {
        let mut s = self.clone();
        s.job.crop = None;
        s.job.rotate = None;
        s
    }

    /// Why the job's count is refused (none, or more than [`MAX_POINTS`]).
    #[must_use]
    pub fn refused_count(&self) -> Option<String> {
        match self.job.points? {
            // The job's own rule, in the app's words.
            0 => self.job.check().err().map(|e| super::words::app_line(&e)),
            n if n > MAX_POINTS as usize => Some(format!(
                "{n} dots is more than the app draws: at most {MAX_POINTS} (the drawing's \
                 domain is at most 4096×4096 px with dots at least 1 px in radius, which \
                 holds about 6 million)"
            )),
            _ => None,
        }
    }

    /// The job (a copy).
    #[must_use]
    pub fn job(&self) -> Job {
        self.job.clone()
    }

    /// The part of the settings that the points depend on.
    #[must_use]
    pub fn sampling_key(&self) -> SamplingKey {
        SamplingKey {
            job: self.job.sampling_key(),
            backend: self.backend,
        }
    }

    /// The periodic domain.
    #[must_use]
    pub fn periodic(&self) -> bool {
        self.job.sampler.periodic
    }
}
