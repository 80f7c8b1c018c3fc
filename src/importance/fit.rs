//! Sampling an importance map: its radii at a scale, the white cutoff, and
//! point-count targeting over the scale. Shared by `stipple`, `sample
//! --importance` and the app, which differ only in how they run the sampler.

use std::sync::Arc;

use rayon::prelude::*;

use super::{Error, ImportanceMap, Mapping, RadiusRange};
use crate::count;
use crate::sampler::{ClassRadii, Params, RadiusMap, SampleSet};

/// An adjusted importance map with its mapping, radius range and cutoff.
pub struct Prepared {
    /// The adjusted map, at the domain's size.
    pub map: ImportanceMap,
    /// The mapping.
    pub mapping: Mapping,
    /// The radius range at scale 1.
    pub range: RadiusRange,
    /// The white cutoff.
    pub cutoff: Option<f32>,
}

/// The result of [`Prepared::sample`].
pub struct Fitted {
    /// The run, its points after the white cutoff.
    pub set: SampleSet,
    /// The radius range used.
    pub range: RadiusRange,
    /// Sampler runs made.
    pub runs: usize,
    /// The count asked for, when the domain could not hold it at radii of
    /// at least 1 px (the sampler's floor).
    pub short_of: Option<usize>,
}

impl Prepared {
    /// The calibrated dot radius at `p` for the radius range `range`
    /// ([`Mapping::dot_radius`] of the value at `p`'s pixel).
    #[must_use]
    pub fn dot_radius(&self, p: &crate::sampler::Point, range: RadiusRange) -> f32 {
        self.mapping.dot_radius(self.map.value_at(p.x, p.y), range)
    }

    /// `base` (domain, policy, seed…) with the map's radii at `scale`.
    pub fn params(&self, base: &Params, scale: f64) -> crate::sampler::Result<Params> {
        let radii = self.map.radii(self.mapping, self.range.scaled(scale));
        let m = RadiusMap::from_pixels(self.map.width(), self.map.height(), &radii)?;
        Ok(base.clone().with_radius_map(Arc::new(m)))
    }

    /// Samples the map with `run`, fitting the radius scale to `points` (±3%)
    /// when given. The scale never takes the smallest radius below 1 px.
    /// The statistics count the points that survive the cutoff.
    pub fn sample<E: From<crate::sampler::Error> + From<Error>>(
        &self,
        base: &Params,
        points: Option<usize>,
        mut run: impl FnMut(&Params) -> Result<SampleSet, E>,
    ) -> Result<Fitted, E> {
        let mut cut_run = move |scale: f64| -> Result<SampleSet, E> {
            let set = run(&self.params(base, scale)?)?;
            let kept = self.map.cut(&set.points, self.cutoff);
            Ok(set.with_points(kept))
        };
        let Some(n) = points else {
            return Ok(Fitted {
                set: cut_run(1.0)?,
                range: self.range,
                runs: 1,
                short_of: None,
            });
        };
        let radii = self.map.radii(self.mapping, self.range);
        let expected = self.map.expected_points(&radii, self.cutoff);
        if expected <= 0.0 {
            return Err(Error::InvalidParameter(
                "the white cutoff leaves no pixel to place dots on".into(),
            )
            .into());
        }
        fit_count(n, expected, self.range, cut_run)
    }
}

/// Fits the radius scale of `range` to `n` points (±3%) from the `expected`
/// count at scale 1, sampling with `run(scale)`; the scale never takes the
/// smallest radius below 1 px.
fn fit_count<E: From<crate::sampler::Error> + From<Error>>(
    n: usize,
    expected: f64,
    range: RadiusRange,
    mut run: impl FnMut(f64) -> Result<SampleSet, E>,
) -> Result<Fitted, E> {
    let floor = 1.0 / f64::from(range.min);
    let initial = (expected / n as f64).sqrt().max(floor);
    let (scale, set, runs) = count::fit_scale(n, initial, |s| -> Result<_, E> {
        let set = run(s.max(floor))?;
        Ok((set.points.len(), set))
    })?;
    let got = set.points.len() as f64;
    let short = (got - n as f64).abs() > count::COUNT_TOLERANCE * n as f64;
    Ok(Fitted {
        set,
        range: range.scaled(scale.max(floor)),
        runs,
        short_of: short.then_some(n),
    })
}

/// The sampling of several importance maps at once, one class each
/// ([`crate::sampler::classes`]): the pens of a colour drawing. The maps
/// share the mapping and the radius range; where a map asks for less ink
/// than half of what its lightest dots put down, its class has no samples.
pub struct Classes<'a> {
    /// One prepared map per class (same size, mapping and range).
    pub maps: &'a [Prepared],
}

impl Classes<'_> {
    /// `base` with every class's radii at `scale`.
    pub fn params(&self, base: &Params, scale: f64) -> crate::sampler::Result<Params> {
        let first = &self.maps[0];
        let range = first.range.scaled(scale);
        // The ink of the lightest dots: below half of it, no dots.
        let white = f64::from(range.max);
        let lightest = super::ink::ink(
            f64::from(first.mapping.dot_radius(1.0, range)) / white,
            white,
        );
        let radii: Vec<Vec<f32>> = self
            .maps
            .par_iter()
            .map(|m| {
                m.map
                    .radii(m.mapping, range)
                    .into_iter()
                    .zip(m.map.values())
                    .map(|(r, &v)| {
                        if f64::from(1.0 - v) < lightest / 2.0 {
                            f32::INFINITY
                        } else {
                            r
                        }
                    })
                    .collect()
            })
            .collect();
        let classes = ClassRadii::new(first.map.width(), first.map.height(), &radii)?;
        Ok(base.clone().with_classes(Arc::new(classes)))
    }

    /// Samples the classes with `run`, fitting the common radius scale to
    /// `points` in all (±3%) when given, as [`Prepared::sample`] does.
    pub fn sample<E: From<crate::sampler::Error> + From<Error>>(
        &self,
        base: &Params,
        points: Option<usize>,
        mut run: impl FnMut(&Params) -> Result<SampleSet, E>,
    ) -> Result<Fitted, E> {
        let range = self.maps[0].range;
        let Some(n) = points else {
            return Ok(Fitted {
                set: run(&self.params(base, 1.0)?)?,
                range,
                runs: 1,
                short_of: None,
            });
        };
        let expected = self.params(base, 1.0)?.plan()?.expected_points();
        if expected <= 0.0 {
            return Err(Error::InvalidParameter("the picture needs no ink".into()).into());
        }
        fit_count(n, expected, range, |s| run(&self.params(base, s)?))
    }
}
