//! The pen-plotter SVG (`stipple --pen-mm`) read by vpype, the plotter users'
//! toolkit: vpype finds exactly one path per dot (the one-touch dots
//! included), and the TSP order cuts its pen-up travel.
//!
//! vpype is the executable named by `PIXELPIE_VPYPE`, or `vpype` on `PATH`
//! (`.ci/vpype.sh` installs one). Without it the test prints a notice and
//! passes, unless `PIXELPIE_EXPECT_VPYPE=1`, where it fails.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The vpype executable, if there is one.
fn find_vpype() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("PIXELPIE_VPYPE") {
        let p = PathBuf::from(p);
        return p.is_file().then_some(p);
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|dir| dir.join("vpype"))
        .find(|p| p.is_file())
}

/// vpype, or None (after a notice) when the test is to be skipped; panics
/// when vpype is missing but expected.
fn vpype() -> Option<PathBuf> {
    let found = find_vpype();
    let expected = std::env::var("PIXELPIE_EXPECT_VPYPE").is_ok_and(|v| v == "1");
    match found {
        Some(p) => Some(p),
        None if expected => panic!(
            "PIXELPIE_EXPECT_VPYPE=1 but no vpype found: set PIXELPIE_VPYPE to the \
             vpype executable (PIXELPIE_VPYPE={:?}) or put vpype on PATH \
             (bash .ci/vpype.sh installs it)",
            std::env::var_os("PIXELPIE_VPYPE")
        ),
        None => {
            eprintln!(
                "notice: vpype interop test skipped: no vpype ({}; bash .ci/vpype.sh \
                 installs one)",
                match std::env::var_os("PIXELPIE_VPYPE") {
                    Some(p) => format!("PIXELPIE_VPYPE={p:?} is not a file"),
                    None => "PIXELPIE_VPYPE unset and none on PATH".into(),
                }
            );
            None
        }
    }
}

/// What `vpype stat` reports in its `Totals` section.
#[derive(Debug)]
struct Stat {
    layers: usize,
    paths: usize,
    /// Pen-up travel between consecutive paths, in CSS px (1/96 in).
    pen_up: f64,
}

/// Parses the `Totals` section of `vpype stat`:
///
/// ```text
/// Totals
///   Layer count: 1
///   Length: 45285.07187075272
///   Pen-up length: 679400.1327466836
///   ...
///   Path count: 2000
/// ```
fn parse_stat(text: &str) -> Stat {
    let totals = text
        .split_once("\nTotals\n")
        .unwrap_or_else(|| panic!("no Totals in vpype stat:\n{text}"))
        .1;
    let field = |name: &str| -> &str {
        totals
            .lines()
            .find_map(|l| l.trim().strip_prefix(name)?.strip_prefix(": "))
            .unwrap_or_else(|| panic!("no '{name}' in vpype stat's Totals:\n{text}"))
    };
    let number = |name: &str| -> f64 {
        field(name)
            .parse()
            .unwrap_or_else(|e| panic!("'{name}' in vpype stat: {e}:\n{text}"))
    };
    Stat {
        layers: number("Layer count") as usize,
        paths: number("Path count") as usize,
        pen_up: number("Pen-up length"),
    }
}

/// The text of `vpype read --no-crop FILE stat`, which must succeed.
/// Without `--no-crop` vpype cuts the dots that reach over the page's edge
/// into several paths.
fn stat_text(vpype: &Path, svg: &Path) -> String {
    let out = Command::new(vpype)
        .arg("read")
        .arg("--no-crop")
        .arg(svg)
        .arg("stat")
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", vpype.display()));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "vpype read {} stat failed: {}\n{stdout}",
        svg.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// `vpype read --no-crop FILE stat`'s totals.
fn stat(vpype: &Path, svg: &Path) -> Stat {
    parse_stat(&stat_text(vpype, svg))
}

/// Runs `pixelpie stipple` on the default asset into `svg`, drawing with a
/// pen `pen_mm` wide on a page 200 mm wide, and returns the file's text.
fn stipple(svg: &Path, pen_mm: &str, extra: &[&str]) -> String {
    let image = Path::new(env!("CARGO_MANIFEST_DIR")).join(if extra.contains(&"--pens") {
        "assets/rocket.jpg"
    } else {
        "assets/default.png"
    });
    let out = Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .arg("stipple")
        .arg(&image)
        .arg("-o")
        .arg(svg)
        .args(["--points", "3000", "--width-mm", "200", "--pen-mm", pen_mm])
        .args(["--backend", "cpu", "--quiet"])
        .args(extra)
        .output()
        .expect("run pixelpie");
    assert!(
        out.status.success(),
        "pixelpie stipple {extra:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read_to_string(svg).expect("read the SVG")
}

/// The number of dots in a pen drawing: its `data-dot` attributes, which
/// must match its paths and its `N dots` comment.
fn dot_count(text: &str) -> usize {
    let n = text.matches("data-dot=").count();
    assert_eq!(n, text.matches("<path").count(), "one path per dot");
    assert!(
        text.contains(&format!("<!-- {n} dots, made by pixelpie -->")),
        "the comment counts {n} dots"
    );
    assert!(n > 2000, "{n} dots");
    n
}

/// The number of points of each path's `d`.
fn path_points(text: &str) -> Vec<usize> {
    text.split("<path d=\"")
        .skip(1)
        .map(|rest| {
            let d = &rest[..rest.find('"').expect("closing quote")];
            pixelpie::stipple::read::polyline(d)
                .expect("a polyline")
                .len()
        })
        .collect()
}

#[test]
fn vpype_reads_one_path_per_dot_and_tsp_shortens_pen_up_travel() {
    let Some(vpype) = vpype() else {
        return;
    };
    let version = Command::new(&vpype)
        .arg("--version")
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", vpype.display()));
    assert!(
        version.status.success(),
        "{} --version failed",
        vpype.display()
    );
    eprintln!("using {}", String::from_utf8_lossy(&version.stdout).trim());
    let dir = tempfile::tempdir().expect("temp dir");

    let mut pen_up = Vec::new();
    for order in ["none", "tsp"] {
        let svg = dir.path().join(format!("{order}.svg"));
        let text = stipple(&svg, "0.3", &["--order", order]);
        let dots = dot_count(&text);
        let s = stat(&vpype, &svg);
        assert_eq!(s.layers, 1, "--order {order}: {s:?}");
        assert_eq!(
            s.paths, dots,
            "--order {order}: vpype's paths vs dots: {s:?}"
        );
        eprintln!("--order {order}: {dots} dots, vpype {s:?}");
        pen_up.push(s.pen_up);
    }
    // The unordered drawing comes along a Hilbert curve through its dots
    // (the sampler's order, before, took 28 times the tour); 2-opt
    // shortens that curve by 7% more here.
    assert!(
        pen_up[1] < pen_up[0] && pen_up[0] <= 1.3 * pen_up[1],
        "pen-up travel: tsp {} vs none {}",
        pen_up[1],
        pen_up[0]
    );

    // Dots 1.3 to 4.5 mm wide with a 2 mm pen: touches, single circles and
    // spirals, each one path in vpype (the touches are 0.01 mm strokes, which
    // vpype keeps where it would drop a zero-length path).
    let svg = dir.path().join("sized.svg");
    let text = stipple(&svg, "2", &["--dot", "sized"]);
    let dots = dot_count(&text);
    let points = path_points(&text);
    assert_eq!(points.len(), dots);
    let touches = points.iter().filter(|&&n| n == 2).count();
    assert!(touches > 0, "no one-touch dot");
    assert!(touches < dots, "only one-touch dots");
    let s = stat(&vpype, &svg);
    eprintln!("--dot sized, 2 mm pen: {dots} dots, {touches} touches, vpype {s:?}");
    assert_eq!(s.paths, dots, "vpype's paths vs dots: {s:?}");
}

#[test]
fn parses_vpype_stat() {
    let text = "========= Stats ========= \nCurrent page size: (755.9, 529.1)\nLayer 1\n  \
                Length: 1.5\n  Pen-up length: 9.0\n  Path count: 3\nTotals\n  Layer count: 1\n  \
                Length: 45285.07187075272\n  Pen-up length: 679400.1327466836\n  \
                Total length: 724685.2046174363\n  Path count: 2000\n  Segment count: 79780\n\
                ========================= \n";
    let s = parse_stat(text);
    assert_eq!((s.layers, s.paths), (1, 2000));
    assert_eq!(s.pen_up, 679400.1327466836);
}

/// `vpype read --no-crop FILE propget -l all vp_color`: each layer's colour,
/// as vpype takes it from the layer's `stroke`.
fn layer_colours(vpype: &Path, svg: &Path) -> Vec<String> {
    let out = Command::new(vpype)
        .arg("read")
        .arg("--no-crop")
        .arg(svg)
        .args(["propget", "-l", "all", "vp_color"])
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", vpype.display()));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Lines such as "layer 2 property vp_color: (color) #ff00ff".
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.rsplit(' ').next().filter(|c| c.starts_with('#')))
        .map(str::to_owned)
        .collect()
}

#[test]
fn vpype_reads_one_layer_per_pen_in_its_colour() {
    let Some(vpype) = vpype() else {
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let svg = dir.path().join("cmyk.svg");
    let text = stipple(&svg, "0.3", &["--pens", "cmyk", "--order", "tsp"]);
    let d = pixelpie::stipple::read::read_svg(&text).expect("reads back");
    let mut per_pen = vec![0usize; d.layers.len()];
    for &l in &d.layer_of {
        per_pen[l] += 1;
    }
    assert_eq!(d.layers.len(), 4);
    assert_eq!(text.matches("data-dot=").count(), d.dots.len());
    let stdout = stat_text(&vpype, &svg);
    assert_eq!(parse_stat(&stdout).layers, 4, "{stdout}");
    // Each "Layer N" section's path count is that pen's dot count.
    let counts: Vec<usize> = stdout
        .split("\nLayer ")
        .skip(1)
        .map(|sec| {
            sec.lines()
                .find_map(|l| l.trim().strip_prefix("Path count: "))
                .and_then(|n| n.trim().parse().ok())
                .unwrap_or_else(|| panic!("no path count in:\n{sec}"))
        })
        .collect();
    assert_eq!(
        counts, per_pen,
        "vpype's paths per layer vs our dots per pen"
    );
    let colours = layer_colours(&vpype, &svg);
    // The lightest ink first (--layer-order light-first, the default).
    assert_eq!(colours, ["#ffff00", "#00ffff", "#ff00ff", "#000000"]);
}

/// Each layer's `(path count, length in CSS px)` from `vpype read --no-crop
/// FILE stat`, in vpype's layer order.
fn layer_stats(vpype: &Path, svg: &Path) -> Vec<(usize, f64)> {
    let text = stat_text(vpype, svg);
    let body = text.split_once("\nTotals\n").map_or(text.as_str(), |t| t.0);
    body.split("\nLayer ")
        .skip(1)
        .map(|section| {
            let field = |name: &str| -> f64 {
                section
                    .lines()
                    .find_map(|l| l.trim().strip_prefix(name)?.strip_prefix(": "))
                    .unwrap_or_else(|| panic!("no {name} in:\n{section}"))
                    .parse()
                    .unwrap()
            };
            (field("Path count") as usize, field("Length"))
        })
        .collect()
}

#[test]
fn refill_parts_reach_vpype_in_order_lightest_pen_first() {
    let Some(vpype) = vpype() else {
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let svg = dir.path().join("refill.svg");
    let refill_mm = 400.0;
    let text = stipple(&svg, "0.3", &["--pens", "cmyk", "--refill-mm", "400"]);
    // Our layers, in the file's order: label and dots.
    let ours: Vec<(String, usize)> = text
        .split("inkscape:label=\"")
        .skip(1)
        .map(|rest| {
            let label = rest[..rest.find('"').unwrap()].to_string();
            let body = &rest[..rest.find("</g>").unwrap()];
            (label, body.matches("<path").count())
        })
        .collect();
    assert!(ours.len() > 4, "{ours:?}");
    // Lightest ink first: yellow, cyan, magenta, black; parts numbered.
    let first_of = |pen: &str| ours.iter().position(|(l, _)| l.contains(pen)).unwrap();
    assert!(first_of("yellow") < first_of("cyan"));
    assert!(first_of("cyan") < first_of("magenta"));
    assert!(first_of("magenta") < first_of("black"));
    let layers = layer_stats(&vpype, &svg);
    assert_eq!(layers.len(), ours.len(), "{layers:?} vs {ours:?}");
    for ((paths, length), (label, dots)) in layers.iter().zip(&ours) {
        assert_eq!(paths, dots, "{label}");
        // vpype's lengths are in CSS px (96 per inch).
        let mm = length * 25.4 / 96.0;
        assert!(
            mm <= refill_mm * 1.001 || *dots == 1,
            "{label}: {mm:.1} mm drawn"
        );
    }
}
