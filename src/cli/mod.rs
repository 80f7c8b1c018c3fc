//! Subcommands of the `pixelpie` binary.

mod sample;

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
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Sample(a) => sample::run(&a),
    }
}
