//! Importance-map options shared by `sample --importance` and `stipple`,
//! and the sampling run with point-count targeting over a radius range.

use std::path::Path;

use anyhow::{Result, bail};
use clap::Args;
use indicatif::ProgressBar;
use serde::Serialize;

use pixelpie::backend::BackendChoice;
use pixelpie::importance::{Adjust, ImportanceMap, Mapping, Prepared, RadiusRange, Tones};
use pixelpie::sampler::{Params, SampleSet};

use super::sample::run_with_progress;

/// r_max / r_min when only one end (or neither) is given.
pub const DEFAULT_RADIUS_RATIO: f32 = 8.0;

/// How importance becomes radius, on the command line.
#[derive(Clone, Copy, Debug, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MappingArg {
    /// r = r_min + (r_max − r_min)·v (paper §3.4).
    Linear,
    /// Calibrated: the stipple's ink equals the darkness (reproduces tones).
    Tone,
}

impl From<MappingArg> for Mapping {
    fn from(m: MappingArg) -> Self {
        match m {
            MappingArg::Linear => Self::Linear,
            MappingArg::Tone => Self::Tone,
        }
    }
}

/// Which grey the drawing reproduces, on the command line.
#[derive(Clone, Copy, Debug, Default, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TonesArg {
    /// The display grey: the sRGB-encoded value a viewer sees, as StippleGen
    /// and the stippling literature target (mid grey gets half of black's ink).
    #[default]
    Display,
    /// Linear light: the photo's luminance (mid grey sRGB 0.5 is 21% light,
    /// so it gets 79% of black's ink and looks dark).
    Linear,
}

impl From<TonesArg> for Tones {
    fn from(t: TonesArg) -> Self {
        match t {
            TonesArg::Display => Self::Display,
            TonesArg::Linear => Self::Linear,
        }
    }
}

/// Options that turn an image into a radius map.
#[derive(Args, Debug, Clone, Serialize)]
pub struct ImportanceOpts {
    /// The grey the drawing reproduces (levels and gamma apply to it).
    #[arg(long, value_enum, default_value_t = TonesArg::Display, requires = "importance")]
    pub tones: TonesArg,
    /// Importance-to-radius mapping [default: tone for stipple, linear for sample].
    #[arg(long, value_enum, requires = "importance")]
    pub mapping: Option<MappingArg>,
    /// Radius in px of black (most important) pixels; scaled with --points.
    #[arg(long, requires = "importance")]
    pub min_radius: Option<f32>,
    /// Radius in px of white pixels [default: 8 × the minimum].
    #[arg(long, requires = "importance")]
    pub max_radius: Option<f32>,
    /// Gamma applied after the levels: above 1 darkens mid-tones.
    #[arg(long, default_value_t = 1.0, requires = "importance")]
    pub gamma: f32,
    /// Black level: values at or below it count as black (0..1).
    #[arg(long, default_value_t = 0.0, requires = "importance")]
    pub black_level: f32,
    /// White level: values at or above it count as white (0..1).
    #[arg(long, default_value_t = 1.0, requires = "importance")]
    pub white_level: f32,
    /// Invert the image: light parts become the important ones.
    #[arg(long, requires = "importance")]
    pub invert: bool,
    /// Drop dots whose (adjusted) importance is above this level (0..1).
    #[arg(long, requires = "importance")]
    pub white_cutoff: Option<f32>,
    /// White point of float images (EXR, float TIFF) [default: their 99.5th percentile].
    #[arg(long, requires = "importance")]
    pub hdr_white: Option<f32>,
}

impl ImportanceOpts {
    /// Loads `path`, resizes it to `size` (the image's own size if `None`)
    /// and applies the adjustments.
    pub fn prepare(
        &self,
        path: &Path,
        size: impl FnOnce(u32, u32) -> (u32, u32),
        default_mapping: Mapping,
        count_target: bool,
    ) -> Result<Prepared> {
        let adjust = Adjust {
            black: self.black_level,
            white: self.white_level,
            gamma: self.gamma,
            invert: self.invert,
        };
        adjust.validate()?;
        if let Some(c) = self.white_cutoff
            && !(0.0..=1.0).contains(&c)
        {
            bail!("--white-cutoff {c} must be between 0 and 1");
        }
        // The library's errors name the file.
        let map = ImportanceMap::open(path, self.hdr_white)?;
        let (w, h) = size(map.width(), map.height());
        let map = map
            .resized(w, h)?
            .toned(self.tones.into())
            .adjusted(&adjust)?;
        let range = match (self.min_radius, self.max_radius) {
            (Some(lo), Some(hi)) => RadiusRange::new(lo, hi)?,
            (Some(lo), None) => RadiusRange::new(lo, lo * DEFAULT_RADIUS_RATIO)?,
            (None, Some(hi)) if count_target => RadiusRange::new(hi / DEFAULT_RADIUS_RATIO, hi)?,
            (None, _) if count_target => RadiusRange::new(1.0, DEFAULT_RADIUS_RATIO)?,
            (None, _) => bail!("give --points or --min-radius with an importance map"),
        };
        Ok(Prepared {
            map,
            mapping: self.mapping.map_or(default_mapping, Into::into),
            range,
            cutoff: self.white_cutoff,
        })
    }
}

/// A sampling run's options, beyond the radius field.
pub struct RunOpts<'a> {
    /// Parameters without a radius (domain, policy, seed…).
    pub base: Params,
    /// `--points`.
    pub points: Option<usize>,
    /// The backend.
    pub backend: BackendChoice,
    /// The progress bar.
    pub bar: &'a ProgressBar,
    /// `--quiet`.
    pub quiet: bool,
    /// `--verbose`.
    pub verbose: bool,
}

/// Samples a prepared map with a progress bar, fitting `--points`; returns
/// the points that survive the white cutoff and the radius range used.
pub fn sample(prepared: &Prepared, o: &RunOpts<'_>) -> Result<(SampleSet, RadiusRange)> {
    let fitted = prepared.sample(&o.base, o.points, |params| {
        run_with_progress(params, o.backend, o.bar, o.verbose)
    })?;
    let got = fitted.set.points.len();
    if o.verbose {
        o.bar
            .suspend(|| eprintln!("{got} points after {} runs", fitted.runs));
    }
    if let Some(n) = fitted.short_of
        && !o.quiet
    {
        o.bar.suspend(|| {
            eprintln!(
                "warning: asked for {n} points, got {got}: the smallest radius is at the sampler's \
                 1 px floor; enlarge the domain with --width/--height"
            );
        });
    }
    Ok((fitted.set, fitted.range))
}
