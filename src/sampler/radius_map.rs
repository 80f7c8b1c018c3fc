//! The radius map (a radius for every pixel, in the sampler's fixed point)
//! and the domain's size limits: what both a run's [`super::Params`] and
//! the classes' stacked maps ([`super::classes`]) build on.

use rayon::prelude::*;

use super::fixed::{self, MAX_SIDE, MIN_RADIUS_FX, radius_to_fx};
use super::{Error, Result};

/// The most pixels a domain may have.
pub const MAX_PIXELS: u64 = 1 << 30;

/// A radius for every pixel, quantized to 1/64 px (row-major, top row first).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RadiusMap {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) radii: Vec<u32>,
    pub(super) min: u32,
    pub(super) max: u32,
}

impl RadiusMap {
    /// Builds a map from radii in pixels. Refuses a wrong length, NaN, infinite
    /// values and radii below 1 px.
    ///
    /// ```
    /// let map = pixelpie::sampler::RadiusMap::from_pixels(2, 1, &[2.0, 3.5]).unwrap();
    /// assert_eq!(map.radius_px(1, 0), 3.5);
    /// ```
    pub fn from_pixels(width: u32, height: u32, radii: &[f32]) -> Result<Self> {
        check_size(width, height)?;
        if radii.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(Error::RadiusMapSize {
                expected: (width, height),
                len: radii.len(),
            });
        }
        Self::from_fn(width, height, |i| radii[i])
    }

    /// [`Self::from_pixels`] of the radii `radius(i)` of pixels `i` (row-major),
    /// without a buffer of them: computed in parallel, quantized as they are
    /// made. The first bad pixel is the one reported.
    pub fn from_fn(width: u32, height: u32, radius: impl Fn(usize) -> f32 + Sync) -> Result<Self> {
        let w = width as usize;
        Self::from_rows(width, height, |y, row| {
            for (r, i) in row.iter_mut().zip(y as usize * w..) {
                *r = radius(i);
            }
        })
    }

    /// [`Self::from_fn`] a row at a time: `fill(y, row)` writes the radii
    /// of row `y` (`width` of them) into `row`, so that a map read across
    /// a row (a picture enlarged to the domain) finds its place once per
    /// row, not once per pixel.
    pub fn from_rows(
        width: u32,
        height: u32,
        fill: impl Fn(u32, &mut [f32]) + Sync,
    ) -> Result<Self> {
        check_size(width, height)?;
        let w = width as usize;
        let n = w * height as usize;
        // u32::MAX stands for a radius that is not finite (or that large).
        // The smallest and largest are found as the radii are made.
        let mut radii = vec![0u32; n];
        let (min, max) = radii
            .par_chunks_mut(w)
            .enumerate()
            .map_init(
                || vec![0.0f32; w],
                |row, (y, out)| {
                    fill(y as u32, row);
                    let (mut lo, mut hi) = (u32::MAX, 0);
                    for (r_out, &r) in out.iter_mut().zip(row.iter()) {
                        let fx = if r.is_finite() {
                            radius_to_fx(r.max(0.0))
                        } else {
                            u32::MAX
                        };
                        (lo, hi) = (lo.min(fx), hi.max(fx));
                        *r_out = fx;
                    }
                    (lo, hi)
                },
            )
            .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        let at = |i: usize| (i as u32 % width, i as u32 / width);
        if max == u32::MAX
            && let Some((i, r)) = (0..height).into_par_iter().find_map_first(|y| {
                let mut row = vec![0.0f32; w];
                fill(y, &mut row);
                let x = row.iter().position(|r| !r.is_finite())?;
                Some((y as usize * w + x, row[x]))
            })
        {
            let (x, y) = at(i);
            return Err(Error::InvalidRadius(format!(
                "radius map holds {r} at pixel ({x}, {y})"
            )));
        }
        if min < MIN_RADIUS_FX {
            let i = radii
                .par_iter()
                .position_first(|&r| r < MIN_RADIUS_FX)
                .unwrap_or(0);
            let (x, y) = at(i);
            // The value as given (−3, 0.4), not as quantized (0).
            let mut row = vec![0.0f32; w];
            fill(y, &mut row);
            return Err(Error::InvalidRadius(format!(
                "radius map holds {} px at pixel ({x}, {y}); radii must be at least 1 px",
                row[x as usize],
            )));
        }
        Ok(Self {
            width,
            height,
            radii,
            min,
            max,
        })
    }

    /// [`Self::from_pixels`] of `radii` × `scale` (each product rounded to
    /// `f32`): the map that `--points` scales to a count.
    ///
    /// ```
    /// let map = pixelpie::sampler::RadiusMap::from_pixels_scaled(2, 1, &[2.0, 3.5], 2.0).unwrap();
    /// assert_eq!(map.radius_px(1, 0), 7.0);
    /// ```
    pub fn from_pixels_scaled(width: u32, height: u32, radii: &[f32], scale: f64) -> Result<Self> {
        let scaled: Vec<f32> = radii
            .par_iter()
            .map(|&r| (f64::from(r) * scale) as f32)
            .collect();
        Self::from_pixels(width, height, &scaled)
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// A map of quantized radii that may hold 0 ("no radius here", the
    /// classes' holes); min and max ignore the zeros. The height may pass
    /// [`fixed::MAX_SIDE`]: classes stack their maps.
    pub(crate) fn stacked(width: u32, height: u32, radii: Vec<u32>) -> Self {
        use rayon::prelude::*;
        // By chunks, each a plain loop (per slot, rayon's fold costs more
        // than the comparison).
        let (min, max) = radii
            .par_chunks(1 << 16)
            .map(|chunk| {
                chunk.iter().fold((u32::MAX, 0), |(lo, hi), &r| {
                    if r > 0 {
                        (lo.min(r), hi.max(r))
                    } else {
                        (lo, hi)
                    }
                })
            })
            .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        let (min, max) = if max == 0 {
            (MIN_RADIUS_FX, MIN_RADIUS_FX)
        } else {
            (min, max)
        };
        Self {
            width,
            height,
            radii,
            min,
            max,
        }
    }

    /// The quantized radii (1/64 px), row-major.
    #[must_use]
    pub fn radii_fx(&self) -> &[u32] {
        &self.radii
    }

    /// The radius of pixel (x, y) in pixels.
    #[must_use]
    pub fn radius_px(&self, x: u32, y: u32) -> f32 {
        fixed::fx_to_radius(self.radii[(y * self.width + x) as usize])
    }

    /// The smallest and largest radius (1/64 px).
    #[must_use]
    pub fn range_fx(&self) -> (u32, u32) {
        (self.min, self.max)
    }
}

/// Checks a domain's size: positive sides, at most [`MAX_SIDE`] each and
/// [`MAX_PIXELS`] in all.
pub(crate) fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::InvalidSize(format!(
            "{width}x{height}: width and height must be positive"
        )));
    }
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(Error::InvalidSize(format!(
            "{width}x{height}: width and height must be at most {MAX_SIDE}"
        )));
    }
    if u64::from(width) * u64::from(height) > MAX_PIXELS {
        return Err(Error::InvalidSize(format!(
            "{width}x{height}: at most {MAX_PIXELS} pixels"
        )));
    }
    Ok(())
}
