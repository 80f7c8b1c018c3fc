//! `pixelpie stipple`: an image in, a stipple drawing (SVG or PNG) out. The
//! job, its options, defaults, checks and writers are the library's
//! ([`Job`]); this adds the paths, the backend, progress bars and the
//! report on stderr.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Result, bail};
use clap::Args;

use pixelpie::io;
use pixelpie::job::{Format, Job, Step};
use pixelpie::stipple::plot::PlotSpeeds;

use super::sample::{RunArgs, progress_bar, run_with_progress, sampling_bar};

/// Arguments of `pixelpie stipple`.
#[derive(Args, Debug)]
pub struct StippleArgs {
    /// The picture: PNG, JPEG, TIFF, BMP, WebP or OpenEXR.
    #[arg(id = "importance", value_name = "IMAGE")]
    image: PathBuf,
    /// Output drawing: .svg or .png (or the dots' points: .csv, .json).
    #[arg(long, short)]
    output: PathBuf,
    #[command(flatten)]
    options: Job,
    /// Also write the dots' centres and radii (.csv or .json), in drawing order.
    #[arg(long)]
    save_points: Option<PathBuf>,
    /// Print, per pen, the dots, pen lifts, pen-down and pen-up distance and
    /// an estimated plotting time (needs --pen-mm, and --width-mm or --paper).
    #[arg(long)]
    plot_stats: bool,
    /// Pen-down speed for --plot-stats, mm/s [default: an AxiDraw's 95].
    #[arg(long, default_value_t = PlotSpeeds::default().draw_mm_s, requires = "plot_stats")]
    plot_speed: f64,
    /// Pen-up speed for --plot-stats, mm/s.
    #[arg(long, default_value_t = PlotSpeeds::default().travel_mm_s, requires = "plot_stats")]
    travel_speed: f64,
    /// Seconds to lift and lower the pen, for --plot-stats.
    #[arg(long, default_value_t = PlotSpeeds::default().lift_s, requires = "plot_stats")]
    pen_delay: f64,
    #[command(flatten)]
    run: RunArgs,
}

pub fn run(a: &StippleArgs) -> Result<()> {
    let o = &a.options;
    let format = Format::from_path(&a.output)?;
    if let Some(p) = &a.save_points {
        io::PointFormat::from_path(p)?;
    }
    o.validate(format)?;
    let speeds = PlotSpeeds {
        draw_mm_s: a.plot_speed,
        travel_mm_s: a.travel_speed,
        lift_s: a.pen_delay,
    };
    if a.plot_stats {
        if o.pen_mm.is_none() {
            bail!(
                "--plot-stats needs --pen-mm (and --width-mm or --paper): a plotter draws pen paths"
            );
        }
        speeds.check()?;
    }
    a.run.apply_gpu_path();
    let t0 = Instant::now();
    let bar = sampling_bar(a.run.quiet);
    let relax_bar = progress_bar(a.run.quiet || o.relax == 0);
    let stage_bar = progress_bar(a.run.quiet);
    stage_bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    relax_bar.set_length(u64::from(o.relax));
    relax_bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} relaxing [{bar:30}] {pos}/{len}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let drawing = o.run(
        &a.image,
        |params| {
            Ok(run_with_progress(
                params,
                a.run.backend,
                &bar,
                a.run.verbose,
            )?)
        },
        |step| {
            match step {
                Step::Relaxed(done) => {
                    relax_bar.set_position(u64::from(done));
                }
                // After sampling, a spinner names the stage, and ticks.
                Step::Stage("prepare" | "sample") => {}
                Step::Stage(name) => {
                    bar.finish_and_clear();
                    if name != "relax" {
                        relax_bar.finish_and_clear();
                        stage_bar.set_message(name);
                        stage_bar.enable_steady_tick(std::time::Duration::from_millis(250));
                    }
                }
                _ => {}
            }
            true
        },
    )?;
    bar.finish_and_clear();
    relax_bar.finish_and_clear();
    stage_bar.finish_and_clear();
    let got = drawing.set.points.len();
    if a.run.verbose {
        eprintln!("{got} points after {} runs", drawing.runs);
    }
    if let Some(n) = drawing.short_of
        && !a.run.quiet
    {
        eprintln!(
            "warning: asked for {n} points, got {got}: the radii are at the sampler's limits \
             (1 px at the darkest, the domain's size at the lightest); change --width/--height"
        );
    }
    if let Some(tour) = &drawing.tour
        && !a.run.quiet
    {
        let saved = if tour.nearest_neighbour_length > 0.0 {
            100.0 * (1.0 - tour.length / tour.nearest_neighbour_length)
        } else {
            0.0
        };
        eprintln!(
            "tsp: pen travel {:.0} px (nearest neighbour) -> {:.0} px (2-opt, {} moves, -{saved:.1}%)",
            tour.nearest_neighbour_length, tour.length, tour.moves,
        );
    }
    o.write(&drawing, &a.output)?;
    if let Some(path) = &a.save_points {
        o.write(&drawing, path)?;
    }
    if a.plot_stats {
        let plots = o.plot_stats(&drawing, speeds)?;
        println!("pen\tdots\tlifts\tpen-down mm\tpen-up mm\tminutes");
        for p in &plots {
            println!(
                "{}\t{}\t{}\t{:.1}\t{:.1}\t{:.1}",
                p.pen,
                p.dots,
                p.lifts,
                p.pen_down_mm,
                p.pen_up_mm,
                p.seconds / 60.0
            );
        }
        let total: f64 = plots.iter().map(|p| p.seconds).sum();
        println!("total\t\t\t\t\t{:.1}", total / 60.0);
    }
    if a.run.verbose {
        let (lo, hi) = drawing
            .dots
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(lo, hi), d| {
                (lo.min(d.radius), hi.max(d.radius))
            });
        let (width, height) = drawing.domain;
        let (t_load, t_sample, t_relax) = drawing.seconds;
        eprintln!(
            "{} dots on a {width}x{height} domain, sample radii {:.2}..{:.2} px, dot radii \
             {lo:.2}..{hi:.2} px; load {t_load:.3} s, sampling {t_sample:.3} s, relax \
             {t_relax:.3} s, total {:.3} s",
            drawing.dots.len(),
            drawing.range.min,
            drawing.range.max,
            t0.elapsed().as_secs_f64()
        );
        let stages: Vec<String> = drawing
            .stages
            .iter()
            .map(|(name, s)| format!("{name} {s:.3} s"))
            .collect();
        eprintln!("stages: {}", stages.join(", "));
    }
    Ok(())
}
