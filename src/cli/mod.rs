//! Subcommands of the `pixelpie` binary.

mod analyze;
mod bench;
mod bench_stipple;
mod calibrate;
mod fidelity;
mod sample;
mod stipple;

use anyhow::Result;
use clap::{Parser, Subcommand};

/// Maximal Poisson-disk sampling by rasterization, and stippling.
#[derive(Parser, Debug)]
#[command(name = "pixelpie", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Samples a maximal Poisson-disk set and writes it as CSV or JSON.
    Sample(sample::SampleArgs),
    /// Draws an image as stipples: SVG (for pen plotters) or PNG.
    Stipple(Box<stipple::StippleArgs>),
    /// Measures a point set (CSV): distances, coverage, angles; --plots draws spectra.
    Analyze(analyze::AnalyzeArgs),
    /// Measures how closely a drawing reproduces its photo: blurred PSNR and SSIM.
    Fidelity(fidelity::FidelityArgs),
    /// Pen calibration: a chart to plot, and a fit of each pen's dot gain and
    /// ink from its scan.
    Calibrate(calibrate::CalibrateArgs),
    /// Prints the paper's Table 1 for the GPU and CPU backends.
    Bench(bench::BenchArgs),
    /// Opens the interactive stippling app (the default without a command).
    Gui {
        /// An image or EXR to open (default: the last one, or the bundled one).
        image: Option<std::path::PathBuf>,
    },
}

/// Runs the parsed command line.
pub fn run(cli: Cli, matches: &clap::ArgMatches) -> Result<()> {
    let result = run_command(cli, matches);
    bench_stipple::print_peak();
    result
}

fn run_command(cli: Cli, matches: &clap::ArgMatches) -> Result<()> {
    match cli.command.unwrap_or(Command::Gui { image: None }) {
        Command::Gui { image } => gui(image),
        Command::Sample(a) => sample::run(&a),
        Command::Stipple(a) => stipple::run(&a, matches.subcommand_matches("stipple")),
        Command::Analyze(a) => analyze::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Fidelity(a) => fidelity::run(&a),
        Command::Calibrate(a) => calibrate::run(&a),
    }
}

/// Opens the app, in a build with it.
#[cfg(feature = "app")]
fn gui(image: Option<std::path::PathBuf>) -> Result<()> {
    pixelpie::app::run(image)
}

/// The headless build has no app: says how to get one.
#[cfg(not(feature = "app"))]
fn gui(_image: Option<std::path::PathBuf>) -> Result<()> {
    anyhow::bail!(
        "this pixelpie is built without the app (headless); build it with the default \
         features to get it: cargo install --path . (from the source tree)"
    )
}

/// A library message or warning in the command line's words: each setting
/// it names spelled as its flag (`--pen-mm`, `--points 0`).
pub fn said(text: impl std::fmt::Display) -> String {
    pixelpie::spelled(&text.to_string(), pixelpie::spell_cli)
}
