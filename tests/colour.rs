//! Colour drawings (`--pens`): flat colour patches come back within ΔE00 2
//! after the blur, under both tone conventions; a grey photo needs only the
//! black pen; transparent pixels need no dots; the outputs carry one layer
//! (SVG), one colour (PNG) and one pen column (CSV, JSON) per pen; and bad
//! pens end in one `error:` line with no output.

mod fixtures;

use std::path::Path;
use std::process::Command;

use image::{ImageBuffer, Rgb, Rgba};
use pixelpie::analyze::fidelity::{Grey, blur};
use pixelpie::colour::{Lab, PenSet, delta_e00};
use pixelpie::importance::Tones;
use pixelpie::job::{Job, Stipple};
use pixelpie::sampler::cpu;
use pixelpie::stipple::plot::{Motion, Plotter, Saxi, plot_paths};

/// Six in-gamut colours of the CMYK pens, 8-bit sRGB.
const PATCHES: [[u8; 3]; 6] = [
    [204, 77, 51],
    [51, 128, 179],
    [128, 128, 128],
    [230, 217, 102],
    [77, 153, 77],
    [64, 56, 110],
];
const SIDE: u32 = 120;

fn patches(dir: &Path) -> std::path::PathBuf {
    let img = ImageBuffer::from_fn(3 * SIDE, 2 * SIDE, |x, y| {
        Rgb(PATCHES[(y / SIDE * 3 + x / SIDE) as usize])
    });
    let path = dir.join("patches.png");
    img.save(&path).unwrap();
    path
}

fn run(job: &Job, path: &Path) -> Stipple {
    job.run(path, |p| Ok(cpu::sample(p, Default::default())?), |_| true)
        .unwrap()
}

fn cmyk(points: usize) -> Job {
    let mut job = Job::default();
    job.points = Some(points);
    job.pens = Some(PenSet::cmyk());
    job
}

/// The blurred drawing's colour in the middle of each patch against the
/// patch's own, ΔE00, under the job's convention.
fn patch_errors(job: &Job, drawing: &Stipple, linear: bool) -> Vec<f64> {
    // At the drawing's own resolution, where its dots are several pixels wide.
    let (w, h) = drawing.domain;
    let side = w / 3;
    let img = job.picture(drawing, (w, h)).unwrap();
    let sigma = (f64::from(w * h) / drawing.points.len() as f64).sqrt();
    let planes: Vec<Grey> = (0..3)
        .map(|k| {
            let values = img
                .pixels()
                .map(|p| {
                    let v = f32::from(p.0[k]) / 255.0;
                    if linear {
                        pixelpie::colour::srgb_to_linear(v)
                    } else {
                        v
                    }
                })
                .collect();
            blur(&Grey::new(w, h, values).unwrap(), sigma)
        })
        .collect();
    (0..6)
        .map(|i| {
            let (x0, y0) = ((i % 3) * side, (i / 3) * side);
            let mut mean = [0f64; 3];
            let mut n = 0.0;
            for y in y0 + side / 4..y0 + 3 * side / 4 {
                for x in x0 + side / 4..x0 + 3 * side / 4 {
                    for (k, m) in mean.iter_mut().enumerate() {
                        *m += f64::from(planes[k].values[(y * w + x) as usize]);
                    }
                    n += 1.0;
                }
            }
            let mean = mean.map(|m| m / n);
            let got = if linear {
                Lab::from_linear(mean)
            } else {
                Lab::from_srgb(mean)
            };
            delta_e00(got, Lab::from_srgb8(PATCHES[i as usize]))
        })
        .collect()
}

#[test]
fn flat_patches_inside_the_gamut_come_back_within_delta_e_2() {
    let dir = tempfile::tempdir().unwrap();
    let path = patches(dir.path());
    for tones in [Tones::Display, Tones::Linear] {
        let mut job = cmyk(20_000);
        job.importance.tones = tones;
        let drawing = run(&job, &path);
        let errors = patch_errors(&job, &drawing, tones == Tones::Linear);
        eprintln!("{tones:?}: ΔE00 per patch {errors:.2?}");
        for (e, c) in errors.iter().zip(PATCHES) {
            assert!(*e < 2.0, "{tones:?}: patch {c:?} comes back {e:.2} off");
        }
    }
}

#[test]
fn a_grey_photo_needs_only_the_black_pen_and_alpha_is_paper() {
    let dir = tempfile::tempdir().unwrap();
    let grey = dir.path().join("grey.png");
    fixtures::halves_gray8(300, 200, 40, 180)
        .save(&grey)
        .unwrap();
    let drawing = run(&cmyk(3000), &grey);
    assert!(drawing.points.len() > 2000);
    assert!(
        drawing.points.iter().all(|p| p.class == 3),
        "colour dots on a grey photo"
    );

    // A red photo whose right half is transparent: no dots there.
    let alpha = dir.path().join("alpha.png");
    ImageBuffer::from_fn(300, 200, |x, _| {
        Rgba([200u8, 40, 40, if x < 150 { 255 } else { 0 }])
    })
    .save(&alpha)
    .unwrap();
    let drawing = run(&cmyk(3000), &alpha);
    let (w, _) = drawing.domain;
    assert!(drawing.points.len() > 1000);
    assert!(
        drawing.points.iter().all(|p| p.x < w as f32 / 2.0 + 10.0),
        "dots on transparent paper"
    );
}

fn pixelpie(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(args)
        .output()
        .unwrap()
}

fn asset(name: &str) -> String {
    format!("{}/assets/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn every_output_carries_the_pens() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).display().to_string();
    let pens = dir.path().join("pens.toml");
    std::fs::write(
        &pens,
        "[[pen]]\nname = \"ink\"\ncolour = \"#101010\"\nwidth_mm = 0.5\ndot_gain = 1.3\n\
         [[pen]]\nname = \"red\"\ncolour = \"#d62728\"\n\
         [[pen]]\nname = \"blue\"\ncolour = \"#1f77b4\"\n",
    )
    .unwrap();
    let pens = pens.display().to_string();
    let rocket = asset("rocket.jpg");
    for f in ["d.svg", "d.csv", "d.json", "d.png", "p.svg"] {
        let target = out(f);
        let mut args = vec!["stipple", &rocket, "-o", &target];
        args.extend([
            "--pens",
            &pens,
            "--points",
            "3000",
            "--backend",
            "cpu",
            "-q",
        ]);
        if f == "p.svg" {
            args.extend(["--width-mm", "150", "--pen-mm", "0.3", "--order", "tsp"]);
        }
        let o = pixelpie(&args);
        assert!(
            o.status.success(),
            "{f}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    // CSV: a pen column; every pen draws.
    let csv = std::fs::read_to_string(out("d.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("x,y,radius,pen"));
    let mut per_pen = [0usize; 3];
    for l in lines {
        per_pen[l.rsplit(',').next().unwrap().parse::<usize>().unwrap()] += 1;
    }
    assert!(per_pen.iter().all(|&n| n > 50), "{per_pen:?}");
    // SVG: one Inkscape layer per pen, in its colour, the same dots.
    for (f, attr) in [("d.svg", "fill"), ("p.svg", "stroke")] {
        let text = std::fs::read_to_string(out(f)).unwrap();
        for (name, c) in [("ink", "#101010"), ("red", "#d62728"), ("blue", "#1f77b4")] {
            // Each pen after the first plotted one pauses AxiDraw's
            // software for the pen change: "!red".
            let (label, paused, colour) = (
                format!(r#"inkscape:label="{name}""#),
                format!(r#"inkscape:label="!{name}""#),
                format!(r#"{attr}="{c}""#),
            );
            assert!(
                text.lines()
                    .any(|l| (l.contains(&label) || l.contains(&paused)) && l.contains(&colour)),
                "{f}: no layer {label} {colour}"
            );
        }
        assert_eq!(text.matches(r#"inkscape:label="!"#).count(), 2, "{f}");
        let d = pixelpie::stipple::read::read_svg(&text).unwrap();
        assert_eq!(d.layers.len(), 3, "{f}");
        let mut counts = [0usize; 3];
        for &l in &d.layer_of {
            counts[l] += 1;
        }
        assert!(counts.iter().all(|&n| n > 50), "{f}: {counts:?}");
        // The layers in plotting order, the lightest ink first.
        let names: Vec<&str> = d.layers.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["blue", "red", "ink"], "{f}");
        if f == "d.svg" {
            assert_eq!(
                counts,
                [per_pen[2], per_pen[1], per_pen[0]],
                "{f}: dots per layer"
            );
        }
        assert_eq!(d.layers[1], ("red".to_owned(), [0xd6, 0x27, 0x28]));
    }
    // The pen file's own width for its pen, --pen-mm for the others.
    let text = std::fs::read_to_string(out("p.svg")).unwrap();
    assert!(text.contains(r##"stroke="#101010" stroke-width="0.5""##));
    assert!(text.contains(r##"stroke="#d62728" stroke-width="0.3""##));
    // JSON: the pens and a pen per point.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out("d.json")).unwrap()).unwrap();
    assert_eq!(json["pens"][2]["colour"], "#1f77b4");
    assert_eq!(
        json["points"].as_array().unwrap().len(),
        per_pen.iter().sum::<usize>()
    );
    assert!(json["points"][0]["pen"].is_u64());
    // PNG: in colour, and measured as one.
    let png = image::open(out("d.png")).unwrap().to_rgb8();
    assert!(
        png.pixels().any(|p| p.0[0] > p.0[2] + 60),
        "no red in the PNG"
    );
    let f = pixelpie(&["fidelity", &asset("rocket.jpg"), &out("d.png")]);
    let report: serde_json::Value = serde_json::from_slice(&f.stdout).unwrap();
    let de = report["colour"]["delta_e00_mean"].as_f64().unwrap();
    assert!(de > 0.0 && de < 30.0, "{report}");
    let f = pixelpie(&["fidelity", &asset("rocket.jpg"), &out("d.svg")]);
    let from_svg: serde_json::Value = serde_json::from_slice(&f.stdout).unwrap();
    assert!(from_svg["colour"]["delta_e00_p95"].as_f64().unwrap() >= de * 0.5);
}

#[test]
fn one_black_pen_is_the_grey_drawing() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.svg").display().to_string();
    let b = dir.path().join("b.svg").display().to_string();
    let rocket = asset("rocket.jpg");
    let base = [
        "stipple",
        &rocket,
        "--points",
        "2000",
        "--backend",
        "cpu",
        "-q",
        "-o",
    ];
    assert!(pixelpie(&[&base[..], &[&a]].concat()).status.success());
    assert!(
        pixelpie(&[&base[..], &[&b, "--pens", "black"]].concat())
            .status
            .success()
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn bad_pens_end_in_one_error_line_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad_file = dir.path().join("bad.toml");
    std::fs::write(&bad_file, "[[pen]]\nname = \"x\"\ncolour = \"#12345g\"\n").unwrap();
    let empty_file = dir.path().join("empty.toml");
    std::fs::write(&empty_file, "").unwrap();
    let out = dir.path().join("out.svg");
    for pens in [
        "rainbow",
        "#00ff",
        "#000000,red",
        "",
        "#000000,#000000",
        bad_file.to_str().unwrap(),
        empty_file.to_str().unwrap(),
        "missing.toml",
    ] {
        let o = pixelpie(&[
            "stipple",
            &asset("rocket.jpg"),
            "-o",
            out.to_str().unwrap(),
            "--pens",
            pens,
            "--points",
            "1000",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "--pens {pens:?} was accepted");
        assert_eq!(err.trim().lines().count(), 1, "--pens {pens:?}: {err}");
        assert!(err.starts_with("error:"), "--pens {pens:?}: {err}");
        assert!(!out.exists(), "--pens {pens:?} left an output");
    }
}

/// Per pen: its dots' count and their distinct drawn radii.
fn per_pen(job: &Job, d: &Stipple) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for layer in job.pen_dots(d) {
        let mut radii: Vec<u32> = layer.iter().map(|d| d.radius.to_bits()).collect();
        radii.sort_unstable();
        radii.dedup();
        out.push((layer.len(), radii.len()));
    }
    out
}

/// The dots' ink: Σ π r² over all pens.
fn ink_area(job: &Job, d: &Stipple) -> f64 {
    job.dots(d)
        .iter()
        .map(|d| std::f64::consts::PI * f64::from(d.radius).powi(2))
        .sum()
}

#[test]
fn colour_takes_every_grey_control() {
    let photo = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/astronaut.jpg");
    let cmyk = |f: &dyn Fn(&mut Job)| {
        let mut j = Job::default();
        j.points = Some(3000);
        j.pens = Some(PenSet::cmyk());
        f(&mut j);
        j
    };
    let plain = cmyk(&|j| j.relax = Some(0));
    let d0 = run(&plain, &photo);
    // Relaxation moves each pen's dots on their own: every dot keeps its
    // pen, and each pen's spacing evens out.
    let relaxed = cmyk(&|j| j.relax = Some(4));
    let d1 = run(&relaxed, &photo);
    let counts = |d: &Stipple| {
        let mut c = [0usize; 4];
        for p in &d.set.points {
            c[p.class as usize] += 1;
        }
        c
    };
    assert_eq!(
        counts(&d0),
        counts(&d1),
        "relaxation changed the pens' counts"
    );
    // Each dot's nearest distance over the mean of its six nearest among
    // its own pen's dots: 1 on a hexagonal packing, lower the more
    // irregular the spacing. Relaxation raises it on average.
    let evenness = |d: &Stipple| {
        let (mut sum, mut n) = (0f64, 0usize);
        for pen in 0..4 {
            let pts: Vec<_> = d.points.iter().filter(|p| p.class == pen).collect();
            if pts.len() < 7 {
                continue;
            }
            for (i, a) in pts.iter().enumerate() {
                let mut near: Vec<f32> = pts
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .map(|(_, b)| ((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt())
                    .collect();
                near.select_nth_unstable_by(5, f32::total_cmp);
                near[..6].sort_by(f32::total_cmp);
                sum += f64::from(near[0] / (near[..6].iter().sum::<f32>() / 6.0));
                n += 1;
            }
        }
        sum / n.max(1) as f64
    };
    assert!(
        evenness(&d1) > evenness(&d0) + 0.02,
        "relaxed: nearest over six nearest {} is not above {}",
        evenness(&d1),
        evenness(&d0)
    );
    // Gamma above 1 darkens the mid-tones: more ink; invert changes it.
    let darker = run(&cmyk(&|j| j.importance.gamma = 2.0), &photo);
    let a0 = ink_area(&plain, &d0);
    assert!(
        ink_area(&plain, &darker) > 1.1 * a0,
        "gamma 2 did not darken"
    );
    let inverted = cmyk(&|j| j.importance.invert = true);
    let di = run(&inverted, &photo);
    assert!(
        (ink_area(&inverted, &di) - a0).abs() > 0.1 * a0,
        "invert changed nothing"
    );
    // The white cutoff: no dots where the adjusted grey is lighter (but
    // for a few at the edges of those areas, which the resize softens).
    let cut = cmyk(&|j| j.importance.white_cutoff = Some(0.5));
    let dc = run(&cut, &photo);
    let grey = pixelpie::importance::ImportanceMap::open(&photo, None)
        .unwrap()
        .resized(dc.domain.0, dc.domain.1)
        .unwrap()
        .toned(Tones::Display);
    let light = |d: &Stipple| {
        d.points
            .iter()
            .filter(|p| grey.value_at(p.x, p.y) > 0.6)
            .count()
    };
    assert!(
        light(&dc) * 10 < light(&d0),
        "{} dots lie where the grey is past the cutoff, {} without it",
        light(&dc),
        light(&d0)
    );
    // Fixed dots: one radius per pen, as in grey; sized dots: many.
    let fixed = cmyk(&|j| j.dot = Some(pixelpie::job::DotMode::Fixed));
    let df = run(&fixed, &photo);
    for (pen, (n, radii)) in per_pen(&fixed, &df).into_iter().enumerate() {
        assert!(
            n == 0 || radii == 1,
            "pen {pen}: {radii} radii in {n} fixed dots"
        );
    }
    assert!(per_pen(&plain, &d0).iter().any(|&(_, r)| r > 10));
    // Out-of-range tone options are refused as in grey.
    for bad in [
        cmyk(&|j| j.importance.white_cutoff = Some(2.0)),
        cmyk(&|j| j.importance.gamma = 0.0),
        cmyk(&|j| (j.importance.black_level, j.importance.white_level) = (0.6, 0.5)),
    ] {
        let r = bad.run(
            &photo,
            |p| Ok(cpu::sample(p, Default::default())?),
            |_| true,
        );
        assert!(r.is_err(), "{:?} was accepted", bad.importance);
    }
    // Linear mapping, per pen: accepted, equal dots within each pen.
    let linear = cmyk(&|j| j.importance.mapping = Some(pixelpie::importance::MappingKind::Linear));
    let dl = run(&linear, &photo);
    assert!(dl.points.len() > 2500);
    for (pen, (n, radii)) in per_pen(&linear, &dl).into_iter().enumerate() {
        assert!(
            n == 0 || radii == 1,
            "pen {pen}: {radii} radii under linear mapping"
        );
    }
}

#[test]
fn plot_stats_count_each_pens_dots_lifts_and_time() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("p.svg");
    let rocket = asset("rocket.jpg");
    let o = pixelpie(&[
        "stipple",
        &rocket,
        "-o",
        svg.to_str().unwrap(),
        "--pens",
        "cmyk",
        "--points",
        "2000",
        "--width-mm",
        "150",
        "--pen-mm",
        "0.4",
        "--order",
        "tsp",
        "--plot-stats",
        "-q",
        "--backend",
        "cpu",
        "--plotter",
        "saxi",
        "--plot-speed",
        "50",
        "--travel-speed",
        "200",
        "--pen-delay",
        "0.5",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split('\t').collect())
        .collect();
    assert_eq!(rows.len(), 5, "{text}");
    let d = pixelpie::stipple::read::read_svg(&std::fs::read_to_string(&svg).unwrap()).unwrap();
    let mut total = 0.0;
    for (k, (row, name)) in rows
        .iter()
        // In plotting order: the lightest ink first.
        .zip(["yellow", "cyan", "magenta", "black"])
        .enumerate()
    {
        assert_eq!(row[0], name);
        let dots: usize = row[1].parse().unwrap();
        assert_eq!(
            dots,
            d.layer_of.iter().filter(|&&l| l == k).count(),
            "{name}"
        );
        assert_eq!(row[2], row[1], "{name}: one lift per dot");
        let (down, up, minutes): (f64, f64, f64) = (
            row[3].parse().unwrap(),
            row[4].parse().unwrap(),
            row.last().unwrap().parse().unwrap(),
        );
        // The time is the motion model's over the layer's own paths, with
        // the flags over saxi's profile: no faster than the top speeds
        // allow.
        let paths: Vec<Vec<(f64, f64)>> = d
            .paths
            .iter()
            .zip(&d.layer_of)
            .filter(|(_, l)| **l == k)
            .map(|(p, _)| p.clone())
            .collect();
        let base = Saxi::default();
        let plotter = Plotter::Saxi(Saxi {
            pen_down: Motion {
                max_velocity: 50.0,
                ..base.pen_down
            },
            pen_drop_s: 0.25,
            pen_lift_s: 0.25,
            ..base
        });
        let want = plot_paths(name, dots, &paths, &plotter).seconds / 60.0;
        assert!((minutes - want).abs() < 0.06, "{name}: {minutes} vs {want}");
        let floor = (down / 50.0 + up / 200.0 + dots as f64 * 0.5) / 60.0;
        assert!(minutes > floor, "{name}: {minutes} vs {floor}");
        total += minutes;
    }
    let last: f64 = rows[4].last().unwrap().parse().unwrap();
    assert!((last - total).abs() < 0.2, "total {last} vs {total}");
    // Without a pen there is nothing to plot, and the error says what is
    // missing, in one line.
    let o = pixelpie(&[
        "stipple",
        &rocket,
        "-o",
        svg.to_str().unwrap(),
        "--plot-stats",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--pen-mm") && err.trim().lines().count() == 1,
        "{err}"
    );
}

#[test]
fn the_run_reports_every_stage_and_the_sizing_parts() {
    let photo = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/rocket.jpg");
    let mut job = cmyk(1500);
    job.relax = Some(1);
    let mut seen = Vec::new();
    job.run(
        &photo,
        |p| Ok(cpu::sample(p, Default::default())?),
        |step| {
            seen.push(step);
            true
        },
    )
    .unwrap();
    use pixelpie::job::Step::{Relaxed, Stage};
    let stages: Vec<String> = seen
        .iter()
        .filter_map(|s| match s {
            Stage(n) => Some(n.to_string()),
            _ => None,
        })
        .collect();
    assert_eq!(
        stages,
        [
            "prepare",
            "sample",
            "relax",
            "order",
            "size",
            "size: calibration",
            "size: correction 1 of 3",
            "size: correction 2 of 3",
            "size: correction 3 of 3"
        ]
    );
    assert!(seen.contains(&Relaxed(1, 1)));
    // Saying stop at a stage cancels the run.
    let stopped = job.run(
        &photo,
        |p| Ok(cpu::sample(p, Default::default())?),
        |step| step != Stage(pixelpie::job::Stage::Order),
    );
    assert!(stopped.is_err());
}

/// The plan spreads a colour drawing's pens and relaxes them, up to the
/// count where grey drawings stop relaxing; grey drawings relax and have
/// no pens to spread.
#[test]
fn the_plan_spreads_and_relaxes_colour_pens_and_relaxes_grey() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.svg").display().to_string();
    let plan = |points: &str, pens: Option<&str>| -> serde_json::Value {
        let photo = asset("astronaut.jpg");
        let mut args = vec!["stipple", &photo, "-o", &out, "--points", points, "--plan"];
        if let Some(p) = pens {
            args.extend(["--pens", p]);
        }
        let r = pixelpie(&args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        serde_json::from_slice(&r.stdout).unwrap()
    };
    let colour = plan("20000", Some("cmyk"));
    assert_eq!(
        (colour["spread"].as_bool(), colour["relax"].as_u64()),
        (Some(true), Some(u64::from(pixelpie::job::AUTO_RELAX_STEPS)))
    );
    assert_eq!(colour["corrected"].as_bool(), Some(true));
    let line = colour["line"].as_str().unwrap();
    assert!(line.contains("pens spread apart"), "{line}");
    let dense = plan("300000", Some("cmyk"));
    assert_eq!(
        (dense["spread"].as_bool(), dense["relax"].as_u64()),
        (Some(false), Some(0))
    );
    let grey = plan("20000", None);
    assert_eq!(
        (grey["spread"].as_bool(), grey["relax"].as_u64()),
        (
            Some(false),
            Some(u64::from(pixelpie::job::AUTO_RELAX_STEPS))
        )
    );
    assert!(!Path::new(&out).exists(), "--plan draws nothing");
}

/// Mean blurred ΔE00 between two RGB pictures of one size (σ in pixels).
fn blurred_delta_e(a: &image::RgbImage, b: &image::RgbImage, sigma: f64) -> f64 {
    let (w, h) = a.dimensions();
    assert_eq!((w, h), b.dimensions());
    let planes = |img: &image::RgbImage| -> Vec<Grey> {
        (0..3)
            .map(|k| {
                let values = img.pixels().map(|p| f32::from(p.0[k]) / 255.0).collect();
                blur(&Grey::new(w, h, values).unwrap(), sigma)
            })
            .collect()
    };
    let (pa, pb) = (planes(a), planes(b));
    let lab = |p: &[Grey], i: usize| Lab::from_srgb([0, 1, 2].map(|k| f64::from(p[k].values[i])));
    let n = (w * h) as usize;
    (0..n)
        .map(|i| delta_e00(lab(&pa, i), lab(&pb, i)))
        .sum::<f64>()
        / n as f64
}

/// An SVG rendered by rsvg-convert `width` px wide, on white.
fn rsvg(svg: &Path, width: u32) -> Option<image::RgbImage> {
    let png = svg.with_extension("rsvg.png");
    let ran = Command::new("rsvg-convert")
        .args(["-w", &width.to_string(), "-b", "white", "-o"])
        .arg(&png)
        .arg(svg)
        .status();
    match ran {
        Ok(s) if s.success() => Some(image::open(&png).unwrap().to_rgb8()),
        _ if std::env::var("PIXELPIE_EXPECT_RSVG").is_ok_and(|v| v == "1") => {
            panic!("rsvg-convert did not run (apt-get install librsvg2-bin)")
        }
        _ => {
            eprintln!("notice: rsvg-convert missing; the SVG-as-PNG check is skipped");
            None
        }
    }
}

#[test]
fn the_colour_svg_looks_like_its_png_in_a_viewer() {
    let dir = tempfile::tempdir().unwrap();
    let rocket = asset("rocket.jpg");
    // Circles against the PNG, and pen paths on paper against their
    // as-plotted preview.
    for (name, pen) in [("dots", false), ("pen", true)] {
        let svg = dir.path().join(format!("{name}.svg"));
        let png = dir.path().join(format!("{name}.png"));
        let (svg_s, png_s) = (svg.to_str().unwrap(), png.to_str().unwrap());
        let common = [
            "--pens",
            "cmyk",
            "--points",
            "6000",
            "-q",
            "--backend",
            "cpu",
        ];
        let runs: Vec<Vec<&str>> = if pen {
            vec![
                [
                    &[
                        "stipple", &rocket, "-o", svg_s, "--paper", "a5", "--pen-mm", "0.3",
                    ][..],
                    &["--preview", png_s],
                    &common,
                ]
                .concat(),
            ]
        } else {
            vec![
                [&["stipple", &rocket, "-o", svg_s][..], &common].concat(),
                [&["stipple", &rocket, "-o", png_s][..], &common].concat(),
            ]
        };
        for args in runs {
            let o = pixelpie(&args);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        let ours = image::open(&png).unwrap().to_rgb8();
        let Some(viewed) = rsvg(&svg, ours.width()) else {
            return;
        };
        let (w, h) = ours.dimensions();
        assert_eq!(viewed.dimensions(), (w, h), "{name}");
        let sigma = (f64::from(w * h) / 6000.0).sqrt();
        let de = blurred_delta_e(&ours, &viewed, sigma);
        // Without the layers' multiply a viewer lays each ink over the last.
        let text = std::fs::read_to_string(&svg).unwrap();
        assert_eq!(text.matches("mix-blend-mode:multiply").count(), 4, "{name}");
        let plain = dir.path().join(format!("{name}-plain.svg"));
        std::fs::write(
            &plain,
            text.replace(r#" style="mix-blend-mode:multiply""#, ""),
        )
        .unwrap();
        let de_plain = blurred_delta_e(&ours, &rsvg(&plain, w).unwrap(), sigma);
        eprintln!("{name}: ΔE00 {de:.2} with multiply, {de_plain:.2} without");
        assert!(
            de <= 1.5,
            "{name}: the SVG in a viewer is ΔE00 {de} from the PNG"
        );
        assert!(de_plain > 2.0 * de, "{name}: {de_plain} without multiply");
    }
}

#[test]
fn an_inventory_gives_the_pens_chosen_for_the_photo_and_the_job_keeps_them() {
    let dir = tempfile::tempdir().unwrap();
    let inventory = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/pens-24.toml");
    let inventory = inventory.to_str().unwrap();
    let names: Vec<String> = PenSet::from_file(Path::new(inventory))
        .unwrap()
        .pens()
        .iter()
        .map(|p| p.name.clone())
        .collect();
    assert_eq!(names.len(), 24);
    let (svg, job) = (dir.path().join("c.svg"), dir.path().join("c.toml"));
    let rocket = asset("rocket.jpg");
    let o = pixelpie(&[
        "stipple",
        &rocket,
        "-o",
        svg.to_str().unwrap(),
        "--pens",
        inventory,
        "--choose",
        "4",
        "--points",
        "3000",
        "--save-job",
        job.to_str().unwrap(),
        "--backend",
        "cpu",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    // Said: the pens and the predicted error.
    let said = err
        .lines()
        .find(|l| l.starts_with("chose 4 of 24 pens"))
        .expect(&err);
    assert!(said.contains("predicted ΔE00"), "{said}");
    // The drawing has the four pens chosen, each a pen of the inventory.
    let d = pixelpie::stipple::read::read_svg(&std::fs::read_to_string(&svg).unwrap()).unwrap();
    assert_eq!(d.layers.len(), 4);
    for (name, _) in &d.layers {
        assert!(
            names.contains(name) && said.contains(name.as_str()),
            "{name}: {said}"
        );
    }
    // The saved job holds them, not the inventory, and draws the same file.
    let text = std::fs::read_to_string(&job).unwrap();
    assert!(
        !text.contains("choose") && text.matches("name = ").count() == 4,
        "{text}"
    );
    let again = dir.path().join("again.svg");
    let o = pixelpie(&[
        "stipple",
        &rocket,
        "--job",
        job.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
        "-q",
        "--backend",
        "cpu",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read(&again).unwrap(), std::fs::read(&svg).unwrap());
    // The inventory alone, or an impossible count: one line, no file.
    for (extra, needle) in [
        (&[][..], "--choose K"),
        (
            &["--choose", "9"][..],
            "--choose 9: choose 1 to 8 of the 24 pens",
        ),
        (&["--choose", "0"][..], "--choose 0"),
    ] {
        let out = dir.path().join("no.svg");
        let mut args = vec![
            "stipple",
            &rocket,
            "-o",
            out.to_str().unwrap(),
            "--pens",
            inventory,
        ];
        args.extend_from_slice(extra);
        let o = pixelpie(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{extra:?}: {err}");
        assert!(
            err.contains(needle) && err.trim().lines().count() == 1,
            "{extra:?}: {err}"
        );
        assert!(!out.exists());
    }
}

/// A picture of `w`×`h` whose grey at column x is `grey(x / w)` (sRGB).
fn grey_picture(path: &Path, w: u32, h: u32, grey: impl Fn(f64) -> f64) {
    let img = ImageBuffer::from_fn(w, h, |x, _| {
        let v = (255.0 * grey((f64::from(x) + 0.5) / f64::from(w))).round() as u8;
        Rgb([v, v, v])
    });
    img.save(path).unwrap();
}

/// `pixelpie fidelity`'s report of `drawing` against `photo`.
fn fidelity(photo: &Path, drawing: &Path) -> serde_json::Value {
    let o = pixelpie(&[
        "fidelity",
        photo.to_str().unwrap(),
        drawing.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn a_white_pen_on_black_paper_draws_a_night_sky_as_well_as_black_on_white() {
    let dir = tempfile::tempdir().unwrap();
    // A dark sky: stars (small bright blobs) and a faint glow.
    let (w, h) = (240u32, 180u32);
    let stars = [
        (40.0, 30.0, 5.0),
        (120.0, 90.0, 9.0),
        (200.0, 140.0, 6.0),
        (70.0, 150.0, 4.0),
    ];
    let sky = |x: f64, y: f64| -> f64 {
        let glow = 0.12 * (-((x - 120.0).powi(2) + (y - 90.0).powi(2)) / 5000.0).exp();
        let star: f64 = stars
            .iter()
            .map(|&(sx, sy, r)| (-((x - sx).powi(2) + (y - sy).powi(2)) / (r * r)).exp())
            .sum();
        (0.02 + glow + star).min(1.0)
    };
    let night = dir.path().join("night.png");
    let inverted = dir.path().join("inverted.png");
    for (path, invert) in [(&night, false), (&inverted, true)] {
        ImageBuffer::from_fn(w, h, |x, y| {
            let v = sky(f64::from(x), f64::from(y));
            let v = if invert { 1.0 - v } else { v };
            let v = (255.0 * v).round() as u8;
            Rgb([v, v, v])
        })
        .save(path)
        .unwrap();
    }
    let (white, black) = (dir.path().join("white.png"), dir.path().join("black.png"));
    // Draws `picture` to `out` with 3000 dots and `extra`.
    let draw = |picture: &Path, out: &Path, extra: &[&str]| {
        let (picture, out) = (picture.to_str().unwrap(), out.to_str().unwrap());
        let mut args = vec!["stipple", picture, "-o", out, "--points", "3000", "-q"];
        args.extend(["--backend", "cpu"]);
        args.extend_from_slice(extra);
        let o = pixelpie(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    draw(
        &night,
        &white,
        &["--pens", "#ffffff", "--paper-colour", "black"],
    );
    draw(&inverted, &black, &[]);
    // The PNG is the black sheet with white dots, the stars' dots.
    let img = image::open(&white).unwrap().to_rgb8();
    assert_eq!(img.get_pixel(2, 2).0, [0, 0, 0], "the paper");
    let (sx, sy) = (120 * img.width() / w, 90 * img.height() / h);
    let bright = (sx - 3..sx + 3)
        .flat_map(|x| (sy - 3..sy + 3).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0[0] > 128)
        .count();
    assert!(
        bright > 18,
        "the brightest star has {bright} of 36 white pixels"
    );
    let on_black = fidelity(&night, &white)["psnr"].as_f64().unwrap();
    let on_white = fidelity(&inverted, &black)["psnr"].as_f64().unwrap();
    eprintln!("white on black {on_black:.2} dB, black on white {on_white:.2} dB");
    assert!(on_black >= on_white - 0.05, "{on_black} vs {on_white}");
    // The as-plotted preview, on a sheet of that paper.
    let (sheet_svg, preview) = (dir.path().join("sheet.svg"), dir.path().join("preview.png"));
    draw(
        &night,
        &sheet_svg,
        &[
            "--pens",
            "#ffffff",
            "--paper-colour",
            "black",
            "--paper",
            "a6",
            "--pen-mm",
            "0.2",
            "--preview",
            preview.to_str().unwrap(),
        ],
    );
    let shown = image::open(&preview).unwrap().to_rgb8();
    assert_eq!(shown.get_pixel(1, 1).0, [0, 0, 0], "the sheet's margin");
    let lit = shown.pixels().filter(|p| p.0[0] > 128).count();
    assert!(
        lit > 0 && lit < shown.pixels().len() / 4,
        "{lit} white pixels"
    );
    // The SVG: the paper on a layer plotters skip, the pen over it.
    let svg = dir.path().join("white.svg");
    draw(
        &night,
        &svg,
        &["--pens", "#ffffff", "--paper-colour", "black"],
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains(r#"inkscape:label="% paper (not plotted)""#),
        "{}",
        &text[..600]
    );
    let d = pixelpie::stipple::read::read_svg(&text).unwrap();
    assert_eq!(d.paper, Some([0, 0, 0]));
    assert!(
        d.layers.iter().all(|(name, _)| !name.starts_with('%')),
        "{:?}",
        d.layers
    );
    assert!(d.dots.len() > 2000, "{} dots read back", d.dots.len());
    assert_eq!(d.ink, Some([255, 255, 255]), "the one ink");
    // The SVG is measured on its paper too, white dots on black.
    let measured = fidelity(&night, &svg)["psnr"].as_f64().unwrap();
    eprintln!("white on black, the SVG: {measured:.2} dB");
    assert!(measured > 30.0, "{measured} dB");
    if let Some(viewed) = rsvg(&svg, img.width()) {
        let sigma = (f64::from(img.width() * img.height()) / 3000.0).sqrt();
        let de = blurred_delta_e(&img, &viewed, sigma);
        eprintln!("white on black: the SVG in a viewer is ΔE00 {de:.2} from the PNG");
        assert!(de <= 1.5, "{de}");
    }
}

#[test]
fn black_and_white_pens_on_grey_paper_keep_the_ramp() {
    let dir = tempfile::tempdir().unwrap();
    let ramp = dir.path().join("ramp.png");
    let (w, h) = (400u32, 100u32);
    grey_picture(&ramp, w, h, |t| t);
    let pens = dir.path().join("pens.toml");
    std::fs::write(
        &pens,
        "[[pen]]\nname = \"black\"\ncolour = \"#000000\"\n\n\
         [[pen]]\nname = \"white gel\"\ncolour = \"#ffffff\"\nopacity = 1\n",
    )
    .unwrap();
    let png = dir.path().join("ramp-out.png");
    let o = pixelpie(&[
        "stipple",
        ramp.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--pens",
        pens.to_str().unwrap(),
        "--paper-colour",
        "grey",
        "--points",
        "12000",
        "-q",
        "--backend",
        "cpu",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&png).unwrap().to_rgb8();
    let (iw, ih) = img.dimensions();
    let sigma = (f64::from(iw * ih) / 12000.0).sqrt();
    let values = img.pixels().map(|p| f32::from(p.0[1]) / 255.0).collect();
    let blurred = blur(&Grey::new(iw, ih, values).unwrap(), sigma);
    // Ten bands, each away from the edges by the blur, against its grey.
    let bands = 10;
    let mut worst: f64 = 0.0;
    for b in 0..bands {
        let (x0, x1) = (b * iw / bands, (b + 1) * iw / bands);
        let margin = (2.0 * sigma) as u32;
        let (mut sum, mut n) = (0.0f64, 0.0f64);
        for y in margin..ih - margin {
            for x in (x0 + margin).min(x1)..x1.saturating_sub(margin).max(x0 + margin) {
                sum += f64::from(blurred.values[(y * iw + x) as usize]);
                n += 1.0;
            }
        }
        let want = (f64::from(x0 + x1) / 2.0 + 0.5) / f64::from(iw);
        let got = sum / n.max(1.0);
        eprintln!("band {b}: {got:.3} for {want:.3}");
        worst = worst.max((got - want).abs());
    }
    assert!(worst <= 0.03, "the ramp on grey paper is off by {worst}");
}

/// `--choose` chooses for the picture as drawn: after `--crop` and
/// `--rotate`, the pens are those chosen for that part saved on its own,
/// and not the whole picture's.
#[test]
fn choose_picks_the_pens_of_the_cropped_picture() {
    let dir = tempfile::tempdir().unwrap();
    let inventory = asset("pens-24.toml");
    let astronaut = asset("astronaut.jpg");
    let chose = |image: &str, extra: &[&str]| {
        let svg = dir.path().join("c.svg");
        let mut args = vec![
            "stipple",
            image,
            "-o",
            svg.to_str().unwrap(),
            "--pens",
            &inventory,
            "--choose",
            "4",
            "--points",
            "500",
            "--backend",
            "cpu",
            "--relax",
            "0",
        ];
        args.extend_from_slice(extra);
        let o = pixelpie(&args);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "{err}");
        let line = err
            .lines()
            .find(|l| l.starts_with("chose 4 of 24 pens"))
            .expect(&err);
        // "chose 4 of 24 pens for FILE: a, b, c, d (predicted ..."
        let names = line.split(": ").nth(1).unwrap().split(" (").next().unwrap();
        names.to_owned()
    };
    // The flag's corner, cut out and turned by hand, saved losslessly.
    let part = image::open(&astronaut)
        .unwrap()
        .crop_imm(20, 30, 180, 150)
        .rotate90()
        .to_rgb8();
    let cut = dir.path().join("part.png");
    part.save(&cut).unwrap();
    let cropped = chose(&astronaut, &["--crop", "20,30,180,150", "--rotate", "90"]);
    let by_hand = chose(cut.to_str().unwrap(), &[]);
    let whole = chose(&astronaut, &[]);
    assert_eq!(cropped, by_hand);
    assert_ne!(cropped, whole, "the crop should change the choice");
    // The plan makes the choice as its first step, and records it.
    let o = pixelpie(&[
        "stipple",
        &astronaut,
        "-o",
        "x.svg",
        "--plan",
        "--pens",
        &inventory,
        "--choose",
        "4",
        "--points",
        "500",
        "--crop",
        "20,30,180,150",
        "--rotate",
        "90",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let names: Vec<&str> = plan["chosen"]["pens"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names.join(", "), cropped);
    assert_eq!(plan["pens"], 4);
}
