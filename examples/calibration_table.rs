//! The calibration loop's figures for the README: a 4-pen chart plotted
//! with known dot gains and inks (synthetic scans: blur, noise, rotation,
//! perspective), fitted; and a grey ramp plotted with a 1.5× gain, with and
//! without the calibrated pen file.
//!
//! `cargo run --release --example calibration_table`

use pixelpie::colour::{Lab, PenSet, delta_e00};
use pixelpie::job::Job;
use pixelpie::stipple::Paper;
use pixelpie::stipple::calibrate::{Chart, ChartSpec, ScanOptions, fit, simulate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a4: Paper = "a4".parse()?;
    let chart = Chart::new(ChartSpec::new(
        &PenSet::cmyk(),
        0.3,
        &a4.place((1, 1), false, 10.0)?,
        0,
    )?)?;
    let inks = [[16, 160, 208], [208, 32, 144], [240, 208, 32], [32, 40, 48]];
    println!("| scan | pen | true gain | fitted | error | ink ΔE00 |");
    println!("|---|---|---|---|---|---|");
    for (name, gains, blur, noise, rotate, perspective, seed) in [
        ("A", [1.0, 1.3, 1.8, 1.5], 1.0, 0.02, 2.0, 0.03, 1),
        ("B", [1.8, 1.0, 1.3, 1.3], 1.6, 0.04, -3.5, 0.05, 7),
    ] {
        let o = ScanOptions {
            gains: gains.to_vec(),
            inks: inks.to_vec(),
            blur_px: blur,
            noise,
            rotate_deg: rotate,
            perspective,
            seed,
            ..ScanOptions::default()
        };
        let scan = simulate::scan(&chart, &o)?;
        let f = fit::fit(&chart, &scan)?;
        for ((p, g), ink) in f.pens.iter().zip(gains).zip(inks) {
            println!(
                "| {name} (blur {blur} px, noise {noise}, {rotate}°, perspective {perspective}) | {} | {g} | {:.3} | {:+.1}% | {:.2} |",
                p.name,
                p.dot_gain,
                100.0 * (p.dot_gain - g) / g,
                delta_e00(Lab::from_srgb8(p.colour), Lab::from_srgb8(ink))
            );
        }
    }
    let pens = PenSet::from_toml(
        "[[pen]]\nname = \"black\"\ncolour = \"#000000\"\nwidth_mm = 0.3\ndot_gain = 1.5\n",
    )?;
    let mut plain = Job::default();
    plain.points = Some(20_000);
    let mut calibrated = plain.clone();
    calibrated.pens = Some(pens);
    println!();
    println!("| 20K-dot grey ramp plotted with gain 1.5 | worst band error (5–95%) | mean |");
    println!("|---|---|---|");
    for (name, job, gain) in [
        ("on screen (gain 1)", &plain, 1.0),
        ("uncalibrated", &plain, 1.5),
        ("calibrated (dot_gain = 1.5)", &calibrated, 1.5),
    ] {
        let e = pixelpie::job::ramp_error(job, gain)?;
        println!("| {name} | {:.3} | {:.3} |", e.worst, e.mean);
    }
    Ok(())
}
