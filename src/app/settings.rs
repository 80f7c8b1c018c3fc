//! The app's controls, persisted between runs through eframe storage: the
//! library's drawing job ([`Job`], the same one `pixelpie stipple` runs)
//! plus what only the app needs (the backend, the view, the last folder).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::backend::BackendChoice;
use crate::job::{DEFAULT_POINTS, Job};
use crate::stipple::svg::DotPath;

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
    /// The drawing job, with every default of `pixelpie stipple`; its
    /// `points` follows [`Self::use_count`] and [`Self::points`] (see
    /// [`Self::job`]).
    pub job: Job,
    /// Target a point count (true) or use the radius range as is.
    pub use_count: bool,
    /// The point count in the Points field (kept while the radius range is
    /// used).
    pub points: u32,
    /// The backend.
    pub backend: BackendChoice,
    /// What is drawn behind the dots.
    pub background: Background,
    /// Show the coverage disks of the samples (paper Figure 4).
    pub show_coverage: bool,
    /// Show the pen's travel: its moves between dots, in drawing order.
    pub show_travel: bool,
    /// The darkest dots' diameter on the page in mm, when it sets the radii
    /// (the job's `dot_mm`; with a width in mm or paper only).
    pub dot_mm: Option<f64>,
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
            job: Job::default(),
            use_count: true,
            points: DEFAULT_POINTS as u32,
            backend: BackendChoice::Auto,
            background: Background::Paper,
            show_coverage: false,
            show_travel: false,
            dot_mm: None,
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

    /// Why the Points field's count is refused (none, or more than
    /// [`MAX_POINTS`]), when the count is used.
    #[must_use]
    pub fn refused_count(&self) -> Option<String> {
        if !self.use_count || self.job().dot_mm.is_some() {
            return None;
        }
        match self.points {
            0 => Some("a drawing needs at least 1 dot".into()),
            n if n > MAX_POINTS => Some(format!(
                "{n} dots is more than the app draws: at most {MAX_POINTS} (the drawing's \
                 domain is at most 4096×4096 px with dots at least 1 px in radius, which \
                 holds about 6 million)"
            )),
            _ => None,
        }
    }

    /// The job these controls stand for: with the Points field, its count;
    /// with the radius range, the range as it is (in domain pixels).
    #[must_use]
    pub fn job(&self) -> Job {
        let mut job = self.job.clone();
        let on_page = job.width_mm.is_some() || job.paper.is_some();
        if let (Some(d), true) = (self.dot_mm, on_page) {
            job.points = None;
            job.dot_radius = None;
            job.importance.min_radius = None;
            job.dot_mm = Some(d);
        } else if self.use_count {
            job.points = Some(self.points as usize);
            job.dot_radius = None;
        } else {
            job.points = None;
            job.dot_radius = None;
            let imp = &mut job.importance;
            imp.min_radius = Some(imp.min_radius.unwrap_or(1.0));
        }
        job
    }

    /// The part of the settings that the points depend on.
    #[must_use]
    pub fn sampling_key(&self) -> SamplingKey {
        let mut job = self.job().sampling_key();
        // The sheet only places the dots, unless the pen sizes them (the
        // job's key keeps the pen then), and the pen's path only draws them.
        if job.pen_mm.is_none() && job.dot_mm.is_none() {
            job.paper = None;
            job.margin = None;
            job.landscape = false;
        }
        job.dot_path = DotPath::Spiral;
        SamplingKey {
            job,
            backend: self.backend,
        }
    }

    /// The periodic domain.
    #[must_use]
    pub fn periodic(&self) -> bool {
        self.job.sampler.periodic
    }
}
