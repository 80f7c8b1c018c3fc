//! The analysis figures, drawn with `plotters` into RGB buffers: the point
//! set, the periodogram, the radially averaged power spectrum, the
//! anisotropy and the angle histogram (paper Figures 7, 9 and 10).
//!
//! plotters is built without a font backend here (no system fonts needed),
//! so tick labels are drawn with a built-in 3×5 pixel digit font.

use std::io::Write;

use image::{ImageEncoder, RgbImage};
use plotters::prelude::*;

use super::spectrum::{Periodogram, RadialSpectrum};
use super::{Error, Result};

/// Side of the square plots in pixels.
pub const SQUARE: u32 = 512;
/// Size of the line and bar charts in pixels.
pub const CHART: (u32, u32) = (640, 360);
/// The periodogram's grey scale: ln(1 + P) / ln(1 + this) is white.
pub const PERIODOGRAM_WHITE: f64 = 4.0;

const LEFT: u32 = 56;
const BOTTOM: u32 = 26;
const PAD: u32 = 12;

fn plot_err(e: impl std::fmt::Display) -> Error {
    Error::Plot(e.to_string())
}

fn finish(buf: Vec<u8>, (w, h): (u32, u32)) -> Result<RgbImage> {
    RgbImage::from_raw(w, h, buf).ok_or_else(|| Error::Plot("buffer of the wrong size".into()))
}

/// The point set as black dots on white, the domain scaled to fit 512 px.
pub fn points(points: &[[f64; 2]], domain: (f64, f64)) -> Result<RgbImage> {
    let s = f64::from(SQUARE) / domain.0.max(domain.1);
    let size = (
        ((domain.0 * s).round() as u32).max(1),
        ((domain.1 * s).round() as u32).max(1),
    );
    let mut buf = vec![255u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        let dot = if points.len() > 20_000 { 1 } else { 2 };
        root.draw(&EmptyElement::at((0, 0))).map_err(plot_err)?;
        for p in points {
            let c = ((p[0] * s) as i32, (p[1] * s) as i32);
            root.draw(&Circle::new(c, dot, BLACK.filled()))
                .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    finish(buf, size)
}

/// The periodogram as a grey image, DC at the centre (and drawn black),
/// grey = ln(1 + P) / ln(1 + [`PERIODOGRAM_WHITE`]), so white noise (P = 1)
/// is mid grey; frequencies grow to the right and upwards.
pub fn periodogram(p: &Periodogram) -> Result<RgbImage> {
    let side = p.side();
    let size = (SQUARE, SQUARE);
    let mut buf = vec![0u8; (SQUARE * SQUARE * 3) as usize];
    let k = p.max_frequency as i64;
    let scale = 255.0 / (1.0 + PERIODOGRAM_WHITE).ln();
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        for py in 0..SQUARE {
            // Row 0 is the highest l.
            let l = k - (u64::from(py) * side as u64 / u64::from(SQUARE)) as i64;
            for px in 0..SQUARE {
                let kx = (u64::from(px) * side as u64 / u64::from(SQUARE)) as i64 - k;
                let v = if kx == 0 && l == 0 { 0.0 } else { p.at(kx, l) };
                let g = ((1.0 + v).ln() * scale).clamp(0.0, 255.0) as u8;
                root.draw_pixel((px as i32, py as i32), &RGBColor(g, g, g))
                    .map_err(plot_err)?;
            }
        }
        root.present().map_err(plot_err)?;
    }
    finish(buf, size)
}

/// "Nice" tick values covering [lo, hi]: steps of 1, 2 or 5 × 10^k.
fn ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    let span = (hi - lo).abs().max(1e-12);
    let raw = span / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + step * 1e-9 {
        out.push(if t.abs() < step * 1e-9 { 0.0 } else { t });
        t += step;
    }
    out
}

/// A line chart of `ys` against `xs` with a dashed reference level.
fn line_chart(xs: &[f64], ys: &[f64], y_range: (f64, f64), reference: f64) -> Result<RgbImage> {
    let size = CHART;
    let mut buf = vec![255u8; (size.0 * size.1 * 3) as usize];
    let x_max = xs.last().copied().unwrap_or(1.0).max(1.0);
    let mut labels = Vec::new();
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        let area = root.margin(PAD, BOTTOM, LEFT, PAD);
        let mut chart = ChartBuilder::on(&area)
            .build_cartesian_2d(0f64..x_max, y_range.0..y_range.1)
            .map_err(plot_err)?;
        let grid = RGBColor(220, 220, 220);
        for t in ticks(0.0, x_max, 8) {
            chart
                .draw_series(LineSeries::new([(t, y_range.0), (t, y_range.1)], grid))
                .map_err(plot_err)?;
            let (px, py) = chart.backend_coord(&(t, y_range.0));
            labels.push((px, py + 6, fmt_tick(t), true));
        }
        for t in ticks(y_range.0, y_range.1, 6) {
            chart
                .draw_series(LineSeries::new([(0.0, t), (x_max, t)], grid))
                .map_err(plot_err)?;
            let (px, py) = chart.backend_coord(&(0.0, t));
            labels.push((px - 6, py - 3, fmt_tick(t), false));
        }
        let dashes: Vec<Vec<(f64, f64)>> = ticks(0.0, x_max, 60)
            .windows(2)
            .step_by(2)
            .map(|w| vec![(w[0], reference), (w[1], reference)])
            .collect();
        for d in dashes {
            chart
                .draw_series(LineSeries::new(d, RGBColor(200, 60, 60)))
                .map_err(plot_err)?;
        }
        let clamp = |y: f64| y.clamp(y_range.0, y_range.1);
        chart
            .draw_series(LineSeries::new(
                xs.iter()
                    .zip(ys)
                    .filter(|(_, y)| y.is_finite())
                    .map(|(&x, &y)| (x, clamp(y))),
                BLACK.stroke_width(2),
            ))
            .map_err(plot_err)?;
        let (x0, y0) = chart.backend_coord(&(0.0, y_range.1));
        let (x1, y1) = chart.backend_coord(&(x_max, y_range.0));
        root.draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK))
            .map_err(plot_err)?;
        root.present().map_err(plot_err)?;
    }
    let mut img = finish(buf, size)?;
    for (x, y, text, centred) in labels {
        draw_label(&mut img, x, y, &text, centred);
    }
    Ok(img)
}

/// The radially averaged power spectrum (dashed: white noise, P = 1).
pub fn radial_power(r: &RadialSpectrum) -> Result<RgbImage> {
    let top = r
        .power
        .iter()
        .copied()
        .filter(|p| p.is_finite())
        .fold(2.0f64, f64::max)
        .min(8.0);
    line_chart(&r.frequency, &r.power, (0.0, top * 1.05), 1.0)
}

/// The anisotropy in dB (dashed: the isotropic level, −10 log₁₀ of the
/// number of sets averaged).
pub fn anisotropy(r: &RadialSpectrum) -> Result<RgbImage> {
    let reference = -10.0 * (r.sets.max(1) as f64).log10();
    let hi = r
        .anisotropy_db
        .iter()
        .copied()
        .filter(|a| a.is_finite())
        .fold(10.0f64, f64::max)
        .min(40.0);
    line_chart(
        &r.frequency,
        &r.anisotropy_db,
        (reference - 10.0, hi),
        reference,
    )
}

/// The 360-bin angle histogram as bars (dashed: the mean count).
pub fn angle_histogram(counts: &[u64]) -> Result<RgbImage> {
    let xs: Vec<f64> = (0..counts.len()).map(|i| i as f64).collect();
    let ys: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
    let mean = ys.iter().sum::<f64>() / ys.len().max(1) as f64;
    let top = ys.iter().copied().fold(2.0 * mean, f64::max).max(1.0);
    let size = CHART;
    let mut buf = vec![255u8; (size.0 * size.1 * 3) as usize];
    let mut labels = Vec::new();
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        let area = root.margin(PAD, BOTTOM, LEFT, PAD);
        let mut chart = ChartBuilder::on(&area)
            .build_cartesian_2d(0f64..xs.len() as f64, 0f64..top * 1.05)
            .map_err(plot_err)?;
        for t in [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0, 360.0] {
            chart
                .draw_series(LineSeries::new(
                    [(t, 0.0), (t, top * 1.05)],
                    RGBColor(220, 220, 220),
                ))
                .map_err(plot_err)?;
            let (px, py) = chart.backend_coord(&(t, 0.0));
            labels.push((px, py + 6, fmt_tick(t), true));
        }
        for t in ticks(0.0, top * 1.05, 6) {
            let (px, py) = chart.backend_coord(&(0.0, t));
            labels.push((px - 6, py - 3, fmt_tick(t), false));
        }
        chart
            .draw_series(xs.iter().zip(&ys).map(|(&x, &y)| {
                Rectangle::new([(x, 0.0), (x + 1.0, y)], RGBColor(200, 40, 40).filled())
            }))
            .map_err(plot_err)?;
        chart
            .draw_series(LineSeries::new([(0.0, mean), (360.0, mean)], BLACK))
            .map_err(plot_err)?;
        root.present().map_err(plot_err)?;
    }
    let mut img = finish(buf, size)?;
    for (x, y, text, centred) in labels {
        draw_label(&mut img, x, y, &text, centred);
    }
    Ok(img)
}

/// Encodes `img` as PNG into `w`: 8-bit grey when every pixel is grey
/// (a third of the size), RGB otherwise.
pub fn write_png(w: &mut dyn Write, img: &RgbImage) -> Result<()> {
    let encoder = image::codecs::png::PngEncoder::new_with_quality(
        w,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    );
    let grey = img.pixels().all(|p| p.0[0] == p.0[1] && p.0[1] == p.0[2]);
    if grey {
        let luma: Vec<u8> = img.pixels().map(|p| p.0[0]).collect();
        encoder.write_image(
            &luma,
            img.width(),
            img.height(),
            image::ExtendedColorType::L8,
        )
    } else {
        encoder.write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
    }
    .map_err(plot_err)
}

fn fmt_tick(t: f64) -> String {
    if (t - t.round()).abs() < 1e-9 {
        format!("{}", t.round() as i64)
    } else {
        let s = format!("{t:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

/// 3×5 glyphs of `0-9 . -`, one row per `u8`, high bit on the left.
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '3' => [0b111, 0b001, 0b111, 0b001, 0b111],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '6' => [0b111, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b010, 0b010, 0b010],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b111],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        _ => return None,
    })
}

/// Draws `text` at 2× scale: centred on `x` below `y`, or right-aligned to `x`.
fn draw_label(img: &mut RgbImage, x: i32, y: i32, text: &str, centred: bool) {
    const S: i32 = 2;
    let width = text.chars().count() as i32 * 4 * S - S;
    let x0 = if centred { x - width / 2 } else { x - width };
    for (i, c) in text.chars().enumerate() {
        let Some(rows) = glyph(c) else { continue };
        for (ry, bits) in rows.iter().enumerate() {
            for rx in 0..3 {
                if bits & (0b100 >> rx) == 0 {
                    continue;
                }
                for dy in 0..S {
                    for dx in 0..S {
                        let px = x0 + (i as i32 * 4 + rx) * S + dx;
                        let py = y + ry as i32 * S + dy;
                        if px >= 0
                            && py >= 0
                            && (px as u32) < img.width()
                            && (py as u32) < img.height()
                        {
                            img.put_pixel(px as u32, py as u32, image::Rgb([0, 0, 0]));
                        }
                    }
                }
            }
        }
    }
}
