//! Pictures that would take more memory than the budget are refused from
//! their header, in words and at once, by every command that opens one:
//! a 1.6 MB PNG of 40000² grey, an RGB one, and an EXR (a smaller one
//! under a smaller `--max-memory`: the same header path).

mod fixtures;

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use fixtures::{exr_y, pixelpie, s};

/// A PNG of `w`×`h` pixels of one value, `channels` 1 (grey) or 3 (RGB),
/// written row by row (its rows compress to almost nothing).
fn bomb(path: &Path, w: u32, h: u32, channels: usize) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, w, h);
    encoder.set_color(if channels == 1 {
        png::ColorType::Grayscale
    } else {
        png::ColorType::Rgb
    });
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row = vec![0x80u8; w as usize * channels];
    for _ in 0..h {
        stream.write_all(&row).unwrap();
    }
    stream.finish().unwrap();
}

/// Runs `args` and checks the refusal: one line naming the file, its size
/// and the budget, a failure exit, no output, and an answer within 2 s.
fn refused(args: &[&str], name: &str, size: &str, out: &Path) {
    let t = Instant::now();
    let r = pixelpie(args);
    let took = t.elapsed();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success(), "{args:?} drew it");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains(name)
            && err.contains(size)
            && err.contains("allowed")
            && err.contains("--max-memory"),
        "{err}"
    );
    assert!(!out.exists());
    assert!(took < Duration::from_secs(2), "{args:?} took {took:?}");
}

#[test]
fn a_picture_bomb_is_refused_from_its_header_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let grey = dir.path().join("bomb.png");
    bomb(&grey, 40_000, 40_000, 1);
    assert!(std::fs::metadata(&grey).unwrap().len() < 8 << 20);
    let out = dir.path().join("x.svg");
    refused(
        &["stipple", s(&grey), "-o", s(&out)],
        "bomb.png",
        "40000×40000 (1.6 Gpx)",
        &out,
    );
    refused(
        &["stipple", s(&grey), "-o", s(&out), "--plan"],
        "bomb.png",
        "1.6 Gpx",
        &out,
    );
    let csv = dir.path().join("x.csv");
    refused(
        &[
            "sample",
            "--importance",
            s(&grey),
            "--points",
            "1000",
            "-o",
            s(&csv),
        ],
        "bomb.png",
        "1.6 Gpx",
        &csv,
    );
    let rgb = dir.path().join("bomb_rgb.png");
    bomb(&rgb, 20_000, 20_000, 3);
    refused(
        &["stipple", s(&rgb), "--pens", "cmyk", "-o", s(&out)],
        "bomb_rgb.png",
        "400 Mpx",
        &out,
    );
}

#[test]
fn the_budget_is_an_option_and_guards_exr_too() {
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("big.exr");
    exr_y(&exr, 2000, 1500, true, false, |x, _| x as f32 / 2000.0);
    let out = dir.path().join("x.svg");
    // 3 Mpx at 20 bytes a pixel: over 50 MB, under 100 MB.
    refused(
        &["stipple", s(&exr), "-o", s(&out), "--max-memory", "50M"],
        "big.exr",
        "2000×1500 (3 Mpx)",
        &out,
    );
    let r = pixelpie(&[
        "stipple",
        s(&exr),
        "-o",
        s(&out),
        "--max-memory",
        "100M",
        "--points",
        "500",
        "-q",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(out.exists());
    let r = pixelpie(&["stipple", s(&exr), "-o", s(&out), "--max-memory", "lots"]);
    assert!(!r.status.success());
    assert!(String::from_utf8_lossy(&r.stderr).contains("'lots' is not a size"));
}

#[test]
fn the_same_budget_guards_the_domain_and_the_plan_predicts_the_peak() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.svg");
    let photo = fixtures::asset("astronaut.jpg");
    let t = Instant::now();
    let r = pixelpie(&[
        "stipple",
        &photo,
        "-o",
        s(&out),
        "--width",
        "20000",
        "--height",
        "20000",
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && !out.exists());
    assert!(
        err.contains("20000×20000 domain") && err.contains("allowed") && err.contains("--width"),
        "{err}"
    );
    assert!(t.elapsed() < Duration::from_secs(2));
    // The plan's predicted peak grows with the domain.
    let plan = |points: &str| -> u64 {
        let r = pixelpie(&[
            "stipple",
            &photo,
            "-o",
            s(&out),
            "--points",
            points,
            "--plan",
        ]);
        let v: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
        v["memory_mb"].as_u64().unwrap()
    };
    let (small, large) = (plan("10000"), plan("1000000"));
    assert!(small >= 10 && large > 10 * small, "{small} MB, {large} MB");
}

#[test]
fn an_exr_whose_header_claims_40000_squared_is_refused_at_once() {
    // The bundled EXR with its windows rewritten: 40000² in its header.
    let mut bytes = std::fs::read(fixtures::asset("gradient.exr")).unwrap();
    for name in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
        for (k, v) in [0i32, 0, 39_999, 39_999].iter().enumerate() {
            bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("bomb.exr");
    std::fs::write(&exr, &bytes).unwrap();
    let out = dir.path().join("x.svg");
    refused(
        &["stipple", s(&exr), "-o", s(&out)],
        "bomb.exr",
        "40000×40000 (1.6 Gpx)",
        &out,
    );
}

#[test]
fn a_point_set_too_large_for_the_budget_is_refused_before_sampling() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.csv");
    let t = Instant::now();
    let r = pixelpie(&[
        "sample",
        "--width",
        "30000",
        "--height",
        "30000",
        "--radius",
        "3",
        "-o",
        s(&out),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && !out.exists());
    assert!(
        err.contains("30000×30000 domain") && err.contains("allowed"),
        "{err}"
    );
    assert!(t.elapsed() < Duration::from_secs(2));
    // A small one runs as before.
    let r = pixelpie(&[
        "sample",
        "--width",
        "300",
        "--height",
        "300",
        "--radius",
        "3",
        "-o",
        s(&out),
        "-q",
    ]);
    assert!(r.status.success() && out.exists());
}
