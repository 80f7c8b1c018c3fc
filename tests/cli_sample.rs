//! `pixelpie sample` through the binary: outputs that read back exactly, and
//! bad input that ends in a one-line error, a non-zero exit and no output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use exr::prelude::*;

fn pixelpie(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(args)
        .env("WGPU_DEBUG", "0")
        .output()
        .expect("run pixelpie")
}

fn write_exr(path: &Path, w: usize, h: usize, data: Vec<f32>) {
    let channel = AnyChannel::new("Y", FlatSamples::F32(data));
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("radius"),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(vec![channel])),
    );
    Image::from_layer(layer)
        .write()
        .to_file(path)
        .expect("write exr");
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("tempdir")
}

/// Runs a command that must fail: one `error:` line, no panic, no output file.
fn assert_fails(args: &[&str], output: &Path, why: &str) {
    let out = pixelpie(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{why}: succeeded");
    assert_ne!(out.status.code(), Some(101), "{why}: panicked: {stderr}");
    let errors: Vec<_> = stderr.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(errors.len(), 1, "{why}: stderr was {stderr:?}");
    assert!(!stderr.contains("panicked"), "{why}: {stderr}");
    assert!(!output.exists(), "{why}: left {}", output.display());
}

#[test]
fn csv_output_reads_back_as_the_exact_points() {
    let dir = tmp();
    let csv = dir.path().join("p.csv");
    let stats = dir.path().join("s.json");
    let out = pixelpie(&[
        "sample",
        "--width",
        "200",
        "--height",
        "100",
        "--radius",
        "5.5",
        "--seed",
        "3",
        "--backend",
        "cpu",
        "-o",
        csv.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,radius"));
    let params = pixelpie::sampler::Params::new(200, 100)
        .with_radius(5.5)
        .with_seed(3);
    let set = pixelpie::sampler::cpu::sample(&params, Default::default()).unwrap();
    let rows: Vec<[f32; 3]> = lines
        .map(|l| {
            let v: Vec<f32> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(rows.len(), set.points.len());
    for (r, p) in rows.iter().zip(&set.points) {
        assert_eq!(r, &[p.x, p.y, p.radius]);
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    for key in [
        "points",
        "iterations",
        "maximal",
        "backend",
        "seconds",
        "throw_seconds",
        "cull_seconds",
        "compact_seconds",
        "bytes_per_pixel",
    ] {
        assert!(s.get(key).is_some(), "stats lack {key}");
    }
    assert_eq!(s["points"].as_u64(), Some(set.points.len() as u64));
    assert_eq!(s["maximal"].as_bool(), Some(true));
}

#[test]
fn json_output_holds_parameters_and_points() {
    let dir = tmp();
    let json = dir.path().join("p.json");
    let out = pixelpie(&[
        "sample",
        "--width",
        "64",
        "--height",
        "64",
        "--radius",
        "4",
        "--periodic",
        "--backend",
        "cpu",
        "-o",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["parameters"]["periodic"].as_bool(), Some(true));
    assert!(v["points"].as_array().unwrap().len() > 20);
}

#[test]
fn point_count_targeting_lands_within_three_percent() {
    let dir = tmp();
    let csv = dir.path().join("p.csv");
    for n in [500usize, 4000] {
        let out = pixelpie(&[
            "sample",
            "--width",
            "400",
            "--height",
            "300",
            "--points",
            &n.to_string(),
            "--backend",
            "cpu",
            "-o",
            csv.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let got = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
        let err = (got as f64 - n as f64).abs() / n as f64;
        assert!(err <= 0.03, "asked {n}, got {got}");
    }
}

#[test]
fn radius_maps_are_read_from_single_channel_exr() {
    let dir = tmp();
    let map = dir.path().join("r.exr");
    let (w, h) = (120, 80);
    write_exr(
        &map,
        w,
        h,
        (0..w * h).map(|i| 2.0 + (i % w) as f32 / 20.0).collect(),
    );
    let csv = dir.path().join("p.csv");
    let out = pixelpie(&[
        "sample",
        "--radius-map",
        map.to_str().unwrap(),
        "--policy",
        "smaller",
        "--backend",
        "cpu",
        "-o",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    // Radii follow the map: small on the left, large on the right.
    let pts: Vec<(f32, f32)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f32> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[2])
        })
        .collect();
    assert!(
        pts.iter()
            .all(|&(x, r)| (r - (2.0 + x.floor() / 20.0)).abs() < 1.0 / 64.0)
    );
}

#[test]
fn bad_input_gives_one_line_errors_and_no_output() {
    let dir = tmp();
    let out = dir.path().join("out.csv");
    let o = out.to_str().unwrap();
    let base = |extra: &[&'static str]| -> Vec<String> {
        let mut v: Vec<String> = vec![
            "sample".into(),
            "--backend".into(),
            "cpu".into(),
            "-o".into(),
            o.into(),
        ];
        v.extend(extra.iter().map(|s| (*s).to_owned()));
        v
    };
    let cases: Vec<(&str, Vec<String>)> = vec![
        (
            "zero width",
            base(&["--width", "0", "--height", "10", "--radius", "2"]),
        ),
        (
            "absurd size",
            base(&["--width", "100000", "--height", "100000", "--radius", "2"]),
        ),
        (
            "negative radius",
            base(&["--width", "64", "--height", "64", "--radius=-1"]),
        ),
        (
            "zero radius",
            base(&["--width", "64", "--height", "64", "--radius", "0"]),
        ),
        (
            "NaN radius",
            base(&["--width", "64", "--height", "64", "--radius", "NaN"]),
        ),
        (
            "radius larger than the domain",
            base(&["--width", "64", "--height", "32", "--radius", "100"]),
        ),
        (
            "missing radius map",
            base(&["--radius-map", "/nonexistent/map.exr"]),
        ),
        (
            "subpixel bits",
            base(&[
                "--width",
                "64",
                "--height",
                "64",
                "--radius",
                "2",
                "--subpixel-bits",
                "9",
            ]),
        ),
        (
            "zero points",
            base(&["--width", "64", "--height", "64", "--points", "0"]),
        ),
    ];
    for (why, args) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_fails(&args, &out, why);
    }
    // Radius maps: corrupt, empty, wrongly sized, NaN, negative.
    let corrupt = dir.path().join("corrupt.exr");
    std::fs::write(&corrupt, b"v/1\x01 this is not an EXR file at all").unwrap();
    let empty = dir.path().join("empty.exr");
    std::fs::write(&empty, b"").unwrap();
    let nan = dir.path().join("nan.exr");
    let mut v = vec![3.0f32; 32 * 32];
    v[100] = f32::NAN;
    write_exr(&nan, 32, 32, v);
    let neg = dir.path().join("neg.exr");
    let mut v = vec![3.0f32; 32 * 32];
    v[5] = -2.0;
    write_exr(&neg, 32, 32, v);
    let good = dir.path().join("good.exr");
    write_exr(&good, 32, 32, vec![3.0; 32 * 32]);
    for (why, map, extra) in [
        ("corrupt map", &corrupt, vec![]),
        ("empty map", &empty, vec![]),
        ("NaN in map", &nan, vec![]),
        ("negative map", &neg, vec![]),
        ("wrongly sized map", &good, vec!["--width", "40"]),
    ] {
        let mut args = vec![
            "sample",
            "--backend",
            "cpu",
            "-o",
            o,
            "--radius-map",
            map.to_str().unwrap(),
        ];
        args.extend(extra);
        assert_fails(&args, &out, why);
    }
    // Outputs: unknown extension, unwritable directory, stats not JSON.
    let small = |output: &str, extra: &[&str]| -> Vec<String> {
        let base = [
            "sample",
            "--width",
            "64",
            "--height",
            "64",
            "--radius",
            "3",
            "--backend",
            "cpu",
            "-o",
        ];
        base.iter()
            .chain(&[output])
            .chain(extra)
            .map(|s| (*s).to_owned())
            .collect()
    };
    let run = |args: Vec<String>, output: &Path, why: &str| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_fails(&args, output, why);
    };
    let txt: PathBuf = dir.path().join("out.txt");
    run(small(txt.to_str().unwrap(), &[]), &txt, "unknown extension");
    let nowhere = Path::new("/nonexistent-dir/out.csv");
    run(
        small(nowhere.to_str().unwrap(), &[]),
        nowhere,
        "unwritable output",
    );
    run(
        small(o, &["--stats", "/tmp/x.yaml"]),
        &out,
        "stats extension",
    );
}

#[test]
fn the_stats_count_the_points_written() {
    // The white cutoff drops points after sampling: the statistics count
    // what the CSV holds, not what the sampler accepted.
    let dir = tmp();
    let (csv, stats) = (dir.path().join("p.csv"), dir.path().join("s.json"));
    let gradient = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/gradient.exr");
    let out = pixelpie(&[
        "sample",
        "--importance",
        gradient,
        "--min-radius",
        "2",
        "--white-cutoff",
        "0.5",
        "-o",
        csv.to_str().unwrap(),
        "--stats",
        stats.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert!(rows > 100);
    assert_eq!(v["points"].as_u64(), Some(rows as u64));
    // Without the cutoff there are more points: the cutoff did drop some.
    let all = dir.path().join("all.csv");
    let out = pixelpie(&[
        "sample",
        "--importance",
        gradient,
        "--min-radius",
        "2",
        "-o",
        all.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(out.status.success());
    assert!(std::fs::read_to_string(&all).unwrap().lines().count() - 1 > rows);
}

#[test]
fn exact_mode_on_the_gpu_backend_writes_the_cpus_points() {
    let dir = tmp();
    let run = |backend: &str| {
        let csv = dir.path().join(format!("{backend}.csv"));
        let stats = dir.path().join(format!("{backend}.json"));
        let out = pixelpie(&[
            "sample",
            "--width",
            "180",
            "--height",
            "140",
            "--radius",
            "3.5",
            "--periodic",
            "--exact",
            "--seed",
            "8",
            "--backend",
            backend,
            "-o",
            csv.to_str().unwrap(),
            "--stats",
            stats.to_str().unwrap(),
        ]);
        (out, csv, stats)
    };
    let (out, gpu_csv, gpu_stats) = run("gpu");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() && stderr.contains("no GPU adapter") {
        assert!(
            std::env::var("PIXELPIE_EXPECT_GPU").as_deref() != Ok("1"),
            "a GPU adapter is expected: {stderr}"
        );
        eprintln!("skipping GPU test: {stderr}");
        return;
    }
    assert!(out.status.success(), "{stderr}");
    let (out, cpu_csv, _) = run("cpu");
    assert!(out.status.success());
    let (g, c) = (
        std::fs::read(&gpu_csv).unwrap(),
        std::fs::read(&cpu_csv).unwrap(),
    );
    assert!(
        c.len() > 1000 && g == c,
        "the GPU's CSV differs from the CPU's"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&gpu_stats).unwrap()).unwrap();
    assert_eq!(s["backend"].as_str(), Some("gpu-exact"));
    assert_eq!(s["exact"].as_bool(), Some(true));
    assert_eq!(s["maximal"].as_bool(), Some(true));
}

#[test]
fn help_texts_carry_no_rustdoc_markup() {
    for cmd in [
        &["sample"][..],
        &["stipple"],
        &["analyze"],
        &["fidelity"],
        &["bench"],
        &["calibrate", "chart"],
        &["calibrate", "fit"],
        &["calibrate", "simulate"],
    ] {
        let mut args = cmd.to_vec();
        args.push("--help");
        let o = pixelpie(&args);
        let help = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success() && help.contains("Usage"),
            "{cmd:?}: {help}"
        );
        for markup in ["[`", "`]", "[`Self", "](", "crate::"] {
            assert!(
                !help.contains(markup),
                "{cmd:?} --help shows rustdoc markup {markup:?}:\n{help}"
            );
        }
    }
}
