//! Subcommands of the `pixelpie` binary.

mod analyze;
mod bench;
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
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Samples a maximal Poisson-disk set and writes it as CSV or JSON.
    Sample(sample::SampleArgs),
    /// Draws an image as stipples: SVG (for pen plotters) or PNG.
    Stipple(stipple::StippleArgs),
    /// Measures a point set (CSV): distances, coverage, angles; --plots draws spectra.
    Analyze(analyze::AnalyzeArgs),
    /// Prints the paper's Table 1 for the GPU and CPU backends.
    Bench(bench::BenchArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Sample(a) => sample::run(&a),
        Command::Stipple(a) => stipple::run(&a),
        Command::Analyze(a) => analyze::run(&a),
        Command::Bench(a) => bench::run(&a),
    }
}
