//! Paper and pen paths from the command line: `--paper`, `--margin`,
//! `--landscape` place the drawing on the sheet in mm, centred inside the
//! margins with the picture's aspect; `--dot-path` picks how the pen draws
//! a dot; `--plot-stats` on paper counts from the sheet's corner.

use std::path::Path;
use std::process::Command;

use pixelpie::stipple::plot::{Plotter, plot_paths_of};
use pixelpie::stipple::read::{polyline, read_svg};

fn pixelpie(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(args)
        .output()
        .expect("run pixelpie")
}

fn rocket() -> String {
    format!("{}/assets/rocket.jpg", env!("CARGO_MANIFEST_DIR"))
}

/// Stipples the rocket (1500 dots, CPU) with `extra` into `out`; the SVG's
/// text.
fn stipple(out: &Path, extra: &[&str]) -> String {
    let image = rocket();
    let o = out.to_str().unwrap();
    let mut args = vec![
        "stipple",
        &image,
        "-o",
        o,
        "--points",
        "1500",
        "--backend",
        "cpu",
        "-q",
    ];
    args.extend_from_slice(extra);
    let r = pixelpie(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    std::fs::read_to_string(out).unwrap()
}

fn attr<'a>(text: &'a str, name: &str) -> &'a str {
    let start = text.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
    &text[start..start + text[start..].find('"').unwrap()]
}

#[test]
fn the_drawing_fits_the_paper_inside_its_margins_centred() {
    let dir = tempfile::tempdir().unwrap();
    let (iw, ih) = image::image_dimensions(rocket()).unwrap();
    for (paper, landscape, margin, sheet) in [
        ("a4", false, None, (210.0, 297.0)),
        ("a4", true, Some("25"), (297.0, 210.0)),
        ("letter", false, Some("0"), (215.9, 279.4)),
        ("300x200mm", false, Some("12.5"), (200.0, 300.0)),
    ] {
        let mut extra = vec!["--paper", paper];
        if landscape {
            extra.push("--landscape");
        }
        if let Some(m) = margin {
            extra.extend(["--margin", m]);
        }
        for pen in [false, true] {
            let mut args = extra.clone();
            if pen {
                args.extend(["--pen-mm", "0.3"]);
            }
            let text = stipple(&dir.path().join("p.svg"), &args);
            let (w, h) = (sheet.0, sheet.1);
            let num = |v: f64| format!("{}", (v * 1000.0).round() / 1000.0);
            assert_eq!(attr(&text, "width"), format!("{}mm", num(w)));
            assert_eq!(attr(&text, "height"), format!("{}mm", num(h)));
            assert_eq!(attr(&text, "viewBox"), format!("0 0 {} {}", num(w), num(h)));
            let d = read_svg(&text).unwrap();
            assert_eq!((d.view_width, d.view_height), (w, h));
            // The dots' extent: inside the margins, centred in the free
            // direction, as large as the printable area allows.
            let m: f64 = margin.map_or(10.0, |m| m.parse().unwrap());
            let (aw, ah) = (w - 2.0 * m, h - 2.0 * m);
            let s = (aw / f64::from(iw)).min(ah / f64::from(ih));
            let (dw, dh) = (f64::from(iw) * s, f64::from(ih) * s);
            let (x0, y0) = ((w - dw) / 2.0, (h - dh) / 2.0);
            let pad = 0.01 * dw.max(dh);
            for dot in &d.dots {
                let (x, y) = (f64::from(dot.x), f64::from(dot.y));
                assert!(
                    x >= x0 - pad && x <= x0 + dw + pad && y >= y0 - pad && y <= y0 + dh + pad,
                    "{paper} {landscape} {margin:?}: dot at ({x}, {y}) outside {x0},{y0} {dw}x{dh}"
                );
            }
            let (lo_x, hi_x) = d.dots.iter().fold((f64::MAX, f64::MIN), |(a, b), p| {
                (a.min(f64::from(p.x)), b.max(f64::from(p.x)))
            });
            let (lo_y, hi_y) = d.dots.iter().fold((f64::MAX, f64::MIN), |(a, b), p| {
                (a.min(f64::from(p.y)), b.max(f64::from(p.y)))
            });
            // The rocket's corners are light: its dots reach within a few
            // per cent of the drawing's edges on some sides only, so check
            // the span and the centre.
            assert!(hi_x - lo_x > 0.7 * dw && hi_y - lo_y > 0.7 * dh);
            assert!(lo_x >= m - pad && hi_x <= w - m + pad);
            assert!(lo_y >= m - pad && hi_y <= h - m + pad);
        }
    }
}

#[test]
fn impossible_paper_options_end_in_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let image = rocket();
    let svg = dir.path().join("x.svg");
    for (out, extra, needle) in [
        (&svg, vec!["--paper", "b9"], "paper 'b9'"),
        (
            &svg,
            vec!["--paper", "a4", "--margin", "120"],
            "leaves no room",
        ),
        (&svg, vec!["--paper", "a4", "--margin=-1"], "--margin"),
        (&svg, vec!["--paper", "0x10mm"], "positive"),
        (
            &svg,
            vec!["--paper", "a4", "--width-mm", "100"],
            "exclude each other",
        ),
        (&svg, vec!["--margin", "5"], "need --paper"),
        (
            &svg,
            vec!["--dot-path", "touch"],
            "--dot-path needs --pen-mm",
        ),
    ] {
        let mut args = vec![
            "stipple",
            &image,
            "-o",
            out.to_str().unwrap(),
            "--points",
            "500",
        ];
        args.extend_from_slice(&extra);
        let r = pixelpie(&args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{extra:?} accepted");
        assert!(err.contains(needle), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?} wrote a file");
        assert!(err.trim().lines().count() <= 6, "{err}");
    }
}

/// A PNG on paper with a pen is the one the library's writer (the app's
/// export) writes for the same job: the command line refuses none of it.
#[test]
fn a_png_with_paper_and_pen_is_the_writers_png() {
    use pixelpie::job::{Job, file::JobFile};
    use pixelpie::sampler::{Control, cpu};
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("x.png");
    let saved = dir.path().join("x.toml");
    let image = rocket();
    let r = pixelpie(&[
        "stipple",
        &image,
        "-o",
        png.to_str().unwrap(),
        "--points",
        "800",
        "--paper",
        "a5",
        "--pen-mm",
        "0.8",
        "--paper-colour",
        "#f0e8d8",
        "--backend",
        "cpu",
        "-q",
        "--save-job",
        saved.to_str().unwrap(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let job = Job::from_table(JobFile::read(&saved).unwrap().table).unwrap();
    assert!(job.paper.is_some() && job.pen_mm == Some(0.8));
    let drawing = job
        .run(
            Path::new(&image),
            |p| Ok(cpu::sample(p, Control::default())?),
            |_| true,
        )
        .unwrap();
    let ours = job.encode(&drawing, pixelpie::job::Format::Png).unwrap();
    assert_eq!(std::fs::read(&png).unwrap(), ours);
}

/// The paths of a pen SVG, as lists of points.
/// Each dot's pen path in mm (the file holds them in hundredths, in a
/// group scaled to mm), as the reader gives them.
fn paths(text: &str) -> Vec<Vec<(f64, f64)>> {
    let paths = read_svg(text).expect("a drawing").paths;
    let raw = text.lines().filter(|l| l.starts_with("<path ")).count();
    assert_eq!(paths.len(), raw, "a path per dot");
    // Each read the same as its `d`, scaled.
    for (p, l) in paths
        .iter()
        .zip(text.lines().filter(|l| l.starts_with("<path ")))
    {
        let d = polyline(attr(l, "d")).expect("a polyline");
        assert_eq!(p.len(), d.len());
    }
    paths
}

#[test]
fn each_dot_path_draws_the_dot_its_own_way() {
    let dir = tempfile::tempdir().unwrap();
    // A thin pen, so that most dots are wider than it.
    let base = ["--paper", "a5", "--pen-mm", "0.1"];
    let get = |path: &str| {
        let mut args = base.to_vec();
        args.extend(["--dot-path", path]);
        let text = stipple(&dir.path().join(format!("{path}.svg")), &args);
        (read_svg(&text).unwrap().dots, paths(&text))
    };
    let (spiral_dots, spiral) = get("spiral");
    let (circle_dots, circle) = get("circle");
    let (touch_dots, touch) = get("touch");
    assert_eq!(spiral_dots, circle_dots);
    assert_eq!(spiral_dots, touch_dots);
    let wide = spiral_dots.iter().filter(|d| 2.0 * d.radius > 0.1).count();
    assert!(wide > spiral_dots.len() / 2, "{wide}");
    // Touch: two points 0.01 mm apart for every dot.
    assert!(
        touch
            .iter()
            .all(|p| p.len() == 2 && (p[1].0 - p[0].0 - 0.01).abs() < 1e-9)
    );
    // Circle: a wide dot is one ring at r − pen/2 from the centre, no
    // spiral: every vertex (but the first, which closes it) on the ring.
    for (p, d) in circle.iter().zip(&circle_dots) {
        if 2.0 * f64::from(d.radius) <= 0.1 + 1e-3 {
            assert_eq!(p.len(), 2);
            continue;
        }
        let big = (f64::from(d.radius) - 0.05).max(0.01);
        for q in p {
            let rr = (q.0 - f64::from(d.x)).hypot(q.1 - f64::from(d.y));
            assert!((rr - big).abs() < 0.02, "vertex at {rr}, ring {big}");
        }
    }
    // Spiral: starts at the centre, so it has more ink and more path.
    let len = |ps: &[Vec<(f64, f64)>]| -> f64 {
        ps.iter()
            .flat_map(|p| {
                p.windows(2)
                    .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
            })
            .sum()
    };
    assert!(len(&spiral) > 1.5 * len(&circle));
    assert!(len(&circle) > 2.0 * len(&touch));
}

#[test]
fn plot_stats_on_paper_start_from_the_sheets_corner() {
    let dir = tempfile::tempdir().unwrap();
    let image = rocket();
    let out = dir.path().join("s.svg");
    // saxi starts at the sheet's top-left corner; AxiDraw's software turns
    // a portrait sheet onto the machine and starts at its top-right.
    for (planner, home) in [("saxi", (0.0, 0.0)), ("axidraw", (210.0, 0.0))] {
        let r = pixelpie(&[
            "stipple",
            &image,
            "-o",
            out.to_str().unwrap(),
            "--points",
            "800",
            "--backend",
            "cpu",
            "-q",
            "--paper",
            "a4",
            "--margin",
            "40",
            "--pen-mm",
            "0.3",
            "--dot-path",
            "touch",
            "--plot-stats",
            "--plotter",
            planner,
            "--plot-speed",
            "50",
            "--travel-speed",
            "100",
            "--pen-delay",
            "0.2",
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let stdout = String::from_utf8_lossy(&r.stdout);
        let row: Vec<&str> = stdout.lines().nth(1).unwrap().split('\t').collect();
        let text = std::fs::read_to_string(&out).unwrap();
        let ps = paths(&text);
        // By hand from the SVG's paths: home → each path → home.
        let mut at = home;
        let (mut up, mut down) = (0.0, 0.0);
        for p in &ps {
            up += (p[0].0 - at.0).hypot(p[0].1 - at.1);
            down += p
                .windows(2)
                .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
                .sum::<f64>();
            at = *p.last().unwrap();
        }
        up += (at.0 - home.0).hypot(at.1 - home.1);
        // The motion model over the file's own paths, with the flags over
        // the planner's profile; never faster than the top speeds allow.
        let mut plotter = Plotter::named(planner).unwrap();
        plotter.set_pen_down_speed(50.0);
        plotter.set_pen_up_speed(100.0);
        plotter.set_pen_delay(0.2);
        let path = |i: usize, buf: &mut Vec<(f64, f64)>| buf.extend_from_slice(&ps[i]);
        let sheet = Some((210.0, 297.0));
        let minutes =
            plot_paths_of("ink", ps.len(), ps.len(), &path, &plotter, sheet).seconds / 60.0;
        let floor = (down / 50.0 + up / 100.0 + ps.len() as f64 * 0.2) / 60.0;
        assert!(minutes > floor, "{planner}: {minutes} {floor}");
        assert_eq!(row[1].parse::<usize>().unwrap(), ps.len());
        assert!(
            (row[3].parse::<f64>().unwrap() - down).abs() < 0.1,
            "{planner}: {row:?} {down}"
        );
        assert!(
            (row[4].parse::<f64>().unwrap() - up).abs() < 0.1 + 1e-3 * up,
            "{planner}: {row:?} {up}"
        );
        assert!(
            (row.last().unwrap().parse::<f64>().unwrap() - minutes).abs() < 0.05,
            "{planner}: {row:?} {minutes}"
        );
        // The first move crosses the 40 mm margin at least.
        assert!(ps[0][0].0 >= 40.0 - 1.0 && ps[0][0].1 >= 40.0 - 1.0);
    }
}
