//! The point-set job: a maximal Poisson-disk set of a uniform radius, of a
//! radius map, or of a picture as importance map, optionally fitted to a
//! point count. `pixelpie sample` and Python's `pixelpie.sample` both run
//! it, so that the same job gives the same points from either, and its
//! rules (what excludes what, the domain, the count fit) are written once.

use std::path::PathBuf;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::importance::{ImportanceMap, ImportanceOptions, Mapping, fit_size};
use crate::sampler::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_POLICY, Params, Policy, RadiusMap, SampleSet, SamplerOptions,
};
use crate::stipple::Error;

/// Where a point set's radii come from, in memory.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum Radii {
    /// One radius for every disk: the job's `radius`, or the one found for
    /// its count.
    Uniform,
    /// A radius per pixel, row-major, `width`×`height`; a count scales it.
    Map {
        /// The map's width (the domain's).
        width: u32,
        /// The map's height.
        height: u32,
        /// The radii in pixels.
        radii: Vec<f32>,
    },
    /// A picture as importance map (dark = small disks), resized to the
    /// domain and mapped to radii by the job's importance options.
    Picture(ImportanceMap),
}

/// A point-set job: the options of `pixelpie sample` (with the `cli`
/// feature, its arguments) and the keyword arguments of Python's
/// `pixelpie.sample`, under the same names, with their defaults
/// ([`SampleJob::default`]) and what excludes what ([`SampleJob::check`]),
/// written once. Where the radii come from is given to [`SampleJob::run`]
/// ([`Radii`]: the files named here, or arrays in memory).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default)]
#[non_exhaustive]
pub struct SampleJob {
    /// Domain width in pixels [default: the radius or importance map's].
    #[cfg_attr(feature = "cli", arg(long))]
    pub width: Option<u32>,
    /// Domain height in pixels [default: the radius or importance map's].
    #[cfg_attr(feature = "cli", arg(long))]
    pub height: Option<u32>,
    /// Disk radius in pixels, for a uniform set (with an importance map,
    /// --min-radius is the black pixels' radius).
    #[cfg_attr(feature = "cli", arg(long))]
    pub radius: Option<f32>,
    /// Target point count (±3%): picks the radius, or scales the radius or
    /// importance map's radii.
    #[cfg_attr(feature = "cli", arg(long))]
    pub points: Option<usize>,
    /// Single-channel float OpenEXR of radii in pixels.
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius_map: Option<PathBuf>,
    /// Importance map (PNG, JPEG, TIFF, BMP, WebP, OpenEXR): dark pixels get
    /// small radii. Resized to --width/--height when given.
    #[cfg_attr(feature = "cli", arg(long))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub importance: Option<PathBuf>,
    /// How a picture becomes radii (its `min_radius` is the black pixels'
    /// radius).
    #[cfg_attr(feature = "cli", command(flatten))]
    #[serde(flatten)]
    pub importance_options: ImportanceOptions,
    /// Disk policy for varying radii (paper §3.4).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t = DEFAULT_POLICY))]
    pub policy: Policy,
    /// Seed, sub-pixel darts, periodic domain, exact mode.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[serde(flatten)]
    pub sampler: SamplerOptions,
    /// Darts per iteration [default: half the expected count].
    #[cfg_attr(feature = "cli", arg(long))]
    pub batch: Option<u32>,
    /// Cap on iterations; a capped run is reported as not maximal.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = DEFAULT_MAX_ITERATIONS))]
    pub max_iterations: u32,
}

impl Default for SampleJob {
    fn default() -> Self {
        Self {
            width: None,
            height: None,
            radius: None,
            points: None,
            radius_map: None,
            importance: None,
            importance_options: ImportanceOptions::default(),
            policy: DEFAULT_POLICY,
            sampler: SamplerOptions::default(),
            batch: None,
            max_iterations: DEFAULT_MAX_ITERATIONS,
        }
    }
}

/// A finished point-set job.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Sampled {
    /// The points (after a picture's white cutoff) and the run's statistics.
    pub set: SampleSet,
    /// Sampler runs made to reach the count.
    pub runs: usize,
    /// The count asked for, when a picture's radii could not shrink enough
    /// (their 1 px floor, or the domain's size for the lightest) to reach it.
    pub short_of: Option<usize>,
}

impl Sampled {
    /// What a front end warns of after the run, in the CLI's words without
    /// its "warning: ": a count short of its target (`asked`), a set left
    /// not maximal (`max_iterations`: the job's cap).
    #[must_use]
    pub fn warnings(&self, max_iterations: u32) -> Vec<String> {
        let mut out = Vec::new();
        if let Some(n) = self.short_of {
            out.push(super::short_of(n, self.set.points.len()));
        }
        out.extend(not_maximal(&self.set, max_iterations));
        out
    }
}

/// The warning of a set that is not maximal: voids finer than the position
/// grid left (exact mode), or the iteration cap reached.
#[must_use]
pub fn not_maximal(set: &SampleSet, max_iterations: u32) -> Option<String> {
    if set.maximal() {
        None
    } else if set.stats.exact && set.iterations() < max_iterations {
        Some(format!(
            "{} voids finer than the position grid remain; the set is not maximal",
            set.stats.empty_left
        ))
    } else {
        Some(format!(
            "stopped after {} iterations before the set was maximal",
            set.iterations()
        ))
    }
}

impl SampleJob {
    /// Checks what excludes what, for radii from `radii` (a map or picture
    /// in memory, else the files this job names), and that a uniform job
    /// has a domain.
    pub fn check(&self, radii: &Radii) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if let Err(crate::importance::Error::InvalidParameter(m)) = self.importance_options.check()
        {
            return bad(m);
        }
        if self.radius_map.is_some() && self.importance.is_some() {
            return bad("give «radius_map» or «importance», not both".into());
        }
        let uniform = matches!(radii, Radii::Uniform)
            && self.radius_map.is_none()
            && self.importance.is_none();
        if let Some(r) = self.radius
            && !(r.is_finite() && r > 0.0)
        {
            return bad(format!("«radius={r}» must be a positive number"));
        }
        if self.points == Some(0) {
            return bad("«points=0»: ask for at least 1 point".into());
        }
        if !uniform {
            if self.radius.is_some() {
                return bad(
                    "«radius» gives a uniform set: a radius map holds the radii («points» scales \
                     it), and with an importance map «min_radius» is the black pixels' radius"
                        .into(),
                );
            }
        } else {
            if self.radius.is_some() && self.points.is_some() {
                return bad("give «radius» or «points», not both".into());
            }
            if self.radius.is_none() && self.points.is_none() {
                return bad("give «radius», «points», «radius_map» or «importance»".into());
            }
            if self.width.is_none() || self.height.is_none() {
                return bad(
                    "«width» and «height» are needed without «radius_map» or «importance»".into(),
                );
            }
        }
        if let Radii::Map { width, height, .. } = radii {
            let (w, h) = (*width, *height);
            if self.width.is_some_and(|x| x != w) || self.height.is_some_and(|x| x != h) {
                return bad(format!(
                    "the radius map is {w}x{h}, not the {}x{} domain asked for",
                    self.width.unwrap_or(w),
                    self.height.unwrap_or(h)
                ));
            }
        }
        if let Radii::Picture(map) = radii
            && let (Some(w), Some(h)) = (self.width, self.height)
            && w != h
            && (map.width(), map.height()) == (h, w)
        {
            // Both sides given and the picture is the domain turned: an
            // array in (width, height) order is the usual mistake, and
            // resizing it would stretch it silently.
            return bad(format!(
                "the importance map is {}x{}, the {w}x{h} domain turned: a picture array \
                 is (height, width); transpose it, or give one of width and height",
                map.width(),
                map.height()
            ));
        }
        Ok(())
    }

    /// The radii this job's files give: its radius map or importance map,
    /// read, or a uniform radius.
    pub fn radii(&self) -> crate::Result<Radii> {
        Ok(match (&self.importance, &self.radius_map) {
            (Some(path), _) => Radii::Picture(ImportanceMap::open(
                path,
                self.importance_options.hdr_white,
            )?),
            (None, Some(path)) => {
                let (width, height, radii) = crate::io::read_radius_map(path)?;
                Radii::Map {
                    width,
                    height,
                    radii,
                }
            }
            (None, None) => Radii::Uniform,
        })
    }

    /// The parameters every run shares on a `width`×`height` domain.
    fn base(&self, width: u32, height: u32) -> Params {
        let base = self.sampler.apply(
            Params::new(width, height)
                .with_policy(self.policy)
                .with_max_iterations(self.max_iterations),
        );
        match self.batch {
            Some(b) => base.with_batch(b),
            None => base,
        }
    }

    /// Runs the job on `radii` ([`Self::radii`] for its own files) with
    /// `sample` running the sampler (a backend).
    pub fn run(
        &self,
        radii: &Radii,
        mut sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
    ) -> crate::Result<Sampled> {
        self.check(radii)?;
        // Past the sampler's own limit its message says more.
        let guard = |w: u32, h: u32| {
            if u64::from(w) * u64::from(h) > crate::sampler::MAX_PIXELS {
                return Ok(());
            }
            crate::importance::budget::check_pixels(
                "a point set",
                (w, h),
                crate::importance::budget::SAMPLE_BYTES_PER_PIXEL,
            )
        };
        match radii {
            Radii::Uniform => guard(self.width.unwrap_or(1), self.height.unwrap_or(1))?,
            Radii::Map { width, height, .. } => guard(*width, *height)?,
            Radii::Picture(map) => {
                let (w, h) = fit_size((map.width(), map.height()), self.width, self.height);
                guard(w, h)?;
            }
        }
        let (start, make): (f64, Box<dyn Fn(f64) -> crate::Result<Params> + '_>) = match radii {
            Radii::Picture(map) => return self.run_picture(map, sample),
            Radii::Uniform => {
                let base = self.base(self.width.unwrap_or(1), self.height.unwrap_or(1));
                let make = move |s: f64| Ok(base.clone().with_radius(s as f32));
                (f64::from(self.radius.unwrap_or(1.0)), Box::new(make))
            }
            Radii::Map {
                width,
                height,
                radii,
            } => {
                let (w, h) = (*width, *height);
                let base = self.base(w, h);
                let make = move |s: f64| -> crate::Result<Params> {
                    let map = RadiusMap::from_pixels_scaled(w, h, radii, s)?;
                    Ok(base.clone().with_radius_map(Arc::new(map)))
                };
                (1.0, Box::new(make))
            }
        };
        let (set, runs) = super::count::sample_scaled(start, self.points, make, &mut sample)?;
        Ok(Sampled {
            set,
            runs,
            short_of: None,
        })
    }

    /// A picture's job: its size is the domain unless `width`/`height`
    /// resize it; the paper's linear ramp unless the options map otherwise.
    fn run_picture(
        &self,
        map: &ImportanceMap,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
    ) -> crate::Result<Sampled> {
        let prepared = self.importance_options.prepare_map(
            map,
            |w, h| fit_size((w, h), self.width, self.height),
            Mapping::Linear,
            self.points.is_some(),
        )?;
        let (w, h) = prepared.domain();
        let base = self.base(w, h);
        let fitted = super::count::sample_map(&prepared, &base, self.points, sample)?;
        Ok(Sampled {
            set: fitted.set,
            runs: fitted.runs,
            short_of: fitted.short_of,
        })
    }
}
