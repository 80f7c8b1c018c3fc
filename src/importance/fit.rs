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

    /// The calibrated dot radii of `points` for the radius range `range`,
    /// in their order ([`Self::dot_radius`] of each, in parallel).
    #[must_use]
    pub fn dot_radii(&self, points: &[crate::sampler::Point], range: RadiusRange) -> Vec<f32> {
        let radius = self.mapping.dot_radii(range);
        points
            .par_iter()
            .map(|p| radius(self.map.value_at(p.x, p.y)))
            .collect()
    }

    /// `base` (domain, policy, seed…) with the map's radii at `scale`.
    pub fn params(&self, base: &Params, scale: f64) -> crate::sampler::Result<Params> {
        // The radii of `map.radii(..)`, quantized as they are made.
        let radius = ImportanceMap::radius_fn(self.mapping, self.range.scaled(scale));
        let values = self.map.values();
        let m = RadiusMap::from_fn(self.map.width(), self.map.height(), |i| radius(values[i]))?;
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
        let knots = self.knots();
        let expected = knots.predicted(self, 1.0);
        if expected <= 0.0 {
            return Err(Error::InvalidParameter(
                "the white cutoff leaves no pixel to place dots on".into(),
            )
            .into());
        }
        // The scale whose predicted count is n: usually one run hits ±3%.
        let floor = 1.0 / f64::from(self.range.min);
        let mut scale = (expected / n as f64).sqrt().max(floor);
        for _ in 0..6 {
            let predicted = knots.predicted(self, scale);
            if predicted <= 0.0 {
                break;
            }
            scale = (scale * (predicted / n as f64).sqrt()).max(floor);
        }
        let predicted = scale * scale * n as f64;
        fit_count(n, predicted, self.range, cut_run)
    }

    /// The count a run at radius `scale` is predicted to give: the RSA
    /// density at each pixel's radius r, times the density of maximal
    /// pixel-mode sets at r over RSA's ([`super::ink::density`]), times
    /// [`COUNT_BIAS`], over every `step`-th pixel of every `step`-th row
    /// (about 250K pixels), those past the white cutoff left out.
    #[must_use]
    pub fn predicted_points(&self, scale: f64) -> f64 {
        self.knots().predicted(self, scale)
    }

    /// The sampled pixels' values as weights on the knots of the density
    /// table that [`Self::predicted_points`] interpolates: made once, it
    /// predicts the count at any scale in 1025 products.
    fn knots(&self) -> Knots {
        let (w, h) = (self.map.width() as usize, self.map.height() as usize);
        let step = ((w * h) as f64 / 250_000.0).sqrt().floor().max(1.0) as usize;
        let values = self.map.values();
        // Integer weights (2^-32 per unit) add up exactly, in any order: the
        // prediction, hence the scale, is the same for any thread count.
        let weights = (0..h)
            .into_par_iter()
            .step_by(step)
            .fold(
                || vec![0u64; KNOTS + 1],
                |mut acc, y| {
                    let row = &values[y * w..(y + 1) * w];
                    for &v in row
                        .iter()
                        .step_by(step)
                        .filter(|&&v| self.cutoff.is_none_or(|c| v <= c))
                    {
                        let x = v.clamp(0.0, 1.0) * KNOTS as f32;
                        let i = (x as usize).min(KNOTS - 1);
                        let f = (f64::from(x - i as f32) * KNOT_ONE) as u64;
                        acc[i] += KNOT_ONE as u64 - f;
                        acc[i + 1] += f;
                    }
                    acc
                },
            )
            .reduce(
                || vec![0u64; KNOTS + 1],
                |mut a, b| {
                    a.iter_mut().zip(&b).for_each(|(a, b)| *a += b);
                    a
                },
            );
        Knots {
            weights,
            sampled: h.div_ceil(step) * w.div_ceil(step),
        }
    }
}

/// Knots of the density table of [`Prepared::predicted_points`].
const KNOTS: usize = 1024;

/// A whole pixel's weight on the knots.
const KNOT_ONE: f64 = 4_294_967_296.0;

/// The sampled pixels of a map as weights on the density table's knots.
struct Knots {
    /// The weight on each knot, in 2^-32 of a pixel.
    weights: Vec<u64>,
    /// The pixels sampled.
    sampled: usize,
}

impl Knots {
    /// [`Prepared::predicted_points`] at `scale`.
    fn predicted(&self, map: &Prepared, scale: f64) -> f64 {
        let range = map.range.scaled(scale);
        let sum: f64 = self
            .weights
            .iter()
            .enumerate()
            .filter(|(_, w)| **w > 0)
            .map(|(i, &w)| {
                let r = f64::from(map.mapping.radius(i as f32 / KNOTS as f32, range));
                let density = crate::sampler::RSA_DENSITY / (std::f64::consts::PI * r * r / 4.0)
                    * super::ink::density(r);
                density * (w as f64 / KNOT_ONE)
            })
            .sum();
        let (w, h) = (map.map.width() as usize, map.map.height() as usize);
        sum * (w * h) as f64 / self.sampled as f64 * COUNT_BIAS
    }
}

/// The sampler's count over the density-corrected RSA estimate
/// ([`Prepared::predicted_points`]) for the Smaller policy on photos: 1.00
/// to 1.04 at the scale that gives the count, measured on four photos at
/// 10K, 100K and 1M dots (`stipple --verbose`); 1.015 puts all of them
/// within 2.5%.
pub const COUNT_BIAS: f64 = 1.015;

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
