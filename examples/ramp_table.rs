//! The grey ramp's tone error (`pixelpie::job::ramp_error`: a black-to-
//! white ramp stippled, each of 32 bands' grey against the ramp's, 5–95%)
//! for each policy, with the default drawing (relaxed and corrected), the
//! correction off (then not relaxed by default), relaxed without the
//! correction, and the drawings of earlier versions.
//!
//! `cargo run --release --example ramp_table [-- POINTS]`

use pixelpie::job::{Correction, Job, Spacing};
use pixelpie::sampler::Policy;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let points: usize = std::env::args().nth(1).map_or(Ok(10_000), |s| s.parse())?;
    println!("{points} dots; worst / mean band error of display grey");
    println!();
    println!(
        "| policy | default | `--correction off` | `--relax 3 --correction off` | \
         `--spacing radius --relax 0 --correction off` |"
    );
    println!("|---|---|---|---|---|");
    for policy in [
        Policy::Smaller,
        Policy::Prior,
        Policy::Current,
        Policy::Bigger,
    ] {
        let mut job = Job::default();
        job.points = Some(points);
        job.policy = policy;
        let mut off = job.clone();
        off.correction = Correction::Off;
        let mut relaxed = off.clone();
        relaxed.relax = Some(3);
        let mut old = off.clone();
        old.spacing = Spacing::Radius;
        old.relax = Some(0);
        let mut row = format!("| {policy:?} |");
        for j in [&job, &off, &relaxed, &old] {
            let e = pixelpie::job::ramp_error(j, 1.0)?;
            row += &format!(" {:.3} / {:.3} |", e.worst, e.mean);
        }
        println!("{row}");
    }
    Ok(())
}
