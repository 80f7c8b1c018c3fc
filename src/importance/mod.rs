//! Importance maps: images turned into a radius field for the sampler (paper
//! §3.4, "the constant r in Equation 2 is replaced by a radius function").
//!
//! The pipeline, each stage a function a caller may stop at:
//!
//! 1. [`load`] decodes PNG, JPEG, TIFF, BMP and WebP through `image`, and
//!    OpenEXR through [`crate::io::read_exr`], into **linear** luminance
//!    Y = 0.2126 R + 0.7152 G + 0.0722 B (Rec. 709). 8- and 16-bit samples
//!    are sRGB-decoded first; float samples (EXR, float TIFF) are already
//!    linear. NaN and infinite samples are refused with the file, channel
//!    and pixel named; negative float samples count as 0.
//! 2. **Normalization** to [0, 1]: integer images are already there; float
//!    images are divided by their *white point*, by default the 99.5th
//!    percentile of their luminance ([`HDR_PERCENTILE`]), and clipped, so that
//!    a few specular highlights do not leave the rest of the picture black.
//!    Alpha composites over white paper: transparent pixels need no dots.
//! 3. [`ImportanceMap::resized`] resamples the linear values (triangle filter).
//! 4. [`ImportanceMap::toned`] picks the grey the drawing reproduces
//!    ([`Tones`]): by default the display grey, the sRGB-encoded value a
//!    viewer sees (what StippleGen targets and the stippling literature
//!    compares against); or linear light.
//! 5. [`Adjust`]: black and white levels, then gamma, then invert.
//! 6. [`Mapping`] turns the value v (0 = black = most important) into a radius
//!    between r_min and r_max; [`ImportanceMap::keeps`] applies the white
//!    cutoff (no dots where v is above it).

pub mod budget;
mod colour;
mod fit;
mod frame;
pub mod ink;
mod ink_table;
mod load;
mod mapping;
mod options;

use std::path::{Path, PathBuf};

pub use colour::ColourMap;
pub use fit::{Classes, Prepared};
pub use frame::{Crop, check_rotation, frame};
pub use load::{
    Luminance, Range, cut_short, cut_short_bytes, decode_file, linear_to_srgb, load, load_bytes,
    srgb_to_linear,
};
pub use mapping::{Mapping, RadiusRange};
pub use options::{DEFAULT_RADIUS_RATIO, ImportanceOptions, MappingKind};

use rayon::prelude::*;

use crate::sampler::Point;

/// The percentile of a float image's luminance that becomes white.
pub const HDR_PERCENTILE: f64 = 99.5;

/// What can go wrong while making an importance map.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be opened or read. (The cause is part of the
    /// message, not a `source`, so that error chains do not repeat it.)
    #[error("cannot read '{}': {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The file is not an image we can decode, or is damaged.
    #[error("cannot decode image '{}': {message}", path.display())]
    Decode {
        /// The file.
        path: PathBuf,
        /// The decoder's message.
        message: String,
    },
    /// The picture would take more memory than the budget allows
    /// ([`budget`]): said from its header, before decoding.
    #[error("'{}' {message}", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size, what it needs and what is allowed.
        message: String,
    },
    /// A drawing that would take more memory than the budget allows.
    #[error("{0}")]
    Memory(String),
    /// The image has no pixels.
    #[error("image '{}' has no pixels", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A sample is NaN or infinite.
    #[error("image '{}' holds {value} in channel '{channel}' at pixel ({x}, {y}); importance maps need finite values", path.display())]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// The channel's name.
        channel: String,
        /// The pixel's column.
        x: u32,
        /// The pixel's row.
        y: u32,
        /// The offending value.
        value: f32,
    },
    /// An EXR file without a luminance or RGB channel set.
    #[error("EXR '{}' has no Y channel, no R, G and B channels and not exactly one channel (it has: {channels})", path.display())]
    Channels {
        /// The file.
        path: PathBuf,
        /// The channel names found.
        channels: String,
    },
    /// A parameter out of range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
}

/// The result type of this module.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Which grey a drawing reproduces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Tones {
    /// The display grey: the sRGB-encoded value a viewer sees. Mid grey
    /// (sRGB 0.5) gets half the ink of black.
    #[default]
    Display,
    /// Linear light (luminance): sRGB 0.5 is 21% light, so it gets 79% of
    /// black's ink.
    Linear,
}

impl Tones {
    /// The grey of the linear value `v` in these tones.
    #[inline]
    #[must_use]
    pub fn tone(self, v: f32) -> f32 {
        match self {
            Self::Display => linear_to_srgb(v).clamp(0.0, 1.0),
            Self::Linear => v,
        }
    }

    /// The linear luminance of tone `t` in [0, 1]: [`Self::tone`]'s
    /// inverse.
    #[must_use]
    pub fn untone(self, t: f32) -> f32 {
        match self {
            Self::Display => crate::colour::srgb_to_linear(t),
            Self::Linear => t,
        }
    }
}

/// Tone adjustments, applied in this order: levels, gamma, invert.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Adjust {
    /// Values at or below this level become 0 (black).
    pub black: f32,
    /// Values at or above this level become 1 (white).
    pub white: f32,
    /// v ↦ v^gamma after the levels: above 1 darkens the mid-tones (more dots).
    pub gamma: f32,
    /// v ↦ 1 − v at the end: light parts become the important ones.
    pub invert: bool,
}

impl Default for Adjust {
    fn default() -> Self {
        Self {
            black: 0.0,
            white: 1.0,
            gamma: 1.0,
            invert: false,
        }
    }
}

impl Adjust {
    /// Checks that 0 ≤ black < white ≤ 1 and that gamma is a positive number.
    ///
    /// ```
    /// use pixelpie::importance::Adjust;
    /// assert!(Adjust { black: 0.5, white: 0.4, ..Adjust::default() }.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<()> {
        let ok = self.black.is_finite()
            && self.white.is_finite()
            && 0.0 <= self.black
            && self.black < self.white
            && self.white <= 1.0;
        if !ok {
            return Err(Error::InvalidParameter(format!(
                "«black_level={}» and «white_level={}» must satisfy 0 <= black < white <= 1",
                self.black, self.white
            )));
        }
        if !(self.gamma.is_finite() && self.gamma > 0.0) {
            return Err(Error::InvalidParameter(format!(
                "«gamma={}» must be a positive number",
                self.gamma
            )));
        }
        Ok(())
    }

    /// Applies the adjustments to one value in [0, 1].
    ///
    /// ```
    /// use pixelpie::importance::Adjust;
    /// let a = Adjust { black: 0.2, white: 0.6, gamma: 2.0, invert: true };
    /// assert!((a.apply(0.4) - 0.75).abs() < 1e-6);
    /// ```
    #[inline]
    #[must_use]
    pub fn apply(&self, v: f32) -> f32 {
        let v = ((v - self.black) / (self.white - self.black)).clamp(0.0, 1.0);
        let v = if self.gamma == 1.0 {
            v
        } else {
            v.powf(self.gamma)
        };
        if self.invert { 1.0 - v } else { v }
    }
}

/// Importance values v ∈ [0, 1] per pixel, row-major, top row first;
/// 0 (black) is the most important.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportanceMap {
    width: u32,
    height: u32,
    values: Vec<f32>,
}

impl ImportanceMap {
    /// A map from values in [0, 1]; refuses a wrong length or values outside.
    ///
    /// ```
    /// let m = pixelpie::importance::ImportanceMap::from_values(2, 1, vec![0.0, 1.0]).unwrap();
    /// assert_eq!(m.value(1, 0), 1.0);
    /// ```
    pub fn from_values(width: u32, height: u32, values: Vec<f32>) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::InvalidParameter(format!(
                "importance map size {width}x{height} has no pixels"
            )));
        }
        if values.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(Error::InvalidParameter(format!(
                "{} values for a {width}x{height} importance map",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !(0.0..=1.0).contains(v)) {
            return Err(Error::InvalidParameter(format!(
                "importance {} at pixel ({}, {}) is outside [0, 1]",
                values[i],
                i as u64 % u64::from(width),
                i as u64 / u64::from(width)
            )));
        }
        Ok(Self {
            width,
            height,
            values,
        })
    }

    /// Loads `path` and normalizes it (steps 1 and 2 of the module's
    /// pipeline). `hdr_white` overrides the white point of float images.
    pub fn open(path: &Path, hdr_white: Option<f32>) -> Result<Self> {
        load(path)?.normalized(hdr_white)
    }

    /// [`Self::open`] for an image file held in memory (not EXR); `name`
    /// names it in errors.
    pub fn from_encoded(bytes: &[u8], name: &Path, hdr_white: Option<f32>) -> Result<Self> {
        load_bytes(bytes, name)?.normalized(hdr_white)
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

    /// The values, row-major.
    #[must_use]
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The value of pixel (x, y).
    #[must_use]
    pub fn value(&self, x: u32, y: u32) -> f32 {
        self.values[(u64::from(y) * u64::from(self.width) + u64::from(x)) as usize]
    }

    /// The value of the pixel that holds the point (x, y) in pixel units
    /// (clamped to the map).
    #[must_use]
    pub fn value_at(&self, x: f32, y: f32) -> f32 {
        let px = (x.max(0.0) as u32).min(self.width - 1);
        let py = (y.max(0.0) as u32).min(self.height - 1);
        self.value(px, py)
    }

    /// The map resampled to `width`×`height` with a triangle filter (area
    /// averaging when shrinking), on linear values.
    ///
    /// ```
    /// use pixelpie::importance::ImportanceMap;
    /// let m = ImportanceMap::from_values(2, 2, vec![0.0, 1.0, 0.0, 1.0]).unwrap();
    /// let r = m.resized(1, 1).unwrap();
    /// assert!((r.value(0, 0) - 0.5).abs() < 1e-6);
    /// ```
    pub fn resized(&self, width: u32, height: u32) -> Result<Self> {
        self.resized_with(width, height, |v| v)
    }

    /// [`Self::resized`] with `post` applied to every value as it is made:
    /// one pass and one map where resizing, then mapping, take two of each.
    pub fn resized_with(
        &self,
        width: u32,
        height: u32,
        post: impl Fn(f32) -> f32 + Sync,
    ) -> Result<Self> {
        if (width, height) == (self.width, self.height) {
            return Ok(Self {
                width,
                height,
                values: self.values.par_iter().map(|&v| post(v)).collect(),
            });
        }
        if width == 0 || height == 0 {
            return Err(Error::InvalidParameter(format!(
                "cannot resize the importance map to {width}x{height}"
            )));
        }
        if self.values.len() != self.width as usize * self.height as usize {
            return Err(Error::InvalidParameter(
                "importance map buffer has the wrong size".into(),
            ));
        }
        let values = resize_triangle(
            &self.values,
            (self.width, self.height),
            (width, height),
            post,
        );
        Ok(Self {
            width,
            height,
            values,
        })
    }

    /// The map's values as the grey `tones` asks for: the loaded values are
    /// linear light; [`Tones::Display`] sRGB-encodes them.
    ///
    /// ```
    /// use pixelpie::importance::{ImportanceMap, Tones};
    /// let m = ImportanceMap::from_values(1, 1, vec![0.214]).unwrap();
    /// assert!((m.toned(Tones::Display).value(0, 0) - 0.5).abs() < 1e-3);
    /// assert_eq!(m.toned(Tones::Linear), m);
    /// ```
    #[must_use]
    pub fn toned(&self, tones: Tones) -> Self {
        match tones {
            Tones::Linear => self.clone(),
            Tones::Display => Self {
                width: self.width,
                height: self.height,
                values: self.values.par_iter().map(|&v| tones.tone(v)).collect(),
            },
        }
    }

    /// The map with `value` at every pixel index `i` where `pick(i)`.
    #[must_use]
    pub fn with_values_where(mut self, pick: impl Fn(usize) -> bool + Sync, value: f32) -> Self {
        let value = value.clamp(0.0, 1.0);
        self.values
            .par_iter_mut()
            .enumerate()
            .filter(|(i, _)| pick(*i))
            .for_each(|(_, v)| *v = value);
        self
    }

    /// The map with `adjust` applied to every value.
    pub fn adjusted(&self, adjust: &Adjust) -> Result<Self> {
        adjust.validate()?;
        Ok(Self {
            width: self.width,
            height: self.height,
            values: self.values.par_iter().map(|&v| adjust.apply(v)).collect(),
        })
    }

    /// The radius of every pixel under `mapping`, row-major.
    ///
    /// ```
    /// use pixelpie::importance::{ImportanceMap, Mapping, RadiusRange};
    /// let m = ImportanceMap::from_values(3, 1, vec![0.0, 0.5, 1.0]).unwrap();
    /// let r = m.radii(Mapping::Linear, RadiusRange::new(2.0, 4.0).unwrap());
    /// assert_eq!(r, vec![2.0, 3.0, 4.0]);
    /// ```
    #[must_use]
    pub fn radii(&self, mapping: Mapping, range: RadiusRange) -> Vec<f32> {
        let radius = Self::radius_fn(mapping, range);
        self.values.par_iter().map(|&v| radius(v)).collect()
    }

    /// The radius of a value under `mapping`, as [`Self::radii`] gives it.
    pub fn radius_fn(mapping: Mapping, range: RadiusRange) -> impl Fn(f32) -> f32 + Sync {
        // The calibrated mappings invert a curve: tabulate them once per
        // mapping and range in the process (a drawing asks for the same
        // table a dozen times, a colour one for each pen's).
        const STEPS: usize = 4096;
        /// Tables kept, the latest made.
        const KEPT: usize = 32;
        type Table = (Mapping, RadiusRange, std::sync::Arc<Vec<f32>>);
        static TABLES: std::sync::Mutex<Vec<Table>> = std::sync::Mutex::new(Vec::new());
        let lut: std::sync::Arc<Vec<f32>> = if mapping == Mapping::Linear {
            std::sync::Arc::new(Vec::new())
        } else {
            let kept = TABLES.lock().ok().and_then(|t| {
                t.iter()
                    .find(|(m, r, _)| *m == mapping && *r == range)
                    .map(|(_, _, lut)| lut.clone())
            });
            kept.unwrap_or_else(|| {
                let lut: std::sync::Arc<Vec<f32>> = std::sync::Arc::new(
                    (0..=STEPS)
                        .into_par_iter()
                        .map(|i| mapping.radius(i as f32 / STEPS as f32, range))
                        .collect(),
                );
                if let Ok(mut t) = TABLES.lock() {
                    if t.len() == KEPT {
                        t.remove(0);
                    }
                    t.push((mapping, range, lut.clone()));
                }
                lut
            })
        };
        move |v: f32| {
            if lut.is_empty() {
                return mapping.radius(v, range);
            }
            let x = v.clamp(0.0, 1.0) * STEPS as f32;
            let i = (x as usize).min(STEPS - 1);
            let f = x - i as f32;
            lut[i] + f * (lut[i + 1] - lut[i])
        }
    }

    /// Whether a dot at (x, y) survives the white cutoff: its pixel's value is
    /// at most `cutoff` (`None` keeps every dot).
    #[must_use]
    pub fn keeps(&self, x: f32, y: f32, cutoff: Option<f32>) -> bool {
        cutoff.is_none_or(|c| self.value_at(x, y) <= c)
    }

    /// The points that survive the white cutoff, in their order.
    #[must_use]
    pub fn cut(&self, points: &[Point], cutoff: Option<f32>) -> Vec<Point> {
        points
            .par_iter()
            .filter(|p| self.keeps(p.x, p.y, cutoff))
            .copied()
            .collect()
    }

    /// The expected number of dots for `radii` at RSA saturation density,
    /// counting only pixels that survive the white cutoff. It starts the
    /// search of `--points` ([`crate::count::fit_scale`]).
    #[must_use]
    pub fn expected_points(&self, radii: &[f32], cutoff: Option<f32>) -> f64 {
        self.values
            .iter()
            .zip(radii)
            .filter(|(v, _)| cutoff.is_none_or(|c| **v <= c))
            .map(|(_, &r)| ink::rsa_per_pixel(f64::from(r)))
            .sum()
    }
}

/// The size that keeps `width`×`height`'s aspect when only one side is given.
///
/// ```
/// use pixelpie::importance::fit_size;
/// assert_eq!(fit_size((400, 200), Some(100), None), (100, 50));
/// assert_eq!(fit_size((400, 200), None, None), (400, 200));
/// ```
#[must_use]
pub fn fit_size(source: (u32, u32), width: Option<u32>, height: Option<u32>) -> (u32, u32) {
    let (w, h) = (f64::from(source.0), f64::from(source.1));
    match (width, height) {
        (Some(a), Some(b)) => (a, b),
        (Some(a), None) => (a, ((f64::from(a) * h / w).round() as u32).max(1)),
        (None, Some(b)) => (((f64::from(b) * w / h).round() as u32).max(1), b),
        (None, None) => source,
    }
}

/// One axis of the triangle (bilinear) filter: for each output position,
/// the first input index and the normalized weights, as `image`'s
/// `imageops::resize` computes them (the same f32 arithmetic).
fn triangle_weights(from: u32, to: u32) -> Vec<(u32, Vec<f32>)> {
    let ratio = from as f32 / to as f32;
    let sratio = if ratio < 1.0 { 1.0 } else { ratio };
    let support = sratio;
    (0..to)
        .map(|o| {
            let input = (o as f32 + 0.5) * ratio;
            let left = ((input - support).floor() as i64).clamp(0, i64::from(from) - 1) as u32;
            let right = ((input + support).ceil() as i64)
                .clamp(i64::from(left) + 1, i64::from(from)) as u32;
            let input = input - 0.5;
            let mut ws: Vec<f32> = (left..right)
                .map(|i| {
                    let x = (i as f32 - input) / sratio;
                    if x.abs() < 1.0 { 1.0 - x.abs() } else { 0.0 }
                })
                .collect();
            let sum: f32 = ws.iter().fold(0.0, |a, w| a + w);
            for w in &mut ws {
                *w /= sum;
            }
            (left, ws)
        })
        .collect()
}

/// `values` (`from`, row-major) resized to `to` by the triangle filter and
/// clamped to [0, 1]: `image::imageops::resize(…, FilterType::Triangle)`
/// value for value (a vertical pass, then a horizontal one, each output's
/// sum in the same order), with rows in parallel.
pub(crate) fn resize_triangle(
    values: &[f32],
    from: (u32, u32),
    to: (u32, u32),
    post: impl Fn(f32) -> f32 + Sync,
) -> Vec<f32> {
    let w = from.0 as usize;
    let (nw, nh) = (to.0 as usize, to.1 as usize);
    let vertical = triangle_weights(from.1, to.1);
    let mut tmp = vec![0.0f32; w * nh];
    tmp.par_chunks_mut(w.max(1))
        .zip(vertical.par_iter())
        .for_each(|(row, (top, ws))| {
            for (x, out) in row.iter_mut().enumerate() {
                let mut t = 0.0f32;
                for (i, wt) in ws.iter().enumerate() {
                    t += values[(*top as usize + i) * w + x] * wt;
                }
                *out = t;
            }
        });
    let horizontal = triangle_weights(from.0, to.0);
    let mut out = vec![0.0f32; nw * nh];
    out.par_chunks_mut(nw.max(1))
        .zip(tmp.par_chunks(w.max(1)))
        .for_each(|(row, src)| {
            for (o, (left, ws)) in row.iter_mut().zip(&horizontal) {
                let mut t = 0.0f32;
                for (i, wt) in ws.iter().enumerate() {
                    t += src[*left as usize + i] * wt;
                }
                *o = post(t.clamp(0.0, 1.0));
            }
        });
    out
}

#[cfg(test)]
mod resize_tests {
    use super::*;

    #[test]
    fn the_parallel_resize_is_images_value_for_value() {
        let mut s = 7u32;
        let mut next = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1 << 24) as f32
        };
        for (from, to) in [
            ((37, 23), (300, 211)),
            ((300, 211), (37, 23)),
            ((64, 64), (64, 129)),
            ((129, 64), (64, 64)),
            ((5, 3), (1024, 683)),
            ((1, 1), (7, 9)),
            ((50, 40), (77, 40)),
        ] {
            let values: Vec<f32> = (0..from.0 * from.1).map(|_| next()).collect();
            let buf = image::ImageBuffer::<image::Luma<f32>, Vec<f32>>::from_raw(
                from.0,
                from.1,
                values.clone(),
            )
            .unwrap();
            let theirs: Vec<f32> =
                image::imageops::resize(&buf, to.0, to.1, image::imageops::FilterType::Triangle)
                    .into_raw()
                    .into_iter()
                    .map(|v| v.clamp(0.0, 1.0))
                    .collect();
            let ours = resize_triangle(&values, from, to, |v| v);
            assert!(
                theirs
                    .iter()
                    .zip(&ours)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{from:?} -> {to:?}"
            );
        }
    }
}
