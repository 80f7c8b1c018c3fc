//! The saxi recipe of docs/plotter.md, run as written: saxi (an AxiDraw
//! driver from npm) plans our SVG with 4 motions a dot and 2 to go home,
//! and its planned duration agrees with `--plot-stats` within 5%, for
//! spiral, circle and touch dots.
//!
//! saxi is the executable named by `PIXELPIE_SAXI` (`.ci/saxi.sh` installs
//! one). Without it the test prints a notice and passes, unless
//! `PIXELPIE_EXPECT_SAXI=1`, where it fails.

use std::path::{Path, PathBuf};
use std::process::Command;

/// saxi, or None (after a notice) when the test is to be skipped; panics
/// when saxi is missing but expected.
fn saxi() -> Option<PathBuf> {
    let found = std::env::var_os("PIXELPIE_SAXI")
        .map(PathBuf::from)
        .filter(|p| p.is_file());
    let expected = std::env::var("PIXELPIE_EXPECT_SAXI").is_ok_and(|v| v == "1");
    match found {
        Some(p) => Some(p),
        None if expected => panic!(
            "PIXELPIE_EXPECT_SAXI=1 but no saxi found: set PIXELPIE_SAXI to the saxi \
             executable (PIXELPIE_SAXI={:?}; bash .ci/saxi.sh installs it)",
            std::env::var_os("PIXELPIE_SAXI")
        ),
        None => {
            eprintln!("notice: saxi test skipped: PIXELPIE_SAXI unset or not a file");
            None
        }
    }
}

/// The recipe: the commands of the first shell block of docs/plotter.md's
/// saxi section.
fn recipe() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("docs/plotter.md")).unwrap();
    let section = &text[text.find("## saxi").expect("a saxi section")..];
    let block = section.split("```sh\n").nth(1).expect("a shell block");
    let block = &block[..block.find("```").unwrap()];
    block.lines().map(str::to_owned).collect()
}

/// Runs a recipe line: `pixelpie` is our binary, `saxi` saxi's.
fn run(line: &str, saxi: &Path, dir: &Path) -> String {
    let mut words = line.split_whitespace();
    let program = match words.next() {
        Some("pixelpie") => PathBuf::from(env!("CARGO_BIN_EXE_pixelpie")),
        Some("saxi") => saxi.to_path_buf(),
        other => panic!("unexpected command {other:?} in the recipe"),
    };
    let out = Command::new(program)
        .args(words)
        .current_dir(dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    // saxi exits 1 when it finds no device, after its plan.
    let planned = stdout.contains("estimated duration");
    assert!(
        out.status.success() || planned,
        "{line}: {}{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Seconds of saxi's "1h16m56s", "59m51s" or "12.3s".
fn duration(text: &str) -> f64 {
    let (mut total, mut number) = (0.0, String::new());
    for c in text.chars() {
        match c {
            'h' | 'm' | 's' => {
                let v: f64 = number.parse().expect(text);
                total += v * match c {
                    'h' => 3600.0,
                    'm' => 60.0,
                    _ => 1.0,
                };
                number.clear();
            }
            _ => number.push(c),
        }
    }
    total
}

#[test]
fn the_saxi_recipe_plans_every_dot_and_agrees_with_plot_stats() {
    let Some(saxi) = saxi() else { return };
    let dir = tempfile::tempdir().unwrap();
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    std::os::unix::fs::symlink(assets, dir.path().join("assets")).unwrap();
    let lines = recipe();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(lines[0].starts_with("pixelpie ") && lines[1].starts_with("saxi "));
    // As written, then with circles and with touches.
    for extra in ["", " --dot-path circle", " --dot-path touch --dot fixed"] {
        let table = run(&format!("{}{extra}", lines[0]), &saxi, dir.path());
        let plan = run(&lines[1], &saxi, dir.path());
        // Ours: the dots and the total minutes.
        let rows: Vec<Vec<&str>> = table.lines().map(|l| l.split('\t').collect()).collect();
        let dots: usize = rows[1][1].parse().unwrap();
        let ours: f64 = rows.last().unwrap().last().unwrap().parse::<f64>().unwrap() * 60.0;
        // saxi's: "N motions, estimated duration: 1h2m3s".
        let line = plan
            .lines()
            .find(|l| l.contains("estimated duration"))
            .expect(&plan);
        let motions: usize = line.split_whitespace().next().unwrap().parse().unwrap();
        let theirs = duration(line.rsplit(' ').next().unwrap());
        eprintln!(
            "{extra:?}: {dots} dots; ours {ours:.0} s, saxi {theirs:.0} s, {motions} motions"
        );
        assert_eq!(motions, 4 * dots + 2, "{extra:?}: {line}");
        assert!(
            (ours / theirs - 1.0).abs() <= 0.05,
            "{extra:?}: --plot-stats {ours} s, saxi {theirs} s"
        );
    }
}

#[test]
fn saxi_durations_parse() {
    assert_eq!(duration("1h16m56s"), 4616.0);
    assert_eq!(duration("59m51s"), 3591.0);
    assert_eq!(duration("12.5s"), 12.5);
}
