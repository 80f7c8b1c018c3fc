//! Colour pictures for drawing with several pens: linear RGB per pixel,
//! composited over white paper, resized like [`super::ImportanceMap`], and
//! separated into one importance map per pen ([`ColourMap::separate`]).
//!
//! Loading follows the grey pipeline's rules ([`super::load`]): 8- and
//! 16-bit samples are sRGB-decoded, float images (EXR, float TIFF) are
//! divided by their luminance's white point and clipped, NaN is refused,
//! and alpha composites over white. An EXR without R, G and B is grey.

use std::path::Path;

use super::{Error, ImportanceMap, Range, Result};
use crate::colour::Separation;
use rayon::prelude::*;

/// A colour picture: linear RGB in [0, 1] per pixel, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourMap {
    width: u32,
    height: u32,
    rgb: Vec<[f32; 3]>,
}

impl ColourMap {
    /// A map from linear RGB values in [0, 1].
    pub fn from_linear(width: u32, height: u32, rgb: Vec<[f32; 3]>) -> Result<Self> {
        if width == 0 || height == 0 || rgb.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(Error::InvalidParameter(format!(
                "{} colours for a {width}x{height} picture",
                rgb.len()
            )));
        }
        if rgb.iter().flatten().any(|v| !(0.0..=1.0).contains(v)) {
            return Err(Error::InvalidParameter(
                "colours must be linear RGB values in [0, 1]".into(),
            ));
        }
        Ok(Self { width, height, rgb })
    }

    /// Loads a picture file in colour (`hdr_white`: the white point of
    /// float images, by default their luminance's 99.5th percentile).
    pub fn open(path: &Path, hdr_white: Option<f32>) -> Result<Self> {
        // The grey loader checks the file (empty, damaged, NaN) and finds
        // the white point; the colours are decoded next to it.
        // Decoded once: the luminance and the colours from the same image.
        let (lum, img) =
            super::load::load_decoded_within(path, super::budget::COLOUR_BYTES_PER_PIXEL, true)?;
        let rgb = match img {
            Some(img) => raster_rgb(img, lum.range),
            None => exr_rgb(path, &lum)?,
        };
        Self::over_white(&lum, rgb, hdr_white)
    }

    /// [`Self::open`] of an image file held in memory (PNG, JPEG, TIFF, BMP,
    /// WebP); `name` names it in errors.
    pub fn from_encoded(bytes: &[u8], name: &Path, hdr_white: Option<f32>) -> Result<Self> {
        let lum =
            super::load::load_bytes_within(bytes, name, super::budget::COLOUR_BYTES_PER_PIXEL)?;
        let img = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .ok()
            .and_then(|r| super::load::upright(r).ok())
            .ok_or_else(|| Error::Decode {
                path: name.to_owned(),
                message: "cannot decode the picture".into(),
            })?;
        let rgb = raster_rgb(img, lum.range);
        Self::over_white(&lum, rgb, hdr_white)
    }

    /// The decoded colours divided by the white point and composited over
    /// white paper: straight alpha for raster images, premultiplied for EXR
    /// (OpenEXR's convention).
    fn over_white(
        lum: &super::Luminance,
        mut rgb: Vec<[f32; 3]>,
        hdr_white: Option<f32>,
    ) -> Result<Self> {
        let white = match (lum.range, hdr_white) {
            (Range::Unit, _) => 1.0,
            (Range::Float, Some(w)) if w.is_finite() && w > 0.0 => w,
            (Range::Float, Some(w)) => {
                return Err(Error::InvalidParameter(format!(
                    "«hdr_white={w}» must be a positive number"
                )));
            }
            (Range::Float, None) => lum.white_point(),
        };
        for (i, c) in rgb.iter_mut().enumerate() {
            let a = lum.alpha.as_ref().map_or(1.0, |a| a[i]);
            for v in c.iter_mut() {
                let v0 = (*v / white).max(0.0);
                let over = if lum.premultiplied {
                    v0 + (1.0 - a)
                } else {
                    a * v0 + (1.0 - a)
                };
                *v = over.clamp(0.0, 1.0);
            }
        }
        Self::from_linear(lum.width, lum.height, rgb)
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

    /// The linear colours, row-major.
    #[must_use]
    pub fn rgb(&self) -> &[[f32; 3]] {
        &self.rgb
    }

    /// The picture's luminance as a grey importance map (linear light).
    #[must_use]
    pub fn luminance(&self) -> ImportanceMap {
        let values = self
            .rgb
            .iter()
            .map(|c| (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]).clamp(0.0, 1.0))
            .collect();
        ImportanceMap::from_values(self.width, self.height, values)
            .expect("luminance of a checked picture is in range")
    }

    /// The picture resampled to `width`×`height` with a triangle filter, on
    /// linear values (as [`ImportanceMap::resized`]).
    pub fn resized(&self, width: u32, height: u32) -> Result<Self> {
        if (width, height) == (self.width, self.height) {
            return Ok(self.clone());
        }
        if width == 0 || height == 0 {
            return Err(Error::InvalidParameter(format!(
                "cannot resize the picture to {width}x{height}"
            )));
        }
        // Channel by channel through the grey maps' parallel resize, which
        // is `image`'s triangle filter value for value.
        let planes = [0, 1, 2].map(|k| {
            let plane: Vec<f32> = self.rgb.iter().map(|c| c[k]).collect();
            super::resize_triangle(&plane, (self.width, self.height), (width, height), |v| v)
        });
        let rgb = (0..planes[0].len())
            .map(|i| [planes[0][i], planes[1][i], planes[2][i]])
            .collect();
        Ok(Self { width, height, rgb })
    }

    /// The picture with the grey drawing's tone adjustments (levels,
    /// gamma, invert) applied to its lightness, hue kept: each pixel's
    /// luminance Y, in the drawing's `tones`, goes through `adjust` as a
    /// grey pixel's value would, and the colour is scaled to the new
    /// luminance; where that pushes a channel past 1, the colour moves
    /// toward the grey of the same luminance until it fits. So a grey
    /// picture is adjusted exactly as the grey drawing adjusts it.
    /// Returns the picture and each pixel's adjusted tone (what
    /// `--white-cutoff` compares).
    pub fn adjusted(
        &self,
        tones: super::Tones,
        adjust: &super::Adjust,
    ) -> Result<(Self, Vec<f32>)> {
        use rayon::prelude::*;
        adjust.validate()?;
        let (rgb, tone): (Vec<[f32; 3]>, Vec<f32>) = self
            .rgb
            .par_iter()
            .map(|&c| {
                let y = (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]).clamp(0.0, 1.0);
                let t = adjust.apply(tones.tone(y));
                let y2 = match tones {
                    super::Tones::Linear => t,
                    super::Tones::Display => crate::colour::srgb_to_linear(t),
                }
                .clamp(0.0, 1.0);
                let out = if y <= 1e-6 {
                    [y2; 3]
                } else {
                    let s = y2 / y;
                    let scaled = c.map(|v| v * s);
                    let top = scaled.iter().copied().fold(0.0f32, f32::max);
                    if top > 1.0 {
                        // Toward the grey of luminance y2, which fits.
                        let k = (1.0 - y2) / (top - y2).max(1e-6);
                        scaled.map(|v| (y2 + k * (v - y2)).clamp(0.0, 1.0))
                    } else {
                        scaled.map(|v| v.clamp(0.0, 1.0))
                    }
                };
                (out, t)
            })
            .unzip();
        Ok((
            Self {
                width: self.width,
                height: self.height,
                rgb,
            },
            tone,
        ))
    }

    /// One importance map per pen: v = 1 − the pen's ink (0 = full ink),
    /// by `separation`.
    pub fn separate(&self, separation: &Separation) -> Vec<ImportanceMap> {
        separation
            .image(&self.rgb)
            .into_par_iter()
            .map(|mut v| {
                // In place: the ink's plane becomes the map's values.
                for a in &mut v {
                    *a = (1.0 - *a).clamp(0.0, 1.0);
                }
                ImportanceMap::from_values(self.width, self.height, v).expect("inks are in range")
            })
            .collect()
    }
}

impl ImportanceMap {
    /// The map's grey as a colour picture (its values as linear light).
    #[must_use]
    pub fn colours(&self) -> ColourMap {
        ColourMap {
            width: self.width(),
            height: self.height(),
            rgb: self.values().iter().map(|&v| [v; 3]).collect(),
        }
    }
}

/// The linear RGB of a raster image file (not yet divided by the white
/// point), with its alpha left to the caller.
fn raster_rgb(img: image::DynamicImage, range: Range) -> Vec<[f32; 3]> {
    use image::DynamicImage as D;
    if range == Range::Float {
        return img.to_rgb32f().pixels().map(|p| p.0).collect();
    }
    // 8 bits a channel (most photos): the 256 values they widen to (v·257),
    // not a table of all 65536.
    if matches!(
        img,
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_)
    ) {
        let lut: [f32; 256] = std::array::from_fn(|v| linear16(v as u16 * 257));
        return img
            .to_rgb8()
            .pixels()
            .map(|p| p.0.map(|v| lut[usize::from(v)]))
            .collect();
    }
    let lut: Vec<f32> = (0..=u16::MAX).map(linear16).collect();
    img.to_rgb16()
        .pixels()
        .map(|p| p.0.map(|v| lut[usize::from(v)]))
        .collect()
}

/// The linear light of a 16-bit sRGB value.
fn linear16(v: u16) -> f32 {
    crate::colour::srgb_to_linear(f32::from(v) / 65535.0)
}

/// The linear RGB of an EXR: its R, G and B channels, or its luminance.
fn exr_rgb(path: &Path, lum: &super::Luminance) -> Result<Vec<[f32; 3]>> {
    let img = crate::io::read_exr(path).map_err(|e| Error::Decode {
        path: path.to_owned(),
        message: crate::text::single_line(&e.to_string()),
    })?;
    let find = |name: &str| {
        img.channels
            .iter()
            .find(|(n, _)| n.rsplit('.').next() == Some(name))
            .map(|(_, v)| v)
    };
    Ok(match (find("Y"), find("R"), find("G"), find("B")) {
        (None, Some(r), Some(g), Some(b)) => (0..r.len()).map(|i| [r[i], g[i], b[i]]).collect(),
        _ => lum.values.iter().map(|&v| [v; 3]).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 8-bit pictures read through their 256 values give what the 16-bit
    /// table gives them (each value widened to v·257), with and without
    /// alpha, grey or colour.
    #[test]
    fn eight_bit_colours_are_the_sixteen_bit_tables() {
        let (w, h) = (256u32, 3u32);
        let raw: Vec<u8> = (0..w * h * 4).map(|i| (i * 97 % 256) as u8).collect();
        let rgba = image::RgbaImage::from_raw(w, h, raw).unwrap();
        let images = [
            image::DynamicImage::ImageRgba8(rgba.clone()),
            image::DynamicImage::ImageRgb8(image::DynamicImage::ImageRgba8(rgba.clone()).to_rgb8()),
            image::DynamicImage::ImageLuma8(
                image::DynamicImage::ImageRgba8(rgba.clone()).to_luma8(),
            ),
            image::DynamicImage::ImageLumaA8(
                image::DynamicImage::ImageRgba8(rgba).to_luma_alpha8(),
            ),
        ];
        let lut: Vec<f32> = (0..=u16::MAX).map(linear16).collect();
        for img in images {
            let want: Vec<[f32; 3]> = img
                .to_rgb16()
                .pixels()
                .map(|p| p.0.map(|v| lut[usize::from(v)]))
                .collect();
            assert_eq!(
                raster_rgb(img.clone(), Range::Unit),
                want,
                "{:?}",
                img.color()
            );
        }
    }
}
