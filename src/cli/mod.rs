//! Subcommands of the `pixelpie` binary.

mod analyze;
mod bench;
mod fidelity;
mod importance;
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
    Stipple(stipple::StippleArgs),
    /// Measures a point set (CSV): distances, coverage, angles; --plots draws spectra.
    Analyze(analyze::AnalyzeArgs),
    /// Measures how closely a drawing reproduces its photo: blurred PSNR and SSIM.
    Fidelity(fidelity::FidelityArgs),
    /// Prints the paper's Table 1 for the GPU and CPU backends.
    Bench(bench::BenchArgs),
    /// Opens the interactive stippling app (the default without a command).
    Gui {
        /// An image or EXR to open (default: the last one, or the bundled one).
        image: Option<std::path::PathBuf>,
    },
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command.unwrap_or(Command::Gui { image: None }) {
        Command::Gui { image } => pixelpie::app::run(image),
        Command::Sample(a) => sample::run(&a),
        Command::Stipple(a) => stipple::run(&a),
        Command::Analyze(a) => analyze::run(&a),
        Command::Bench(a) => bench::run(&a),
        Command::Fidelity(a) => fidelity::run(&a),
    }
}
