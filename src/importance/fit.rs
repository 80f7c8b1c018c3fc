//! Sampling an importance map: its radii at a scale, the white cutoff, and
//! the count a run at a scale is predicted to give (one map, or several
//! maps sampled together as classes). The count fit itself, which runs the
//! sampler, is the job's ([`crate::job::count`]).

use std::sync::Arc;

use rayon::prelude::*;

use super::{ImportanceMap, Mapping, RadiusRange};
use crate::sampler::{Params, RadiusMap};

/// An adjusted importance map with its mapping, radius range and cutoff,
/// read at the domain's pixels: the map's own, or, where the map is smaller
/// than the domain ([`Self::stretched`]), read bilinearly (the triangle
/// filter's upsampling) without a copy at the domain's size.
pub struct Prepared {
    /// The adjusted map, at the domain's size or smaller ([`Self::map`]).
    map: ImportanceMap,
    /// The mapping.
    pub mapping: Mapping,
    /// The radius range at scale 1.
    pub range: RadiusRange,
    /// The white cutoff ([`Self::cutoff`]).
    cutoff: Option<f32>,
    /// Where the map is read at a larger domain.
    stretch: Option<Stretch>,
    /// [`Self::knots`], made on first use (of the map and cutoff, which
    /// do not change after [`Self::new`]).
    knots: std::sync::OnceLock<Knots>,
}

/// A map read at a larger domain: per domain column and row, the two map
/// pixels between which it lies and the weight of the second.
#[derive(Clone, Debug)]
struct Stretch {
    domain: (u32, u32),
    xs: Vec<(u32, u32, f32)>,
    ys: Vec<(u32, u32, f32)>,
}

impl Stretch {
    /// The value at domain pixel (`x`, `y`) of `values`, a map `width`
    /// pixels wide.
    fn read(&self, values: &[f32], width: u32, x: u32, y: u32) -> f32 {
        let (a, b, fy) = self.rows(values, width, y);
        mix(a, b, self.xs[x as usize], fy)
    }

    /// [`Self::read`] of every pixel of domain row `y` into `row`.
    fn read_row(&self, values: &[f32], width: u32, y: u32, row: &mut [f32]) {
        let (a, b, fy) = self.rows(values, width, y);
        for (out, &x) in row.iter_mut().zip(&self.xs) {
            *out = mix(a, b, x, fy);
        }
    }

    /// [`Self::read`] of the pixels of domain row `y` at `columns` into
    /// `out`.
    fn read_at(&self, values: &[f32], width: u32, y: u32, columns: &[u32], out: &mut [f32]) {
        let (a, b, fy) = self.rows(values, width, y);
        for (o, &x) in out.iter_mut().zip(columns) {
            *o = mix(a, b, self.xs[x as usize], fy);
        }
    }

    /// The two map rows under domain row `y` and the weight of the second.
    fn rows<'v>(&self, values: &'v [f32], width: u32, y: u32) -> (&'v [f32], &'v [f32], f32) {
        let (y0, y1, fy) = self.ys[y as usize];
        let line = |y: u32| &values[y as usize * width as usize..][..width as usize];
        (line(y0), line(y1), fy)
    }
}

/// The bilinear value between map rows `a` and `b` (weight `fy` on `b`) at
/// the columns `x0`, `x1` (weight `fx` on `x1`): every read of a stretched
/// map, the same operations in the same order.
#[inline]
fn mix(a: &[f32], b: &[f32], (x0, x1, fx): (u32, u32, f32), fy: f32) -> f32 {
    let (x0, x1) = (x0 as usize, x1 as usize);
    let top = a[x0] + fx * (a[x1] - a[x0]);
    let bottom = b[x0] + fx * (b[x1] - b[x0]);
    top + fy * (bottom - top)
}

/// The two pixels of `from` under each of `to` pixels (centres aligned, as
/// the triangle filter upsamples) and the weight of the second.
fn stretch_axis(from: u32, to: u32) -> Vec<(u32, u32, f32)> {
    let ratio = from as f32 / to as f32;
    (0..to)
        .map(|o| {
            let s = ((o as f32 + 0.5) * ratio - 0.5).max(0.0);
            let i0 = (s as u32).min(from - 1);
            let i1 = (i0 + 1).min(from - 1);
            (i0, i1, s - i0 as f32)
        })
        .collect()
}

impl Prepared {
    /// A map prepared for a domain of its own size.
    #[must_use]
    pub fn new(
        map: ImportanceMap,
        mapping: Mapping,
        range: RadiusRange,
        cutoff: Option<f32>,
    ) -> Self {
        Self {
            map,
            mapping,
            range,
            cutoff,
            stretch: None,
            knots: std::sync::OnceLock::new(),
        }
    }

    /// The map read at a `domain` larger than itself (bilinearly); the
    /// same map where the sizes are equal.
    #[must_use]
    pub fn stretched(mut self, domain: (u32, u32)) -> Self {
        let own = (self.map.width(), self.map.height());
        self.stretch = (domain != own).then(|| Stretch {
            domain,
            xs: stretch_axis(own.0, domain.0),
            ys: stretch_axis(own.1, domain.1),
        });
        self
    }

    /// The adjusted map, at the domain's size or smaller.
    #[must_use]
    pub fn map(&self) -> &ImportanceMap {
        &self.map
    }

    /// The white cutoff: values above it get no dots.
    #[must_use]
    pub fn cutoff(&self) -> Option<f32> {
        self.cutoff
    }

    /// The domain's size in pixels.
    #[must_use]
    pub fn domain(&self) -> (u32, u32) {
        self.stretch
            .as_ref()
            .map_or((self.map.width(), self.map.height()), |s| s.domain)
    }

    /// The value at domain pixel (`x`, `y`).
    #[must_use]
    pub fn value(&self, x: u32, y: u32) -> f32 {
        match &self.stretch {
            None => self.map.value(x, y),
            Some(s) => s.read(self.map.values(), self.map.width(), x, y),
        }
    }

    /// The values of domain row `y` (as [`Self::value`] gives them) into
    /// `row`, the domain's width long.
    pub fn row(&self, y: u32, row: &mut [f32]) {
        match &self.stretch {
            None => {
                let w = self.map.width() as usize;
                row.copy_from_slice(&self.map.values()[y as usize * w..][..w]);
            }
            Some(s) => s.read_row(self.map.values(), self.map.width(), y, row),
        }
    }

    /// The values of domain row `y` at the domain columns `columns` (as
    /// [`Self::value`] gives them) into `out`, as long as `columns`: a
    /// row read once for many columns.
    pub fn row_at(&self, y: u32, columns: &[u32], out: &mut [f32]) {
        let width = self.map.width() as usize;
        let values = self.map.values();
        match &self.stretch {
            None => {
                let line = &values[y as usize * width..][..width];
                for (o, &x) in out.iter_mut().zip(columns) {
                    *o = line[x as usize];
                }
            }
            Some(s) => s.read_at(values, width as u32, y, columns, out),
        }
    }

    /// The domain pixel under (`x`, `y`), as [`Self::value_at`] reads it.
    #[must_use]
    pub fn pixel_at(&self, x: f32, y: f32) -> (u32, u32) {
        let (w, h) = self.domain();
        (
            (x.max(0.0) as u32).min(w - 1),
            (y.max(0.0) as u32).min(h - 1),
        )
    }

    /// The value at domain pixel `i` (row-major).
    #[must_use]
    pub fn value_index(&self, i: usize) -> f32 {
        match &self.stretch {
            None => self.map.values()[i],
            Some(s) => {
                // A domain holds at most 2^30 pixels: 32-bit division.
                let (i, w) = (i as u32, s.domain.0);
                self.value(i % w, i / w)
            }
        }
    }

    /// The value at the domain pixel under (`x`, `y`).
    #[must_use]
    pub fn value_at(&self, x: f32, y: f32) -> f32 {
        let (px, py) = self.pixel_at(x, y);
        self.value(px, py)
    }

    /// The points that survive the white cutoff (their pixel's value at
    /// most the cutoff), in their order.
    #[must_use]
    pub fn cut(&self, points: &[crate::sampler::Point]) -> Vec<crate::sampler::Point> {
        points
            .par_iter()
            .filter(|p| self.cutoff.is_none_or(|c| self.value_at(p.x, p.y) <= c))
            .copied()
            .collect()
    }

    /// The calibrated dot radius at `p` for the radius range `range`
    /// ([`Mapping::dot_radius`] of the value at `p`'s pixel).
    #[must_use]
    pub fn dot_radius(&self, p: &crate::sampler::Point, range: RadiusRange) -> f32 {
        self.mapping.dot_radius(self.value_at(p.x, p.y), range)
    }

    /// The calibrated dot radii of `points` for the radius range `range`,
    /// in their order ([`Self::dot_radius`] of each, in parallel).
    #[must_use]
    pub fn dot_radii(&self, points: &[crate::sampler::Point], range: RadiusRange) -> Vec<f32> {
        let radius = self.mapping.dot_radii(range);
        points
            .par_iter()
            .map(|p| radius(self.value_at(p.x, p.y)))
            .collect()
    }

    /// `base` (domain, policy, seed…) with the map's radii at `scale`.
    pub fn params(&self, base: &Params, scale: f64) -> crate::sampler::Result<Params> {
        // The radii of `map.radii(..)`, quantized as they are made.
        let radius = ImportanceMap::radius_fn(self.mapping, self.range.scaled(scale));
        let (w, h) = self.domain();
        let m = RadiusMap::from_rows(w, h, |y, row| {
            self.row(y, row);
            for r in row.iter_mut() {
                *r = radius(*r);
            }
        })?;
        Ok(base.clone().with_radius_map(Arc::new(m)))
    }

    /// [`Self::predicted_points`] at `scale` split into `cells` parts:
    /// `cell(x, y)` names the part of domain point (x, y). Read on a grid
    /// of about 250K of the domain's pixels, the parts add up to the
    /// whole's prediction (a poster's dots per sheet, `--plan`).
    #[must_use]
    pub fn predicted_in(
        &self,
        scale: f64,
        cells: usize,
        cell: impl Fn(f64, f64) -> usize,
    ) -> Vec<f64> {
        let (w, h) = self.domain();
        let step = ((f64::from(w) * f64::from(h) / 250_000.0).sqrt().floor() as u32).max(1);
        let range = self.range.scaled(scale);
        let mut parts = vec![0.0; cells];
        let mut sampled = 0usize;
        for y in (0..h).step_by(step as usize) {
            for x in (0..w).step_by(step as usize) {
                sampled += 1;
                let v = self.value(x, y);
                if self.cutoff.is_some_and(|c| v > c) {
                    continue;
                }
                let r = f64::from(self.mapping.radius(v.clamp(0.0, 1.0), range));
                let density = super::ink::rsa_per_pixel(r) * super::ink::density(r);
                if let Some(p) = parts.get_mut(cell(f64::from(x) + 0.5, f64::from(y) + 0.5)) {
                    *p += density;
                }
            }
        }
        let per = f64::from(w) * f64::from(h) / sampled.max(1) as f64 * COUNT_BIAS;
        parts.iter_mut().for_each(|p| *p *= per);
        parts
    }

    /// [`Self::predicted_points`] as a function of the scale, its table
    /// made once.
    pub fn predictor(&self) -> impl Fn(f64) -> f64 + '_ {
        let knots = self.knots();
        move |scale| knots.predicted(self, scale)
    }

    /// [`Self::made_knots`], made once: the plan, the count's fit and a
    /// colour drawing's sizes each predict from them.
    fn knots(&self) -> &Knots {
        self.knots.get_or_init(|| self.made_knots())
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
    fn made_knots(&self) -> Knots {
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

/// Σ f(bin, count) over the bins of a histogram that hold something, in
/// bin order (the same sum, so the same count fit, on every machine).
fn over_bins(bins: &[u64], f: impl Fn(usize, u64) -> f64) -> f64 {
    bins.iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(i, &n)| f(i, n))
        .sum()
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
        let sum = over_bins(&self.weights, |i, w| {
            let r = f64::from(map.mapping.radius(i as f32 / KNOTS as f32, range));
            let density = super::ink::rsa_per_pixel(r) * super::ink::density(r);
            density * (w as f64 / KNOT_ONE)
        });
        // The map's own pixels stand for the domain's (a stretched map's
        // values are spread as its pixels').
        let (w, h) = map.domain();
        sum * (f64::from(w) * f64::from(h)) / self.sampled as f64 * COUNT_BIAS
    }
}

/// The sampler's count over the density-corrected RSA estimate
/// ([`Prepared::predicted_points`]) for the Smaller policy on photos: 1.00
/// to 1.04 at the scale that gives the count, measured on four photos at
/// 10K, 100K and 1M dots (`stipple --verbose`); 1.015 puts all of them
/// within 2.5%.
pub const COUNT_BIAS: f64 = 1.015;

/// The sampler's count over the union's prediction ([`Classes::union_predictor`]:
/// the density-corrected RSA estimate at the union radius R, unbiased) for
/// the predicted count `raw`, fitted to the first runs of 2K to 1M dots:
/// from 1.23–1.28 at 2K down to 1.14 at 1M on `assets/astronaut.jpg`,
/// `assets/rocket.jpg` and two held-out photos (`--pens cmyk`, the first
/// run's count in `stipple --verbose`): the union's radius changes faster
/// than one pen's, and the Smaller policy packs more where it does.
fn union_count_bias(raw: f64) -> f64 {
    1.235 - 0.039 * (raw.max(1.0) / 16_500.0).log10()
}

/// Bins of [`UnionRadii`]' histogram over log R.
const UNION_BINS: usize = 2048;
/// The histogram's smallest and largest radius, px.
const UNION_RANGE: (f64, f64) = (0.25, 4096.0);

/// The union radii of a [`Classes`] map, binned over log R.
struct UnionRadii {
    /// Sampled pixels per bin.
    bins: Vec<u64>,
    /// Domain pixels per sampled pixel.
    scale: f64,
}

impl UnionRadii {
    fn bin(r: f64) -> usize {
        let (lo, hi) = (UNION_RANGE.0.ln(), UNION_RANGE.1.ln());
        let t = (r.ln() - lo) / (hi - lo);
        ((t * UNION_BINS as f64) as usize).min(UNION_BINS - 1)
    }

    fn radius(bin: usize) -> f64 {
        let (lo, hi) = (UNION_RANGE.0.ln(), UNION_RANGE.1.ln());
        (lo + (bin as f64 + 0.5) / UNION_BINS as f64 * (hi - lo)).exp()
    }
}

/// Whether a class whose map holds `v` has samples there: where it asks
/// for at least half the ink of the lightest dots (`lightest`,
/// [`Classes::lightest`]).
fn has_samples(v: f32, lightest: f64) -> bool {
    f64::from(1.0 - v) >= lightest / 2.0
}

/// Several importance maps drawn together, one class each: the pens of a
/// colour drawing, sampled as their union ([`Self::union_params`]) whose
/// points are then given pens by their shares of its density. The maps
/// share the mapping and the radius range; where a map asks for less ink
/// than half of what its lightest dots put down, its class has no samples.
pub struct Classes<'a> {
    /// One prepared map per class (same size, mapping and range).
    pub maps: &'a [Prepared],
}

impl Classes<'_> {
    /// The ink of the lightest dots at radius range `range`: where a map
    /// asks for less than half of it, its class has no samples.
    #[must_use]
    fn lightest(&self, range: RadiusRange) -> f64 {
        let white = f64::from(range.max);
        super::ink::ink(
            f64::from(self.maps[0].mapping.dot_radius(1.0, range)) / white,
            white,
        )
    }

    /// The radius of class `c` at pixel `i` for the radius range `range`,
    /// `f32::INFINITY` where the class has no samples ([`Self::lightest`]).
    pub(crate) fn class_radius(
        &self,
        range: RadiusRange,
    ) -> impl Fn(usize, usize) -> f32 + Sync + '_ {
        let lightest = self.lightest(range);
        let radius: Vec<_> = self
            .maps
            .iter()
            .map(|m| ImportanceMap::radius_fn(m.mapping, range))
            .collect();
        move |c, i| {
            let v = self.maps[c].value_index(i);
            if has_samples(v, lightest) {
                radius[c](v)
            } else {
                f32::INFINITY
            }
        }
    }

    /// `base` with the union of the classes as one radius map at `scale`:
    /// R = 1/√(Σ 1/r_c²) over the classes that have samples at a pixel (at
    /// least 1 px), the lightest dots' radius where none has (the points
    /// there carry no pen and are dropped). Its maximal set has the
    /// classes' summed density: the colour drawing's one sample, whose
    /// points are then given pens ([`Self::shares`]).
    pub fn union_params(&self, base: &Params, scale: f64) -> crate::sampler::Result<Params> {
        let range = self.maps[0].range.scaled(scale);
        let (w, h) = self.maps[0].domain();
        let inv = self.union_density_rows(range);
        let m = RadiusMap::from_rows(w, h, |y, row| {
            inv(y, row);
            for r in row.iter_mut() {
                let inv = *r;
                *r = if inv > 0.0 {
                    // At most the lightest dots' radius (where a stretched
                    // map's sum fades out between pixels with and without ink).
                    (1.0 / inv.sqrt()).clamp(1.0, range.max)
                } else {
                    range.max
                };
            }
        })?;
        Ok(base.clone().with_radius_map(Arc::new(m)))
    }

    /// Σ 1/r_c² over the classes that have samples, at each pixel of a
    /// domain row, for the radius range `range`: the union's density (its
    /// radius map's 1/R²), made where it is asked (`rows(y, out)` writes
    /// row `y`'s). Summed over the pens at the maps' own pixels once and
    /// read at the domain's (one map read, not one per pen, where the maps
    /// are stretched).
    pub(crate) fn union_density_rows(&self, range: RadiusRange) -> impl Fn(u32, &mut [f32]) + Sync {
        let first = &self.maps[0];
        let density = self.densities(range);
        let own = (first.map.width(), first.map.height());
        let summed: Vec<f32> = (0..own.0 as usize * own.1 as usize)
            .into_par_iter()
            .map(|i| {
                self.maps
                    .iter()
                    .zip(&density)
                    .map(|(m, d)| d(m.map.values()[i]))
                    .sum()
            })
            .collect();
        let stretch = first.stretch.clone();
        move |y, out| match &stretch {
            None => {
                let w = own.0 as usize;
                out.copy_from_slice(&summed[y as usize * w..][..w]);
            }
            Some(s) => s.read_row(&summed, own.0, y, out),
        }
    }

    /// Per class, its density 1/r² as a function of the map's value for
    /// the radius range `range` (0 where it has no samples,
    /// [`Self::lightest`]), tabulated once.
    fn densities(&self, range: RadiusRange) -> Vec<impl Fn(f32) -> f32 + Sync + use<>> {
        const STEPS: usize = 4096;
        let lightest = self.lightest(range);
        self.maps
            .iter()
            .map(|m| {
                let radius = ImportanceMap::radius_fn(m.mapping, range);
                let lut: Vec<f32> = (0..=STEPS)
                    .map(|k| {
                        let v = k as f32 / STEPS as f32;
                        if has_samples(v, lightest) {
                            let r = radius(v);
                            1.0 / (r * r)
                        } else {
                            0.0
                        }
                    })
                    .collect();
                move |v: f32| lut[((v.clamp(0.0, 1.0) * STEPS as f32).round()) as usize]
            })
            .collect()
    }

    /// Each class's share of the union's points at pixel `i` (row-major)
    /// for the radius range `range`: its density 1/r_c² over the sum, in
    /// `out`; false where no class has samples.
    pub(crate) fn shares(
        &self,
        range: RadiusRange,
    ) -> impl Fn(usize, &mut [f32]) -> bool + Sync + '_ {
        let density = self.densities(range);
        move |i, out| {
            let mut sum = 0f32;
            for ((o, d), m) in out.iter_mut().zip(&density).zip(self.maps) {
                *o = d(m.value_index(i));
                sum += *o;
            }
            if sum <= 0.0 {
                return false;
            }
            out.iter_mut().for_each(|o| *o /= sum);
            true
        }
    }

    /// The count one run of the union ([`Self::union_params`]) at radius
    /// `scale` is predicted to give, as [`Prepared::predicted_points`] does
    /// one map's, as a function of the scale, its table made once.
    pub fn union_predictor(&self) -> impl Fn(f64) -> f64 + '_ {
        let union = self.union_radii();
        move |scale| {
            let sum = over_bins(&union.bins, |i, n| {
                let r = (UnionRadii::radius(i) * scale).max(1.0);
                super::ink::rsa_per_pixel(r) * super::ink::density(r) * n as f64
            });
            let raw = sum * union.scale;
            raw * union_count_bias(raw)
        }
    }

    /// The union's radius R = 1/√(Σ 1/r_k²) at scale 1 (the cross radius
    /// of [`crate::sampler::ClassRadii`]) over every `step`-th pixel of every `step`-th row,
    /// as a histogram over log R: the count at any scale in a few
    /// thousand products.
    fn union_radii(&self) -> UnionRadii {
        let first = &self.maps[0];
        let domain = first.domain();
        // Read at the maps' own pixels: a map stretched to a larger domain
        // has no more detail there, and each pixel read stands for its
        // share of the domain.
        let (w, h) = (first.map.width() as usize, first.map.height() as usize);
        let step = ((w * h) as f64 / 250_000.0).sqrt().floor().max(1.0) as usize;
        let density = self.densities(first.range);
        let bins = (0..h)
            .into_par_iter()
            .step_by(step)
            .fold(
                || vec![0u64; UNION_BINS],
                |mut acc, y| {
                    for x in (0..w).step_by(step) {
                        let inv: f32 = self
                            .maps
                            .iter()
                            .zip(&density)
                            .map(|(m, d)| d(m.map.value(x as u32, y as u32)))
                            .sum();
                        if inv > 0.0 {
                            acc[UnionRadii::bin(1.0 / f64::from(inv).sqrt())] += 1;
                        }
                    }
                    acc
                },
            )
            .reduce(
                || vec![0u64; UNION_BINS],
                |mut a, b| {
                    a.iter_mut().zip(&b).for_each(|(a, b)| *a += b);
                    a
                },
            );
        UnionRadii {
            bins,
            scale: f64::from(domain.0) * f64::from(domain.1)
                / (h.div_ceil(step) * w.div_ceil(step)) as f64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The knots made once predict what knots made anew do, at every
    /// scale, and a prepared map with a cutoff predicts fewer points.
    #[test]
    fn predictions_from_the_knots_made_once_are_the_fresh_ones() {
        let (w, h) = (64u32, 48u32);
        let values = (0..w * h).map(|i| (i % w) as f32 / w as f32).collect();
        let map = ImportanceMap::from_values(w, h, values).unwrap();
        let range = RadiusRange::new(2.0, 8.0).unwrap();
        let p = Prepared::new(map.clone(), Mapping::Tone, range, None);
        let cut = Prepared::new(map, Mapping::Tone, range, Some(0.25));
        for scale in [0.5, 1.0, 1.7, 3.0] {
            let fresh = p.made_knots().predicted(&p, scale);
            assert_eq!(p.predicted_points(scale), fresh);
            assert_eq!(p.predictor()(scale), fresh);
            assert!(cut.predicted_points(scale) < fresh);
        }
    }

    #[test]
    fn a_stretched_map_reads_as_the_map_resized_to_the_domain() {
        let (w, h) = (7u32, 5u32);
        let values: Vec<f32> = (0..w * h).map(|i| ((i * 37) % 11) as f32 / 10.0).collect();
        let map = ImportanceMap::from_values(w, h, values).unwrap();
        let range = RadiusRange::new(2.0, 8.0).unwrap();
        let domain = (23, 16);
        let resized = map.resized(domain.0, domain.1).unwrap();
        let stretched = Prepared::new(map, Mapping::Tone, range, None).stretched(domain);
        assert_eq!(stretched.domain(), domain);
        for y in 0..domain.1 {
            for x in 0..domain.0 {
                let (a, b) = (stretched.value(x, y), resized.value(x, y));
                assert!((a - b).abs() < 1e-5, "({x}, {y}): {a} against {b}");
                let i = (y * domain.0 + x) as usize;
                assert_eq!(stretched.value_index(i), a);
            }
        }
        // A map of the domain's own size is read as it is.
        let own = Prepared::new(resized.clone(), Mapping::Tone, range, None).stretched(domain);
        assert_eq!(own.value(3, 4), resized.value(3, 4));
        // Rows read as their pixels do, stretched or not, whole or at
        // some columns.
        let mut row = vec![0.0; domain.0 as usize];
        let columns = [0u32, 5, 5, 22, 1];
        let mut some = vec![0.0; columns.len()];
        for map in [&stretched, &own] {
            for y in 0..domain.1 {
                map.row(y, &mut row);
                for (x, &v) in row.iter().enumerate() {
                    assert_eq!(v, map.value(x as u32, y), "({x}, {y})");
                }
                map.row_at(y, &columns, &mut some);
                for (&x, &v) in columns.iter().zip(&some) {
                    assert_eq!(v, map.value(x, y), "({x}, {y})");
                }
            }
        }
    }
}
