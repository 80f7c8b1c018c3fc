//! `--style line`: one continuous pen line per pen, whose ink reproduces the
//! picture's tones: one stroke (one subpath) without self-crossings, its
//! mean grey the picture's, its count following the pen, cut into parts by
//! `--refill-mm`, plotted with one pen drop, smooth with `--line-smooth`.

mod common;

use common::{asset, pixelpie};

use pixelpie::stipple::line::crossings;
use pixelpie::stipple::read::polyline;

/// Runs `pixelpie stipple` with `args` (CPU), asserting success; stderr.
fn stipple(args: &[&str]) -> String {
    let mut all = vec!["stipple", "--backend", "cpu"];
    all.extend_from_slice(args);
    let r = pixelpie(&all);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    String::from_utf8_lossy(&r.stderr).into_owned()
}

/// How many numbers the path data `d` holds (whole numbers, a `-` always
/// starting one: `M1 2l3-4 5 6` holds six).
fn numbers(d: &str) -> usize {
    let (mut n, mut inside) = (0, false);
    for ch in d.chars() {
        match ch {
            '-' => {
                n += 1;
                inside = true;
            }
            '0'..='9' | '.' => {
                if !inside {
                    n += 1;
                    inside = true;
                }
            }
            _ => inside = false,
        }
    }
    n
}

/// The `d` attributes of every `<path` in `svg`.
fn paths(svg: &str) -> Vec<&str> {
    svg.split("<path d=\"")
        .skip(1)
        .map(|p| &p[..p.find('"').unwrap()])
        .collect()
}

/// The issue's shape target: `--style line --width-mm 90 --pen-mm 1.0`
/// draws one stroke, one subpath, and the polyline the file holds (on its
/// 0.01 mm grid) crosses itself nowhere.
#[test]
fn a_line_is_one_stroke_that_never_crosses_itself() {
    let dir = tempfile::tempdir().unwrap();
    for photo in ["rocket.jpg", "astronaut.jpg"] {
        let out = dir.path().join("line.svg");
        stipple(&[
            &asset(photo),
            "--style",
            "line",
            "--width-mm",
            "90",
            "--pen-mm",
            "1.0",
            "-o",
            out.to_str().unwrap(),
        ]);
        let svg = std::fs::read_to_string(&out).unwrap();
        let d = paths(&svg);
        assert_eq!(d.len(), 1, "{photo}: one path");
        assert_eq!(d[0].matches(['M', 'm']).count(), 1, "{photo}: one subpath");
        let line = polyline(d[0]).expect("a polyline");
        assert!(line.len() > 500, "{photo}: {} points", line.len());
        let xy: Vec<[f64; 2]> = line.iter().map(|&(x, y)| [x, y]).collect();
        assert_eq!(crossings(&xy), Vec::<(usize, usize)>::new(), "{photo}");
        // The pen's width, in the path's hundredths of a mm.
        assert!(svg.contains(r#"stroke-width="100""#), "{photo}");
    }
}

/// The mean grey of a line drawing's PNG is the picture's within 0.03 (the
/// issue's tone target), and darker parts of the picture are darker in
/// the drawing.
#[test]
fn the_lines_ink_is_the_pictures_tone() {
    let dir = tempfile::tempdir().unwrap();
    let photo = asset("astronaut.jpg");
    let out = dir.path().join("line.png");
    stipple(&[
        &photo,
        "--style",
        "line",
        "--points",
        "6000",
        "-o",
        out.to_str().unwrap(),
    ]);
    let picture = image::open(&photo).unwrap().to_luma8();
    let drawing = image::open(&out).unwrap().to_luma8();
    let drawing = image::imageops::resize(
        &drawing,
        picture.width(),
        picture.height(),
        image::imageops::FilterType::Triangle,
    );
    let mean = |img: &image::GrayImage, x0: u32, x1: u32, y0: u32, y1: u32| {
        let mut s = 0.0;
        for y in y0..y1 {
            for x in x0..x1 {
                s += f64::from(img.get_pixel(x, y).0[0]) / 255.0;
            }
        }
        s / f64::from((x1 - x0) * (y1 - y0))
    };
    let (w, h) = picture.dimensions();
    let (p, d) = (mean(&picture, 0, w, 0, h), mean(&drawing, 0, w, 0, h));
    assert!((p - d).abs() < 0.03, "picture {p:.3}, drawing {d:.3}");
    // Quarters of the picture keep their order of lightness.
    let quarters = |img| {
        let mut q = Vec::new();
        for (x0, y0) in [(0, 0), (w / 2, 0), (0, h / 2), (w / 2, h / 2)] {
            q.push(mean(img, x0, x0 + w / 2, y0, y0 + h / 2));
        }
        q
    };
    let (qp, qd) = (quarters(&picture), quarters(&drawing));
    for i in 0..4 {
        for j in 0..4 {
            if qp[i] > qp[j] + 0.08 {
                assert!(qd[i] > qd[j], "quarters {qp:?} drawn {qd:?}");
            }
        }
        assert!((qp[i] - qd[i]).abs() < 0.06, "quarters {qp:?} drawn {qd:?}");
    }
}

/// The line is refined toward the picture's tones by rendering it: its
/// grey blurred by the mean spacing of its points (as the issue measures)
/// is at least 5 dB closer to the picture's than the same line's without
/// the refinement (`--correction off`), and its mean grey is closer too.
#[test]
fn the_refined_line_holds_the_pictures_blurred_tones() {
    use pixelpie::stipple::refine::gauss;
    let dir = tempfile::tempdir().unwrap();
    let photo = asset("rocket.jpg");
    let picture = image::open(&photo).unwrap().to_luma8();
    let (w, h) = picture.dimensions();
    let grey = |img: &image::GrayImage| -> Vec<f32> {
        img.pixels().map(|p| f32::from(p.0[0]) / 255.0).collect()
    };
    let sigma = (f64::from(w) * f64::from(h) / 4000.0).sqrt();
    let want = gauss(&grey(&picture), (w, h), sigma);
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    let measure = |extra: &[&str], name: &str| -> (f64, f64) {
        let out = dir.path().join(name);
        let mut args = vec![
            photo.as_str(),
            "--style",
            "line",
            "--points",
            "4000",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        stipple(&args);
        let drawing = image::imageops::resize(
            &image::open(&out).unwrap().to_luma8(),
            w,
            h,
            image::imageops::FilterType::Triangle,
        );
        let got = gauss(&grey(&drawing), (w, h), sigma);
        let mse = want
            .iter()
            .zip(&got)
            .map(|(&a, &b)| f64::from(a - b).powi(2))
            .sum::<f64>()
            / want.len() as f64;
        (10.0 * (1.0 / mse).log10(), (mean(&got) - mean(&want)).abs())
    };
    let (off, off_mean) = measure(&["--correction", "off"], "off.png");
    let (on, on_mean) = measure(&[], "on.png");
    assert!(on > off + 5.0, "blurred PSNR {off:.2} → {on:.2} dB");
    assert!(
        on_mean < off_mean.max(0.01),
        "mean grey off by {off_mean:.3} → {on_mean:.3}"
    );
}

/// With a pen the count follows from the pen and the page: a pen half as
/// wide needs about four times the points; a count far from the pen's asks
/// for a warning, and `--plan` says why the count is what it is.
#[test]
fn the_count_follows_the_pen() {
    let dir = tempfile::tempdir().unwrap();
    let photo = asset("rocket.jpg");
    // The plan's count: the pen's need (the correction may then recount
    // the line by a few per cent as it corrects the ink).
    let count = |pen: &str| -> usize {
        let out = dir.path().join(format!("line{pen}.svg"));
        let r = pixelpie(&[
            "stipple",
            &photo,
            "--style",
            "line",
            "--width-mm",
            "100",
            "--pen-mm",
            pen,
            "--plan",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let plan: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
        plan["dots"].as_u64().unwrap() as usize
    };
    let (wide, fine) = (count("0.8"), count("0.4"));
    let ratio = fine as f64 / wide as f64;
    assert!((3.5..4.5).contains(&ratio), "{wide} -> {fine}: {ratio:.2}");
    let out = dir.path().join("far.svg");
    let err = stipple(&[
        &photo,
        "--style",
        "line",
        "--width-mm",
        "100",
        "--pen-mm",
        "0.8",
        "--points",
        &(wide * 3).to_string(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        err.contains("warning:") && err.contains("--points") && err.contains("too dark"),
        "{err}"
    );
    let plan = pixelpie(&[
        "stipple",
        &photo,
        "--style",
        "line",
        "--width-mm",
        "100",
        "--pen-mm",
        "0.8",
        "--plan",
        "-o",
        out.to_str().unwrap(),
    ]);
    let plan = String::from_utf8_lossy(&plan.stdout);
    assert!(
        plan.contains("\"style\": \"line\"") && plan.contains("the pen's line needs"),
        "{plan}"
    );
}

/// `--refill-mm` cuts the line into parts, each a layer of one stroke that
/// starts where the one before ended, none longer than the limit (but for
/// a single longer segment); `--plot-stats` drops the pen once per part.
#[test]
fn refills_cut_the_line_into_parts_plotted_with_one_drop_each() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("parts.svg");
    let o = out.to_str().unwrap();
    let args = [
        &asset("rocket.jpg") as &str,
        "--style",
        "line",
        "--width-mm",
        "80",
        "--pen-mm",
        "0.8",
        "-o",
        o,
    ];
    stipple(&args);
    let whole = std::fs::read_to_string(&out).unwrap();
    let whole_line = polyline(paths(&whole)[0]).unwrap();
    let length: f64 = whole_line
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum::<f64>()
        / 100.0;
    let limit = length / 3.5;
    let mut refill = args.to_vec();
    let limit_text = format!("{limit:.1}");
    refill.extend_from_slice(&["--refill-mm", &limit_text]);
    stipple(&refill);
    let parts_svg = std::fs::read_to_string(&out).unwrap();
    let parts: Vec<Vec<(f64, f64)>> = paths(&parts_svg)
        .iter()
        .map(|d| polyline(d).unwrap())
        .collect();
    assert_eq!(parts.len(), 4, "{length:.0} mm in parts of {limit:.0}");
    assert_eq!(parts_svg.matches("inkscape:groupmode=\"layer\"").count(), 4);
    for w in parts.windows(2) {
        assert_eq!(
            w[0].last(),
            w[1].first(),
            "each part starts where the last ended"
        );
    }
    let joined: usize = parts.iter().map(Vec::len).sum::<usize>() - (parts.len() - 1);
    assert_eq!(joined, whole_line.len());
    let mut stats = args.to_vec();
    stats.extend_from_slice(&["--refill-mm", &limit_text, "--plot-stats"]);
    let mut all = vec!["stipple", "--backend", "cpu"];
    all.extend_from_slice(&stats);
    let r = pixelpie(&all);
    let table = String::from_utf8_lossy(&r.stdout);
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| !l.starts_with("pen") && !l.starts_with("total"))
        .collect();
    assert_eq!(rows.len(), 1, "{table}");
    // One lift for the whole line: the parts are one pen's drawing.
    assert_eq!(rows[0].split('\t').nth(2), Some("1"), "{table}");
}

/// `--line-smooth` writes the line as cubic Béziers through as many points
/// as the straight line's; without `--style line` it is refused in one
/// line.
#[test]
fn a_smooth_line_is_curves_through_its_points() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("smooth.svg");
    let o = out.to_str().unwrap();
    let base = [
        &asset("rocket.jpg") as &str,
        "--style",
        "line",
        "--width-mm",
        "60",
        "--pen-mm",
        "0.8",
        "-o",
        o,
    ];
    stipple(&base);
    let straight = std::fs::read_to_string(&out).unwrap();
    let mut smooth_args = base.to_vec();
    smooth_args.push("--line-smooth");
    stipple(&smooth_args);
    let smooth = std::fs::read_to_string(&out).unwrap();
    let (s, c) = (paths(&straight)[0], paths(&smooth)[0]);
    assert!(s.contains('l') && !s.contains('c'), "straight");
    assert!(c.contains('c') && !c.contains('l'), "smooth");
    // As many points, each refined as it is drawn (curves lay more ink),
    // so they lie a little apart: the starts within 0.5 mm.
    assert_eq!((numbers(s) - 2) / 2, (numbers(c) - 2) / 6, "as many points");
    let start = |d: &str| -> Vec<f64> {
        d[1..]
            .split(['l', 'c'])
            .next()
            .unwrap()
            .split(' ')
            .map(|v| v.parse().unwrap())
            .collect()
    };
    let (a, b) = (start(s), start(c));
    assert!(
        (a[0] - b[0]).hypot(a[1] - b[1]) <= 50.0,
        "starts {a:?} and {b:?} (hundredths of a mm)"
    );
    let bad = pixelpie(&["stipple", &asset("rocket.jpg"), "--line-smooth", "-o", o]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("--style line"), "{err}");
}

/// `--pens cmyk --style line` draws one line per pen, each on its pen's
/// layer, each one subpath without self-crossings, with the pens' widths.
#[test]
fn several_pens_draw_one_line_each() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmyk.svg");
    stipple(&[
        &asset("rocket.jpg"),
        "--style",
        "line",
        "--pens",
        "cmyk",
        "--width-mm",
        "80",
        "--pen-mm",
        "0.6",
        "-o",
        out.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(&out).unwrap();
    let d = paths(&svg);
    assert_eq!(d.len(), 4, "one line per pen");
    assert_eq!(svg.matches("inkscape:groupmode=\"layer\"").count(), 4);
    for (i, d) in d.iter().enumerate() {
        assert_eq!(d.matches(['M', 'm']).count(), 1, "pen {i}: one subpath");
        let line = polyline(d).unwrap();
        let xy: Vec<[f64; 2]> = line.iter().map(|&(x, y)| [x, y]).collect();
        assert!(crossings(&xy).is_empty(), "pen {i} crosses itself");
    }
}

/// Paper and ink as for dots: a white line on black paper covers the
/// paper (its layer does not multiply, or viewers would show nothing),
/// over the paper's own layer; a black line on white multiplies.
#[test]
fn a_light_line_covers_dark_paper() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("stars.svg");
    let o = out.to_str().unwrap();
    let base = [
        &asset("rocket.jpg") as &str,
        "--style",
        "line",
        "--width-mm",
        "60",
        "--pen-mm",
        "0.8",
        "-o",
        o,
    ];
    let mut white = base.to_vec();
    white.extend_from_slice(&["--ink", "#ffffff", "--paper-colour", "black"]);
    stipple(&white);
    let svg = std::fs::read_to_string(&out).unwrap();
    let layer = svg
        .lines()
        .find(|l| l.contains(r##"stroke="#ffffff""##))
        .expect("the white line's layer");
    assert!(!layer.contains("multiply"), "{layer}");
    assert!(svg.contains(r##"fill="#000000""##), "the paper's layer");
    assert_eq!(paths(&svg).len(), 1);
    stipple(&base);
    let svg = std::fs::read_to_string(&out).unwrap();
    let layer = svg
        .lines()
        .find(|l| l.contains("inkscape:groupmode=\"layer\""))
        .unwrap();
    assert!(layer.contains("multiply"), "{layer}");
}
