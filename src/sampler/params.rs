//! Sampling parameters (a builder in the style of `fast_poisson`), the radius
//! map, the disk policies of paper §3.4 and the per-run [`Plan`] derived from
//! them: key layout, batch size and expected count.

use std::sync::Arc;

use rayon::prelude::*;

use super::classes::ClassRadii;
use super::fixed::{self, KEY_BITS, MAX_SUBPIXEL_BITS, RADIUS_ONE, radius_to_fx};
use super::radius_map::{RadiusMap, check_size};
use super::{Error, Result};

/// The random-sequential-addition saturation density (Zhang & Torquato 2013).
pub const RSA_DENSITY: f64 = 0.547;
/// The fewest index bits a key keeps: a radius range needing more bits is refused.
pub const MIN_INDEX_BITS: u32 = 8;

/// How two samples of different radii are kept apart (paper §3.4, after
/// Mitchell et al. 2012). `i` is the earlier sample, `j` the later one.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Policy {
    /// f(i, j) = r(i): the earlier sample's disk. Key = dart index, Less wins.
    Prior,
    /// f(i, j) = r(j): the later sample's disk. Key = dart index, Greater wins.
    Current,
    /// f(i, j) = max(r(i), r(j)). Radius in the key's high bits, Greater wins.
    Bigger,
    /// f(i, j) = min(r(i), r(j)). Radius in the key's high bits, Less wins.
    /// The default.
    #[default]
    Smaller,
}

/// The default disk policy of every front end and of [`Params::new`]: the
/// smaller disk, the paper's choice for stippling (it keeps large
/// light-area disks out of dark areas). With a uniform radius it gives
/// Prior's points, at Prior's speed.
pub const DEFAULT_POLICY: Policy = Policy::Smaller;

impl Policy {
    /// All four policies.
    pub const ALL: [Self; 4] = [Self::Prior, Self::Current, Self::Bigger, Self::Smaller];

    /// The lower-case name used on the command line.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Prior => "prior",
            Self::Current => "current",
            Self::Bigger => "bigger",
            Self::Smaller => "smaller",
        }
    }

    /// Whether the greater depth key wins a conflict (depth compare Greater).
    #[must_use]
    pub const fn greater_wins(self) -> bool {
        matches!(self, Self::Current | Self::Bigger)
    }

    /// Whether the radius sits in the key's most significant bits.
    #[must_use]
    pub const fn keys_radius(self) -> bool {
        matches!(self, Self::Bigger | Self::Smaller)
    }

    /// Whether the coverage radius depends on the covered pixel's own radius.
    #[must_use]
    pub const fn reads_pixel_radius(self) -> bool {
        !matches!(self, Self::Prior)
    }

    /// The separation f(r_sample, r_pixel) that the coverage rule uses.
    #[must_use]
    pub fn coverage_radius(self, r_sample: u32, r_pixel: u32) -> u32 {
        match self {
            Self::Prior => r_sample,
            Self::Current => r_pixel,
            Self::Bigger => r_sample.max(r_pixel),
            Self::Smaller => r_sample.min(r_pixel),
        }
    }

    /// The policy's index in `shaders/common.wgsl` (`POLICY_*`).
    #[must_use]
    pub const fn index(self) -> u32 {
        self as u32
    }
}

/// The radius field of a run: one radius everywhere, or a map.
#[derive(Clone, Debug, PartialEq)]
pub enum Radius {
    /// The same radius, in pixels, at every pixel.
    Uniform(f32),
    /// A radius per pixel; its size must equal the domain's.
    Map(Arc<RadiusMap>),
    /// A radius map per class ([`super::classes`]); its size must equal the
    /// domain's.
    Classes(Arc<ClassRadii>),
}

/// Everything that determines a run's output.
///
/// ```
/// use pixelpie::sampler::{Params, Policy};
/// let params = Params::new(256, 256).with_radius(8.5).with_policy(Policy::Prior).with_seed(7);
/// assert_eq!(params.seed, 7);
/// ```
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Params {
    /// Domain width in pixels.
    pub width: u32,
    /// Domain height in pixels.
    pub height: u32,
    /// The radius field.
    pub radius: Radius,
    /// The disk policy.
    pub policy: Policy,
    /// The seed of the dart hash.
    pub seed: u64,
    /// Sub-pixel bits per axis of a dart's position (0 = pixel centres).
    pub subpixel_bits: u32,
    /// Darts per iteration; `None` picks half the expected count (paper §5.1).
    pub batch: Option<u32>,
    /// Whether distances and disks wrap around the domain (tileable output).
    pub periodic: bool,
    /// The most iterations before the run stops without being maximal.
    pub max_iterations: u32,
    /// Exact mode: the disk condition between dart centres with no slack,
    /// maximal in the continuous domain, unbiased (see [`crate::sampler::exact`]).
    pub exact: bool,
}

/// The default number of sub-pixel bits (8×8 dart positions per pixel).
pub const DEFAULT_SUBPIXEL_BITS: u32 = 3;
/// The default cap on iterations.
pub const DEFAULT_MAX_ITERATIONS: u32 = 1000;

impl Params {
    /// A `width`×`height` domain with radius 8.5 px, the Smaller policy
    /// ([`DEFAULT_POLICY`]), seed 0.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            radius: Radius::Uniform(8.5),
            policy: DEFAULT_POLICY,
            seed: 0,
            subpixel_bits: DEFAULT_SUBPIXEL_BITS,
            batch: None,
            periodic: false,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            exact: false,
        }
    }

    /// Sets a uniform radius in pixels.
    #[must_use]
    pub fn with_radius(mut self, r: f32) -> Self {
        self.radius = Radius::Uniform(r);
        self
    }

    /// Sets a radius map (its size must equal the domain's).
    #[must_use]
    pub fn with_radius_map(mut self, map: Arc<RadiusMap>) -> Self {
        self.radius = Radius::Map(map);
        self
    }

    /// Sets a radius map per class (multi-class sampling, [`super::classes`]).
    #[must_use]
    pub fn with_classes(mut self, classes: Arc<ClassRadii>) -> Self {
        self.radius = Radius::Classes(classes);
        self
    }

    /// Sets the disk policy.
    #[must_use]
    pub fn with_policy(mut self, policy: Policy) -> Self {
        self.policy = policy;
        self
    }

    /// Sets the seed.
    #[must_use]
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets the sub-pixel bits per axis (0 to 7).
    #[must_use]
    pub fn with_subpixel_bits(mut self, bits: u32) -> Self {
        self.subpixel_bits = bits;
        self
    }

    /// Sets the darts per iteration.
    #[must_use]
    pub fn with_batch(mut self, batch: u32) -> Self {
        self.batch = Some(batch);
        self
    }

    /// Turns the periodic (wrap-around) domain on or off.
    #[must_use]
    pub fn with_periodic(mut self, periodic: bool) -> Self {
        self.periodic = periodic;
        self
    }

    /// Sets the cap on iterations.
    #[must_use]
    pub fn with_max_iterations(mut self, n: u32) -> Self {
        self.max_iterations = n;
        self
    }

    /// Turns exact mode on or off ([`crate::sampler::exact`]).
    #[must_use]
    pub fn with_exact(mut self, exact: bool) -> Self {
        self.exact = exact;
        self
    }

    /// Checks the parameters and derives the run's constants.
    pub fn plan(&self) -> Result<Plan> {
        Plan::new(self)
    }
}

/// How a dart's depth key is laid out, and which key wins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KeyLayout {
    /// Bits of `radius - min_radius` in the key's most significant bits.
    pub radius_bits: u32,
    /// Bits of the dart index in the low bits: a batch has at most 2^index_bits darts.
    pub index_bits: u32,
    /// The radius (1/64 px) that the radius bits count from.
    pub min_radius: u32,
    /// Whether the greater key wins.
    pub greater_wins: bool,
}

impl KeyLayout {
    /// The key of dart `index` with radius `r_fx`.
    #[inline]
    #[must_use]
    pub fn key(&self, index: u32, r_fx: u32) -> u32 {
        if self.radius_bits == 0 {
            index
        } else {
            ((r_fx - self.min_radius) << self.index_bits) | index
        }
    }

    /// Whether key `a` beats key `b`.
    #[inline]
    #[must_use]
    pub fn beats(&self, a: u32, b: u32) -> bool {
        if self.greater_wins { a > b } else { a < b }
    }

    /// Where key `a` stands in winning order: `beats(a, b)` exactly when
    /// `rank(a) < rank(b)`.
    #[inline]
    #[must_use]
    pub fn rank(&self, a: u32) -> u32 {
        if self.greater_wins { !a } else { a }
    }

    /// The largest batch the layout allows: 2^index_bits darts, and at most
    /// [`fixed::MAX_BATCH`].
    #[must_use]
    pub fn max_batch(&self) -> u32 {
        (1u32 << self.index_bits).min(fixed::MAX_BATCH)
    }
}

/// The checked, derived constants of one run. Only [`Params::plan`] makes
/// one, so a plan is always valid; its fields are read through methods.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Domain width in pixels.
    pub(crate) width: u32,
    /// Domain height in pixels.
    pub(crate) height: u32,
    /// The disk policy.
    pub(crate) policy: Policy,
    /// Sub-pixel bits per axis.
    pub(crate) subpixel_bits: u32,
    /// Whether the domain wraps.
    pub(crate) periodic: bool,
    /// The 32-bit key of the seed.
    pub(crate) seed_key: u32,
    /// The depth-key layout.
    pub(crate) layout: KeyLayout,
    /// Darts per iteration (before the cap by empty pixels and key layout).
    pub(crate) batch: u32,
    /// The cap on iterations.
    pub(crate) max_iterations: u32,
    /// Smallest and largest radius (1/64 px).
    pub(crate) radius_range: (u32, u32),
    /// The radius map, or `None` for a uniform radius. With classes, their
    /// maps stacked (slot s reads entry s; 0 = no radius).
    pub(crate) map: Option<Arc<RadiusMap>>,
    /// With classes: the cross-class radius R(p) per pixel.
    pub(crate) cross: Option<Arc<Vec<u32>>>,
    /// Classes (1 without).
    pub(crate) classes: u32,
    /// Whether some slots start covered (a class without a radius there).
    pub(crate) holes: bool,
    /// The expected number of points at RSA saturation density, summed in
    /// parallel: within 4·n·ε of [`Self::expected_points`] (n pixels),
    /// relatively.
    pub(crate) expected_points: f64,
    /// Exact mode.
    pub(crate) exact: bool,
}

impl Plan {
    fn new(p: &Params) -> Result<Self> {
        check_size(p.width, p.height)?;
        if p.subpixel_bits > MAX_SUBPIXEL_BITS {
            return Err(Error::InvalidParameter(format!(
                "{}: sub-pixel bits range from 0 to {MAX_SUBPIXEL_BITS}",
                crate::text::given("subpixel_bits", p.subpixel_bits)
            )));
        }
        if p.batch == Some(0) {
            return Err(Error::InvalidParameter(format!(
                "{}: the batch must hold at least one dart",
                crate::text::given("batch", 0)
            )));
        }
        if p.max_iterations == 0 {
            return Err(Error::InvalidParameter(format!(
                "{}: at least one iteration is needed",
                crate::text::given("max_iterations", 0)
            )));
        }
        let (map, radius_range, expected_points) = match &p.radius {
            Radius::Uniform(r) => {
                let r = *r;
                if !r.is_finite() || r < 1.0 {
                    return Err(Error::InvalidRadius(format!(
                        "{} px: it must be a number of at least 1 px",
                        crate::text::given("radius", r)
                    )));
                }
                let fx = radius_to_fx(r);
                let area = f64::from(p.width) * f64::from(p.height);
                (None, (fx, fx), RsaCount::exact(area * rsa_per_pixel(fx)))
            }
            Radius::Map(m) => {
                if (m.width, m.height) != (p.width, p.height) {
                    return Err(Error::RadiusMapSize {
                        expected: (p.width, p.height),
                        len: m.radii.len(),
                    });
                }
                let expected = rsa_count(&m.radii, (m.min, m.max));
                (Some(m.clone()), (m.min, m.max), expected)
            }
            Radius::Classes(c) => {
                if (c.width(), c.height()) != (p.width, p.height) {
                    return Err(Error::RadiusMapSize {
                        expected: (p.width, p.height),
                        len: c.cross.len(),
                    });
                }
                if p.exact {
                    return Err(Error::InvalidParameter(
                        "exact mode does not take classes yet".into(),
                    ));
                }
                // The classes' own counts, summed.
                let m = &c.stacked;
                let expected = rsa_count(&m.radii, (m.min, m.max));
                (Some(m.clone()), (m.min, m.max), expected)
            }
        };
        let (cross, classes, holes) = match &p.radius {
            Radius::Classes(c) => (Some(c.cross.clone()), c.classes, c.holes),
            _ => (None, 1, false),
        };
        let r_max_px = radius_range.1 as f64 / f64::from(RADIUS_ONE);
        let (w, h) = (f64::from(p.width), f64::from(p.height));
        if p.periodic && 2.0 * r_max_px > w.min(h) {
            return Err(Error::InvalidRadius(format!(
                "radius {r_max_px} px: a periodic {}x{} domain allows at most {} px",
                p.width,
                p.height,
                w.min(h) / 2.0
            )));
        }
        if r_max_px > w.max(h) {
            return Err(Error::InvalidRadius(format!(
                "radius {r_max_px} px is larger than the {}x{} domain",
                p.width, p.height
            )));
        }
        // With one radius, Smaller's keys are Prior's (no radius bits, the
        // smaller index wins): the same points, by Prior's cheaper path.
        let policy = match p.policy {
            Policy::Smaller if radius_range.0 == radius_range.1 && classes == 1 => Policy::Prior,
            other => other,
        };
        let radius_bits = if policy.keys_radius() {
            32 - (radius_range.1 - radius_range.0).leading_zeros()
        } else {
            0
        };
        if radius_bits + MIN_INDEX_BITS > KEY_BITS {
            return Err(Error::InvalidRadius(format!(
                "radius range {}..{} px is too wide for the {} policy's depth keys",
                fixed::fx_to_radius(radius_range.0),
                fixed::fx_to_radius(radius_range.1),
                policy.name()
            )));
        }
        let layout = KeyLayout {
            radius_bits,
            index_bits: KEY_BITS - radius_bits,
            min_radius: radius_range.0,
            greater_wins: policy.greater_wins(),
        };
        let batch = p.batch.unwrap_or_else(|| {
            expected_points.batch(|| match &map {
                Some(m) => rsa_count_serial(&m.radii),
                None => expected_points.sum,
            })
        });
        let expected_points = expected_points.sum;
        Ok(Self {
            width: p.width,
            height: p.height,
            policy,
            subpixel_bits: p.subpixel_bits,
            periodic: p.periodic,
            seed_key: fixed::seed_key(p.seed),
            layout,
            batch,
            max_iterations: p.max_iterations,
            radius_range,
            map,
            cross,
            classes,
            holes,
            expected_points,
            exact: p.exact,
        })
    }

    /// The number of classes (1 without).
    #[must_use]
    pub fn classes(&self) -> u32 {
        self.classes
    }

    /// The slots the empty list starts with: classes × pixels.
    #[must_use]
    pub fn slots(&self) -> u32 {
        self.classes * self.pixels()
    }

    /// The rows of the stacked slot domain: classes × height.
    #[must_use]
    pub fn slot_rows(&self) -> u32 {
        self.classes * self.height
    }

    /// The cross-class radius (1/64 px) at pixel `p` (classes only).
    #[inline]
    #[must_use]
    pub fn cross_at(&self, p: u32) -> u32 {
        match &self.cross {
            Some(c) => c[p as usize],
            None => self.radius_at(p),
        }
    }

    /// The accepted sample that dart `d` (on slot `d.pixel`) becomes.
    #[inline]
    #[must_use]
    pub fn point(&self, d: &super::Dart) -> super::Point {
        let mut p = d.point();
        if self.classes > 1 {
            p.class = d.pixel / self.pixels();
        }
        p
    }

    /// The number of pixels.
    #[must_use]
    pub fn pixels(&self) -> u32 {
        self.width * self.height
    }

    /// The domain's size in pixels.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The depth-key layout.
    #[must_use]
    pub fn layout(&self) -> KeyLayout {
        self.layout
    }

    /// Darts per iteration (before the cap by empty pixels and key layout).
    #[must_use]
    pub fn batch(&self) -> u32 {
        self.batch
    }

    /// The expected number of points at RSA saturation density: the RSA
    /// density of every pixel's radius, summed in pixel order.
    #[must_use]
    pub fn expected_points(&self) -> f64 {
        match &self.map {
            Some(m) => rsa_count_serial(&m.radii),
            None => self.expected_points,
        }
    }

    /// The radius (1/64 px) of pixel index `p`.
    #[inline]
    #[must_use]
    pub fn radius_at(&self, p: u32) -> u32 {
        self.radius_in_map(p).map_or(self.radius_range.0, |r| *r)
    }

    /// Where the radius map holds slot `p`'s radius; `None` without a map.
    #[inline]
    pub(crate) fn radius_in_map(&self, p: u32) -> Option<&u32> {
        self.map.as_ref().map(|m| &m.radii[p as usize])
    }

    /// The darts of iteration with `empty` empty pixels: the batch, capped by
    /// the empty pixels (paper §3.3) and by the key layout.
    #[must_use]
    pub fn darts_for(&self, empty: u32) -> u32 {
        self.batch.min(empty).min(self.layout.max_batch())
    }

    /// The wrap periods in 1/256 px (0 when not periodic).
    #[must_use]
    pub fn periods(&self) -> (u32, u32) {
        if self.periodic {
            (
                self.width << fixed::POS_FRAC_BITS,
                self.height << fixed::POS_FRAC_BITS,
            )
        } else {
            (0, 0)
        }
    }
}

/// The RSA count of a radius map, summed in parallel, with a bound on how
/// far it lies from the sum in pixel order ([`rsa_count_serial`]).
#[derive(Clone, Copy, Debug)]
struct RsaCount {
    /// The sum.
    sum: f64,
    /// |sum − the sum in pixel order| is at most this.
    slack: f64,
}

impl RsaCount {
    /// A count known exactly.
    fn exact(sum: f64) -> Self {
        Self { sum, slack: 0.0 }
    }

    /// The default batch, half the count in pixel order, rounded: read off
    /// the parallel sum when every value within its slack rounds alike,
    /// else from `serial()`, so that the batch never depends on the
    /// summation order.
    fn batch(self, serial: impl FnOnce() -> f64) -> u32 {
        let of = |s: f64| (s / 2.0).round().clamp(1.0, f64::from(u32::MAX)) as u32;
        let (lo, hi) = (of(self.sum - self.slack), of(self.sum + self.slack));
        if lo == hi { lo } else { of(serial()) }
    }
}

/// The RSA count of `radii` (1/64 px; radius 0, a class's hole, left
/// out), in pixel order.
fn rsa_count_serial(radii: &[u32]) -> f64 {
    radii
        .iter()
        .filter(|&&r| r > 0)
        .map(|&r| rsa_per_pixel(r))
        .sum::<f64>()
}

/// [`rsa_count_serial`] in parallel chunks. The terms are positive, so a
/// sum of n of them in any order lies within (n−1)·2⁻⁵³ of the exact sum,
/// relatively (Higham, Accuracy and Stability, §4.2): two orders differ
/// by less than 4·n·ε·sum.
fn rsa_count(radii: &[u32], (min, max): (u32, u32)) -> RsaCount {
    // The terms tabulated (the same values), and summed in four lanes.
    let table: Vec<f64> = if max - min < 1 << 16 {
        (min..=max)
            .map(|r| if r > 0 { rsa_per_pixel(r) } else { 0.0 })
            .collect()
    } else {
        Vec::new()
    };
    let term = |r: u32| match table.get((r.wrapping_sub(min)) as usize) {
        Some(&t) => t,
        None if r > 0 => rsa_per_pixel(r),
        None => 0.0,
    };
    let sum = radii
        .par_chunks(1 << 16)
        .map(|c| {
            let mut lanes = [0.0f64; 4];
            let quads = c.chunks_exact(4);
            let rest: f64 = quads.remainder().iter().map(|&r| term(r)).sum();
            for q in quads {
                for (lane, &r) in lanes.iter_mut().zip(q) {
                    *lane += term(r);
                }
            }
            lanes.iter().sum::<f64>() + rest
        })
        .collect::<Vec<f64>>()
        .iter()
        .sum::<f64>();
    RsaCount {
        sum,
        slack: 4.0 * radii.len() as f64 * f64::EPSILON * sum,
    }
}

/// The RSA point density that one pixel of radius `r_fx` contributes.
fn rsa_per_pixel(r_fx: u32) -> f64 {
    let r = f64::from(r_fx) / f64::from(RADIUS_ONE);
    RSA_DENSITY / (std::f64::consts::PI * r * r / 4.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_batch_is_half_the_rsa_count() {
        let plan = Params::new(1024, 1024).with_radius(8.5).plan().unwrap();
        let expected = 0.547 * 1024.0 * 1024.0 / (std::f64::consts::PI * 4.25 * 4.25);
        assert!((plan.expected_points - expected).abs() < 1e-6);
        assert_eq!(plan.batch, (expected / 2.0).round() as u32);
    }

    /// The batch read off the parallel sum is the one of the sum in pixel
    /// order, and a parallel sum too near a rounding edge defers to it.
    #[test]
    fn the_batch_does_not_depend_on_the_summation_order() {
        let mut state = 7u32;
        // Radii of 1..32 px, of 1..1100 px (past the table), and with
        // holes (radius 0).
        for (n, spread, holes) in [
            (1usize, 2000, false),
            (1000, 2000, false),
            (200_000, 2000, true),
            (1 << 20, 2000, false),
            (100_000, 70_000, false),
        ] {
            let radii: Vec<u32> = (0..n)
                .map(|i| {
                    state = crate::sampler::fixed::mix(state);
                    if holes && i % 7 == 3 {
                        0
                    } else {
                        64 + state % spread
                    }
                })
                .collect();
            let min = if holes { 0 } else { 64 };
            let count = rsa_count(&radii, (min, 64 + spread - 1));
            let serial = rsa_count_serial(&radii);
            assert!((count.sum - serial).abs() <= count.slack, "n {n}");
            let want = ((serial / 2.0).round() as u32).max(1);
            assert_eq!(count.batch(|| serial), want, "n {n}");
            assert_eq!(count.batch(|| panic!("the slack decides")), want, "n {n}");
        }
        let edge = RsaCount {
            sum: 5.0,
            slack: 0.5,
        };
        assert_eq!(edge.batch(|| 4.9), 2);
        assert_eq!(edge.batch(|| 5.1), 3);
    }

    #[test]
    fn bigger_policy_puts_radius_bits_above_the_index() {
        let radii: Vec<f32> = (0..256).map(|i| 2.0 + i as f32 / 64.0).collect();
        let map = Arc::new(RadiusMap::from_pixels(16, 16, &radii).unwrap());
        let plan = Params::new(16, 16)
            .with_radius_map(map)
            .with_policy(Policy::Bigger)
            .plan()
            .unwrap();
        let l = plan.layout;
        assert_eq!(l.radius_bits + l.index_bits, KEY_BITS);
        // A bigger radius beats any index; among equals the index decides.
        assert!(l.beats(l.key(0, 300), l.key(l.max_batch() - 1, 200)));
        assert!(l.beats(l.key(5, 200), l.key(4, 200)));
    }

    #[test]
    fn one_radius_takes_prior_path_for_smaller_and_the_same_points() {
        let smaller = Params::new(200, 120).with_radius(4.0).with_seed(3);
        assert_eq!(smaller.policy, Policy::Smaller);
        let prior = smaller.clone().with_policy(Policy::Prior);
        assert_eq!(smaller.plan().unwrap().policy, Policy::Prior);
        let run = |p: &Params| crate::sampler::cpu::sample(p, Default::default()).unwrap();
        assert_eq!(run(&smaller).points, run(&prior).points);
        // A radius map keeps its policy.
        let radii: Vec<f32> = (0..256).map(|i| 2.0 + i as f32 / 64.0).collect();
        let map = Arc::new(RadiusMap::from_pixels(16, 16, &radii).unwrap());
        let plan = Params::new(16, 16).with_radius_map(map).plan().unwrap();
        assert_eq!(plan.policy, Policy::Smaller);
    }

    #[test]
    fn impossible_parameters_are_refused() {
        assert!(Params::new(0, 10).plan().is_err());
        assert!(
            Params::new(10, crate::sampler::fixed::MAX_SIDE + 1)
                .plan()
                .is_err()
        );
        assert!(Params::new(64, 64).with_radius(f32::NAN).plan().is_err());
        assert!(Params::new(64, 64).with_radius(0.5).plan().is_err());
        assert!(Params::new(64, 64).with_radius(65.0).plan().is_err());
        assert!(
            Params::new(64, 64)
                .with_radius(40.0)
                .with_periodic(true)
                .plan()
                .is_err()
        );
        assert!(Params::new(64, 64).with_subpixel_bits(8).plan().is_err());
        assert!(RadiusMap::from_pixels(2, 2, &[1.0, 2.0, f32::NAN, 3.0]).is_err());
        assert!(RadiusMap::from_pixels(2, 2, &[1.0, 2.0, -1.0, 3.0]).is_err());
        assert!(RadiusMap::from_pixels(2, 2, &[1.0, 2.0]).is_err());
    }
}
