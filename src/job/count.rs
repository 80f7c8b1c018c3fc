//! Point-count targeting, written once for every job: finds the radius
//! scale that yields about N points, for a uniform radius or a radius map
//! ([`sample_scaled`], `pixelpie sample`), a picture ([`sample_map`]) and the
//! pens of a colour drawing ([`sample_union`]).
//!
//! The count of a maximal set goes as 1/r², so each run corrects the scale by
//! sqrt(count / target), starting from the RSA density estimate.

use rayon::prelude::*;

use crate::importance::{Classes, Error as ImportanceError, Prepared, RadiusRange};
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
        return Err(Error::InvalidParameter("«points=0»: ask for at least 1".into()).into());
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
    let valid = |s: f64| make(s).ok().is_some_and(|p| p.plan().is_ok());
    if n > 0 && !valid(initial) {
        // More points than the domain holds: said in points, as asked,
        // with the most it holds at the smallest scale the sampler takes.
        let mut hi = initial.max(1.0);
        while !valid(hi) && hi < 1e9 {
            hi *= 2.0;
        }
        let mut lo = initial;
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if valid(mid) { hi = mid } else { lo = mid }
        }
        return Err(Error::InvalidParameter(format!(
            "{}: this domain holds about {} points at the sampler's smallest radii (1 px)",
            crate::text::given("points", n),
            (expected / (hi * hi)).floor() as u64
        ))
        .into());
    }
    let (_, set, runs) = fit_scale(n, initial, |s| -> Result<_, E> {
        let set = run(&make(s)?)?;
        Ok((set.points.len(), set))
    })?;
    Ok((set, runs))
}

/// The result of [`sample_map`] and [`sample_union`].
pub struct Fitted {
    /// The run, its points after the white cutoff.
    pub set: SampleSet,
    /// The radius range used.
    pub range: RadiusRange,
    /// Sampler runs made.
    pub runs: usize,
    /// The count asked for, when the domain could not hold it within the
    /// sampler's radii (at least 1 px, at most the domain's size).
    pub short_of: Option<usize>,
}

/// Samples `map` with `run`, fitting the radius scale to `points` (±3%)
/// when given, from the map's predicted count
/// ([`Prepared::predicted_points`]). The scale never takes the smallest
/// radius below 1 px, nor the largest past the domain's size; a count too
/// small for that is refused in plain words. The statistics count the
/// points that survive the cutoff.
pub fn sample_map<E: From<Error> + From<ImportanceError>>(
    map: &Prepared,
    base: &Params,
    points: Option<usize>,
    mut run: impl FnMut(&Params) -> Result<SampleSet, E>,
) -> Result<Fitted, E> {
    let mut cut_run = move |scale: f64| -> Result<SampleSet, E> {
        let set = run(&map.params(base, scale)?)?;
        let kept = map.cut(&set.points);
        Ok(set.with_points(kept))
    };
    let Some(n) = points else {
        return Ok(Fitted {
            set: cut_run(1.0)?,
            range: map.range,
            runs: 1,
            short_of: None,
        });
    };
    let target = Target {
        n,
        range: map.range,
        domain: map.domain(),
        periodic: base.periodic,
    };
    target.fit(
        map.predictor(),
        "the white cutoff leaves no pixel to place dots on",
        cut_run,
    )
}

/// Samples the union of `classes` (the pens of a colour drawing) as one
/// map ([`Classes::union_params`]) with `run`, then gives each point a pen
/// ([`super::assign::pens`]), fitting the radius scale to `points` in all
/// (±3%) when given, from the union's predicted count, as [`sample_map`]
/// does; with `spread`, the chosen run's pens are then spread apart
/// ([`super::assign::spread_pens`]). One run costs what a grey drawing's
/// does.
pub fn sample_union<E: From<Error> + From<ImportanceError>>(
    classes: &Classes<'_>,
    base: &Params,
    points: Option<usize>,
    spread: bool,
    mut run: impl FnMut(&Params) -> Result<SampleSet, E>,
) -> Result<Fitted, E> {
    let range = classes.maps[0].range;
    let domain = classes.maps[0].domain();
    let mut pen_run = |s: f64| -> Result<SampleSet, E> {
        let set = run(&classes.union_params(base, s)?)?;
        let shares = classes.shares(range.scaled(s));
        let given = super::assign::pens(&set.points, domain, classes.maps.len(), &shares);
        Ok(set.with_points(given))
    };
    // The fit's chosen run (the nearest to the count), its pens spread
    // apart (where `spread`), and each point's radius
    // its pen's own at its pixel, as a pen's sample (and relaxation) has
    // it, not the union's.
    let finish = |mut fitted: Fitted| -> Fitted {
        let mut given = std::mem::take(&mut fitted.set.points);
        let shares = classes.shares(fitted.range);
        if spread {
            super::assign::spread_pens(&mut given, domain, classes.maps.len(), &shares);
        }
        let radius = classes.class_radius(fitted.range);
        given.par_iter_mut().for_each(|p| {
            let px = (p.x.max(0.0) as u32).min(domain.0 - 1) as usize;
            let py = (p.y.max(0.0) as u32).min(domain.1 - 1) as usize;
            let r = radius(p.class as usize, py * domain.0 as usize + px);
            if r.is_finite() {
                p.radius = r;
            }
        });
        fitted.set = fitted.set.with_points(given);
        fitted
    };
    let Some(n) = points else {
        return Ok(finish(Fitted {
            set: pen_run(1.0)?,
            range,
            runs: 1,
            short_of: None,
        }));
    };
    let target = Target {
        n,
        range,
        domain,
        periodic: base.periodic,
    };
    target
        .fit(
            classes.union_predictor(),
            "the picture needs no ink",
            pen_run,
        )
        .map(finish)
}

/// A count to fit on a map of radii `range` (scale 1) over `domain`.
struct Target {
    n: usize,
    range: RadiusRange,
    domain: (u32, u32),
    periodic: bool,
}

impl Target {
    /// Fits the scale from the count `predict` gives at any scale
    /// ([`predicted_scale`]), refusing a count too small for the domain
    /// ([`too_few`]) and one where nothing is predicted (`nothing`), then
    /// sampling with `run(scale)` ([`fit_count`]).
    fn fit<E: From<Error> + From<ImportanceError>>(
        &self,
        predict: impl Fn(f64) -> f64,
        nothing: &str,
        run: impl FnMut(f64) -> Result<SampleSet, E>,
    ) -> Result<Fitted, E> {
        let (n, range) = (self.n, self.range);
        let floor = 1.0 / f64::from(range.min);
        let Some(scale) = predicted_scale(&predict, n, floor) else {
            return Err(ImportanceError::InvalidParameter(nothing.into()).into());
        };
        let ceiling = too_few(n, scale, range, self.domain, self.periodic, &predict)?;
        // The predicted scale handed on as the count it expects at scale 1,
        // as the fit has always taken it (the same first scale to the bit).
        fit_count(n, scale * scale * n as f64, range, ceiling, run)
    }
}

/// The largest scale of `range` that the sampler allows on `domain` (the
/// largest radius at most its longer side, half the shorter one when
/// periodic); a count `n` whose predicted `scale` passes it is refused in
/// plain words, with the smallest count that fits.
fn too_few(
    n: usize,
    scale: f64,
    range: RadiusRange,
    domain: (u32, u32),
    periodic: bool,
    predict: &impl Fn(f64) -> f64,
) -> Result<f64, ImportanceError> {
    let (w, h) = (f64::from(domain.0), f64::from(domain.1));
    let largest = if periodic { w.min(h) / 2.0 } else { w.max(h) };
    let widest = f64::from(range.max);
    if widest * scale <= largest {
        return Ok(largest / widest);
    }
    // The count at the largest scale the sampler allows, rounded up.
    let least = predict(largest / widest).ceil().max(1.0) as usize + 1;
    Err(ImportanceError::InvalidParameter(format!(
        "{n} dots are too few for a {}x{} drawing: its lightest dots would lie farther apart \
         than the picture is wide; ask for at least {least}",
        domain.0, domain.1
    )))
}

/// The radius scale at which `predict(scale)` is `n` points (six fixed-point
/// steps from the count at scale 1), never below `floor`; `None` when
/// nothing is predicted at scale 1.
fn predicted_scale(predict: &impl Fn(f64) -> f64, n: usize, floor: f64) -> Option<f64> {
    let expected = predict(1.0);
    if expected <= 0.0 {
        return None;
    }
    let mut scale = (expected / n as f64).sqrt().max(floor);
    for _ in 0..6 {
        let predicted = predict(scale);
        if predicted <= 0.0 {
            break;
        }
        scale = (scale * (predicted / n as f64).sqrt()).max(floor);
    }
    Some(scale)
}

/// Fits the radius scale of `range` to `n` points (±3%) from the `expected`
/// count at scale 1, sampling with `run(scale)`; the scale never takes the
/// smallest radius below 1 px, nor the largest past the sampler's
/// `ceiling` (then the count is as near as the picture allows, and
/// `short_of` says so).
fn fit_count<E: From<Error>>(
    n: usize,
    expected: f64,
    range: RadiusRange,
    ceiling: f64,
    mut run: impl FnMut(f64) -> Result<SampleSet, E>,
) -> Result<Fitted, E> {
    let floor = 1.0 / f64::from(range.min);
    let clamp = |s: f64| s.min(ceiling).max(floor);
    let initial = clamp((expected / n as f64).sqrt());
    let (scale, set, runs) = fit_scale(n, initial, |s| -> Result<_, E> {
        let set = run(clamp(s))?;
        Ok((set.points.len(), set))
    })?;
    let got = set.points.len() as f64;
    let short = (got - n as f64).abs() > COUNT_TOLERANCE * n as f64;
    Ok(Fitted {
        set,
        range: range.scaled(clamp(scale)),
        runs,
        short_of: short.then_some(n),
    })
}
