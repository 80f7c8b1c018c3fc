//! `pixelpie stipple`: an image in, a stipple drawing (SVG or PNG) out. The
//! job, its options, defaults, checks and writers are the library's
//! ([`Job`]); this adds the paths, the backend, progress bars and the
//! report on stderr.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::Args;
use clap::parser::ValueSource;

use pixelpie::io;
use pixelpie::job::file::{JobFile, KEYS};
use pixelpie::job::{Decoded, Format, Job, Stage, Step};
use pixelpie::stipple::plot::Plotter;

use super::sample::{RunArgs, progress_bar, run_with_progress, sampling_bar};

/// Arguments of `pixelpie stipple`.
#[derive(Args, Debug)]
pub struct StippleArgs {
    /// The picture: PNG, JPEG, TIFF, BMP, WebP or OpenEXR. Several
    /// pictures make a batch: one drawing each, in the folder -o names.
    #[arg(id = "importance", value_name = "IMAGE", required = true, num_args = 1..)]
    images: Vec<PathBuf>,
    /// Output drawing: .svg or .png (or the dots' points: .csv, .json); for
    /// a batch, a folder (made if missing; a path ending in / is one too),
    /// where each picture's drawing is NAME.svg (or --format's extension).
    #[arg(long, short)]
    output: PathBuf,
    /// The drawings' format in a batch [default: svg; for one drawing, the
    /// output's extension].
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// Read every setting from a job file (written by --save-job or saved as
    /// a preset in the app); the options given with it override it.
    #[arg(long, value_name = "FILE.toml")]
    job: Option<PathBuf>,
    /// Also write the drawing as the pens will plot it, as a PNG: each dot as
    /// its pen path inks it with a pen of its plotted width (--pen-mm × the
    /// pen's dot gain), the inks multiplied, on the sheet with --paper.
    /// Without a pen, the dots as drawn.
    #[arg(long, value_name = "FILE.png")]
    preview: Option<PathBuf>,
    /// Write every setting of this drawing to a job file, to replay it with
    /// --job (the same file, byte for byte) or batch it.
    #[arg(long, value_name = "FILE.toml")]
    save_job: Option<PathBuf>,
    #[command(flatten)]
    options: Job,
    /// Also write the dots' centres and radii (.csv or .json), in drawing order.
    #[arg(long)]
    save_points: Option<PathBuf>,
    /// Print, per pen, the dots, pen lifts, pen-down and pen-up distance and
    /// an estimated plotting time (needs --pen-mm, and --width-mm or --paper).
    #[arg(long)]
    plot_stats: bool,
    /// The plotter's motion profile for --plot-stats: axidraw (AxiDraw's
    /// own software's planner, its defaults), saxi (saxi's), or a TOML file
    /// of AxiDraw's option names (speed_pendown, speed_penup, accel,
    /// pen_pos_up, pen_pos_down, pen_rate_lower, pen_rate_raise,
    /// pen_delay_down, pen_delay_up, const_speed, model, resolution) or
    /// saxi's (pen_down_acceleration, pen_down_max_velocity,
    /// pen_down_cornering_factor, pen_up_acceleration, pen_up_max_velocity,
    /// pen_drop_duration, pen_lift_duration; mm and s) [default: axidraw].
    #[arg(long, value_name = "axidraw|saxi|FILE.toml", requires = "plot_stats")]
    plotter: Option<PathBuf>,
    /// Top pen-down speed for --plot-stats, mm/s [default: the profile's, an AxiDraw's 50.2].
    #[arg(long, requires = "plot_stats")]
    plot_speed: Option<f64>,
    /// Top pen-up speed for --plot-stats, mm/s [default: the profile's, an AxiDraw's 150.6].
    #[arg(long, requires = "plot_stats")]
    travel_speed: Option<f64>,
    /// Seconds to drop and lift the pen, both together, for --plot-stats
    /// [default: the profile's, an AxiDraw's 0.276].
    #[arg(long, requires = "plot_stats")]
    pen_delay: Option<f64>,
    /// Print the drawing's plan as JSON (every decision: the domain, the
    /// count, the dots, relaxation, the correction, an estimated time) and
    /// draw nothing.
    #[arg(long)]
    plan: bool,
    #[command(flatten)]
    run: RunArgs,
}

/// The job: the command line's options, or the job file's (`--job`) with
/// the options given on the command line over it ([`Job::with_overrides`]).
fn job(a: &StippleArgs, matches: Option<&clap::ArgMatches>) -> Result<Job> {
    let Some(path) = &a.job else {
        return Ok(a.options.clone());
    };
    let file = JobFile::read(path)?;
    if let Some(w) = &file.warning
        && !a.run.quiet
    {
        eprintln!("warning: {}: {}", path.display(), super::said(w));
    }
    let on_line = KEYS.iter().copied().filter(|key| {
        matches.is_some_and(|m| m.value_source(key) == Some(ValueSource::CommandLine))
    });
    Job::with_overrides(file.table, &a.options, on_line)
        .with_context(|| format!("{}", path.display()))
}

/// Whether `path` names a folder: one that exists, or ends in a separator.
fn is_folder(path: &Path) -> bool {
    path.is_dir() || path.as_os_str().to_string_lossy().ends_with(['/', '\\'])
}

pub fn run(a: &StippleArgs, matches: Option<&clap::ArgMatches>) -> Result<()> {
    pixelpie::importance::budget::set_max_memory(a.run.max_memory);
    let mut o = job(a, matches)?;
    if o.poster.is_some() {
        if a.images.len() > 1 {
            bail!("--poster draws one picture into a folder of sheets: give one picture");
        }
        pixelpie::job::Poster::check_folder(&a.output)?;
        if a.format.is_some_and(|f| f != Format::Svg) {
            bail!("--poster writes SVG sheets: drop --format");
        }
    }
    let batch = o.poster.is_none() && (a.images.len() > 1 || is_folder(&a.output));
    let format = match (batch, a.format) {
        _ if o.poster.is_some() => Format::Svg,
        (true, f) => f.unwrap_or(Format::Svg),
        (false, None) => Format::from_path(&a.output)?,
        (false, Some(f)) => {
            let by_name = Format::from_path(&a.output)?;
            if by_name != f {
                bail!(
                    "--format {} disagrees with the output's extension ({})",
                    f.extension(),
                    a.output.display()
                );
            }
            f
        }
    };
    if let Some(p) = &a.save_points {
        if batch {
            bail!("--save-points writes one drawing's points: give one picture, not a batch");
        }
        io::PointFormat::from_path(p)?;
    }
    if let Some(p) = &a.preview {
        if batch {
            bail!("--preview writes one drawing's preview: give one picture, not a batch");
        }
        if Format::from_path(p).ok() != Some(Format::Png) {
            bail!("the preview is a PNG: name it .png, not '{}'", p.display());
        }
    }
    o.validate(format)?;
    if a.plan {
        for image in &a.images {
            let picture = Decoded::open(&o, image)?;
            println!(
                "{}",
                super::said(o.plan(picture.picture())?.plan.to_json()?)
            );
        }
        return Ok(());
    }
    // One picture: its pens are chosen before the job is saved; a batch
    // chooses for each picture.
    let mut decoded = None;
    if o.choose.is_some() && !batch {
        (o, decoded) = chosen(a, &o, &a.images[0])?;
    }
    if let Some(path) = &a.save_job {
        let source = (a.images.len() == 1).then(|| a.images[0].as_path());
        let text = o.to_toml(source)?;
        io::write_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))?;
    }
    if !batch {
        return draw(a, &o, &a.images[0], &a.output, decoded);
    }
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("cannot make the folder '{}'", a.output.display()))?;
    let mut outputs: Vec<PathBuf> = Vec::with_capacity(a.images.len());
    for image in &a.images {
        let stem = image.file_stem().unwrap_or(image.as_os_str());
        let out = a.output.join(stem).with_extension(format.extension());
        if let Some(i) = outputs.iter().position(|o| *o == out) {
            bail!(
                "'{}' and '{}' would both be drawn to '{}': rename one",
                a.images[i].display(),
                image.display(),
                out.display()
            );
        }
        outputs.push(out);
    }
    let mut failed = 0;
    for (image, out) in a.images.iter().zip(&outputs) {
        match draw(a, &o, image, out, None) {
            Ok(()) if !a.run.quiet => eprintln!("wrote {}", out.display()),
            Ok(()) => {}
            Err(e) => {
                failed += 1;
                eprintln!(
                    "error: {}: {}",
                    image.display(),
                    super::said(pixelpie::single_line(&format!("{e:#}")))
                );
            }
        }
    }
    if failed > 0 {
        bail!(
            "{failed} of {} pictures failed; the others are drawn",
            a.images.len()
        );
    }
    Ok(())
}

/// Prints --plot-stats: a row per pen of each sheet (named before its
/// pens when there are several), and the total.
fn print_plot_stats(sheets: &[(String, Vec<pixelpie::stipple::plot::PenPlot>)]) {
    let named = sheets.len() > 1;
    let sheet = if named { "sheet\t" } else { "" };
    println!("{sheet}pen\tdots\tlifts\tpen-down mm\tpen-up mm\tdrawing min\ttravel min\tminutes");
    for (name, plots) in sheets {
        for p in plots {
            let sheet = if named {
                format!("{name}\t")
            } else {
                String::new()
            };
            println!(
                "{sheet}{}\t{}\t{}\t{:.1}\t{:.1}\t{:.1}\t{:.1}\t{:.1}",
                p.pen,
                p.dots,
                p.lifts,
                p.pen_down_mm,
                p.pen_up_mm,
                p.pen_down_s / 60.0,
                p.pen_up_s / 60.0,
                p.seconds / 60.0
            );
        }
    }
    let total: f64 = sheets.iter().flat_map(|(_, p)| p).map(|p| p.seconds).sum();
    let tabs = if named { "\t" } else { "" };
    println!("total{tabs}\t\t\t\t\t\t\t{:.1}", total / 60.0);
}

/// Cuts `drawing` (made whole for job `o`'s poster) into sheets and
/// writes them with `poster.json` to folder `output`; the preview, the
/// points and the plot statistics as asked.
fn write_poster(
    a: &StippleArgs,
    o: &Job,
    picture: &Decoded,
    drawing: &pixelpie::job::Stipple,
    output: &Path,
    plotter: &Plotter,
) -> Result<()> {
    let whole = o
        .poster_whole(picture.picture())?
        .context("a poster job without a poster")?;
    let t0 = Instant::now();
    let poster = o.poster(&whole, drawing, &mut || false)?;
    let plotted = a.plot_stats.then_some(plotter);
    poster.write(o, output, plotted)?;
    if !a.run.quiet {
        let g = &poster.grid;
        eprintln!(
            "poster: {} sheets ({} rows × {} columns of {} mm × {} mm, overlapping {} mm), {:.1} s to cut and write: {}",
            poster.sheets.len(),
            g.rows,
            g.cols,
            g.sheet_mm[0],
            g.sheet_mm[1],
            g.overlap_mm,
            t0.elapsed().as_secs_f64(),
            output.join("poster.json").display()
        );
    }
    if let Some(path) = &a.preview {
        let img = poster.preview(&whole, drawing)?;
        io::write_atomic(path, |w| {
            Ok(pixelpie::stipple::raster::write_png_rgb(
                w,
                &img,
                drawing.points.len(),
            )?)
        })?;
    }
    if let Some(path) = &a.save_points {
        whole.write(drawing, path)?;
    }
    if a.plot_stats {
        let mut rows = Vec::with_capacity(poster.sheets.len());
        for (i, s) in poster.sheets.iter().enumerate() {
            rows.push((s.file_name(i), s.job.plot_stats(&s.drawing, plotter)?));
        }
        print_plot_stats(&rows);
    }
    Ok(())
}

/// The plotter profile of --plotter, with --plot-speed, --travel-speed
/// and --pen-delay over it.
fn plotter(a: &StippleArgs) -> Result<Plotter> {
    for (flag, v, zero) in [
        ("--plot-speed", a.plot_speed, false),
        ("--travel-speed", a.travel_speed, false),
        ("--pen-delay", a.pen_delay, true),
    ] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && (*v > 0.0 || zero && *v == 0.0))) {
            let unit = if zero {
                "seconds, at least 0"
            } else {
                "mm/s above 0"
            };
            bail!("{flag} {v}: expected {unit}");
        }
    }
    let mut p = match &a.plotter {
        Some(value) => Plotter::from_name_or_file(value)?,
        None => Plotter::default(),
    };
    if let Some(v) = a.plot_speed {
        p.set_pen_down_speed(v);
    }
    if let Some(v) = a.travel_speed {
        p.set_pen_up_speed(v);
    }
    if let Some(v) = a.pen_delay {
        p.set_pen_delay(v);
    }
    p.check()?;
    Ok(p)
}

/// Job `o` with the pens of `--choose` chosen for `image`, the choice said
/// on stderr (unless `--quiet`), and the picture as decoded (and the
/// seconds that took), to be drawn without decoding it again.
fn chosen(a: &StippleArgs, o: &Job, image: &Path) -> Result<(Job, Option<(Decoded, f64)>)> {
    let t0 = Instant::now();
    let picture = Decoded::open(o, image)?;
    let opened = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let (job, choice) = o.chosen(picture.picture())?;
    if let (Some(c), false) = (choice, a.run.quiet) {
        let names: Vec<&str> = c.pens.pens().iter().map(|p| p.name.as_str()).collect();
        eprintln!(
            "chose {} of {} pens for {}: {} (predicted ΔE00 {:.2}; {:.2} s, {} sets)",
            names.len(),
            o.pens.as_ref().map_or(0, pixelpie::colour::PenSet::len),
            image.display(),
            names.join(", "),
            c.predicted,
            t0.elapsed().as_secs_f64(),
            c.sets_scored
        );
    }
    // A choice of one pen may draw in grey: that picture decodes apart.
    let same = job.colour() == o.colour();
    Ok((job, same.then_some((picture, opened))))
}

/// Draws `image` with job `o` to `output` in `format`; `decoded`: the
/// picture already decoded (to choose its pens), and the seconds that took.
fn draw(
    a: &StippleArgs,
    o: &Job,
    image: &Path,
    output: &Path,
    mut decoded: Option<(Decoded, f64)>,
) -> Result<()> {
    let _gpu = pixelpie::backend::open_early(a.run.backend);
    let resolved;
    let o = if o.choose.is_some() {
        (resolved, decoded) = chosen(a, o, image)?;
        &resolved
    } else {
        o
    };
    let plotter = if a.plot_stats {
        if o.pen_mm.is_none() {
            bail!(
                "--plot-stats needs --pen-mm (and --width-mm or --paper): a plotter draws pen paths"
            );
        }
        plotter(a)?
    } else {
        Plotter::default()
    };
    a.run.apply_gpu_path();
    let t0 = Instant::now();
    let bar = sampling_bar(a.run.quiet);
    let relax_bar = progress_bar(a.run.quiet || o.relax == Some(0));
    let stage_bar = progress_bar(a.run.quiet);
    stage_bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    relax_bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} relaxing [{bar:30}] {pos}/{len}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    // The picture decoded once: here, or to choose its pens.
    let (picture, opened) = match decoded {
        Some(d) => d,
        None => {
            let t0 = Instant::now();
            let picture = Decoded::open(o, image)?;
            (picture, t0.elapsed().as_secs_f64())
        }
    };
    let mut drawing = o.draw(
        picture.picture(),
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
                Step::Relaxed(done, of) => {
                    relax_bar.set_length(u64::from(of));
                    relax_bar.set_position(u64::from(done));
                }
                // After sampling, a spinner names the stage, and ticks.
                Step::Stage(Stage::Prepare | Stage::Sample) => {}
                Step::Stage(stage) => {
                    bar.finish_and_clear();
                    if stage != Stage::Relax {
                        relax_bar.finish_and_clear();
                        stage_bar.set_message(stage.to_string());
                        stage_bar.enable_steady_tick(std::time::Duration::from_millis(250));
                    }
                }
                _ => {}
            }
            true
        },
    )?;
    drawing.stages[0].1 += opened;
    bar.finish_and_clear();
    relax_bar.finish_and_clear();
    stage_bar.finish_and_clear();
    // Said once the picture has decoded (a file that does not is an error).
    if let Some(w) = pixelpie::importance::cut_short(image)
        && !a.run.quiet
    {
        eprintln!("warning: {}", super::said(w));
    }
    let got = drawing.set.points.len();
    if a.run.verbose {
        eprintln!("{got} points after {} runs", drawing.runs);
    }
    if let Some(tour) = &drawing.tour
        && !a.run.quiet
    {
        let saved = if tour.start_length > 0.0 {
            100.0 * (1.0 - tour.length / tour.start_length)
        } else {
            0.0
        };
        eprintln!(
            "tsp: pen travel {:.0} px (Hilbert curve) -> {:.0} px (2-opt, Or-opt: {} moves, -{saved:.1}%)",
            tour.start_length, tour.length, tour.moves,
        );
    }
    if o.poster.is_some() {
        return write_poster(a, o, &picture, &drawing, output, &plotter);
    }
    o.write(&drawing, output)?;
    if let Some(path) = &a.preview {
        o.write_preview(&drawing, path)?;
    }
    if !a.run.quiet {
        for w in o.warnings(&drawing, Format::from_path(output).ok())? {
            eprintln!("warning: {}", super::said(w));
        }
    }
    if let Some(path) = &a.save_points {
        o.write(&drawing, path)?;
    }
    if a.plot_stats {
        print_plot_stats(&[(String::new(), o.plot_stats(&drawing, &plotter)?)]);
    }
    if a.run.verbose {
        let (lo, hi) = drawing
            .dots
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(lo, hi), d| {
                (lo.min(d.radius), hi.max(d.radius))
            });
        let (width, height) = drawing.domain;
        let (t_load, t_sample, t_relax) = (
            drawing.seconds(Stage::Prepare),
            drawing.seconds(Stage::Sample),
            drawing.seconds(Stage::Relax),
        );
        if let (Some(line), Some(tour)) = (&drawing.plan.line, &drawing.tour) {
            eprintln!(
                "one line through {} points, {:.2} px wide, {:.0} px long, on a {width}x{height} \
                 domain, sample radii {:.2}..{:.2} px; total {:.3} s",
                drawing.points.len(),
                line.width_px,
                tour.length,
                drawing.range.min,
                drawing.range.max,
                t0.elapsed().as_secs_f64()
            );
        } else {
            eprintln!(
                "{} dots on a {width}x{height} domain, sample radii {:.2}..{:.2} px, dot radii \
                 {lo:.2}..{hi:.2} px; load {t_load:.3} s, sampling {t_sample:.3} s, relax \
                 {t_relax:.3} s, total {:.3} s",
                drawing.dots.len(),
                drawing.range.min,
                drawing.range.max,
                t0.elapsed().as_secs_f64()
            );
        }
        let stages: Vec<String> = drawing
            .stages
            .iter()
            .map(|(name, s)| format!("{name} {s:.3} s"))
            .collect();
        eprintln!("stages: {}", stages.join(", "));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use clap::{Args, CommandFactory};

    /// The job file's keys are the CLI's option names, one for one.
    #[test]
    fn job_file_keys_are_the_options() {
        let cli = crate::cli::Cli::command();
        let stipple = cli.find_subcommand("stipple").expect("stipple");
        let mut job: Vec<String> = pixelpie::job::Job::augment_args(clap::Command::new("x"))
            .get_arguments()
            .map(|a| a.get_id().to_string())
            .collect();
        job.sort();
        let mut keys: Vec<String> = super::KEYS.iter().map(|k| (*k).to_string()).collect();
        keys.sort();
        assert_eq!(job, keys);
        for key in super::KEYS {
            assert!(stipple.get_arguments().any(|a| a.get_id() == *key), "{key}");
        }
    }
}
