//! The `pixelpie` command line: a thin layer over the library.

mod cli;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches};

/// mimalloc keeps the pages of freed buffers for the next: a drawing makes
/// and drops maps of the domain's size (the radius map, the blocks, the
/// renders, the SVG's chunks), and with the system
/// allocator each is a fresh mapping whose every page faults in (12% of a
/// 100K-dot run's CPU). 0.85–0.97× the time of a 100K-dot SVG, 0.88–1.05×
/// at 1M, peak 241 → 290 MB there (`docs/benchmarks.md`).
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    quiet_device_select();
    // The matches are kept: `stipple --job` lets only the flags given on
    // the command line override the job file.
    let parsed = cli::Cli::command()
        .try_get_matches()
        .and_then(|m| cli::Cli::from_arg_matches(&m).map(|a| (a, m)));
    let (args, matches) = match parsed {
        Ok(parsed) => parsed,
        Err(e) if !e.use_stderr() => {
            // --help and --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) if let Some(line) = file_value_error(&e) => {
            eprintln!("{line}");
            return ExitCode::FAILURE;
        }
        Err(e) => {
            // clap's first line names the argument and the problem; the
            // rest is usage advice. Bad input gets one line.
            let text = e.to_string();
            let mut lines = text.lines();
            let mut line = lines
                .next()
                .unwrap_or("error: invalid arguments")
                .to_owned();
            // "the following required arguments were not provided:" lists
            // them on the lines below: they belong on this one.
            if line.ends_with(':') {
                let listed: Vec<&str> = lines
                    .take_while(|l| l.starts_with("  "))
                    .map(str::trim)
                    .collect();
                line = format!("{line} {}", listed.join(", "));
            }
            eprintln!("{line}");
            return ExitCode::from(2);
        }
    };
    match cli::run(args, &matches) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!(
                "error: {}",
                cli::said(pixelpie::single_line(&format!("{e:#}")))
            );
            ExitCode::FAILURE
        }
    }
}

/// A value naming a file the option reads (a pen file) whose contents are
/// wrong, said as a job file's are: "error: FILE: pen 2: width_mm = \"x\":
/// expected a number" (clap would put "invalid value … for '--pens'"
/// first).
fn file_value_error(e: &clap::Error) -> Option<String> {
    use std::error::Error as _;
    let clap::error::ContextValue::String(value) = e.get(clap::error::ContextKind::InvalidValue)?
    else {
        return None;
    };
    if !value.to_ascii_lowercase().ends_with(".toml") {
        return None;
    }
    let source = e.source()?.to_string();
    let (_, problem) = source.split_once(&format!("'{value}': "))?;
    Some(format!(
        "error: {value}: {}",
        pixelpie::single_line(problem)
    ))
}

/// Mesa's Vulkan device-selection layer probes for a Wayland display, and
/// without `XDG_RUNTIME_DIR` (servers, containers, CI) libwayland prints two
/// `error:` lines on every run that touches the GPU, though nothing failed.
/// Without `XDG_RUNTIME_DIR` there is no Wayland session to find, and the
/// layer only reorders the adapters, which wgpu ranks itself: turn it off
/// through its own switch (`NODEVICE_SELECT`, in its manifest).
fn quiet_device_select() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none()
        && std::env::var_os("NODEVICE_SELECT").is_none()
    {
        #[expect(
            unsafe_code,
            reason = "set_var is unsafe in edition 2024; main has started no thread yet"
        )]
        // SAFETY: no other thread exists yet to read the environment.
        unsafe {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    }
}
