//! The colour table of the README: PixelPie's coupled pens against
//! DrawingBotV3's way (each CMYK channel of a naive GCR stippled on its
//! own with our calibrated grey stipple, the layers laid over each other)
//! and against black dots only, by the colour measure of
//! `pixelpie fidelity` (CIEDE2000 between the blurred photo and the
//! blurred drawing, σ = the mean dot spacing), with the time of each, and
//! the separation's continuous-tone limit (its colours with no dots).
//!
//! ```text
//! cargo run --release --example colour_table -- [--pens SPEC] [--points N] [--sigma-factor F] PHOTO...
//! ```
//!
//! One run each, on the CPU backend, seed 0.

use std::time::Instant;

use anyhow::{Context, Result};
use pixelpie::analyze::fidelity::colour::{Rgb, compare_colour, luminance};
use pixelpie::analyze::fidelity::{Grey, compare};
use pixelpie::colour::{PenSet, RenderModel, Separation};
use pixelpie::importance::ink::K_MAX;
use pixelpie::importance::{ColourMap, ImportanceMap, linear_to_srgb, srgb_to_linear};
use pixelpie::job::Job;
use pixelpie::sampler::cpu;

/// The three channels of `img`, rendered at `k` times the photo's size,
/// each pixel the mean of its k×k block (in display values, as the
/// measure averages): dots a pixel or two wide at the photo's size are so
/// measured by their coverage (`pixelpie fidelity` likewise renders an
/// SVG finer and brings it down to the photo's size).
fn channels(img: &image::RgbImage, k: u32) -> Rgb {
    let (fw, fh) = img.dimensions();
    let (w, h) = (fw / k, fh / k);
    let raw = img.as_raw();
    [0, 1, 2].map(|c| Grey {
        width: w,
        height: h,
        values: (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let mut sum = 0u32;
                for fy in y * k..(y + 1) * k {
                    for fx in x * k..(x + 1) * k {
                        sum += u32::from(raw[3 * (fy * fw + fx) as usize + c]);
                    }
                }
                sum as f32 / (255 * k * k) as f32
            })
            .collect(),
    })
}

/// The render's scale over the photo's size: up to 4, at most 4096 px a
/// side.
fn fine_scale(w: u32, h: u32) -> u32 {
    (4096 / w.max(h).max(1)).clamp(1, 4)
}

struct Row {
    method: &'static str,
    overlap: Option<f64>,
    de: f64,
    p95: f64,
    de_linear: f64,
    psnr: f64,
    seconds: f64,
}

fn measure(
    photo: &Rgb,
    drawing: &Rgb,
    sigma: f64,
    method: &'static str,
    seconds: f64,
) -> Result<Row> {
    let c = compare_colour(photo, drawing, sigma)?;
    let g = compare(&luminance(photo), &luminance(drawing), sigma)?;
    Ok(Row {
        method,
        overlap: None,
        de: c.delta_e00_mean,
        p95: c.delta_e00_p95,
        de_linear: c.delta_e00_mean_linear,
        psnr: g.psnr,
        seconds,
    })
}

/// The share of the inked paper where two or more pens' dots overlap (each
/// pixel's inks taken as independent within it).
fn overlap(layers: &[image::GrayImage]) -> f64 {
    let (mut inked, mut over) = (0.0, 0.0);
    for i in 0..layers[0].as_raw().len() {
        let a: Vec<f64> = layers
            .iter()
            .map(|l| 1.0 - f64::from(l.as_raw()[i]) / 255.0)
            .collect();
        let none: f64 = a.iter().map(|v| 1.0 - v).product();
        let one: f64 = (0..a.len())
            .map(|k| {
                a[k] * a
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != k)
                    .map(|(_, v)| 1.0 - v)
                    .product::<f64>()
            })
            .sum();
        inked += 1.0 - none;
        over += 1.0 - none - one;
    }
    if inked > 0.0 { over / inked } else { 0.0 }
}

fn sample(p: &pixelpie::sampler::Params) -> pixelpie::Result<pixelpie::sampler::SampleSet> {
    Ok(cpu::sample(p, Default::default())?)
}

fn main() -> Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut take = |flag: &str| -> Option<String> {
        let i = args.iter().position(|a| a == flag)?;
        args.remove(i);
        Some(args.remove(i))
    };
    let pens = PenSet::parse(&take("--pens").unwrap_or_else(|| "cmyk".into()))?;
    let points: usize = take("--points").map_or(Ok(20_000), |s| s.parse())?;
    let sigma_factor: f64 = take("--sigma-factor").map_or(Ok(1.0), |s| s.parse())?;
    println!(
        "| photo | method | ΔE00 mean | ΔE00 p95 | ΔE00 mean (linear) | luminance PSNR dB | pens overlap | seconds |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for path in &args {
        let path = std::path::Path::new(path);
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let picture = ColourMap::open(path, None).with_context(|| name.to_string())?;
        let (w, h) = (picture.width(), picture.height());
        let photo: Rgb = [0, 1, 2].map(|k| Grey {
            width: w,
            height: h,
            values: picture.rgb().iter().map(|c| linear_to_srgb(c[k])).collect(),
        });
        let sigma = sigma_factor * (f64::from(w) * f64::from(h) / points as f64).sqrt();
        let mut rows = Vec::new();

        // PixelPie: the pens sampled together.
        let mut job = Job::default();
        job.points = Some(points);
        job.pens = Some(pens.clone());
        let t = Instant::now();
        let drawing = job.draw(pixelpie::job::Picture::Colour(&picture), sample, |_| true)?;
        let seconds = t.elapsed().as_secs_f64();
        let domain = drawing.domain;
        let k = fine_scale(w, h);
        let img = job.picture(&drawing, (w * k, h * k))?;
        let mut row = measure(
            &photo,
            &channels(&img, k),
            sigma,
            "PixelPie --pens",
            seconds,
        )?;
        let view = (f64::from(domain.0), f64::from(domain.1));
        let layers = job
            .pen_dots(&drawing)
            .iter()
            .map(|l| pixelpie::stipple::raster::render_view_union(l, view, domain))
            .collect::<Result<Vec<_>, _>>()?;
        row.overlap = Some(overlap(&layers));
        rows.push(row);

        // The continuous-tone limit: the separation's own colours.
        let model = RenderModel::new(&pens, false);
        let inks = Separation::new(model.clone(), K_MAX).image(picture.rgb());
        let limit: Rgb = [0, 1, 2].map(|k| Grey {
            width: w,
            height: h,
            values: (0..(w * h) as usize)
                .map(|i| {
                    let a: Vec<f64> = inks.iter().map(|p| f64::from(p[i])).collect();
                    model.mix(&a)[k] as f32
                })
                .collect(),
        });
        rows.push(measure(&photo, &limit, sigma, "separation, no dots", 0.0)?);

        // DrawingBotV3's way: naive GCR, each channel stippled alone.
        if pens == PenSet::cmyk() {
            let t = Instant::now();
            let enc: Vec<[f32; 3]> = photo[0]
                .values
                .iter()
                .zip(&photo[1].values)
                .zip(&photo[2].values)
                .map(|((&r, &g), &b)| [r, g, b])
                .collect();
            let mut planes: Vec<Vec<f32>> = (0..4).map(|_| Vec::with_capacity(enc.len())).collect();
            for c in &enc {
                let k = 1.0 - c[0].max(c[1]).max(c[2]);
                for i in 0..3 {
                    let v = if k < 1.0 {
                        (1.0 - c[i] - k) / (1.0 - k)
                    } else {
                        0.0
                    };
                    planes[i].push(v.clamp(0.0, 1.0));
                }
                planes[3].push(k);
            }
            let total: f64 = planes.iter().flatten().map(|&v| f64::from(v)).sum();
            let (mut layers, mut fine) = (Vec::new(), Vec::new());
            for (plane, pen) in planes.iter().zip(pens.pens()) {
                let share = plane.iter().map(|&v| f64::from(v)).sum::<f64>() / total;
                let n = (points as f64 * share).round() as usize;
                if n == 0 {
                    layers.push(image::GrayImage::from_pixel(
                        w * k,
                        h * k,
                        image::Luma([255]),
                    ));
                    fine.push(image::GrayImage::from_pixel(
                        domain.0,
                        domain.1,
                        image::Luma([255]),
                    ));
                    continue;
                }
                // The grey job reproduces the display grey 1 − ink.
                let map = ImportanceMap::from_values(
                    w,
                    h,
                    plane.iter().map(|&k| srgb_to_linear(1.0 - k)).collect(),
                )?;
                let mut grey = Job::default();
                grey.points = Some(n);
                (grey.width, grey.height) = (Some(domain.0), Some(domain.1));
                // A channel with too little ink for its share of the dots
                // at radii the domain holds draws nothing.
                let Ok(d) = grey.run_map(&map, sample, |_| true) else {
                    layers.push(image::GrayImage::from_pixel(
                        w * k,
                        h * k,
                        image::Luma([255]),
                    ));
                    fine.push(image::GrayImage::from_pixel(
                        domain.0,
                        domain.1,
                        image::Luma([255]),
                    ));
                    continue;
                };
                let dots = grey.dots(&d);
                let view = (f64::from(d.domain.0), f64::from(d.domain.1));
                layers.push(pixelpie::stipple::raster::render_view_union(
                    &dots,
                    view,
                    (w * k, h * k),
                )?);
                fine.push(pixelpie::stipple::raster::render_view_union(
                    &dots, view, domain,
                )?);
                let _ = pen;
            }
            let img = pixelpie::stipple::raster::composite(&layers, &model)?;
            let seconds = t.elapsed().as_secs_f64();
            let method = "CMYK channels apart (DrawingBotV3)";
            let mut row = measure(&photo, &channels(&img, k), sigma, method, seconds)?;
            row.overlap = Some(overlap(&fine));
            rows.push(row);
        }

        // Black dots only.
        let mut grey = Job::default();
        grey.points = Some(points);
        (grey.width, grey.height) = (Some(domain.0), Some(domain.1));
        let t = Instant::now();
        let d = grey.run_map(&picture.luminance(), sample, |_| true)?;
        let seconds = t.elapsed().as_secs_f64();
        let img = grey.picture(&d, (w * k, h * k))?;
        rows.push(measure(
            &photo,
            &channels(&img, k),
            sigma,
            "black only",
            seconds,
        )?);

        for r in rows {
            let overlap = r
                .overlap
                .map_or("".into(), |o| format!("{:.1}%", 100.0 * o));
            println!(
                "| {name} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {overlap} | {:.2} |",
                r.method, r.de, r.p95, r.de_linear, r.psnr, r.seconds
            );
        }
    }
    Ok(())
}
