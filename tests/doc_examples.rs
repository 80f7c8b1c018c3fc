//! Every `pixelpie` command in the README and docs/ runs as written: each
//! page's shell blocks, in order, in a fresh folder holding the bundled
//! `assets/` and `python/` and a stand-in for the user's own files that
//! the pages name (`photo.jpg`, `pens.toml`, a radius map `radii.exr`); each command
//! must succeed and write the files its `-o` names. (The `vpype` lines and
//! the Python blocks run in the Python suites, where the package is
//! installed; `cargo` and `pip` lines are the install itself.)

mod fixtures;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The pages: the README and every page of docs/.
fn pages() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![root.join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// The `pixelpie` commands of a page's shell blocks (```sh, ```bash or
/// unmarked), continuation lines joined, in order.
fn commands(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_block = false;
    let mut shell = false;
    let mut line = String::new();
    for raw in text.lines() {
        if let Some(lang) = raw.trim_start().strip_prefix("```") {
            if in_block {
                in_block = false;
            } else {
                in_block = true;
                shell = matches!(lang.trim(), "" | "sh" | "bash" | "shell");
            }
            continue;
        }
        if !(in_block && shell) {
            continue;
        }
        line.push_str(raw.trim_end());
        if line.ends_with('\\') {
            line.pop();
            line.push(' ');
            continue;
        }
        let whole = std::mem::take(&mut line);
        if whole.trim_start().starts_with("pixelpie ") {
            out.push(whole.trim().to_string());
        }
    }
    out
}

/// The files a command writes with `-o` or `--output` (the shell's words,
/// comments left out).
fn outputs(command: &str) -> Vec<String> {
    let words: Vec<&str> = command
        .split(" #")
        .next()
        .unwrap_or_default()
        .split_whitespace()
        .collect();
    words
        .windows(2)
        .filter(|w| w[0] == "-o" || w[0] == "--output")
        .map(|w| w[1].trim_matches('"').to_string())
        .collect()
}

/// A fresh folder as a reader's: the assets, the Python package's files,
/// and stand-ins for the files the pages take to be the reader's own.
fn folder() -> tempfile::TempDir {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    for name in ["assets", "python"] {
        std::os::unix::fs::symlink(root.join(name), dir.path().join(name)).unwrap();
    }
    std::fs::copy(root.join("assets/rocket.jpg"), dir.path().join("photo.jpg")).unwrap();
    // The reader's pens (docs/colour.md's pen file).
    std::fs::write(
        dir.path().join("pens.toml"),
        "[[pen]]\nname = \"fine black\"\ncolour = \"#101010\"\nwidth_mm = 0.3\n\
         [[pen]]\nname = \"red\"\ncolour = \"#d62728\"\n",
    )
    .unwrap();
    // A radius map: 4 px at the left to 12 px at the right.
    let (w, h) = (256usize, 128usize);
    fixtures::exr_y(&dir.path().join("radii.exr"), w, h, false, false, |x, _| {
        4.0 + 8.0 * x as f32 / (w - 1) as f32
    });
    dir
}

#[test]
fn every_pixelpie_command_in_the_docs_runs_as_written() {
    let bin = Path::new(env!("CARGO_BIN_EXE_pixelpie"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut ran = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let commands = commands(&text);
        if commands.is_empty() {
            continue;
        }
        let dir = folder();
        for command in &commands {
            let out = Command::new("sh")
                .arg("-c")
                .arg(command)
                .current_dir(dir.path())
                .env("PATH", &path)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}: `{command}` failed:\n{}",
                page.display(),
                String::from_utf8_lossy(&out.stderr)
            );
            for file in outputs(command) {
                let written = dir.path().join(&file);
                let full =
                    written.is_dir() || std::fs::metadata(&written).is_ok_and(|m| m.len() > 0);
                assert!(full, "{}: `{command}` wrote no {file}", page.display());
            }
            ran += 1;
        }
    }
    assert!(ran > 20, "only {ran} commands found in the docs");
}

#[test]
fn commands_are_read_from_shell_blocks_only() {
    let text = "x\n```sh\npixelpie a -o b.svg  # c\npixelpie d \\\n  --e f\ncargo x\n```\n\
                ```text\npixelpie no\n```\n```python\npixelpie no\n```\n";
    assert_eq!(
        commands(text),
        ["pixelpie a -o b.svg  # c", "pixelpie d    --e f"]
    );
    assert_eq!(
        outputs("pixelpie a -o b.svg --output c.png # -o no"),
        ["b.svg", "c.png"]
    );
}
