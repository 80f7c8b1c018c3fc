//! Each front end speaks its own words: every `pixelpie stipple` option
//! given a bad value ends in one `error:` line that names the option as
//! the command line spells it (`--pen-mm`), and no message names a setting
//! as Python or a job file spells it (`pen_mm`, `points=0`). Python's side
//! of the sweep is in python/tests.

mod fixtures;

use fixtures::{asset, pixelpie};

/// Each job-file key (`pixelpie::job::file::KEYS`) with a bad value, and
/// what else the option needs to reach its own check. Switches that take
/// no value are bad only without what they need.
fn bad_values(pens: &str) -> Vec<(&'static str, Vec<String>)> {
    let v = |a: &[&str]| a.iter().map(|s| (*s).to_owned()).collect::<Vec<_>>();
    vec![
        ("points", v(&["--points", "0"])),
        ("width", v(&["--width", "0"])),
        ("height", v(&["--height", "0"])),
        ("crop", v(&["--crop", "1,2"])),
        ("rotate", v(&["--rotate", "45"])),
        ("tones", v(&["--tones", "bogus"])),
        ("mapping", v(&["--mapping", "bogus"])),
        ("min_radius", v(&["--min-radius=-1"])),
        ("max_radius", v(&["--max-radius", "nan"])),
        ("gamma", v(&["--gamma=-1"])),
        ("black_level", v(&["--black-level", "2"])),
        ("white_level", v(&["--white-level=-1"])),
        ("white_cutoff", v(&["--white-cutoff", "2"])),
        ("hdr_white", v(&["--hdr-white=-1"])),
        ("dot", v(&["--dot", "bogus"])),
        ("dot_factor", v(&["--dot-factor=-1"])),
        ("dot_ratio", v(&["--dot-ratio", "2"])),
        ("dot_radius", v(&["--dot-radius=-1"])),
        ("dot_mm", v(&["--dot-mm=-1", "--width-mm", "100"])),
        ("relax", v(&["--relax=-1"])),
        ("order", v(&["--order", "bogus"])),
        ("style", v(&["--style", "bogus"])),
        ("line_smooth", v(&["--line-smooth"])),
        ("scale", v(&["--scale", "0"])),
        ("width_mm", v(&["--width-mm=-1"])),
        ("paper", v(&["--paper", "b9"])),
        ("margin", v(&["--margin=-1", "--paper", "a4"])),
        ("landscape", v(&["--landscape"])),
        ("poster", v(&["--poster", "0x400", "--paper", "a4"])),
        ("pen_mm", v(&["--pen-mm=-1", "--width-mm", "100"])),
        ("dot_path", v(&["--dot-path", "touch"])),
        (
            "refill_mm",
            v(&["--refill-mm=-1", "--pen-mm", "0.3", "--width-mm", "100"]),
        ),
        ("layer_order", v(&["--layer-order", "bogus"])),
        ("spacing", v(&["--spacing", "bogus"])),
        ("correction", v(&["--correction", "bogus"])),
        ("ink", v(&["--ink", "bogus"])),
        ("pens", v(&["--pens", "bogus"])),
        ("choose", v(&["--choose", "0", "--pens", pens])),
        ("paper_colour", v(&["--paper-colour", "bogus"])),
        ("policy", v(&["--policy", "bogus"])),
        ("seed", v(&["--seed=-1"])),
        ("subpixel_bits", v(&["--subpixel-bits", "99"])),
    ]
}

/// A setting as Python or a job file would name it: a word with `_`
/// (`pen_mm`), or `key=value`.
fn python_words(text: &str) -> Option<String> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '='))
        .find(|w| {
            let key = w.split('=').next().unwrap_or_default();
            (key.contains('_') && key.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
                || (w.contains('=')
                    && key.chars().all(|c| c.is_ascii_lowercase())
                    && !key.is_empty())
        })
        .map(str::to_owned)
}

#[test]
fn every_bad_option_is_named_as_the_command_line_spells_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.svg");
    let pens = asset("pens-24.toml");
    let image = asset("rocket.jpg");
    let keys = pixelpie::job::file::KEYS;
    let cases = bad_values(&pens);
    // The sweep covers every setting but the switches that are never bad
    // on their own.
    for key in keys {
        if matches!(*key, "invert" | "size_px" | "periodic" | "exact") {
            continue;
        }
        assert!(cases.iter().any(|(k, _)| k == key), "{key} is not swept");
    }
    let mut wrong = Vec::new();
    for (key, args) in cases {
        let mut all = vec!["stipple".to_owned(), image.clone(), "-o".into()];
        all.push(out.to_str().unwrap().into());
        all.extend(["--backend".into(), "cpu".into(), "-q".into()]);
        all.extend(args.iter().cloned());
        let argv: Vec<&str> = all.iter().map(String::as_str).collect();
        let r = pixelpie(&argv);
        let err = String::from_utf8_lossy(&r.stderr).trim().to_owned();
        let flag = format!("--{}", key.replace('_', "-"));
        if r.status.success() {
            wrong.push(format!("{args:?} accepted"));
        } else if err.lines().count() != 1 || !err.starts_with("error:") {
            wrong.push(format!("{args:?}: not one error line: {err}"));
        } else if !err.contains(&flag) {
            wrong.push(format!("{args:?}: does not name {flag}: {err}"));
        } else if let Some(w) = python_words(&err) {
            wrong.push(format!("{args:?}: names `{w}`, not the CLI's word: {err}"));
        }
        if out.exists() {
            wrong.push(format!("{args:?} wrote a file"));
        }
    }
    assert!(wrong.is_empty(), "\n{}", wrong.join("\n"));
}
