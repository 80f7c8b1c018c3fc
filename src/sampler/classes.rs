//! Multi-class sampling (Wei 2010, "Multi-class blue noise sampling") in the
//! one PixelPie loop: a radius map per class, and a cross-class radius.
//!
//! # Semantics
//!
//! * **Classes.** C classes over the W×H domain, each with its own radius
//!   map r_c(p), or no samples of class c at pixel p ("no ink there").
//! * **Cross radius.** R(p) = 1 / √(Σ_c 1 / r_c(p)²) over the classes that
//!   have a radius at p, quantized to 1/64 px and at least 1 px: the radius of
//!   the union of all classes, whose density is the sum of theirs. R ≤ r_c.
//! * **Slots.** The run samples C·W·H slots, slot s = c·W·H + p (class-major):
//!   the empty list holds slots, a dart lands on an empty slot, takes its
//!   class and pixel from it, and its own radius r_c(p). Slots of a class
//!   with no radius at the pixel start covered.
//! * **Separation.** Between samples i and j the policy's f applies to
//!   (r_i, r_j) when they share a class and to (R_i, R_j) otherwise: each
//!   class is a Poisson-disk set of its own radii, and all samples together
//!   one of the cross radii (Wei's r-matrix with the union on its
//!   off-diagonal).
//! * **Conflicts** within a batch: dart j survives iff no dart i whose key
//!   beats j's has |c_i − p_j| < ρ_i, ρ_i = r_i for the same class and R_i
//!   for another. **Coverage:** slot (c, p) is covered when an accepted i has
//!   |p − c_i| < f(r_i, r_c(p)) (same class) or f(R_i, R(p)) (other class).
//! * **Maximal** means no slot is empty: no dart of any class fits anywhere.
//! * Keys, darts, compaction and output follow [`super`] with slots for
//!   pixels; each point carries its class ([`super::Point::class`]).

use std::sync::Arc;

use rayon::prelude::*;

use super::fixed::{self, MIN_RADIUS_FX, RADIUS_ONE, radius_to_fx};
use super::radius_map::RadiusMap;
use super::{Error, Result};

/// The most classes a run may have.
pub const MAX_CLASSES: u32 = 16;

/// A radius map per class and the cross-class radius derived from them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ClassRadii {
    /// The classes' radii stacked: class c's map is rows c·H .. (c+1)·H;
    /// 0 where the class has no samples.
    pub(crate) stacked: Arc<RadiusMap>,
    /// R(p), 1/64 px, for every pixel; 0 where no class has a radius.
    pub(crate) cross: Arc<Vec<u32>>,
    /// Classes.
    pub(crate) classes: u32,
    /// Whether some slot has no radius (and starts covered).
    pub(crate) holes: bool,
}

/// Slots per chunk of the parallel scans over every class's radii.
const SCAN_CHUNK: usize = 1 << 16;

impl ClassRadii {
    /// Radius maps in pixels, one per class, each `width`×`height` values,
    /// row-major. A value of `f32::INFINITY` means "no samples of this class
    /// here"; every other value must be a number of at least 1 px.
    ///
    /// ```
    /// use pixelpie::sampler::ClassRadii;
    /// let c = ClassRadii::new(2, 1, &[vec![4.0, 4.0], vec![4.0, f32::INFINITY]]).unwrap();
    /// assert_eq!(c.classes(), 2);
    /// assert!((c.cross_px(0, 0) - 4.0 / 2f32.sqrt()).abs() < 1.0 / 64.0);
    /// assert_eq!(c.cross_px(1, 0), 4.0);
    /// ```
    pub fn new(width: u32, height: u32, maps: &[Vec<f32>]) -> Result<Self> {
        let pixels = width as usize * height as usize;
        if let Some(map) = maps.iter().find(|m| m.len() != pixels) {
            return Err(Error::RadiusMapSize {
                expected: (width, height),
                len: map.len(),
            });
        }
        Self::from_fn(width, height, maps.len(), |c, i| maps[c][i])
    }

    /// [`Self::new`] of the radii `radius(c, i)` of class `c` at pixel `i`
    /// (row-major), without a buffer of them: made in parallel, quantized
    /// as they are made. The first bad pixel is the one reported.
    pub fn from_fn(
        width: u32,
        height: u32,
        classes: usize,
        radius: impl Fn(usize, usize) -> f32 + Sync,
    ) -> Result<Self> {
        super::radius_map::check_size(width, height)?;
        if classes == 0 || classes > MAX_CLASSES as usize {
            return Err(Error::InvalidParameter(format!(
                "{classes} classes: a run takes 1 to {MAX_CLASSES}"
            )));
        }
        let classes = classes as u32;
        let pixels = width as usize * height as usize;
        if (pixels as u64) * u64::from(classes) > u64::from(u32::MAX >> 1) {
            return Err(Error::InvalidSize(format!(
                "{width}x{height} with {classes} classes: too many slots"
            )));
        }
        // u32::MAX marks a radius below 1 px (or not a number).
        let mut radii = vec![0u32; pixels * classes as usize];
        radii
            .par_chunks_mut(width as usize)
            .enumerate()
            .for_each(|(row, out)| {
                let (c, y) = (row / height as usize, row % height as usize);
                let first = y * width as usize;
                for (x, o) in out.iter_mut().enumerate() {
                    let r = radius(c, first + x);
                    *o = if r == f32::INFINITY {
                        0
                    } else {
                        let fx = if r.is_finite() {
                            radius_to_fx(r.max(0.0))
                        } else {
                            0
                        };
                        if fx < MIN_RADIUS_FX { u32::MAX } else { fx }
                    };
                }
            });
        // Found in parallel by chunks, then the first one in order (rayon's
        // position_first over every slot took half a second at 1M dots).
        let has = |chunk: &[u32], v: u32| chunk.contains(&v);
        if radii.par_chunks(SCAN_CHUNK).any(|c| has(c, u32::MAX)) {
            let bad = radii.iter().position(|&r| r == u32::MAX).unwrap_or(0);
            let (c, i) = (bad / pixels, bad % pixels);
            return Err(Error::InvalidRadius(format!(
                "class {c} holds {} px at pixel ({}, {}); radii must be at least 1 px",
                radius(c, i),
                i as u32 % width,
                i as u32 / width
            )));
        }
        let cross: Vec<u32> = (0..pixels)
            .into_par_iter()
            .map(|p| {
                let density: f64 = (0..classes as usize)
                    .map(|c| radii[c * pixels + p])
                    .filter(|&r| r > 0)
                    .map(|r| {
                        let r = f64::from(r) / f64::from(RADIUS_ONE);
                        1.0 / (r * r)
                    })
                    .sum();
                if density == 0.0 {
                    0
                } else {
                    radius_to_fx((1.0 / density.sqrt()) as f32).max(MIN_RADIUS_FX)
                }
            })
            .collect();
        let holes = radii.par_chunks(SCAN_CHUNK).any(|c| has(c, 0));
        let stacked = RadiusMap::stacked(width, height * classes, radii);
        Ok(Self {
            stacked: Arc::new(stacked),
            cross: Arc::new(cross),
            classes,
            holes,
        })
    }

    /// The number of classes.
    #[must_use]
    pub fn classes(&self) -> u32 {
        self.classes
    }

    /// The domain's width.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.stacked.width()
    }

    /// The domain's height.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.stacked.height() / self.classes
    }

    /// Class `c`'s radius at pixel (x, y) in pixels; `None` where it has none.
    #[must_use]
    pub fn radius_px(&self, c: u32, x: u32, y: u32) -> Option<f32> {
        let r = self.stacked.radius_px(x, c * self.height() + y);
        (r > 0.0).then_some(r)
    }

    /// The cross-class radius at pixel (x, y) in pixels (0 where no class
    /// has a radius).
    #[must_use]
    pub fn cross_px(&self, x: u32, y: u32) -> f32 {
        fixed::fx_to_radius(self.cross[(y * self.width() + x) as usize])
    }
}
