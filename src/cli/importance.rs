//! `sample --importance`: the sampling run with point-count targeting over
//! a radius range, with a progress bar (the options are the library's
//! [`pixelpie::importance::ImportanceOptions`]).

use anyhow::Result;
use indicatif::ProgressBar;

use pixelpie::backend::BackendChoice;
use pixelpie::importance::{Prepared, RadiusRange};
use pixelpie::sampler::{Params, SampleSet};

use super::sample::run_with_progress;

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
    let fitted = prepared.sample(&o.base, o.points, |params| -> Result<SampleSet> {
        Ok(run_with_progress(params, o.backend, o.bar, o.verbose)?)
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
