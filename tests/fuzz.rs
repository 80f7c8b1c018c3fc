//! A mutation fuzzer over every parser and check PixelPie owns, and random
//! valid jobs through the whole pipeline: nothing may panic, and a failed
//! run leaves no file.
//!
//! The seed corpus is `tests/fuzz/` (a job file, a pen file, point CSVs, a
//! drawing's SVG, a calibration chart's header, and the crop, paper, ink
//! and pen strings) and the bundled pictures. Each case takes a seed and
//! applies a few mutations (bit flips, bytes that matter to the format,
//! insertions, deletions, copies, splices, truncation), deterministically
//! from the case's number.
//!
//! `PIXELPIE_FUZZ_SCALE=10 cargo test --release --test fuzz` runs ten
//! times as many cases (the default: 100 000 over the text parsers, 3 000
//! mutated pictures, 1 000 random jobs, about a minute on two cores). A
//! crash found here becomes a named regression test below.

mod fixtures;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use fixtures::Rng;
use pixelpie::colour::PenSet;
use pixelpie::importance::{ColourMap, Crop, ImportanceMap};
use pixelpie::job::file::JobFile;
use pixelpie::job::{Decoded, Format, Ink, Job};
use pixelpie::stipple::Paper;

/// The run's scale: `PIXELPIE_FUZZ_SCALE` times the default counts.
fn scale() -> usize {
    std::env::var("PIXELPIE_FUZZ_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
}

fn corpus(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name)
}

/// Bytes that matter to our formats: TOML, CSV, SVG, JSON and numbers.
const SPECIAL: &[u8] = b"\"'=[]{},;:#\n\r\t .-+eE0123456789<>/&\\xX%";

/// `seed` mutated by 1 to 8 random edits (`other`: a second input to
/// splice from).
fn mutate(rng: &mut Rng, seed: &[u8], other: &[u8]) -> Vec<u8> {
    let mut out = seed.to_vec();
    let edits = 1 + (rng.next_f64() * 8.0) as usize;
    let pick = |n: usize, rng: &mut Rng| (rng.next_f64() * n as f64) as usize;
    for _ in 0..edits {
        let n = out.len();
        match pick(8, rng) {
            0 if n > 0 => {
                let i = pick(n, rng);
                out[i] ^= 1 << pick(8, rng);
            }
            1 if n > 0 => {
                let i = pick(n, rng);
                out[i] = SPECIAL[pick(SPECIAL.len(), rng)];
            }
            2 => {
                let i = pick(n + 1, rng);
                let len = 1 + pick(8, rng);
                let bytes: Vec<u8> = (0..len)
                    .map(|_| SPECIAL[pick(SPECIAL.len(), rng)])
                    .collect();
                out.splice(i..i, bytes);
            }
            3 if n > 0 => {
                let i = pick(n, rng);
                let len = (1 + pick(32, rng)).min(n - i);
                out.drain(i..i + len);
            }
            4 if n > 0 => {
                let i = pick(n, rng);
                let len = (1 + pick(64, rng)).min(n - i);
                let copy = out[i..i + len].to_vec();
                let at = pick(out.len() + 1, rng);
                out.splice(at..at, copy);
            }
            5 if !other.is_empty() => {
                let i = pick(other.len(), rng);
                let len = (1 + pick(64, rng)).min(other.len() - i);
                let at = pick(n + 1, rng);
                out.splice(at..at, other[i..i + len].iter().copied());
            }
            6 if n > 0 => out.truncate(pick(n, rng)),
            _ => {
                // A number made huge, negative or odd.
                let i = pick(n + 1, rng);
                let word: &[u8] = [
                    &b"1e308"[..],
                    b"-1",
                    b"99999999999",
                    b"nan",
                    b"inf",
                    b"0",
                    b"4294967296",
                    b"0.0000001",
                ][pick(8, rng)];
                out.splice(i..i, word.iter().copied());
            }
        }
    }
    out
}

/// Runs `parse` on `cases` mutations of `seeds`; a panic fails the test
/// with the input that made it.
fn fuzz_text(name: &str, seeds: &[Vec<u8>], cases: usize, parse: impl Fn(&str)) {
    let mut rng = Rng::new(name.len() as u64 * 7919 + 1);
    for case in 0..cases {
        let seed = &seeds[case % seeds.len()];
        let other = &seeds[(case / seeds.len()) % seeds.len()];
        let bytes = mutate(&mut rng, seed, other);
        let text = String::from_utf8_lossy(&bytes);
        if catch_unwind(AssertUnwindSafe(|| parse(&text))).is_err() {
            panic!("{name}, case {case}: a panic on {text:?}");
        }
    }
}

#[test]
fn text_parsers_never_panic() {
    let n = 100_000 * scale();
    let lines = |name: &str| -> Vec<Vec<u8>> {
        String::from_utf8(corpus(name))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.as_bytes().to_vec())
            .collect()
    };
    let job = vec![corpus("job.toml")];
    fuzz_text("job file", &job, n * 30 / 100, |text| {
        if let Ok(file) = JobFile::parse(text) {
            let _ = Job::from_table(file.table);
        }
    });
    fuzz_text("pen file", &[corpus("pens.toml")], n * 15 / 100, |text| {
        let _ = PenSet::from_toml(text);
    });
    let points = vec![corpus("points.csv"), corpus("points_pens.csv")];
    fuzz_text("point CSV", &points, n * 15 / 100, |text| {
        let _ = pixelpie::analyze::csv::parse(text);
    });
    fuzz_text(
        "drawing SVG",
        &[corpus("drawing.svg")],
        n * 10 / 100,
        |text| {
            let _ = pixelpie::stipple::read::read_svg(text);
        },
    );
    let strings = lines("strings.txt");
    fuzz_text(
        "crop, paper, ink and pens",
        &strings,
        n * 29 / 100,
        |text| {
            let _ = Crop::from_str(text);
            let _ = Paper::from_str(text);
            let _ = Ink::from_str(text);
            let _ = PenSet::from_str(text);
        },
    );
    // A chart's metadata builds the chart (its patches are sampled): fewer.
    fuzz_text("chart SVG", &[corpus("chart.svg")], n / 100, |text| {
        let _ = pixelpie::stipple::calibrate::Chart::read_svg(text);
    });
}

#[test]
fn picture_loaders_never_panic_on_mutated_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut seeds: Vec<(&str, Vec<u8>)> = ["rocket.jpg", "default.png", "gradient.exr"]
        .iter()
        .map(|n| (*n, std::fs::read(asset(n)).unwrap()))
        .collect();
    // Small pictures of the other formats, made here.
    let img = image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(24, 16, |x, y| {
        image::Rgb([(x * 10) as u8, (y * 15) as u8, 128])
    }));
    for (name, format) in [
        ("small.tiff", image::ImageFormat::Tiff),
        ("small.bmp", image::ImageFormat::Bmp),
        ("small.webp", image::ImageFormat::WebP),
        ("small.png", image::ImageFormat::Png),
    ] {
        let mut bytes = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut bytes), format)
            .unwrap();
        seeds.push((name, bytes));
    }
    let mut rng = Rng::new(11);
    let cases = 3_000 * scale();
    for case in 0..cases {
        let (name, seed) = &seeds[case % seeds.len()];
        let bytes = mutate(&mut rng, seed, &[]);
        let path = dir
            .path()
            .join(format!("case.{}", name.rsplit('.').next().unwrap()));
        std::fs::write(&path, &bytes).unwrap();
        let loaded = catch_unwind(AssertUnwindSafe(|| {
            let _ = ImportanceMap::open(&path, None);
            let _ = ColourMap::open(&path, None);
            let _ = ImportanceMap::from_encoded(&bytes, Path::new(name), None);
        }));
        assert!(
            loaded.is_ok(),
            "{name}, case {case}: a panic (kept in {})",
            {
                let keep = std::env::temp_dir().join(format!("pixelpie-fuzz-{case}-{name}"));
                std::fs::write(&keep, &bytes).unwrap();
                keep.display().to_string()
            }
        );
    }
}

/// A random valid job on a small picture: counts, dots, relaxation,
/// order, pens, page and pen, and an output format.
fn random_job(rng: &mut Rng) -> (Job, Format) {
    let mut pick = |n: usize| (rng.next_f64() * n as f64) as usize;
    let mut job = Job::default();
    job.points = Some(20 + pick(400));
    job.relax = [None, Some(0), Some(1), Some(3)][pick(4)];
    job.order = [pixelpie::job::Order::None, pixelpie::job::Order::Tsp][pick(2)];
    job.sampler.seed = pick(1000) as u64;
    job.dot = [
        None,
        Some(pixelpie::job::DotMode::Fixed),
        Some(pixelpie::job::DotMode::Sized),
    ][pick(3)];
    job.pens = match pick(4) {
        0 => Some(PenSet::cmyk()),
        1 => Some(PenSet::from_colours(["#d02020", "#2040c0"]).unwrap()),
        _ => None,
    };
    if pick(3) == 0 {
        job.paper = Some("a6".parse().unwrap());
        job.pen_mm = Some(0.2 + 0.1 * pick(4) as f64);
    }
    job.importance.gamma = [1.0, 0.7, 1.6][pick(3)];
    job.importance.invert = pick(5) == 0;
    let format = [Format::Svg, Format::Png, Format::Csv, Format::Json][pick(4)];
    (job, format)
}

#[test]
fn random_jobs_run_the_whole_pipeline() {
    let dir = tempfile::tempdir().unwrap();
    // Three small pictures: a ramp, noise and a flat grey.
    let mut rng = Rng::new(5);
    let pictures: Vec<PathBuf> = (0..3)
        .map(|k| {
            let img = image::RgbImage::from_fn(48, 32, |x, y| {
                let v = match k {
                    0 => (x * 5) as u8,
                    1 => (rng.next_f64() * 255.0) as u8,
                    _ => 128,
                };
                image::Rgb([v, v.wrapping_add(y as u8 * 3), v / 2])
            });
            let path = dir.path().join(format!("p{k}.png"));
            img.save(&path).unwrap();
            path
        })
        .collect();
    let mut rng = Rng::new(17);
    let cases = 1_000 * scale();
    let mut drawn = 0;
    for case in 0..cases {
        let (job, format) = random_job(&mut rng);
        let picture = &pictures[case % pictures.len()];
        let out = dir.path().join(format!("out.{}", format.extension()));
        let _ = std::fs::remove_file(&out);
        let run = catch_unwind(AssertUnwindSafe(|| -> pixelpie::Result<_> {
            job.validate(format)?;
            let decoded = Decoded::open(&job, picture)?;
            let planned = job.plan(decoded.picture())?.plan;
            let drawing = job.draw(
                decoded.picture(),
                |p| Ok(pixelpie::sampler::cpu::sample(p, Default::default())?),
                |_| true,
            )?;
            job.write(&drawing, &out)?;
            Ok((planned, drawing))
        }));
        let Ok(result) = run else {
            panic!("case {case}: a panic on {job:?} to {format:?}");
        };
        match result {
            Err(_) => assert!(!out.exists(), "case {case}: a failed run left {out:?}"),
            Ok((plan, drawing)) => {
                drawn += 1;
                // The output reads back.
                let bytes = std::fs::read(&out).unwrap();
                match format {
                    Format::Svg => {
                        let text = String::from_utf8(bytes).unwrap();
                        assert!(text.starts_with("<?xml") && text.trim_end().ends_with("</svg>"));
                    }
                    Format::Png => {
                        image::load_from_memory(&bytes).unwrap();
                    }
                    Format::Csv => {
                        let t = pixelpie::analyze::csv::parse(&String::from_utf8(bytes).unwrap())
                            .unwrap();
                        assert_eq!(t.points.len(), drawing.points.len(), "case {case}");
                    }
                    Format::Json => {
                        serde_json::from_slice::<serde_json::Value>(&bytes).unwrap();
                    }
                }
                // The count is the plan's, or the plan said it falls short.
                let got = drawing.points.len() as f64;
                let want = plan.dots as f64;
                assert!(
                    drawing.short_of.is_some() || (got - want).abs() <= 0.25 * want + 10.0,
                    "case {case}: {got} dots where the plan said {want}: {job:?}"
                );
            }
        }
    }
    assert!(
        drawn * 2 > cases,
        "only {drawn} of {cases} random jobs drew"
    );
}

#[test]
fn the_chart_scan_reader_never_panics_on_damaged_scans() {
    use pixelpie::stipple::calibrate::{Chart, ScanOptions, fit::fit, simulate};
    let chart = Chart::read_svg(&String::from_utf8(corpus("chart.svg")).unwrap()).unwrap();
    let options = ScanOptions {
        px_per_mm: 3.0,
        ..ScanOptions::default()
    };
    let clean = simulate::scan(&chart, &options).unwrap();
    assert!(fit(&chart, &clean).is_ok(), "the clean scan must fit");
    let mut rng = Rng::new(23);
    let cases = 60 * scale();
    for case in 0..cases {
        let mut pick = |n: u32| (rng.next_f64() * f64::from(n)) as u32;
        let mut img = clean.clone();
        let (w, h) = img.dimensions();
        match case % 4 {
            // Painted rectangles (tape, a hand, a shadow).
            0 => {
                for _ in 0..1 + pick(6) {
                    let (x0, y0) = (pick(w), pick(h));
                    let (x1, y1) = ((x0 + pick(w / 2)).min(w), (y0 + pick(h / 2)).min(h));
                    let c = [pick(256) as u8, pick(256) as u8, pick(256) as u8];
                    for y in y0..y1 {
                        for x in x0..x1 {
                            img.put_pixel(x, y, image::Rgb(c));
                        }
                    }
                }
            }
            // Noise over everything.
            1 => {
                let amount = pick(256);
                for p in img.pixels_mut() {
                    for c in &mut p.0 {
                        *c = c.wrapping_add((pick(amount + 1)) as u8);
                    }
                }
            }
            // A crop: part of the sheet missing.
            2 => {
                let (cw, ch) = (1 + pick(w), 1 + pick(h));
                img = image::imageops::crop_imm(&img, pick(w - cw + 1), pick(h - ch + 1), cw, ch)
                    .to_image();
            }
            // Another resolution, down to a few pixels.
            _ => {
                let (nw, nh) = (1 + pick(w * 2), 1 + pick(h * 2));
                img = image::imageops::resize(&img, nw, nh, image::imageops::FilterType::Nearest);
            }
        }
        let read = catch_unwind(AssertUnwindSafe(|| {
            let _ = fit(&chart, &img);
        }));
        assert!(
            read.is_ok(),
            "case {case}: a panic on a {:?} scan",
            img.dimensions()
        );
    }
}
