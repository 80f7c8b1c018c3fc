//! PNG output: black anti-aliased dots on white, 8-bit grey.
//!
//! Two renders. [`render_union`] (and [`render_exact`], [`render_mean`]),
//! what the PNG, the correction and the measures draw: the dots' union on
//! 4×4 samples a pixel, true coverage at every dot size and overlap.
//! [`render`], the app's quick view: a pixel's coverage by a dot
//! approximated by clamp(R + ½ − d, 0, 1), d the distance from the pixel
//! centre to the dot's centre (and at most the dot's area for dots thinner
//! than a pixel), overlapping dots combined as independent inks, paper =
//! Π (1 − coverage). The grey written is the
//! paper fraction itself, as a display value: a pixel half covered reads
//! 128, as browsers and plotter previews blend a drawing's edges, so that a
//! blurred drawing's display grey is 1 − its ink ([`mean_ink`]).

use std::io::Write;

use image::{GrayImage, Luma, RgbImage};
use rayon::prelude::*;

use super::{Dot, Error, Result, Stroke};

/// The largest PNG, in pixels, that [`render`] agrees to draw.
pub const MAX_PIXELS: u64 = 1 << 28;

/// Draws `dots` on a `domain` scaled by `scale` (output pixels per domain pixel).
///
/// ```
/// use pixelpie::stipple::{Dot, raster};
/// let img = raster::render(&[Dot { x: 4.0, y: 4.0, radius: 2.0 }], (8, 8), 1.0).unwrap();
/// assert_eq!(img.get_pixel(4, 4).0[0], 0); // ink in the middle
/// assert_eq!(img.get_pixel(0, 0).0[0], 255); // paper in the corner
/// ```
pub fn render(dots: &[Dot], domain: (u32, u32), scale: f32) -> Result<GrayImage> {
    let (w, h) = scaled_size(domain, scale)?;
    // The dots' pixel boxes, in the dots' order, bucketed by band of rows:
    // the bands are drawn in parallel, each pixel's dots in the same order
    // as one pass over the dots would take them, so the result does not
    // depend on the threads.
    let boxes: Vec<Option<[f32; 3]>> = dots
        .iter()
        .map(|d| {
            let (cx, cy, r) = (d.x * scale, d.y * scale, d.radius * scale);
            (cx.is_finite() && cy.is_finite() && r.is_finite() && r > 0.0).then_some([cx, cy, r])
        })
        .collect();
    let rows = |c: &[f32; 3]| {
        let y0 = (c[1] - c[2] - 1.0).floor().max(0.0) as u32;
        let y1 = ((c[1] + c[2] + 1.0).ceil().max(0.0) as u32).min(h);
        (y0, y1)
    };
    let in_band = in_bands(&boxes, rows, BAND, h);
    let mut pixels = vec![255u8; w as usize * h as usize];
    pixels
        .par_chunks_mut(BAND as usize * w as usize)
        .zip(in_band.par_iter())
        .enumerate()
        .for_each(|(b, (out, list))| {
            let top = b as u32 * BAND;
            let band_h = (out.len() / w as usize) as u32;
            let mut paper = vec![1.0f32; out.len()];
            for &i in list {
                let Some([cx, cy, r]) = boxes[i as usize] else {
                    continue;
                };
                let area = std::f32::consts::PI * r * r;
                let x0 = (cx - r - 1.0).floor().max(0.0) as u32;
                let x1 = ((cx + r + 1.0).ceil().max(0.0) as u32).min(w);
                let (y0, y1) = rows(&[cx, cy, r]);
                // Squared distances clearly outside the coverage's ramp (no
                // ink) and, for dots of 1 px or more, clearly inside it (all
                // ink): the ramp itself is computed as it is defined, so the
                // shortcuts give the same bytes (a relative margin of 1e-5
                // covers the rounding of the distance and the ramp).
                let outside = (r + 0.5) * (r + 0.5) * (1.0 + 1e-5);
                let inside = if r >= 1.0 {
                    (r - 0.5) * (r - 0.5) * (1.0 - 1e-5)
                } else {
                    -1.0
                };
                for py in y0.max(top)..y1.min(top + band_h) {
                    let dy = py as f32 + 0.5 - cy;
                    let row = (py - top) as usize * w as usize;
                    for px in x0..x1 {
                        let dx = px as f32 + 0.5 - cx;
                        let d2 = dx * dx + dy * dy;
                        if d2 > outside {
                            continue;
                        }
                        if d2 < inside {
                            paper[row + px as usize] = 0.0;
                            continue;
                        }
                        let dist = d2.sqrt();
                        let a = (r + 0.5 - dist).clamp(0.0, 1.0).min(area);
                        if a > 0.0 {
                            paper[row + px as usize] *= 1.0 - a;
                        }
                    }
                }
            }
            for (o, &p) in out.iter_mut().zip(&paper) {
                *o = grey(p);
            }
        });
    GrayImage::from_raw(w, h, pixels)
        .ok_or_else(|| Error::Encode("pixel buffer of the wrong size".into()))
}

/// Draws `dots` (in pixels) on a `size` image as their union's exact
/// coverage on a 4×4 grid of sample points in each pixel (at (i + ½)/4 of
/// it): a pixel's grey is the paper's share of its 16 samples, rounded to
/// 8 bits. Unlike [`render`]'s distance ramp it draws a dot's area as it is
/// at every size (the ramp adds π/12 px² a dot, 6% of a dot 1.2 px wide),
/// and where dots meet inside a pixel it counts the ink they share once
/// (the ramp takes their coverages as independent). What a drawing's
/// correction renders. The same image for any number of threads.
///
/// ```
/// use pixelpie::stipple::{Dot, raster};
/// let img = raster::render_union(&[Dot { x: 4.0, y: 4.0, radius: 2.0 }], (8, 8)).unwrap();
/// assert_eq!(img.get_pixel(4, 4).0[0], 0);
/// assert_eq!(img.get_pixel(0, 0).0[0], 255);
/// ```
pub fn render_union(dots: &[Dot], size: (u32, u32)) -> Result<GrayImage> {
    let (w, h) = size;
    if w == 0 || h == 0 || u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(Error::InvalidParameter(format!(
            "a {w}x{h} render: each side must be at least 1 px, at most {MAX_PIXELS} pixels"
        )));
    }
    const S: u32 = 4;
    let sf = S as f32;
    let discs: Vec<Option<[f32; 3]>> = dots
        .iter()
        .map(|d| {
            (d.x.is_finite() && d.y.is_finite() && d.radius.is_finite() && d.radius > 0.0)
                .then_some([d.x, d.y, d.radius])
        })
        .collect();
    // Sample rows (S a pixel row) a disc's samples can lie in.
    let rows = |c: &[f32; 3]| {
        let y0 = ((c[1] - c[2]) * sf - 0.5).ceil().max(0.0) as u32;
        let y1 = ((f64::from(c[1] + c[2]) * f64::from(sf) - 0.5).floor() + 1.0)
            .clamp(0.0, f64::from(h * S)) as u32;
        (y0, y1)
    };
    let band = BAND * S;
    let in_band = in_bands(&discs, rows, band, h * S);
    let mut pixels = vec![255u8; w as usize * h as usize];
    pixels
        .par_chunks_mut(BAND as usize * w as usize)
        .zip(in_band.par_iter())
        .enumerate()
        .for_each(|(b, (out, list))| {
            let top = b as u32 * band;
            let bottom = top + (out.len() / w as usize) as u32 * S;
            let mut masks = vec![0u16; out.len()];
            let last = f64::from(w * S - 1);
            for &i in list {
                let Some(c @ [cx, cy, r]) = discs[i as usize] else {
                    continue;
                };
                let (y0, y1) = rows(&c);
                let (y0, y1) = (y0.max(top), y1.min(bottom));
                if y1 <= y0 {
                    continue;
                }
                // Pixel row by pixel row: each of its sample rows' span of
                // samples within the disc, then whole pixels at once.
                for py in y0 / S..y1.div_ceil(S) {
                    let mut spans = [(1u32, 0u32); S as usize];
                    for (k, span) in spans.iter_mut().enumerate() {
                        let sy = py * S + k as u32;
                        if sy < y0 || sy >= y1 {
                            continue;
                        }
                        let dy = (sy as f32 + 0.5) / sf - cy;
                        let half2 = r * r - dy * dy;
                        if half2 < 0.0 {
                            continue;
                        }
                        let half = half2.sqrt();
                        // The samples (sx + ½)/S within [cx − half, cx + half].
                        let lo = f64::from((cx - half) * sf - 0.5).ceil().max(0.0);
                        let hi = f64::from((cx + half) * sf - 0.5).floor().min(last);
                        if hi >= lo {
                            *span = (lo as u32, hi as u32);
                        }
                    }
                    // Pixels every sample row covers wholly.
                    let (full_lo, full_hi) =
                        spans.iter().fold((0u32, u32::MAX), |(a, b), &(l, h)| {
                            if l > h {
                                (1, 0)
                            } else {
                                (a.max(l.div_ceil(S)), b.min((h + 1) / S))
                            }
                        });
                    let row = (py - top / S) as usize * w as usize;
                    for px in full_lo..full_hi {
                        masks[row + px as usize] = u16::MAX;
                    }
                    for (k, &(lo, hi)) in spans.iter().enumerate() {
                        if lo > hi {
                            continue;
                        }
                        let shift = k as u32 * S;
                        // The pixels of the span left of the whole ones and
                        // right of them (all of it where none is whole).
                        let (first, end) = (lo / S, hi / S + 1);
                        let (left, right) = if full_lo < full_hi {
                            (first..full_lo.max(first), full_hi.min(end)..end)
                        } else {
                            (first..end, end..end)
                        };
                        for px in left.chain(right) {
                            let a = lo.max(px * S) - px * S;
                            let z = hi.min(px * S + S - 1) - px * S;
                            let bits = ((1u16 << (z + 1)) - (1u16 << a)) << shift;
                            masks[row + px as usize] |= bits;
                        }
                    }
                }
            }
            // The grey of each count of samples inside, made once.
            let greys: [u8; (S * S + 1) as usize] =
                std::array::from_fn(|k| grey(1.0 - k as f32 / (S * S) as f32));
            for (o, &m) in out.iter_mut().zip(&masks) {
                *o = greys[m.count_ones() as usize];
            }
        });
    GrayImage::from_raw(w, h, pixels)
        .ok_or_else(|| Error::Encode("pixel buffer of the wrong size".into()))
}

/// The image size of a `domain` drawn at `scale` (output pixels per domain
/// pixel): a positive scale, at most [`MAX_PIXELS`].
fn scaled_size(domain: (u32, u32), scale: f32) -> Result<(u32, u32)> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(Error::InvalidParameter(format!(
            "scale {scale} must be a positive number"
        )));
    }
    let w = (f64::from(domain.0) * f64::from(scale)).round().max(1.0);
    let h = (f64::from(domain.1) * f64::from(scale)).round().max(1.0);
    if w * h > MAX_PIXELS as f64 {
        return Err(Error::InvalidParameter(format!(
            "a {w}x{h} PNG is too large (at most {MAX_PIXELS} pixels); lower «scale»"
        )));
    }
    Ok((w as u32, h as u32))
}

/// [`render`]'s image drawn as the dots' union ([`render_union`]): their
/// true coverage, what the PNG of a drawing and the ramp's check show.
///
/// ```
/// use pixelpie::stipple::{Dot, raster};
/// let img = raster::render_exact(&[Dot { x: 4.0, y: 4.0, radius: 2.0 }], (8, 8), 2.0).unwrap();
/// assert_eq!((img.width(), img.get_pixel(8, 8).0[0]), (16, 0));
/// ```
pub fn render_exact(dots: &[Dot], domain: (u32, u32), scale: f32) -> Result<GrayImage> {
    let size = scaled_size(domain, scale)?;
    let scaled: Vec<Dot> = dots
        .iter()
        .map(|d| Dot {
            x: d.x * scale,
            y: d.y * scale,
            radius: d.radius * scale,
        })
        .collect();
    render_union(&scaled, size)
}

/// The dots of `discs` (those that are some) that reach each band of
/// `band` rows of `rows_in_all`, by the rows `rows` gives a dot, each
/// band's in the dots' order: what each band's thread draws.
fn in_bands(
    discs: &[Option<[f32; 3]>],
    rows: impl Fn(&[f32; 3]) -> (u32, u32),
    band: u32,
    rows_in_all: u32,
) -> Vec<Vec<u32>> {
    let mut in_band: Vec<Vec<u32>> = vec![Vec::new(); rows_in_all.div_ceil(band) as usize];
    for (i, c) in discs.iter().enumerate() {
        if let Some(c) = c {
            let (y0, y1) = rows(c);
            if y1 > y0 {
                for b in y0 / band..=(y1 - 1) / band {
                    in_band[b as usize].push(i as u32);
                }
            }
        }
    }
    in_band
}

/// The 8-bit grey of `p` ∈ [0, 1]: `(255·p).round()`, without the libm
/// call that `round()` is on baseline x86-64 (255·p is exact in f64 with
/// at most 24 significant bits, so adding ½ there and truncating rounds
/// half away from zero, as `round()` does).
#[inline]
fn grey(p: f32) -> u8 {
    (f64::from(255.0 * p.clamp(0.0, 1.0)) + 0.5) as u8
}

/// Rows per band that one thread draws.
const BAND: u32 = 64;

pub use crate::importance::linear_to_srgb;

/// Draws `dots`, given in the units of a `view` (width, height: an SVG
/// viewBox, a sampling domain), stretched onto a `size` image: the drawing
/// at a photo's resolution.
///
/// ```
/// use pixelpie::stipple::{Dot, raster};
/// let dot = Dot { x: 50.0, y: 50.0, radius: 20.0 };
/// let img = raster::render_view(&[dot], (100.0, 100.0), (10, 10)).unwrap();
/// assert_eq!(img.get_pixel(5, 5).0[0], 0);
/// ```
pub fn render_view(dots: &[Dot], view: (f64, f64), size: (u32, u32)) -> Result<GrayImage> {
    render(&in_view(dots, view, size), size, 1.0)
}

/// `dots` in a `view`'s units, stretched onto a `size` image's pixels.
fn in_view(dots: &[Dot], view: (f64, f64), size: (u32, u32)) -> Vec<Dot> {
    let (sx, sy) = (f64::from(size.0) / view.0, f64::from(size.1) / view.1);
    dots.iter()
        .map(|d| Dot {
            x: (f64::from(d.x) * sx) as f32,
            y: (f64::from(d.y) * sy) as f32,
            radius: (f64::from(d.radius) * sx) as f32,
        })
        .collect()
}

/// [`render_view`] drawn as the dots' union ([`render_union`]): the
/// coverage a measure reads.
pub fn render_view_union(dots: &[Dot], view: (f64, f64), size: (u32, u32)) -> Result<GrayImage> {
    render_union(&in_view(dots, view, size), size)
}

/// Draws `strokes` at their widths on a `domain` scaled by `scale`
/// (output pixels per domain pixel), each as the union of its pen's
/// passes ([`super::line::render_polyline`]), several strokes as the
/// darker of theirs at each pixel.
pub fn render_strokes(strokes: &[Stroke], domain: (u32, u32), scale: f64) -> Result<GrayImage> {
    let size = scaled_size(domain, scale as f32)?;
    let mut img = GrayImage::from_pixel(size.0, size.1, Luma([255]));
    for s in strokes {
        let path = s.path(0.05);
        let one = super::line::render_polyline(&path, f64::from(s.width), size, scale);
        for (a, b) in img.as_mut().iter_mut().zip(one.as_raw()) {
            *a = (*a).min(*b);
        }
    }
    Ok(img)
}

/// The PNG text keyword that marks our drawings and holds their dot count.
pub const DOTS_KEYWORD: &str = "pixelpie:dots";

/// The paper's display grey of `dots` (in a `view`) at `size`, each pixel
/// the mean of k×k pixels rendered at k times the size (k up to 4, at most
/// 4096 px on the longer side) as the dots' union ([`render_union`], 16
/// samples a pixel): their true coverage, however few pixels wide the dots
/// are and however they overlap. What `pixelpie fidelity` measures.
pub fn render_mean(dots: &[Dot], view: (f64, f64), size: (u32, u32)) -> Result<Vec<f32>> {
    if size.0 == 0 || size.1 == 0 {
        return Ok(Vec::new());
    }
    let k = (4096 / size.0.max(size.1).max(1)).clamp(1, 4);
    let fine = render_view_union(dots, view, (size.0 * k, size.1 * k))?;
    let (fw, raw) = (size.0 * k, fine.as_raw());
    let norm = 1.0 / (255.0 * (k * k) as f32);
    Ok((0..size.0 as usize * size.1 as usize)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i as u32 % size.0, i as u32 / size.0);
            let mut sum = 0u32;
            for fy in y * k..(y + 1) * k {
                let row = (fy * fw) as usize;
                for fx in x * k..(x + 1) * k {
                    sum += u32::from(raw[row + fx as usize]);
                }
            }
            sum as f32 * norm
        })
        .collect())
}

/// Encodes `img` as an 8-bit grey PNG into `w`, with text chunks naming
/// the software and the drawing's number of `dots` ([`DOTS_KEYWORD`]), so
/// that [`read_png_dots`] recognises our drawings.
pub fn write_png(w: &mut dyn Write, img: &GrayImage, dots: usize) -> Result<()> {
    encode(
        w,
        img.dimensions(),
        png::ColorType::Grayscale,
        img.as_raw(),
        dots,
    )
}

/// Writes `data` (rows of `color` pixels, `width`×`height`) as an 8-bit PNG with
/// our text chunks.
fn encode(
    w: &mut dyn Write,
    (width, height): (u32, u32),
    color: png::ColorType,
    data: &[u8],
    dots: usize,
) -> Result<()> {
    let encode = |e: png::EncodingError| Error::Encode(e.to_string());
    let mut enc = png::Encoder::new(w, width, height);
    enc.set_color(color);
    enc.set_depth(png::BitDepth::Eight);
    // Fast deflate: a 16-Mpx drawing encodes in a fraction of a second; the
    // files are a little larger than at the default level.
    enc.set_compression(png::Compression::Fast);
    enc.add_text_chunk("Software".into(), "pixelpie".into())
        .map_err(encode)?;
    enc.add_text_chunk(DOTS_KEYWORD.into(), dots.to_string())
        .map_err(encode)?;
    let mut writer = enc.write_header().map_err(encode)?;
    writer.write_image_data(data).map_err(encode)?;
    writer.finish().map_err(encode)
}

/// Encodes `img` (paper white, grey where ink is) as an 8-bit RGB PNG with
/// ink of colour `ink` (sRGB): each pixel blends the paper and the ink by
/// the ink's coverage, as [`write_png`] does in grey (black ink gives the
/// same greys).
pub fn write_png_ink(w: &mut dyn Write, img: &GrayImage, ink: [u8; 3], dots: usize) -> Result<()> {
    write_png_on(w, img, ink, [255; 3], dots)
}

/// [`write_png_ink`] on paper of colour `paper`: each pixel the paper's
/// colour and the ink's (as it shows on that paper) mixed by its coverage,
/// in sRGB values as the grey drawing averages them.
pub fn write_png_on(
    w: &mut dyn Write,
    img: &GrayImage,
    ink: [u8; 3],
    paper: [u8; 3],
    dots: usize,
) -> Result<()> {
    let rgb: Vec<u8> = img
        .as_raw()
        .iter()
        .flat_map(|&g| {
            let g = u32::from(g);
            std::array::from_fn::<u8, 3, _>(|i| {
                ((u32::from(ink[i]) * (255 - g) + u32::from(paper[i]) * g + 127) / 255) as u8
            })
        })
        .collect();
    encode(w, img.dimensions(), png::ColorType::Rgb, &rgb, dots)
}

/// The dot count of a PNG drawing we wrote ([`write_png`]), or `None` for
/// any other PNG (or bytes that are not a PNG).
///
/// ```
/// use pixelpie::stipple::{Dot, raster};
/// let img = raster::render(&[Dot { x: 4.0, y: 4.0, radius: 2.0 }], (8, 8), 1.0).unwrap();
/// let mut bytes = Vec::new();
/// raster::write_png(&mut bytes, &img, 1).unwrap();
/// assert_eq!(raster::read_png_dots(&bytes), Some(1));
/// assert_eq!(raster::read_png_dots(b"not a png"), None);
/// ```
#[must_use]
pub fn read_png_dots(bytes: &[u8]) -> Option<usize> {
    let reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .ok()?;
    reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .find(|t| t.keyword == DOTS_KEYWORD)
        .and_then(|t| t.text.trim().parse().ok())
}

/// The mean ink coverage (0 = white, 1 = black) of a region of `img`: one
/// minus its mean display grey, the check that a drawing reproduces a tone.
///
/// ```
/// use pixelpie::stipple::raster;
/// let img = image::GrayImage::from_fn(2, 1, |x, _| image::Luma([if x == 0 { 0 } else { 255 }]));
/// assert!((raster::mean_ink(&img, 0, 0, 2, 1) - 0.5).abs() < 1e-9);
/// ```
#[must_use]
pub fn mean_ink(img: &GrayImage, x0: u32, y0: u32, x1: u32, y1: u32) -> f64 {
    let mut sum = 0.0;
    let mut n = 0u64;
    for y in y0..y1.min(img.height()) {
        for x in x0..x1.min(img.width()) {
            let Luma([g]) = *img.get_pixel(x, y);
            sum += 1.0 - f64::from(g) / 255.0;
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// The composite of a colour drawing's layers, each rendered as by
/// [`render`] (paper white, grey where its pen's ink is), under the render
/// model ([`crate::colour::separation`]): at every pixel pen k covers
/// a_k = 1 − its layer's paper, and the pixel shows `model.mix(a)`, the
/// overlapping inks multiplied, its partial inks averaged under the model's
/// convention (sRGB values, as the grey PNG does, or linear light).
pub fn composite(layers: &[GrayImage], model: &crate::colour::RenderModel) -> Result<RgbImage> {
    let Some(first) = layers.first() else {
        return Err(Error::InvalidParameter(
            "a colour drawing needs a layer".into(),
        ));
    };
    use rayon::prelude::*;
    let (w, h) = first.dimensions();
    let pens = layers.len();
    let bytes = |a: &[f64]| -> [u8; 3] {
        let c = model.mix(a);
        let c = if model.linear() {
            c.map(crate::colour::encode)
        } else {
            c
        };
        c.map(|v| (255.0 * v.clamp(0.0, 1.0)).round() as u8)
    };
    // Where every pen covers the pixel wholly or not at all (most pixels:
    // paper, and the insides of dots) the colour is one of the 2^pens
    // overlaps', exactly what `mix` gives for inks of 0 and 1: made once.
    let whole: Vec<[u8; 3]> = (0..1usize << pens)
        .map(|s| {
            bytes(
                &(0..pens)
                    .map(|k| f64::from((s >> k) as u8 & 1))
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    // Dots' edges (the rest) repeat few coverages: each worker keeps the
    // last colours in a direct-mapped cache keyed by the layers' bytes.
    const CACHE: usize = 1 << 12;
    let mut rgb = vec![0u8; 3 * w as usize * h as usize];
    let row = 3 * w as usize;
    rgb.par_chunks_mut(row.max(1)).enumerate().for_each_init(
        || vec![(u64::MAX, [0u8; 3]); CACHE],
        |cache, (y, out)| {
            let at = y * w as usize;
            for (x, px) in out.chunks_exact_mut(3).enumerate() {
                let i = at + x;
                let mut s = 0usize;
                let mut key = 0u64;
                let mut partial = false;
                for (k, l) in layers.iter().enumerate() {
                    let v = l.as_raw()[i];
                    key |= u64::from(v) << (8 * k);
                    match v {
                        0 => s |= 1 << k,
                        255 => {}
                        _ => partial = true,
                    }
                }
                let c = if partial {
                    // No partial pixel has every byte 255: u64::MAX marks
                    // an empty slot.
                    let slot = &mut cache[(key.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 52) as usize];
                    if slot.0 != key {
                        let mut a = [0f64; crate::colour::pens::MAX_PENS];
                        for (k, l) in layers.iter().enumerate() {
                            a[k] = 1.0 - f64::from(l.as_raw()[i]) / 255.0;
                        }
                        *slot = (key, bytes(&a[..pens]));
                    }
                    slot.1
                } else {
                    whole[s]
                };
                px.copy_from_slice(&c);
            }
        },
    );
    RgbImage::from_raw(w, h, rgb)
        .ok_or_else(|| Error::Encode("pixel buffer of the wrong size".into()))
}

/// Encodes a colour drawing as an 8-bit RGB PNG with our text chunks.
pub fn write_png_rgb(w: &mut dyn Write, img: &RgbImage, dots: usize) -> Result<()> {
    encode(w, img.dimensions(), png::ColorType::Rgb, img.as_raw(), dots)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A xorshift32 stream from `seed` (not 0): the tests' random inputs.
    fn xorshift(mut state: u32) -> impl FnMut() -> u32 {
        move || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state
        }
    }

    /// `n` dots from `seed` anywhere on a `(w, h)` image, of radii from
    /// `radii.0` to `radii.0 + radii.1`, most of them small.
    fn random_dots(seed: u32, n: usize, (w, h): (u32, u32), radii: (f64, f64)) -> Vec<Dot> {
        let mut bits = xorshift(seed);
        let mut next = || f64::from(bits()) / f64::from(u32::MAX);
        (0..n)
            .map(|_| Dot {
                x: (next() * f64::from(w)) as f32,
                y: (next() * f64::from(h)) as f32,
                radius: (radii.0 + radii.1 * next() * next()) as f32,
            })
            .collect()
    }

    /// The render's shortcuts (no distance where a pixel is clearly out of
    /// a dot or clearly inside it) give what one pass computing the ramp at
    /// every pixel gives: many small dots, whose ramps fill their boxes.
    #[test]
    fn the_render_is_the_ramp_at_every_pixel() {
        let (w, h) = (83u32, 71u32);
        let dots = random_dots(0x1234_5678, 400, (w, h), (0.2, 7.0));
        let img = render(&dots, (w, h), 1.0).unwrap();
        assert_eq!(img.into_raw(), one_pass(&dots, (w, h), 1.0));
    }

    /// The union render is each sample's inside-or-not, computed one
    /// sample at a time, for many dots of every size (whole pixels filled
    /// at once give the same bytes), on a band boundary too.
    #[test]
    fn the_union_render_is_its_samples() {
        let (w, h) = (83u32, 151u32);
        let dots = random_dots(0x2545_f491, 300, (w, h), (0.1, 9.0));
        let img = render_union(&dots, (w, h)).unwrap();
        for y in 0..h {
            for x in 0..w {
                let mut inside = 0u32;
                for k in 0..16 {
                    let (sx, sy) = (
                        ((x * 4 + k % 4) as f32 + 0.5) / 4.0,
                        ((y * 4 + k / 4) as f32 + 0.5) / 4.0,
                    );
                    let hit = dots.iter().any(|d| {
                        let dy = sy - d.y;
                        let half2 = d.radius * d.radius - dy * dy;
                        half2 >= 0.0 && (sx - d.x).abs() <= half2.sqrt()
                    });
                    inside += u32::from(hit);
                }
                assert_eq!(
                    img.get_pixel(x, y).0[0],
                    grey(1.0 - inside as f32 / 16.0),
                    "pixel ({x}, {y})"
                );
            }
        }
    }

    /// A dot's ink in the union render is its area at every size, where
    /// the distance ramp adds about π/12 px² (6% of a dot 1.2 px wide); a
    /// dot drawn twice puts down its ink once.
    #[test]
    fn the_union_render_inks_a_dots_area_once() {
        let ink = |img: &GrayImage| {
            img.as_raw()
                .iter()
                .map(|&g| 1.0 - f64::from(g) / 255.0)
                .sum::<f64>()
        };
        let mut bits = xorshift(0x0bad_5eed);
        let mut next = || f64::from(bits()) / f64::from(u32::MAX);
        for r in [1.2f32, 2.0, 3.5, 8.0] {
            // Many places within a pixel: the samples' grid averages out.
            let (mut union, mut ramp, n) = (0.0, 0.0, 64);
            for _ in 0..n {
                let d = Dot {
                    x: 16.0 + next() as f32,
                    y: 16.0 + next() as f32,
                    radius: r,
                };
                union += ink(&render_union(&[d], (32, 32)).unwrap());
                ramp += ink(&render(&[d], (32, 32), 1.0).unwrap());
            }
            let area = std::f64::consts::PI * f64::from(r * r);
            let (union, ramp) = (union / f64::from(n), ramp / f64::from(n));
            assert!(
                (union / area - 1.0).abs() < 0.02,
                "r {r}: {union} against {area}"
            );
            assert!(ramp > area, "r {r}: the ramp {ramp} against {area}");
            let d = Dot {
                x: 9.3,
                y: 7.6,
                radius: r,
            };
            assert_eq!(
                render_union(&[d, d], (20, 20)).unwrap(),
                render_union(&[d], (20, 20)).unwrap()
            );
        }
    }

    /// The composite's shortcuts (whole coverages made once, a cache of
    /// partial ones) give what the render model gives at every pixel, for
    /// both conventions.
    #[test]
    fn the_composite_is_the_model_at_every_pixel() {
        use crate::colour::{PenSet, RenderModel};
        let (w, h) = (97u32, 61u32);
        let mut next = xorshift(0x9e37_79b9);
        // Mostly paper or full ink, as a drawing is, with partial edges.
        let layers: Vec<GrayImage> = (0..4)
            .map(|_| {
                let raw = (0..w * h)
                    .map(|_| match next() % 4 {
                        0 => 0,
                        1 | 2 => 255,
                        _ => (next() % 256) as u8,
                    })
                    .collect();
                GrayImage::from_raw(w, h, raw).unwrap()
            })
            .collect();
        for linear in [false, true] {
            let model = RenderModel::new(&PenSet::cmyk(), linear);
            let img = composite(&layers, &model).unwrap();
            for i in 0..(w * h) as usize {
                let a: Vec<f64> = layers
                    .iter()
                    .map(|l| 1.0 - f64::from(l.as_raw()[i]) / 255.0)
                    .collect();
                let c = model.mix(&a);
                let c = if linear {
                    c.map(crate::colour::encode)
                } else {
                    c
                };
                let want = c.map(|v| (255.0 * v.clamp(0.0, 1.0)).round() as u8);
                assert_eq!(
                    img.as_raw()[3 * i..3 * i + 3],
                    want,
                    "pixel {i}, linear {linear}"
                );
            }
        }
    }

    #[test]
    fn grey_rounds_as_round_does() {
        let mut next = xorshift(0x2545_f491);
        let mut values = vec![
            0.0,
            1.0,
            -0.0,
            -1.0,
            2.0,
            0.5 / 255.0,
            1.5 / 255.0,
            f32::NAN,
        ];
        for k in 0..=255u32 {
            // The ties and their neighbours.
            let t = (k as f32 + 0.5) / 255.0;
            values.extend([
                t,
                f32::from_bits(t.to_bits() - 1),
                f32::from_bits(t.to_bits() + 1),
            ]);
        }
        for _ in 0..1_000_000 {
            values.push((next() >> 8) as f32 / (1 << 24) as f32);
        }
        for p in values {
            assert_eq!(grey(p), (255.0 * p.clamp(0.0, 1.0)).round() as u8, "{p:e}");
        }
    }

    /// The drawing as one pass over the dots makes it: what the bands must
    /// give, pixel for pixel.
    fn one_pass(dots: &[Dot], (w, h): (u32, u32), scale: f32) -> Vec<u8> {
        let mut paper = vec![1.0f32; w as usize * h as usize];
        for d in dots {
            let (cx, cy, r) = (d.x * scale, d.y * scale, d.radius * scale);
            if !(cx.is_finite() && cy.is_finite() && r.is_finite()) || r <= 0.0 {
                continue;
            }
            let area = std::f32::consts::PI * r * r;
            let x0 = (cx - r - 1.0).floor().max(0.0) as u32;
            let y0 = (cy - r - 1.0).floor().max(0.0) as u32;
            let x1 = ((cx + r + 1.0).ceil().max(0.0) as u32).min(w);
            let y1 = ((cy + r + 1.0).ceil().max(0.0) as u32).min(h);
            for py in y0..y1 {
                let dy = py as f32 + 0.5 - cy;
                for px in x0..x1 {
                    let dx = px as f32 + 0.5 - cx;
                    let a = (r + 0.5 - (dx * dx + dy * dy).sqrt())
                        .clamp(0.0, 1.0)
                        .min(area);
                    if a > 0.0 {
                        paper[py as usize * w as usize + px as usize] *= 1.0 - a;
                    }
                }
            }
        }
        paper.iter().map(|&p| grey(p)).collect()
    }

    #[test]
    fn the_bands_draw_what_one_pass_draws() {
        let mut s = 99u32;
        let mut next = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (s >> 8) as f32 / (1 << 24) as f32
        };
        // Overlapping dots of all sizes, some across band edges and the
        // image's edges, some degenerate.
        let mut dots: Vec<Dot> = (0..3000)
            .map(|_| Dot {
                x: next() * 330.0 - 10.0,
                y: next() * 270.0 - 10.0,
                radius: next() * next() * 40.0,
            })
            .collect();
        dots.push(Dot {
            x: f32::NAN,
            y: 3.0,
            radius: 2.0,
        });
        for scale in [1.0, 0.5, 1.7] {
            let img = render(&dots, (310, 250), scale).unwrap();
            let (w, h) = img.dimensions();
            assert_eq!(
                img.into_raw(),
                one_pass(&dots, (w, h), scale),
                "scale {scale}"
            );
        }
    }
}
