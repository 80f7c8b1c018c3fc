//! Our pen SVG as AxiDraw's own software (evil-mad/axidraw: the Inkscape
//! extension and `axicli`) reads it, by its rules (docs/plotter.md; the
//! software itself is GPL and not run here):
//!
//! * its layer grammar: a label starting with `%` is a layer it skips, one
//!   starting with `!` a pause before the layer (then the layer's number);
//!   each refill part and each pen after the first must pause it, and only
//!   the paper's layer be skipped;
//! * its path joining: a pen-up move shorter than `min_gap` (0.006 in) is
//!   drawn pen-down, so no dot's path may end that close to where another
//!   starts;
//! * `--plotter`: its planner by default, saxi's by name, and profile files
//!   with either program's option names.

mod common;

use common::{asset, pixelpie};
use std::path::Path;

use pixelpie::stipple::read::read_svg;

/// AxiDraw's `min_gap`: 0.006 in, in mm.
const MIN_GAP_MM: f64 = 0.006 * 25.4;

/// Stipples asset `image` into `out` on A4 with a 0.3 mm pen, CPU, and
/// `extra`; the SVG's text (and --plot-stats's output when asked).
fn stipple(image: &str, out: &Path, extra: &[&str]) -> (String, String) {
    let image = asset(image);
    let mut args = vec![
        "stipple",
        &image,
        "-o",
        out.to_str().unwrap(),
        "--paper",
        "a4",
        "--pen-mm",
        "0.3",
        "--backend",
        "cpu",
        "-q",
    ];
    args.extend_from_slice(extra);
    let o = pixelpie(&args);
    assert!(
        o.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    (
        std::fs::read_to_string(out).unwrap(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
    )
}

/// The labels of the file's top-level layers, in order.
fn layer_labels(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.starts_with(r#"<g inkscape:groupmode="layer""#))
        .map(|l| {
            let rest = &l[l.find(r#"inkscape:label=""#).unwrap() + 16..];
            rest[..rest.find('"').unwrap()].to_owned()
        })
        .collect()
}

/// A layer as AxiDraw's software reads its label: (skipped, pause before
/// it, its number).
type LayerRead = (bool, bool, Option<u32>);

/// What AxiDraw's software makes of a layer's label: (skipped, pause
/// before it, its number): `%` first skips it; `!` first pauses, and is
/// dropped; then an integer, if any, numbers it.
fn axidraw_layer(label: &str) -> LayerRead {
    if label.starts_with('%') {
        return (true, false, None);
    }
    let (pause, rest) = match label.strip_prefix('!') {
        Some(rest) => (true, rest),
        None => (false, label),
    };
    let digits: String = rest
        .trim_start()
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    (false, pause, digits.parse().ok())
}

#[test]
fn axidraws_layer_grammar_reads_our_labels() {
    assert_eq!(axidraw_layer("% paper (not plotted)"), (true, false, None));
    assert_eq!(axidraw_layer("!2 black 2/35"), (false, true, Some(2)));
    assert_eq!(axidraw_layer("1 black 1/35"), (false, false, Some(1)));
    assert_eq!(axidraw_layer("!cyan"), (false, true, None));
}

#[test]
fn axidraw_pauses_before_each_refill_part_and_pen_after_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.svg");
    for extra in [
        &["--points", "3000", "--refill-mm", "2000"][..],
        &[
            "--points",
            "3000",
            "--pens",
            "cmyk",
            "--paper-colour",
            "kraft",
        ],
        &["--points", "3000", "--pens", "cmyk", "--refill-mm", "2000"],
    ] {
        let (text, _) = stipple("rocket.jpg", &out, extra);
        let labels = layer_labels(&text);
        let read: Vec<_> = labels.iter().map(|l| axidraw_layer(l)).collect();
        // Only the paper's layer is skipped.
        let skipped: Vec<&String> = labels
            .iter()
            .zip(&read)
            .filter(|(_, r)| r.0)
            .map(|(l, _)| l)
            .collect();
        let paper = extra.contains(&"--paper-colour");
        assert_eq!(
            skipped,
            if paper {
                vec!["% paper (not plotted)"]
            } else {
                Vec::<&str>::new()
            },
            "{extra:?}"
        );
        // Every plotted layer but the first pauses it.
        let plotted: Vec<(&String, &LayerRead)> =
            labels.iter().zip(&read).filter(|(_, r)| !r.0).collect();
        assert!(plotted.len() > 3, "{extra:?}: {labels:?}");
        for (k, (label, r)) in plotted.iter().enumerate() {
            assert_eq!(r.1, k > 0, "{extra:?}: {label}");
        }
        // Refill parts keep their number, their place in plotting order.
        if extra.contains(&"--refill-mm") {
            for (k, (label, r)) in plotted.iter().enumerate() {
                assert_eq!(r.2, Some(k as u32 + 1), "{label}");
            }
        } else {
            let names: Vec<&str> = plotted.iter().map(|(l, _)| l.as_str()).collect();
            assert_eq!(names, ["yellow", "!cyan", "!magenta", "!black"]);
        }
        // Our own reader takes the pens' names back without the mark.
        let d = read_svg(&text).unwrap();
        assert!(d.layers.iter().all(|(name, _)| !name.starts_with('!')));
    }
}

/// The pairs of paths (i, j, distance in mm), by index into `paths`, where
/// path i ends closer than `min_gap` to where path j starts in the same
/// layer: what AxiDraw's path joining draws pen-down (in any order).
fn joins(paths: &[Vec<(f64, f64)>], layer_of: &[usize], min_gap: f64) -> Vec<(usize, usize, f64)> {
    let key = |p: (f64, f64)| {
        (
            (p.0 / min_gap).floor() as i64,
            (p.1 / min_gap).floor() as i64,
        )
    };
    let mut starts: std::collections::HashMap<(usize, i64, i64), Vec<usize>> = Default::default();
    for (i, p) in paths.iter().enumerate() {
        let (x, y) = key(p[0]);
        starts.entry((layer_of[i], x, y)).or_default().push(i);
    }
    let mut found = Vec::new();
    for (i, p) in paths.iter().enumerate() {
        let end = *p.last().unwrap();
        let (kx, ky) = key(end);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &j in starts
                    .get(&(layer_of[i], kx + dx, ky + dy))
                    .into_iter()
                    .flatten()
                {
                    let d = (paths[j][0].0 - end.0).hypot(paths[j][0].1 - end.1);
                    if j != i && d < min_gap {
                        found.push((i, j, d));
                    }
                }
            }
        }
    }
    found
}

#[test]
fn no_pen_up_move_is_short_enough_for_axidraw_to_join_two_dots() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("g.svg");
    for image in ["default.png", "rocket.jpg", "astronaut.jpg"] {
        for dots in [
            &["--dot-path", "spiral"][..],
            &["--dot-path", "circle"],
            &["--dot-path", "touch", "--dot", "fixed"],
        ] {
            for more in [
                &["--points", "5000", "--order", "tsp"][..],
                &["--points", "20000"],
                &["--points", "20000", "--pens", "cmyk", "--order", "tsp"],
            ] {
                let extra: Vec<&str> = dots.iter().chain(more).copied().collect();
                let (text, _) = stipple(image, &out, &extra);
                let d = read_svg(&text).unwrap();
                let found = joins(&d.paths, &d.layer_of, MIN_GAP_MM);
                eprintln!("{image} {extra:?}: {} joins", found.len());
                if extra.contains(&"cmyk") && extra.contains(&"spiral") {
                    // A colour pen's dots may overlap: a spiral's last
                    // point can fall by another's centre, where that one
                    // starts. Few, and each join lies inside the second
                    // dot's ink, so the plot looks the same
                    // (docs/plotter.md: `axicli --reordering 4`, or
                    // `min_gap = -1`, keeps them apart).
                    assert!(found.len() * 100 < d.dots.len(), "{image}: {}", found.len());
                    for &(_, j, gap) in &found {
                        let dot = d.dots[j];
                        let centre = (f64::from(dot.x), f64::from(dot.y));
                        let start = d.paths[j][0];
                        let off = (start.0 - centre.0).hypot(start.1 - centre.1);
                        assert!(off + gap < f64::from(dot.radius), "{image}: {dot:?}");
                    }
                } else {
                    assert!(found.is_empty(), "{image} {extra:?}: {found:?}");
                }
            }
        }
    }
}

#[test]
fn joins_are_found_in_a_layer_from_an_end_to_a_start() {
    let paths = vec![
        vec![(0.0, 0.0), (1.0, 0.0)],
        vec![(1.1, 0.0), (2.0, 0.0)],
        vec![(5.0, 5.0), (0.0, 0.05)],
    ];
    let found = joins(&paths, &[0, 0, 0], 0.15);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(
        found
            .iter()
            .any(|&(i, j, d)| (i, j) == (0, 1) && (d - 0.1).abs() < 1e-12)
    );
    assert!(
        found
            .iter()
            .any(|&(i, j, d)| (i, j) == (2, 0) && (d - 0.05).abs() < 1e-12)
    );
    // Not across layers.
    assert!(joins(&paths, &[0, 1, 2], 0.15).is_empty());
}

/// The total minutes of --plot-stats's output.
fn minutes(stats: &str) -> f64 {
    stats
        .lines()
        .last()
        .and_then(|l| l.rsplit('\t').next())
        .and_then(|m| m.parse().ok())
        .unwrap_or_else(|| panic!("no total in {stats}"))
}

#[test]
fn plotter_takes_axidraw_by_default_saxi_by_name_and_either_programs_names() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.svg");
    let fast = dir.path().join("fast.toml");
    std::fs::write(&fast, "speed_pendown = 50\naccel = 100\n").unwrap();
    let saxi_file = dir.path().join("saxi.toml");
    std::fs::write(&saxi_file, "pen_down_max_velocity = 50\n").unwrap();
    let base = ["--points", "800", "--order", "tsp", "--plot-stats"];
    let time = |plotter: &[&str]| {
        let extra: Vec<&str> = base.iter().chain(plotter).copied().collect();
        minutes(&stipple("rocket.jpg", &out, &extra).1)
    };
    let default = time(&[]);
    assert_eq!(default, time(&["--plotter", "axidraw"]));
    // An empty profile is AxiDraw's defaults.
    let empty = dir.path().join("empty.toml");
    std::fs::write(&empty, "").unwrap();
    assert_eq!(default, time(&["--plotter", empty.to_str().unwrap()]));
    // Faster drawing, harder acceleration: less time.
    assert!(time(&["--plotter", fast.to_str().unwrap()]) < default);
    // saxi's planner by name, and a file of its names.
    let saxi = time(&["--plotter", "saxi"]);
    assert_ne!(saxi, default);
    assert_eq!(saxi, time(&["--plotter", saxi_file.to_str().unwrap()]));
    // An unknown name lists the known ones; a missing file says the names.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "speed_pendown = 50\npen_speed = 3\n").unwrap();
    let image = asset("rocket.jpg");
    for (plotter, want) in [
        (bad.to_str().unwrap(), "pen_speed"),
        ("nosuch", "not axidraw or saxi"),
    ] {
        let o = pixelpie(&[
            "stipple",
            &image,
            "-o",
            out.to_str().unwrap(),
            "--paper",
            "a4",
            "--pen-mm",
            "0.3",
            "--points",
            "300",
            "--plot-stats",
            "--plotter",
            plotter,
            "-q",
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains(want),
            "{plotter}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        if plotter.ends_with("bad.toml") {
            for key in ["speed_pendown", "accel", "pen_rate_lower", "pen_delay_up"] {
                assert!(err.contains(key), "{key}: {err}");
            }
            assert!(err.contains("pen_down_max_velocity"), "{err}");
        }
    }
}
