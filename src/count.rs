//! Point-count targeting: finds the radius scale that yields about N points.
//!
//! The count of a maximal set goes as 1/r², so each run corrects the scale by
//! sqrt(count / target), starting from the RSA density estimate.

use crate::sampler::{Error, Params, SampleSet};

/// The relative tolerance that `--points` promises.
pub const COUNT_TOLERANCE: f64 = 0.03;
/// The most sampler runs a search makes.
pub const MAX_RUNS: usize = 8;

/// Searches the scale `s` (radii multiply by `s`) for which `run(s)` returns
/// about `target` points, starting at `initial`. Returns the best scale, its
/// result and the number of runs made.
pub(crate) fn fit_scale<T, E: From<Error>>(
    target: usize,
    initial: f64,
    mut run: impl FnMut(f64) -> Result<(usize, T), E>,
) -> Result<(f64, T, usize), E> {
    if target == 0 {
        return Err(Error::InvalidParameter("the point count must be positive".into()).into());
    }
    let target_f = target as f64;
    let mut scale = initial;
    let mut best: Option<(f64, f64, T)> = None;
    let mut runs = 0;
    while runs < MAX_RUNS {
        runs += 1;
        let (count, out) = run(scale)?;
        let err = (count as f64 - target_f).abs() / target_f;
        let next = scale * (count.max(1) as f64 / target_f).sqrt();
        if best.as_ref().is_none_or(|b| err < b.1) {
            best = Some((scale, err, out));
        }
        if err <= COUNT_TOLERANCE || next == scale {
            break;
        }
        scale = next;
    }
    let Some((scale, _, out)) = best else {
        return Err(Error::InvalidParameter("no sampler run was made".into()).into());
    };
    Ok((scale, out, runs))
}

/// Samples the parameters `make(scale)` with `run`: at `start` (a radius, or
/// 1 for a radius map's own scale), or, with `target`, at the scale that
/// gives about that many points, found by [`fit_scale`] from the RSA
/// estimate at scale 1. Returns the set and the number of runs. The CLI's
/// `sample --points` and the Python package's `sample(points=…)`.
pub fn sample_scaled<E: From<Error>>(
    start: f64,
    target: Option<usize>,
    make: impl Fn(f64) -> Result<Params, E>,
    mut run: impl FnMut(&Params) -> Result<SampleSet, E>,
) -> Result<(SampleSet, usize), E> {
    let Some(n) = target else {
        return Ok((run(&make(start)?)?, 1));
    };
    let expected = make(1.0)?.plan()?.expected_points();
    let initial = (expected / n.max(1) as f64).sqrt();
    let (_, set, runs) = fit_scale(n, initial, |s| -> Result<_, E> {
        let set = run(&make(s)?)?;
        Ok((set.points.len(), set))
    })?;
    Ok((set, runs))
}
