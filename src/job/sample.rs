//! The point-set job: a maximal Poisson-disk set of a uniform radius, of a
//! radius map, or of a picture as importance map, optionally fitted to a
//! point count. `pixelpie sample` and Python's `pixelpie.sample` both run
//! it, so that the same job gives the same points from either, and its
//! rules (what excludes what, the domain, the count fit) are written once.

use std::sync::Arc;

use crate::importance::{ImportanceMap, ImportanceOptions, Mapping, fit_size};
use crate::sampler::{
    DEFAULT_MAX_ITERATIONS, DEFAULT_POLICY, Params, Policy, RadiusMap, SampleSet, SamplerOptions,
};
use crate::stipple::Error;

/// Where a point set's radii come from.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum Radii {
    /// One radius for every disk, in pixels; `None` finds it for the count.
    Uniform(Option<f32>),
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

/// A point-set job: where the radii come from, the domain, the count, the
/// policy and the sampler's options. [`SampleJob::new`] holds the defaults.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct SampleJob {
    /// Where the radii come from.
    pub radii: Radii,
    /// Domain width in pixels (default: the map's or the picture's).
    pub width: Option<u32>,
    /// Domain height in pixels (default: the map's or the picture's).
    pub height: Option<u32>,
    /// About this many points (±3%): finds the radius, or scales the map.
    pub points: Option<usize>,
    /// How a picture becomes radii (its `min_radius` is the black pixels'
    /// radius).
    pub importance: ImportanceOptions,
    /// The disk policy.
    pub policy: Policy,
    /// Seed, sub-pixel darts, periodic domain, exact mode.
    pub sampler: SamplerOptions,
    /// Darts per iteration (default: half the expected count).
    pub batch: Option<u32>,
    /// Cap on iterations; a capped set is not maximal.
    pub max_iterations: u32,
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
    /// (their 1 px floor) to reach it.
    pub short_of: Option<usize>,
}

impl SampleJob {
    /// A job for `radii`, with every default: the domain of the map or
    /// picture, no count, the default policy and sampler options.
    #[must_use]
    pub fn new(radii: Radii) -> Self {
        Self {
            radii,
            width: None,
            height: None,
            points: None,
            importance: ImportanceOptions::default(),
            policy: DEFAULT_POLICY,
            sampler: SamplerOptions::default(),
            batch: None,
            max_iterations: DEFAULT_MAX_ITERATIONS,
        }
    }

    /// Checks what excludes what, and that a uniform job has a domain.
    pub fn check(&self) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        match &self.radii {
            Radii::Uniform(r) => {
                if r.is_some() && self.points.is_some() {
                    return bad("give radius or points, not both".into());
                }
                if r.is_none() && self.points.is_none() {
                    return bad("give radius, points, a radius map or an importance map".into());
                }
                if self.width.is_none() || self.height.is_none() {
                    return bad(
                        "width and height are needed without a radius or importance map".into(),
                    );
                }
            }
            Radii::Map { width, height, .. } => {
                let (w, h) = (*width, *height);
                if self.width.is_some_and(|x| x != w) || self.height.is_some_and(|x| x != h) {
                    return bad(format!(
                        "the radius map is {w}x{h}, not the {}x{} domain asked for",
                        self.width.unwrap_or(w),
                        self.height.unwrap_or(h)
                    ));
                }
            }
            Radii::Picture(_) => {}
        }
        Ok(())
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

    /// Runs the job with `sample` running the sampler (a backend).
    pub fn run(
        &self,
        mut sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
    ) -> crate::Result<Sampled> {
        self.check()?;
        let (start, make): (f64, Box<dyn Fn(f64) -> crate::Result<Params> + '_>) = match &self.radii
        {
            Radii::Picture(map) => return self.run_picture(map, sample),
            Radii::Uniform(r) => {
                let base = self.base(self.width.unwrap_or(1), self.height.unwrap_or(1));
                let make = move |s: f64| Ok(base.clone().with_radius(s as f32));
                (f64::from(r.unwrap_or(1.0)), Box::new(make))
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
        let prepared = self.importance.prepare_map(
            map,
            |w, h| fit_size((w, h), self.width, self.height),
            Mapping::Linear,
            self.points.is_some(),
        )?;
        let base = self.base(prepared.map.width(), prepared.map.height());
        let fitted = super::count::sample_map(&prepared, &base, self.points, sample)?;
        Ok(Sampled {
            set: fitted.set,
            runs: fitted.runs,
            short_of: fitted.short_of,
        })
    }
}
