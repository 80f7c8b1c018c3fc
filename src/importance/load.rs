//! Decoding images into linear luminance, and normalizing it to [0, 1].

use std::io::Read;
use std::path::Path;

use super::{Error, HDR_PERCENTILE, ImportanceMap, Result};

/// Rec. 709 luminance weights of linear R, G and B.
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];
/// The first four bytes of every OpenEXR file.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// The range of a decoded image's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Range {
    /// Integer samples, sRGB-decoded: linear values in [0, 1], white = 1.
    Unit,
    /// Float samples (EXR, float TIFF): linear, unbounded; white is a percentile.
    Float,
}

/// Linear luminance of a decoded image, before normalization.
#[derive(Clone, Debug, PartialEq)]
pub struct Luminance {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear luminance per pixel, row-major, at least 0.
    pub values: Vec<f32>,
    /// Alpha per pixel in [0, 1], when the image has it.
    pub alpha: Option<Vec<f32>>,
    /// Whether alpha is premultiplied into `values` (OpenEXR's convention).
    pub premultiplied: bool,
    /// The samples' range.
    pub range: Range,
}

/// Decodes `path` (any supported format, recognized by content, or by an
/// `.exr` extension) into linear luminance.
///
/// ```no_run
/// let lum = pixelpie::importance::load(std::path::Path::new("assets/default.png")).unwrap();
/// assert!(lum.values.iter().all(|&y| (0.0..=1.0).contains(&y)));
/// ```
pub fn load(path: &Path) -> Result<Luminance> {
    load_within(path, super::budget::GREY_BYTES_PER_PIXEL)
}

/// [`load`], refusing from its header a picture that would need more than
/// the memory budget at `per_pixel` bytes a pixel ([`super::budget`]).
pub(crate) fn load_within(path: &Path, per_pixel: u64) -> Result<Luminance> {
    Ok(load_decoded_within(path, per_pixel, false)?.0)
}

/// [`load_within`], with `keep`, the decoded raster image it read the
/// luminance from (`None` for an EXR or without `keep`), for a caller that
/// needs its colours too.
pub(crate) fn load_decoded_within(
    path: &Path,
    per_pixel: u64,
    keep: bool,
) -> Result<(Luminance, Option<image::DynamicImage>)> {
    let io = |error| Error::Io {
        path: path.to_owned(),
        error,
    };
    let mut magic = Vec::with_capacity(4);
    std::fs::File::open(path)
        .map_err(io)?
        .take(4)
        .read_to_end(&mut magic)
        .map_err(io)?;
    if magic.is_empty() {
        return Err(Error::Decode {
            path: path.to_owned(),
            message: "the file is empty".into(),
        });
    }
    let exr_extension = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let exr = magic == EXR_MAGIC || exr_extension;
    if let Some(size) = super::budget::file_size(path, exr) {
        super::budget::check(path, size, per_pixel)?;
    }
    let (lum, img) = if exr {
        (load_exr(path)?, None)
    } else if keep {
        let img = decode_file(path)?;
        (luminance(&img, path)?, Some(img))
    } else {
        (luminance(&decode_file(path)?, path)?, None)
    };
    if lum.width == 0 || lum.height == 0 {
        return Err(Error::Empty {
            path: path.to_owned(),
        });
    }
    Ok((lum, img))
}

fn non_finite(path: &Path, channel: &str, i: usize, width: u32, value: f32) -> Error {
    Error::NonFinite {
        path: path.to_owned(),
        channel: channel.to_owned(),
        x: (i as u64 % u64::from(width.max(1))) as u32,
        y: (i as u64 / u64::from(width.max(1))) as u32,
        value,
    }
}

/// Checks a float channel for NaN and infinities.
fn check_finite(path: &Path, channel: &str, width: u32, samples: &[f32]) -> Result<()> {
    match samples.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(non_finite(path, channel, i, width, samples[i])),
        None => Ok(()),
    }
}

pub use crate::colour::{linear_to_srgb, srgb_to_linear};

/// Decodes an image file held in memory (PNG, JPEG, TIFF, BMP, WebP) into
/// linear luminance, as [`load`] does a file; `name` names it in errors.
pub fn load_bytes(bytes: &[u8], name: &Path) -> Result<Luminance> {
    load_bytes_within(bytes, name, super::budget::GREY_BYTES_PER_PIXEL)
}

/// [`load_bytes`] under the memory budget ([`load_within`]).
pub(crate) fn load_bytes_within(bytes: &[u8], name: &Path, per_pixel: u64) -> Result<Luminance> {
    if let Some(size) = super::budget::encoded_size(bytes) {
        super::budget::check(name, size, per_pixel)?;
    }
    let decode = |e: &dyn std::fmt::Display| Error::Decode {
        path: name.to_owned(),
        message: crate::text::single_line(&e.to_string()),
    };
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| decode(&e))?;
    let img = upright(reader).map_err(|e| decode(&e))?;
    let lum = luminance(&img, name)?;
    if lum.width == 0 || lum.height == 0 {
        return Err(Error::Empty {
            path: name.to_owned(),
        });
    }
    Ok(lum)
}

/// Decodes a raster image file (PNG, JPEG, TIFF, BMP, WebP), turned upright
/// by its EXIF orientation ([`upright`]), its errors naming the file.
pub fn decode_file(path: &Path) -> Result<image::DynamicImage> {
    let decode = |e: &dyn std::fmt::Display| Error::Decode {
        path: path.to_owned(),
        message: crate::text::single_line(&e.to_string()),
    };
    let reader = image::ImageReader::open(path)
        .map_err(|error| Error::Io {
            path: path.to_owned(),
            error,
        })?
        .with_guessed_format()
        .map_err(|e| decode(&e))?;
    upright(reader).map_err(|e| decode(&e))
}

/// A warning when the image file at `path` is cut short, so that its
/// decoder filled the missing part (JPEG decoders do: the picture opens
/// whole, its lost part one flat tone): a JPEG without its end marker.
/// `None` for a whole file, or one that cannot be read (its loading says
/// why).
#[must_use]
pub fn cut_short(path: &Path) -> Option<String> {
    use std::io::{Read, Seek, SeekFrom};
    // The first two bytes and the last few KiB: not the file again.
    let mut file = std::fs::File::open(path).ok()?;
    let len = file.metadata().ok()?.len();
    let mut head = [0u8; 2];
    file.read_exact(&mut head).ok()?;
    let from = len.saturating_sub(TAIL as u64).max(2);
    file.seek(SeekFrom::Start(from)).ok()?;
    let mut bytes = head.to_vec();
    file.read_to_end(&mut bytes).ok()?;
    cut_short_bytes(&bytes).then(|| {
        format!(
            "{} ends early (no JPEG end marker): part of the picture is missing and is \
             drawn as one flat tone",
            path.display()
        )
    })
}

/// How far from its end a JPEG's end marker is looked for (writers may pad
/// after it).
const TAIL: usize = 4096;

/// Whether `bytes` are a JPEG cut short: a JPEG start marker without the
/// end marker (padding after it allowed).
#[must_use]
pub fn cut_short_bytes(bytes: &[u8]) -> bool {
    if !bytes.starts_with(&[0xFF, 0xD8]) {
        return false;
    }
    // Writers may pad after the end marker; look for it near the end.
    let tail = &bytes[bytes.len().saturating_sub(TAIL)..];
    !tail.windows(2).any(|w| w == [0xFF, 0xD9])
}

/// Decodes the image of `reader` and turns it upright by its EXIF
/// orientation (a phone's photo taken sideways says how to turn it), as a
/// viewer shows it.
pub(super) fn upright<R: std::io::BufRead + std::io::Seek>(
    reader: image::ImageReader<R>,
) -> image::ImageResult<image::DynamicImage> {
    use image::ImageDecoder;
    let mut decoder = reader.into_decoder()?;
    let orientation = decoder
        .orientation()
        .unwrap_or(image::metadata::Orientation::NoTransforms);
    let mut img = image::DynamicImage::from_decoder(decoder)?;
    img.apply_orientation(orientation);
    Ok(img)
}

/// A decoded raster image's linear luminance (and alpha).
fn luminance(img: &image::DynamicImage, path: &Path) -> Result<Luminance> {
    let (width, height) = (img.width(), img.height());
    let color = img.color();
    let has_alpha = color.has_alpha();
    let gray = !color.has_color();
    let float = matches!(
        img,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let n = width as usize * height as usize;
    let mut values = Vec::with_capacity(n);
    let mut alpha = has_alpha.then(|| Vec::with_capacity(n));
    if float {
        let buf = img.to_rgba32f();
        for (i, px) in buf.pixels().enumerate() {
            for (c, name) in ["R", "G", "B", "A"].iter().enumerate() {
                if !px.0[c].is_finite() {
                    return Err(non_finite(path, name, i, width, px.0[c]));
                }
            }
            let [r, g, b, a] = px.0.map(|v| v.max(0.0));
            values.push(if gray {
                r
            } else {
                LUMA[0] * r + LUMA[1] * g + LUMA[2] * b
            });
            if let Some(al) = alpha.as_mut() {
                al.push(a.min(1.0));
            }
        }
    } else {
        let lut: Vec<f32> = (0..=u16::MAX)
            .map(|v| srgb_to_linear(f32::from(v) / 65535.0))
            .collect();
        let buf = img.to_rgba16();
        for px in buf.pixels() {
            let [r, g, b, a] = px.0;
            let y = if gray {
                lut[usize::from(r)]
            } else {
                LUMA[0] * lut[usize::from(r)]
                    + LUMA[1] * lut[usize::from(g)]
                    + LUMA[2] * lut[usize::from(b)]
            };
            values.push(y.clamp(0.0, 1.0));
            if let Some(al) = alpha.as_mut() {
                al.push(f32::from(a) / 65535.0);
            }
        }
    }
    Ok(Luminance {
        width,
        height,
        values,
        alpha,
        premultiplied: false,
        range: if float { Range::Float } else { Range::Unit },
    })
}

fn load_exr(path: &Path) -> Result<Luminance> {
    let img = crate::io::read_exr(path).map_err(|e| Error::Decode {
        path: path.to_owned(),
        message: crate::text::single_line(
            &std::iter::successors(Some(&e as &dyn std::error::Error), |e| e.source())
                .last()
                .map_or_else(|| e.to_string(), ToString::to_string),
        ),
    })?;
    // Layered files name channels "layer.R"; match on the last component.
    let find = |name: &str| {
        img.channels
            .iter()
            .find(|(n, _)| n.rsplit('.').next() == Some(name))
    };
    let channels: Vec<&(String, Vec<f32>)> = if let Some(y) = find("Y") {
        vec![y]
    } else if let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) {
        vec![r, g, b]
    } else if img.channels.len() == 1 {
        vec![&img.channels[0]]
    } else {
        return Err(Error::Channels {
            path: path.to_owned(),
            channels: img
                .channels
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        });
    };
    for (name, samples) in &channels {
        check_finite(path, name, img.width, samples)?;
    }
    let n = img.width as usize * img.height as usize;
    let values: Vec<f32> = match channels.as_slice() {
        [(_, y)] => y.iter().map(|v| v.max(0.0)).collect(),
        [(_, r), (_, g), (_, b)] => (0..n)
            .map(|i| (LUMA[0] * r[i] + LUMA[1] * g[i] + LUMA[2] * b[i]).max(0.0))
            .collect(),
        _ => unreachable!("one or three channels were picked"),
    };
    let alpha = match find("A") {
        Some((name, a)) => {
            check_finite(path, name, img.width, a)?;
            Some(a.iter().map(|v| v.clamp(0.0, 1.0)).collect())
        }
        None => None,
    };
    Ok(Luminance {
        width: img.width,
        height: img.height,
        values,
        alpha,
        premultiplied: true,
        range: Range::Float,
    })
}

impl Luminance {
    /// The luminance that becomes white: 1 for integer images, the
    /// [`HDR_PERCENTILE`]th percentile for float images (1 if that is 0).
    #[must_use]
    pub fn white_point(&self) -> f32 {
        match self.range {
            Range::Unit => 1.0,
            Range::Float => {
                let mut v = self.values.clone();
                if v.is_empty() {
                    return 1.0;
                }
                let k = ((HDR_PERCENTILE / 100.0 * v.len() as f64).ceil() as usize)
                    .clamp(1, v.len())
                    - 1;
                let (_, &mut p, _) = v.select_nth_unstable_by(k, f32::total_cmp);
                if p > 0.0 { p } else { 1.0 }
            }
        }
    }

    /// Normalizes to [0, 1] by the white point (`hdr_white` overrides it for
    /// float images) and composites alpha over white.
    ///
    /// ```
    /// use pixelpie::importance::{Luminance, Range};
    /// let lum = Luminance {
    ///     width: 2, height: 1, values: vec![0.5, 4.0], alpha: Some(vec![1.0, 0.5]),
    ///     premultiplied: true, range: Range::Float,
    /// };
    /// let m = lum.normalized(Some(2.0)).unwrap();
    /// assert_eq!(m.values(), &[0.25, 1.0]);
    /// ```
    pub fn normalized(self, hdr_white: Option<f32>) -> Result<ImportanceMap> {
        if let Some(w) = hdr_white
            && !(w.is_finite() && w > 0.0)
        {
            return Err(Error::InvalidParameter(format!(
                "«hdr_white={w}» must be a positive number"
            )));
        }
        let white = match (self.range, hdr_white) {
            (Range::Float, Some(w)) => w,
            _ => self.white_point(),
        };
        let mut values: Vec<f32> = self
            .values
            .iter()
            .map(|&y| (y / white).clamp(0.0, 1.0))
            .collect();
        if let Some(alpha) = &self.alpha {
            for (v, &a) in values.iter_mut().zip(alpha) {
                *v = if self.premultiplied {
                    (*v + (1.0 - a)).min(1.0)
                } else {
                    a * *v + (1.0 - a)
                };
            }
        }
        ImportanceMap::from_values(self.width, self.height, values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cut_jpeg_is_told_from_a_whole_one() {
        let whole =
            std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/astronaut.jpg")).unwrap();
        assert!(!cut_short_bytes(&whole));
        assert!(cut_short_bytes(&whole[..whole.len() / 3]));
        let png = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/rings.png")).unwrap();
        assert!(!cut_short_bytes(&png[..png.len() / 2]));
    }
}
