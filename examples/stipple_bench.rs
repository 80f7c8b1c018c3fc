//! The drawings side by side: PixelPie's default stipple, without its
//! correction, as earlier versions drew, with equal dots, weighted Voronoi stippling from a random start (Secord 2002,
//! StippleGen's method: 30 Lloyd iterations) and i.i.d. random dots, at the
//! same dot count, measured as `pixelpie fidelity` measures (blurred PSNR
//! and SSIM on display grey, σ = the mean dot spacing).
//!
//! ```text
//! cargo run --release --example stipple_bench -- [--points N] [PHOTO...]
//! ```
//!
//! Every row of equal dots is scored with its own best constant dot radius
//! (a sweep), as the comparison asks; PixelPie's rows also show the
//! calibrated dots (no sweep: what `pixelpie stipple` draws), and rows of
//! dots sized by tone only those. Seconds are the drawing's time from the
//! loaded photo (PixelPie: the whole job; the others: placement), not the
//! scoring's.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use pixelpie::analyze::fidelity::{self, Grey};
use pixelpie::importance::{Adjust, ImportanceMap, Tones, linear_to_srgb};
use pixelpie::job::{Correction, DotMode, Job, Spacing};
use pixelpie::stipple::{Dot, raster, relax};

/// The default domain's longer side, as `pixelpie stipple` picks it.
fn domain(w: u32, h: u32, n: usize) -> (u32, u32) {
    let side = 1024f64.max(10.0 * (n as f64).sqrt()).ceil();
    let s = side / f64::from(w.max(h));
    (
        (f64::from(w) * s).round() as u32,
        (f64::from(h) * s).round() as u32,
    )
}

struct Row {
    name: &'static str,
    seconds: f64,
    points: Vec<[f32; 2]>,
    calibrated: Option<Vec<f32>>,
    sized: bool,
}

fn main() -> Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut n = 10_000usize;
    if let Some(i) = args.iter().position(|a| a == "--points") {
        n = args.get(i + 1).map_or(Ok(n), |s| s.parse())?;
        args.drain(i..(i + 2).min(args.len()));
    }
    let photos: Vec<PathBuf> = if args.is_empty() {
        vec!["assets/default.png".into(), "assets/rocket.jpg".into()]
    } else {
        args.iter().map(PathBuf::from).collect()
    };
    println!("| photo | drawing | dots | PSNR dB | SSIM | seconds | dot radius (domain px) |");
    println!("|---|---|---|---|---|---|---|");
    for path in &photos {
        let photo_map = ImportanceMap::open(path, None)?;
        let (pw, ph) = (photo_map.width(), photo_map.height());
        let photo = Grey {
            width: pw,
            height: ph,
            values: photo_map
                .values()
                .iter()
                .map(|&v| linear_to_srgb(v))
                .collect(),
        };
        let (w, h) = domain(pw, ph, n);
        let map = photo_map
            .resized(w, h)?
            .toned(Tones::Display)
            .adjusted(&Adjust::default())?;
        let darkness: Vec<f32> = map.values().iter().map(|v| 1.0 - v).collect();
        let density = relax::Density {
            width: w,
            height: h,
            weights: &darkness,
        };
        let rows = [
            pixelpie_row("PixelPie default", &photo_map, n, w, |_| {})?,
            pixelpie_row("PixelPie --correction off", &photo_map, n, w, |j| {
                j.correction = Correction::Off;
            })?,
            pixelpie_row(
                "PixelPie --spacing radius --relax 0 --correction off (earlier versions)",
                &photo_map,
                n,
                w,
                |j| {
                    j.spacing = Spacing::Radius;
                    j.relax = Some(0);
                    j.correction = Correction::Off;
                },
            )?,
            pixelpie_row("PixelPie --dot fixed", &photo_map, n, w, |j| {
                j.dot = Some(DotMode::Fixed);
            })?,
            voronoi_row(&density, n),
            random_row(&density, n),
        ];
        let sigma = (f64::from(pw) * f64::from(ph) / n as f64).sqrt();
        let name = path
            .file_name()
            .map_or_else(String::new, |f| f.to_string_lossy().into());
        for row in &rows {
            let score = |dots: &[Dot]| -> Result<fidelity::Fidelity> {
                let view = (f64::from(w), f64::from(h));
                let drawing = Grey {
                    width: pw,
                    height: ph,
                    values: raster::render_mean(dots, view, (pw, ph))?,
                };
                Ok(fidelity::compare(&photo, &drawing, sigma)?)
            };
            if let Some(cal) = &row.calibrated {
                let dots: Vec<Dot> = row
                    .points
                    .iter()
                    .zip(cal)
                    .map(|(p, &r)| Dot {
                        x: p[0],
                        y: p[1],
                        radius: r,
                    })
                    .collect();
                let f = score(&dots)?;
                println!(
                    "| {name} | {} (calibrated dots) | {} | {:.2} | {:.3} | {:.3} | {:.2} |",
                    row.name,
                    row.points.len(),
                    f.psnr,
                    f.ssim,
                    row.seconds,
                    cal.iter().sum::<f32>() / cal.len().max(1) as f32
                );
            }
            if row.sized {
                // Dots sized by tone: a constant radius would undo the mode.
                continue;
            }
            // The best constant radius: a sweep around the radius at which
            // the dots' total area equals the photo's total darkness.
            let ink: f64 = darkness.iter().map(|&d| f64::from(d)).sum();
            let base = (ink / std::f64::consts::PI / row.points.len().max(1) as f64).sqrt();
            let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
            for i in 0..13 {
                let r = base * (0.7 + 0.05 * f64::from(i));
                let dots: Vec<Dot> = row
                    .points
                    .iter()
                    .map(|p| Dot {
                        x: p[0],
                        y: p[1],
                        radius: r as f32,
                    })
                    .collect();
                let f = score(&dots)?;
                if f.psnr > best.0 {
                    best = (f.psnr, f.ssim, r);
                }
            }
            println!(
                "| {name} | {} (best constant dots) | {} | {:.2} | {:.3} | {:.3} | {:.2} |",
                row.name,
                row.points.len(),
                best.0,
                best.1,
                row.seconds,
                best.2
            );
        }
    }
    Ok(())
}

/// `pixelpie stipple`'s drawing of `photo` at `n` dots, with the default
/// job changed by `set`: its dots, in a domain `w` pixels wide.
fn pixelpie_row(
    name: &'static str,
    photo: &ImportanceMap,
    n: usize,
    w: u32,
    set: impl Fn(&mut Job),
) -> Result<Row> {
    let mut job = Job::default();
    job.points = Some(n);
    set(&mut job);
    let t = Instant::now();
    let drawing = job.run_map(photo, |p| Ok(p.generate()?), |_| true)?;
    let seconds = t.elapsed().as_secs_f64();
    let k = f64::from(w) / f64::from(drawing.domain.0);
    let dots = job.dots(&drawing);
    Ok(Row {
        name,
        seconds,
        points: dots
            .iter()
            .map(|d| [(f64::from(d.x) * k) as f32, (f64::from(d.y) * k) as f32])
            .collect(),
        calibrated: Some(
            dots.iter()
                .map(|d| (f64::from(d.radius) * k) as f32)
                .collect(),
        ),
        sized: job.dot_mode() == DotMode::Sized,
    })
}

/// Weighted Voronoi stippling: 30 Lloyd iterations on the darkness from
/// random points drawn by the darkness.
fn voronoi_row(density: &relax::Density<'_>, n: usize) -> Row {
    let t = Instant::now();
    let start = relax::random_start(n, density, 7);
    let options = relax::RelaxOptions {
        iterations: 30,
        periodic: false,
        cells: relax::Cells::Pixels,
        over: 1.0,
    };
    let points = relax::relax(&start, density, options, |_| true);
    Row {
        name: "weighted Voronoi (30 Lloyd steps from random)",
        seconds: t.elapsed().as_secs_f64(),
        points,
        calibrated: None,
        sized: false,
    }
}

/// i.i.d. random dots drawn by the darkness.
fn random_row(density: &relax::Density<'_>, n: usize) -> Row {
    let t = Instant::now();
    let points = relax::random_start(n, density, 7);
    Row {
        name: "i.i.d. random",
        seconds: t.elapsed().as_secs_f64(),
        points,
        calibrated: None,
        sized: false,
    }
}
