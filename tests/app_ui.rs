//! The app driven through its UI with egui_kittest, rendered with wgpu (on
//! lavapipe in CI): controls change the drawing, dropped files replace the
//! map, exports read back with the CLI.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use pixelpie::app::{self, PixelPieApp};

fn gradient_png(path: &Path, w: u32, h: u32) {
    let img = image::GrayImage::from_fn(w, h, |x, y| {
        image::Luma([((x * 255) / w) as u8 ^ (((y / 20) % 2) as u8 * 40)])
    });
    img.save(path).expect("write png");
}

fn harness(image: &Path) -> Harness<'static, PixelPieApp> {
    let image = image.to_path_buf();
    let h = Harness::builder()
        .with_size([1000.0, 950.0])
        .wgpu_setup(app::wgpu_setup())
        .build_eframe(move |cc| PixelPieApp::new(cc, Some(image)));
    if std::env::var("PIXELPIE_EXPECT_GPU").as_deref() == Ok("1") {
        assert!(
            h.state().adapter().is_some(),
            "a GPU adapter is expected for the app"
        );
    }
    h
}

/// The app on a fresh `w`×`h` gradient, sampled: its folder, the image and
/// the harness.
fn ready(w: u32, h: u32) -> (tempfile::TempDir, PathBuf, Harness<'static, PixelPieApp>) {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, w, h);
    let mut harness = harness(&png);
    settle(&mut harness);
    (dir, png, harness)
}

/// Steps the UI until sampling is done (debounce, worker, reply).
fn settle(h: &mut Harness<'_, PixelPieApp>) {
    finish(h);
    assert!(h.state().error.is_none(), "error: {:?}", h.state().error);
}

/// Folds the panel's sections named, so that those below come into sight.
fn fold(h: &mut Harness<'_, PixelPieApp>, sections: &[&str]) {
    for name in sections {
        h.get_all_by_label(name).next().expect("a section").click();
        h.run_steps(2);
    }
}

/// Steps the UI until the app is idle, whatever the outcome.
fn finish(h: &mut Harness<'_, PixelPieApp>) {
    let start = Instant::now();
    loop {
        h.step();
        if !h.state().busy() {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "sampling never finished"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    h.run_steps(2);
}

#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn the_point_count_control_changes_the_dots_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 200, 150);
    let mut h = harness(&png);
    // Sample on egui's own device (auto would pick the CPU on lavapipe).
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Gpu;
    for target in [400.0, 1500.0] {
        h.get_by_label("Points").set_value_accesskit(target);
        settle(&mut h);
        let drawn = h.state().dots_drawn() as f64;
        assert!(
            (drawn - target).abs() <= 0.03 * target,
            "asked {target}, drew {drawn}"
        );
    }
}

#[test]
fn a_dropped_file_replaces_the_map() {
    let dir = tempfile::tempdir().unwrap();
    let (first, second) = (dir.path().join("a.png"), dir.path().join("b.png"));
    gradient_png(&first, 200, 150);
    gradient_png(&second, 90, 60);
    let mut h = harness(&first);
    settle(&mut h);
    assert_eq!(h.state().source.as_ref().unwrap().map.width(), 200);
    h.input_mut()
        .dropped_files
        .push(Arc::new(Dropped(second.clone())));
    settle(&mut h);
    let app = h.state();
    let src = app.source.as_ref().unwrap();
    assert_eq!((src.map.width(), src.map.height()), (90, 60));
    assert_eq!(src.path.as_deref(), Some(second.as_path()));
    // Sampled on the image enlarged to the CLI's 1024 px domain.
    let outcome = app.outcome.as_ref().unwrap();
    let set = &outcome.drawing.set;
    assert_eq!((set.width, set.height), (1024, 683));
    assert!((outcome.scale - 1024.0 / 90.0).abs() < 1e-4);
    let (dw, dh) = (set.width as f32, set.height as f32);
    assert!(set.points.iter().all(|p| p.x < dw && p.y < dh));
    // A bad file shows an error and keeps the map.
    let bad = dir.path().join("bad.png");
    std::fs::write(&bad, b"not a png").unwrap();
    h.input_mut().dropped_files.push(Arc::new(Dropped(bad)));
    settle(&mut h);
    assert!(
        h.state()
            .open_error
            .as_deref()
            .is_some_and(|e| e.contains("bad.png"))
    );
    assert_eq!(h.state().source.as_ref().unwrap().map.width(), 90);
}

#[test]
fn exports_are_read_by_the_cli_analyzer() {
    let (dir, _, mut h) = ready(160, 120);
    h.state_mut().export_path = dir.path().join("out.svg").display().to_string();
    h.get_by_label("CSV").click();
    h.run_steps(2);
    let csv = dir.path().join("out.csv");
    assert!(
        csv.exists(),
        "status {:?}, error {:?}",
        h.state().status,
        h.state().export_error
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args([
            "analyze",
            csv.to_str().unwrap(),
            "--width",
            "160",
            "--height",
            "120",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["count"].as_u64(), Some(h.state().dots_drawn() as u64));
    h.get_by_label("SVG").click();
    h.run_steps(2);
    let svg = std::fs::read_to_string(dir.path().join("out.svg")).unwrap();
    assert_eq!(svg.matches("<circle").count(), h.state().dots_drawn());
}

#[test]
fn the_canvas_renders_dots_and_backgrounds() {
    let (_dir, _, mut h) = ready(200, 150);
    let dark = |img: &image::RgbaImage| {
        // The canvas: right of the side panel.
        img.enumerate_pixels()
            .filter(|(x, _, p)| *x > 320 && p[0] < 60 && p[1] < 60 && p[2] < 60)
            .count()
    };
    let paper = h.render().expect("render");
    let _ = paper.save(concat!(env!("CARGO_TARGET_TMPDIR"), "/app-paper.png"));
    let dots = dark(&paper);
    assert!(dots > 200, "only {dots} dark pixels: no dots drawn");
    // The view's section comes into sight below the dots' controls.
    fold(&mut h, &["Dot size"]);
    h.get_by_label("Photo").click();
    h.run_steps(3);
    let photo = h.render().expect("render");
    let _ = photo.save(concat!(env!("CARGO_TARGET_TMPDIR"), "/app-photo.png"));
    assert_ne!(
        paper.as_raw(),
        photo.as_raw(),
        "the photo background changed nothing"
    );
}

#[test]
fn relaxation_runs_on_the_worker_and_can_be_cancelled() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("a.png");
    gradient_png(&first, 200, 150);
    let mut h = harness(&first);
    settle(&mut h);
    let before = h
        .state()
        .outcome
        .as_ref()
        .unwrap()
        .drawing
        .set
        .points
        .clone();
    // A long relaxation, then Cancel: the worker stops, the drawing stays.
    h.state_mut().settings.job.points = Some(60_000);
    h.state_mut().settings.job.relax = Some(30);
    let start = Instant::now();
    while !h.state().busy() {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(10), "no job started");
    }
    h.state_mut().cancel_job();
    h.run_steps(3);
    assert!(!h.state().busy());
    assert!(h.state().status.starts_with("cancelled"));
    h.get_by_label("cancelled");
    assert_eq!(
        h.state().outcome.as_ref().unwrap().drawing.set.points,
        before
    );
    // The controls show the drawing's settings again, not the cancelled ones.
    assert_eq!(h.state().settings.job.points, Some(10_000));
    assert_eq!(h.state().settings.job.relax, None);
    h.run_steps(3);
    assert!(!h.state().busy(), "going back re-sampled");
    // A short relaxation finishes, with the count asked for.
    h.state_mut().settings.job.points = Some(2000);
    h.state_mut().settings.job.relax = Some(3);
    h.step();
    settle(&mut h);
    let relaxed = &h.state().outcome.as_ref().unwrap().drawing.set.points;
    assert!((1900..=2100).contains(&relaxed.len()), "{}", relaxed.len());
}

#[test]
fn a_new_image_shows_no_stale_dots() {
    // Bug: the old dots were drawn enlarged over a new image of another
    // size until its sampling finished.
    let dir = tempfile::tempdir().unwrap();
    let (first, second) = (dir.path().join("a.png"), dir.path().join("b.png"));
    gradient_png(&first, 300, 200);
    gradient_png(&second, 128, 128);
    let mut h = harness(&first);
    settle(&mut h);
    assert!(h.state().dots_drawn() > 100);
    h.input_mut()
        .dropped_files
        .push(Arc::new(Dropped(second.clone())));
    // The new picture decodes on its own thread; the first frame that shows
    // it shows no dots.
    let start = Instant::now();
    while h.state().source.as_ref().unwrap().map.width() != 128 {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(30), "never decoded");
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(h.state().dots_drawn(), 0, "old dots over the new image");
    assert!(h.state().outcome.is_none());
    settle(&mut h);
    let set = &h.state().outcome.as_ref().unwrap().drawing.set;
    assert_eq!((set.width, set.height), (1024, 1024));
    assert!(h.state().dots_drawn() > 100);
}

#[test]
fn exports_use_the_dot_colour_and_the_png_scale() {
    // Bug: with red dots on screen the SVG said fill="black" and the PNG
    // was grey; the PNG had no size control.
    let (dir, _, mut h) = ready(160, 120);
    h.state_mut().settings.job.ink = pixelpie::job::Ink([220, 30, 30]);
    h.state_mut().settings.job.scale = 0.5;
    h.state_mut().export_path = dir.path().join("out").display().to_string();
    h.get_by_label("SVG").click();
    h.get_by_label("PNG").click();
    h.run_steps(2);
    assert!(
        h.state().export_error.is_none(),
        "{:?}",
        h.state().export_error
    );
    let svg = std::fs::read_to_string(dir.path().join("out.svg")).unwrap();
    assert!(
        svg.contains(r##"fill="#dc1e1e""##),
        "the SVG's ink is not the dots' colour"
    );
    let img = image::open(dir.path().join("out.png")).unwrap().to_rgb8();
    let set = &h.state().outcome.as_ref().unwrap().drawing.set;
    assert_eq!(img.dimensions(), (set.width / 2, set.height / 2));
    let inked: Vec<_> = img.pixels().filter(|p| p.0 != [255, 255, 255]).collect();
    assert!(inked.len() > 100);
    // Every inked pixel lies between the paper and the ink: reddish.
    assert!(inked.iter().all(|p| p.0[0] >= p.0[1] && p.0[1] == p.0[2]));
    assert!(inked.iter().any(|p| p.0[0] > 200 && p.0[1] < 80));
}

#[test]
fn errors_sit_by_their_action_and_go_when_it_succeeds() {
    let (dir, png, mut h) = ready(160, 120);
    // Open with an empty path: a plain message, not "cannot read ''".
    h.state_mut().open_path.clear();
    h.get_by_label("Open").click();
    h.run_steps(2);
    let e = h.state().open_error.clone().expect("an open error");
    assert!(!e.contains("''"), "{e}");
    assert!(h.state().export_error.is_none() && h.state().error.is_none());
    // A failed export names the user's file, not the temporary one.
    let missing = dir.path().join("no-such-folder").join("out");
    h.state_mut().export_path = missing.display().to_string();
    h.get_by_label("SVG").click();
    h.run_steps(2);
    let e = h.state().export_error.clone().expect("an export error");
    assert!(e.contains("out.svg") && !e.contains(".pixelpie-"), "{e}");
    h.get_by_label(&e);
    // The next export succeeds: its error goes, the full path shows.
    h.state_mut().export_path = "out".into();
    std::env::set_current_dir(dir.path()).unwrap();
    h.get_by_label("SVG").click();
    h.run_steps(2);
    assert!(h.state().export_error.is_none());
    let full = std::fs::canonicalize(dir.path().join("out.svg")).unwrap();
    assert_eq!(h.state().exported.as_deref(), Some(full.as_path()));
    h.get_by_label(&format!("wrote {}", full.display()));
    // Opening an image clears the open error.
    h.state_mut().open_path = png.display().to_string();
    h.get_by_label("Open").click();
    h.step();
    settle(&mut h);
    assert!(h.state().open_error.is_none());
}

/// File dialogs that answer with set paths, and remember where they started.
struct Answers {
    open: Option<PathBuf>,
    save: Option<PathBuf>,
    started_in: std::sync::Arc<std::sync::Mutex<Vec<Option<PathBuf>>>>,
}

impl app::dialogs::FileDialogs for Answers {
    fn pick_image(&mut self, folder: Option<&Path>) -> app::dialogs::Answer {
        self.started_in
            .lock()
            .unwrap()
            .push(folder.map(Path::to_path_buf));
        Ok(self.open.clone())
    }
    fn save_drawing(&mut self, folder: Option<&Path>, _name: &str) -> app::dialogs::Answer {
        self.started_in
            .lock()
            .unwrap()
            .push(folder.map(Path::to_path_buf));
        Ok(self.save.clone())
    }
}

/// Whether some text on screen holds `text` (wrapped text is read as runs
/// of one line each, in their values).
fn shows(h: &Harness<'_, PixelPieApp>, text: &str) -> bool {
    h.query_all_by(|n| {
        [n.label(), n.value()]
            .into_iter()
            .flatten()
            .any(|l| l.contains(text))
    })
    .count()
        > 0
}

/// A node's accessible label.
fn label(n: &egui_kittest::Node<'_>) -> Option<String> {
    use egui_kittest::kittest::NodeT;
    n.accesskit_node().label()
}

fn press(h: &mut Harness<'_, PixelPieApp>, key: egui::Key, modifiers: egui::Modifiers) {
    h.key_press_modifiers(modifiers, key);
    h.run_steps(2);
}

#[test]
fn shortcuts_and_file_dialogs_work() {
    let dir = tempfile::tempdir().unwrap();
    let (first, second) = (dir.path().join("a.png"), dir.path().join("b.png"));
    gradient_png(&first, 200, 150);
    gradient_png(&second, 100, 100);
    let mut h = harness(&first);
    settle(&mut h);
    let started = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let out = dir.path().join("drawing.png");
    h.state_mut().dialogs = Box::new(Answers {
        open: Some(second.clone()),
        save: Some(out.clone()),
        started_in: started.clone(),
    });
    let cmd = egui::Modifiers::COMMAND;
    // Ctrl+O opens through the dialog, which starts in the last folder.
    press(&mut h, egui::Key::O, cmd);
    settle(&mut h);
    assert_eq!(h.state().source.as_ref().unwrap().map.width(), 100);
    // Ctrl+S exports where the dialog says, in its extension's format.
    press(&mut h, egui::Key::S, cmd);
    assert!(out.exists(), "{:?}", h.state().export_error);
    assert!(pixelpie::stipple::raster::read_png_dots(&std::fs::read(&out).unwrap()).is_some());
    let started = started.lock().unwrap().clone();
    assert_eq!(started, vec![Some(dir.path().to_path_buf()); 2]);
    // F fits, + and − zoom the picture (not the UI, even with Ctrl).
    let fit = h.state().zoom();
    press(&mut h, egui::Key::Plus, egui::Modifiers::NONE);
    assert!((h.state().zoom() / fit - 1.25).abs() < 1e-3);
    press(&mut h, egui::Key::Minus, cmd);
    assert!((h.state().zoom() / fit - 1.0).abs() < 1e-3);
    press(&mut h, egui::Key::Plus, cmd);
    assert_eq!(h.ctx.zoom_factor(), 1.0, "Ctrl+plus scaled the UI");
    press(&mut h, egui::Key::F, egui::Modifiers::NONE);
    assert!((h.state().zoom() - fit).abs() < 1e-3);
    // R re-rolls; Ctrl+Z undoes it; Reset restores the defaults, undoably.
    let seed = h.state().settings.job.sampler.seed;
    press(&mut h, egui::Key::R, egui::Modifiers::NONE);
    assert_ne!(h.state().settings.job.sampler.seed, seed);
    press(&mut h, egui::Key::Z, cmd);
    assert_eq!(h.state().settings.job.sampler.seed, seed);
    h.state_mut().settings.job.importance.gamma = 2.0;
    std::thread::sleep(pixelpie::app::shortcuts::UNDO_GROUP);
    h.run_steps(1);
    h.get_by_label("Reset").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.importance.gamma, 1.0);
    assert_eq!(
        h.state().source.as_ref().unwrap().map.width(),
        100,
        "reset kept the picture"
    );
    press(&mut h, egui::Key::Z, cmd);
    assert_eq!(h.state().settings.job.importance.gamma, 2.0);
    // F1 shows the help, which lists every shortcut.
    press(&mut h, egui::Key::F1, egui::Modifiers::NONE);
    assert!(h.state().show_help);
    for (keys, what) in pixelpie::app::shortcuts::SHORTCUTS {
        assert!(h.query_all_by_label(keys).count() > 0, "{keys} not listed");
        h.get_by_label(what);
    }
}

#[test]
fn the_export_row_and_re_roll_stay_put() {
    let (_dir, _, mut h) = ready(200, 150);
    let svg = h.get_by_label("SVG").rect();
    let reroll = h.get_by_label("Re-roll").rect();
    // Busy: the progress line shows; nothing below it moves.
    h.state_mut().settings.job.points = Some(50_000);
    let start = Instant::now();
    while !h.state().busy() {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(10));
    }
    h.run_steps(1);
    assert!(h.state().busy());
    assert_eq!(h.get_by_label("SVG").rect(), svg, "the export row moved");
    h.state_mut().cancel_job();
    h.run_steps(2);
    // A seed of many digits: Re-roll stays where it was.
    h.state_mut().settings.job.sampler.seed = u64::MAX / 3;
    h.run_steps(2);
    assert_eq!(h.get_by_label("Re-roll").rect(), reroll, "Re-roll moved");
    assert_eq!(h.get_by_label("SVG").rect(), svg);
}

#[test]
fn every_label_is_in_the_fonts_and_the_controls_explain_themselves() {
    let (_dir, _, mut h) = ready(200, 150);
    h.ctx.all_styles_mut(|s| s.interaction.tooltip_delay = 0.0);
    h.state_mut().show_help = true;
    h.run_steps(2);
    // No glyph missing from the bundled fonts (the colour picker's header
    // once showed an empty box).
    let labels: Vec<String> = h.query_all_by(|_| true).filter_map(|n| label(&n)).collect();
    assert!(labels.len() > 40);
    let font = egui::FontId::proportional(14.0);
    for l in &labels {
        let ok = h.ctx.fonts_mut(|f| f.has_glyphs(&font, l));
        assert!(ok, "a glyph of {l:?} is missing from the fonts");
    }
    // Tooltips in plain words, keeping the paper's terms (the help window
    // closed, so that it covers nothing; the sections above Sampling folded,
    // so that its controls are in sight).
    h.state_mut().show_help = false;
    h.run_steps(2);
    fold(&mut h, &["Pens", "Paper"]);
    let mut missing = Vec::new();
    for (control, words) in [
        ("Black", "Black"),
        ("SVG", "SVG"),
        ("Policy", "disk policy"),
        ("Sub-pixel bits", "pixel centre"),
        ("Coverage disks (Figure 4)", "Figure 4"),
        ("Re-roll", "seed"),
        ("Periodic (tileable)", "tile"),
    ] {
        if control == "Policy" {
            // The Dot size section folded too: Sampling's controls in sight.
            fold(&mut h, &["Dot size"]);
        }
        // Away first (onto the title, in sight however the panel scrolls):
        // egui shows a tooltip after the pointer rests.
        h.get_by_label("PixelPie").hover();
        h.run_steps(2);
        h.get_all_by_label(control).next().unwrap().hover();
        h.run_steps(2);
        if !shows(&h, words) {
            missing.push((control, words));
        }
    }
    assert!(missing.is_empty(), "no tooltips: {missing:?}");
    // S1/S2/PP are named in the statistics' tooltip.
    h.get_by_label("PixelPie").hover();
    h.run_steps(2);
    h.get_by_label_contains("S1 ").hover();
    h.run_steps(2);
    assert!(shows(&h, "S1 throws darts"), "S1/S2/PP are not explained");
}

#[test]
fn a_periodic_drawing_shows_two_by_two_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 200, 200);
    let mut h = harness(&png);
    h.state_mut().settings.job.sampler.periodic = true;
    settle(&mut h);
    assert_eq!(h.state().tiles(), 2);
    // The canvas holds four copies: dark dots in each quadrant of the
    // 2×2 block, and the block fits the canvas.
    let img = h.render().expect("render");
    let _ = img.save(concat!(env!("CARGO_TARGET_TMPDIR"), "/app-tiles.png"));
    let canvas_x0 = app::PANEL_WIDTH as u32 + 30;
    let (w, hgt) = (img.width() - canvas_x0, img.height());
    let side = w.min(hgt) as f32 * 0.98;
    let (cx, cy) = (canvas_x0 as f32 + w as f32 / 2.0, hgt as f32 / 2.0);
    let dark_in = |qx: f32, qy: f32| {
        img.enumerate_pixels()
            .filter(|(x, y, p)| {
                let (fx, fy) = (*x as f32 - cx, *y as f32 - cy);
                (qx * fx) > 5.0
                    && (qy * fy) > 5.0
                    && fx.abs() < side / 2.0
                    && fy.abs() < side / 2.0
                    && p[0] < 60
            })
            .count()
    };
    for (qx, qy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        assert!(dark_in(qx, qy) > 100, "no dots in quadrant ({qx}, {qy})");
    }
    fold(&mut h, &["Pens", "Paper", "Dot size"]);
    h.get_by_label("Show 2×2 tiles").click();
    h.run_steps(2);
    assert_eq!(h.state().tiles(), 1);
}

#[test]
fn the_status_follows_the_job_on_the_gpu_backend() {
    // Bug: with the GPU backend, "sampling…" stayed up well after the
    // statistics showed a finished run. The status now follows the job (its
    // elapsed time while it runs, "ready" when done) and the statistics give
    // the whole job's time beside the last run's.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 200, 150);
    let mut h = harness(&png);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Gpu;
    settle(&mut h);
    let has = shows;
    assert!(!has(&h, "sampling"), "a finished job still says sampling");
    h.get_by_label("ready");
    let o = h.state().outcome.as_ref().unwrap();
    let d = &o.drawing;
    assert!(o.seconds >= d.set.stats.seconds && d.runs >= 1);
    assert!(has(&h, &format!("{} · took", d.plan.line())));
    // While a job runs, its elapsed time shows.
    h.state_mut().settings.job.points = Some(40_000);
    let start = Instant::now();
    while h
        .state()
        .progress_shown()
        .is_none_or(|l| l.starts_with("waiting"))
    {
        h.step();
        std::thread::sleep(Duration::from_millis(5));
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no progress shown"
        );
    }
    let shown = h.state().progress_shown().unwrap();
    assert!(shown.ends_with(" s"), "{shown}");
    settle(&mut h);
    assert!(!has(&h, "sampling") && h.state().progress_shown().is_none());
}

#[test]
fn exact_spacing_gives_sets_without_slack() {
    let (_dir, _png, mut h) = ready(200, 150);
    assert!(!h.state().outcome.as_ref().unwrap().drawing.set.stats.exact);
    // Relaxation moves the points off the sampler's set: none here.
    h.state_mut().settings.job.relax = Some(0);
    h.step();
    settle(&mut h);
    fold(&mut h, &["Dot size"]);
    h.get_by_label("Exact spacing").click();
    settle(&mut h);
    let set = &h.state().outcome.as_ref().unwrap().drawing.set;
    assert!(set.stats.exact && set.maximal(), "{:?}", set.stats);
    // The app's policy is Smaller: every pair at least min(r_i, r_j) apart,
    // exactly (the values are dyadic, their squares exact in f64).
    let p = &set.points;
    assert!(p.len() > 1000);
    for i in 0..p.len() {
        for j in 0..i {
            let (dx, dy) = (
                f64::from(p[i].x) - f64::from(p[j].x),
                f64::from(p[i].y) - f64::from(p[j].y),
            );
            let f = f64::from(p[i].radius.min(p[j].radius));
            assert!(dx * dx + dy * dy >= f * f, "points {j} and {i} too close");
        }
    }
    // On egui's own device the GPU runs the pixel pass: the same dots.
    let on_cpu = set.points.clone();
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Gpu;
    settle(&mut h);
    let set = &h.state().outcome.as_ref().unwrap().drawing.set;
    if h.state().adapter().is_some() {
        assert_eq!(set.stats.backend, pixelpie::sampler::BackendKind::GpuExact);
        assert_eq!(set.points, on_cpu);
    }
}

/// Runs the `pixelpie` binary; its output must be a success.
fn cli(args: &[&str]) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(args)
        .output()
        .expect("run pixelpie");
    assert!(
        out.status.success(),
        "pixelpie {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Exports the app's drawing to `path` (the extension picks the format).
fn export(h: &mut Harness<'_, PixelPieApp>, path: &Path) {
    let ext = path.extension().unwrap().to_str().unwrap().to_owned();
    h.state_mut().export_path = path.with_extension("").display().to_string();
    h.state_mut().export_as(&ext);
    assert!(
        h.state().export_error.is_none(),
        "{:?}",
        h.state().export_error
    );
}

#[test]
fn the_app_draws_and_exports_what_the_cli_does() {
    // A large photo (longer side 3000 px): the app once enlarged it with
    // rules of its own, so its first view was not the CLI's drawing.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("photo.png");
    gradient_png(&png, 3000, 2000);
    let p = |name: &str| dir.path().join(name);
    let s = |path: &Path| path.display().to_string();
    let mut h = harness(&png);
    settle(&mut h);
    // The defaults: the same dots, in the same order, and the same files.
    cli(&[
        "stipple",
        &s(&png),
        "-o",
        &s(&p("cli.svg")),
        "--save-points",
        &s(&p("cli.csv")),
        "--quiet",
    ]);
    export(&mut h, &p("app.svg"));
    export(&mut h, &p("app.csv"));
    let drawing = &h.state().outcome.as_ref().unwrap().drawing;
    assert_eq!(drawing.domain, (1024, 683));
    let rows = std::fs::read_to_string(p("cli.csv")).unwrap();
    let cli_points: Vec<[f32; 3]> = rows
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f32> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    let app_points: Vec<[f32; 3]> = drawing
        .points
        .iter()
        .map(|q| [q.x, q.y, q.radius])
        .collect();
    assert_eq!(app_points, cli_points, "the app's dots are not the CLI's");
    for (a, c) in [("app.svg", "cli.svg"), ("app.csv", "cli.csv")] {
        assert_eq!(
            std::fs::read(p(a)).unwrap(),
            std::fs::read(p(c)).unwrap(),
            "{a}"
        );
    }
    // Other settings, through the app's controls' fields, and the CLI's
    // arguments for them: plotter SVG, coloured PNG.
    {
        let st = &mut h.state_mut().settings;
        st.job.points = Some(3000);
        let job = &mut st.job;
        job.dot = Some(pixelpie::job::DotMode::Fixed);
        job.relax = Some(2);
        job.order = pixelpie::job::Order::Tsp;
        job.width_mm = Some(150.0);
        job.pen_mm = Some(0.4);
        job.ink = "#1f77b4".parse().unwrap();
        job.policy = pixelpie::sampler::Policy::Bigger;
        job.sampler.seed = 5;
        job.importance.gamma = 1.4;
        job.importance.white_cutoff = Some(0.9);
    }
    h.step();
    settle(&mut h);
    export(&mut h, &p("app-pen.svg"));
    // The CLI's arguments for the same job; the page and pen for the SVG,
    // the scale for the PNG.
    let same = [
        "--quiet",
        "--points",
        "3000",
        "--dot",
        "fixed",
        "--relax",
        "2",
        "--order",
        "tsp",
        "--ink",
        "#1f77b4",
        "--policy",
        "bigger",
        "--seed",
        "5",
        "--gamma",
        "1.4",
        "--white-cutoff",
        "0.9",
    ];
    let (png_path, pen_svg) = (s(&png), s(&p("cli-pen.svg")));
    let page = ["--width-mm", "150", "--pen-mm", "0.4"];
    cli(&[&["stipple", &png_path, "-o", &pen_svg][..], &same, &page].concat());
    let pen = std::fs::read(p("app-pen.svg")).unwrap();
    assert_eq!(pen, std::fs::read(p("cli-pen.svg")).unwrap());
    assert!(String::from_utf8_lossy(&pen).contains(r##"stroke="#1f77b4""##));
    {
        let job = &mut h.state_mut().settings.job;
        job.width_mm = None;
        job.pen_mm = None;
        job.scale = 0.5;
    }
    h.run_steps(2);
    assert!(!h.state().busy(), "export options re-sampled");
    export(&mut h, &p("app.png"));
    let cli_png = s(&p("cli.png"));
    let scale = ["--scale", "0.5"];
    cli(&[&["stipple", &png_path, "-o", &cli_png][..], &same, &scale].concat());
    assert_eq!(
        std::fs::read(p("app.png")).unwrap(),
        std::fs::read(p("cli.png")).unwrap()
    );
}

/// File dialogs that cannot open (a desktop without a portal).
struct NoDialogs;

impl app::dialogs::FileDialogs for NoDialogs {
    fn pick_image(&mut self, _: Option<&Path>) -> app::dialogs::Answer {
        Err("no file dialog on this desktop (test)".into())
    }
    fn save_drawing(&mut self, _: Option<&Path>, _: &str) -> app::dialogs::Answer {
        Err("no file dialog on this desktop (test)".into())
    }
}

#[test]
fn a_dialog_that_cannot_open_says_why() {
    let (_dir, _, mut h) = ready(160, 120);
    h.state_mut().dialogs = Box::new(NoDialogs);
    let cmd = egui::Modifiers::COMMAND;
    press(&mut h, egui::Key::O, cmd);
    assert_eq!(
        h.state().open_error.as_deref(),
        Some("no file dialog on this desktop (test)")
    );
    h.get_by_label("no file dialog on this desktop (test)");
    press(&mut h, egui::Key::S, cmd);
    assert_eq!(
        h.state().export_error.as_deref(),
        Some("no file dialog on this desktop (test)")
    );
    // The typed path takes ~/ and file:// addresses.
    let home = std::env::var("HOME").unwrap();
    assert_eq!(app::typed_path("~/a.png"), Path::new(&home).join("a.png"));
    assert_eq!(
        app::typed_path(" file:///tmp/a b.png "),
        Path::new("/tmp/a b.png")
    );
}

#[test]
fn a_big_picture_decodes_while_frames_keep_coming() {
    let (dir, _, mut h) = ready(160, 120);
    let big = dir.path().join("big.png");
    gradient_png(&big, 6000, 4000);
    let ctx = h.ctx.clone();
    h.state_mut().open(&ctx, &big);
    assert!(
        h.state().loading_name().is_some(),
        "open() waited for the decoder"
    );
    h.step();
    let mut frames = 1;
    let spinner_seen = shows(&h, "decoding");
    let start = Instant::now();
    while h.state().loading_name().is_some() {
        h.step();
        frames += 1;
        std::thread::sleep(Duration::from_millis(5));
        assert!(start.elapsed() < Duration::from_secs(60), "never decoded");
    }
    assert!(
        spinner_seen || frames > 1,
        "no frame while the picture decoded"
    );
    settle(&mut h);
    let src = h.state().source.as_ref().unwrap();
    assert_eq!((src.map.width(), src.map.height()), (6000, 4000));
    assert!(h.state().dots_drawn() > 1000);
}

#[test]
fn errors_and_modes_leave_the_controls_in_place_and_the_view_refits() {
    let (dir, _, mut h) = ready(200, 150);
    let csv = h.get_by_label("CSV").rect();
    let behind = h.get_by_label("Behind").rect();
    // A long export error stays on one line: the export row stays put.
    let deep = dir
        .path()
        .join("no-such-folder-with-a-rather-long-name-to-wrap-the-error")
        .join("and-a-long-file-name-too");
    h.state_mut().export_path = deep.display().to_string();
    h.get_by_label("SVG").click();
    h.run_steps(2);
    assert!(h.state().export_error.is_some());
    assert_eq!(h.get_by_label("CSV").rect(), csv, "the export row moved");
    // Each dot mode shows the same rows: nothing below them jumps.
    for mode in [
        pixelpie::job::DotMode::Proportional,
        pixelpie::job::DotMode::Fixed,
        pixelpie::job::DotMode::Sized,
    ] {
        h.state_mut().settings.job.dot = Some(mode);
        h.run_steps(2);
        assert_eq!(h.get_by_label("Behind").rect(), behind, "{mode:?}");
    }
    settle(&mut h);
    // A resized window refits a fitted view.
    let before = h.state().zoom();
    h.set_size(egui::vec2(800.0, 600.0));
    h.run_steps(3);
    let after = h.state().zoom();
    assert!(after < before * 0.9, "zoom {before} -> {after}: no refit");
}

#[test]
fn the_pens_section_draws_and_exports_in_colour() {
    let dir = tempfile::tempdir().unwrap();
    let photo = dir.path().join("colour.png");
    // Red on the left, blue on the right, a grey ramp down the middle.
    image::RgbImage::from_fn(240, 160, |x, y| {
        if x < 100 {
            image::Rgb([200, 40, 40])
        } else if x >= 140 {
            image::Rgb([40, 60, 190])
        } else {
            let g = (y * 255 / 160) as u8;
            image::Rgb([g, g, g])
        }
    })
    .save(&photo)
    .unwrap();
    let mut h = harness(&photo);
    settle(&mut h);
    h.get_by_label("Points").set_value_accesskit(3000.0);
    settle(&mut h);
    assert!(h.state().outcome.as_ref().unwrap().drawing.pens.is_none());
    // CMYK: four pens, each drawing, and the swatches named.
    // Below the fold of the panel: scroll to it first.
    h.get_by_label("CMYK").scroll_to_me();
    h.run_steps(10);
    h.get_by_label("CMYK").click();
    settle(&mut h);
    let drawing = &h.state().outcome.as_ref().unwrap().drawing;
    let pens = drawing.pens.clone().expect("a colour drawing");
    assert_eq!(pens.len(), 4);
    let mut per_pen = [0usize; 4];
    for p in &drawing.points {
        per_pen[p.class as usize] += 1;
    }
    assert!(per_pen.iter().all(|&n| n > 20), "{per_pen:?}");
    assert!((drawing.points.len() as f64 - 3000.0).abs() <= 90.0);
    for name in ["cyan", "magenta", "yellow", "black"] {
        assert!(
            h.query_by_label(&format!("pen {name}")).is_some(),
            "no swatch of {name}"
        );
    }
    // Without a pen width anywhere the rows say so, not "0.00mm".
    assert!(
        shows(&h, "no width"),
        "the pen rows do not say they have no width"
    );
    assert!(!shows(&h, "0.00mm"));
    // The view shows the composite; hiding every pen leaves white paper.
    h.run_steps(2);
    let shown = h.render().expect("render");
    let dark = |img: &image::RgbaImage| {
        img.pixels()
            .filter(|p| p.0[0] < 128 || p.0[2] < 128)
            .count()
    };
    let with_pens = dark(&shown);
    h.state_mut().settings.hidden_pens = vec![true; 4];
    h.run_steps(3);
    let without = dark(&h.render().expect("render"));
    assert!(
        with_pens > without + 500,
        "pens shown {with_pens} vs hidden {without}"
    );
    h.state_mut().settings.hidden_pens = vec![false; 4];
    // Add a pen (a fifth colour), remove it again.
    // Below the fold of the panel: scroll to it first.
    h.get_by_label("Add pen").scroll_to_me();
    h.run_steps(3);
    h.get_by_label("Add pen").click();
    settle(&mut h);
    assert_eq!(h.state().settings.job.pens.as_ref().unwrap().len(), 5);
    h.get_all_by_label("−").last().unwrap().scroll_to_me();
    h.run_steps(3);
    h.get_all_by_label("−").last().unwrap().click();
    settle(&mut h);
    assert_eq!(
        h.state().settings.job.pens,
        Some(pixelpie::colour::PenSet::cmyk())
    );
    // The export: one Inkscape layer per pen, the CLI's own file.
    let svg = dir.path().join("app.svg");
    export(&mut h, &svg);
    let text = std::fs::read_to_string(&svg).unwrap();
    let d = pixelpie::stipple::read::read_svg(&text).unwrap();
    assert_eq!(d.layers.len(), 4);
    let cli_svg = dir.path().join("cli.svg");
    cli(&[
        "stipple",
        photo.to_str().unwrap(),
        "-o",
        cli_svg.to_str().unwrap(),
        "--pens",
        "cmyk",
        "--points",
        "3000",
        "--backend",
        "cpu",
    ]);
    assert_eq!(text, std::fs::read_to_string(&cli_svg).unwrap());
    // One ink again: the grey drawing.
    h.get_by_label("One ink").scroll_to_me();
    h.run_steps(10);
    h.get_by_label("One ink").click();
    settle(&mut h);
    assert!(h.state().outcome.as_ref().unwrap().drawing.pens.is_none());
}

/// Runs the `pixelpie` binary and returns what it printed; its output must
/// be a success.
fn cli_stdout(args: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(args)
        .output()
        .expect("run pixelpie");
    assert!(
        out.status.success(),
        "pixelpie {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The Paper section's combo box (the Behind row has a Paper button too).
fn paper_combo<'a>(h: &'a Harness<'_, PixelPieApp>) -> egui_kittest::Node<'a> {
    h.get_by(|n| {
        n.role() == egui::accesskit::Role::ComboBox && n.label().as_deref() == Some("Paper")
    })
}

/// Opens the Paper section's combo box (scrolled into view first).
fn open_paper_combo(h: &mut Harness<'_, PixelPieApp>) {
    paper_combo(h).scroll_to_me();
    h.run_steps(10);
    paper_combo(h).click();
    // The popup takes a few frames to open.
    for _ in 0..20 {
        h.step();
        if h.query_by_role(egui::accesskit::Role::ListBox).is_some() {
            break;
        }
    }
    h.run_steps(2);
}

/// Steps the UI until the plot time's estimate is in, and returns its line.
fn plot_line(h: &mut Harness<'_, PixelPieApp>) -> String {
    let start = Instant::now();
    loop {
        h.step();
        if !h.state().plot_pending() && h.state().plot_line().is_some() {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no plot time: {:?}",
            h.state().plot_line()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    h.run_steps(2);
    let line = h.state().plot_line().unwrap();
    // On screen, in the export section.
    h.get_by_label(&line);
    line
}

/// The minutes and lifts of a plot-time line ("plot ≈ 1 h 23 min · 1 pen
/// · 3 012 lifts").
fn plot_minutes_and_lifts(line: &str) -> (f64, usize) {
    let parts: Vec<&str> = line.split(" · ").collect();
    assert_eq!(parts.len(), 3, "{line}");
    let time = parts[0].strip_prefix("plot ≈ ").expect(line);
    let words: Vec<&str> = time.split(' ').collect();
    let minutes = match words.as_slice() {
        [h, "h", m, "min"] => h.parse::<f64>().unwrap() * 60.0 + m.parse::<f64>().unwrap(),
        [m, "min"] => m.parse().unwrap(),
        [s, "s"] => s.parse::<f64>().unwrap() / 60.0,
        _ => panic!("{line}"),
    };
    let lifts = parts[2]
        .strip_suffix(" lifts")
        .expect(line)
        .replace(' ', "")
        .parse()
        .unwrap();
    (minutes, lifts)
}

/// The total minutes and the lifts of `--plot-stats`'s table.
fn cli_plot_minutes_and_lifts(table: &str) -> (f64, usize) {
    let mut lifts = 0;
    let mut total = None;
    for row in table.lines().skip(1) {
        let cells: Vec<&str> = row.split('\t').collect();
        if cells[0] == "total" {
            total = Some(cells.last().unwrap().parse().unwrap());
        } else {
            lifts += cells[2].parse::<usize>().unwrap();
        }
    }
    (total.expect(table), lifts)
}

#[test]
fn paper_and_pen_export_the_cli_s_sheet_and_show_its_plot_time() {
    let (dir, png, mut h) = ready(200, 150);
    h.get_by_label("Points").set_value_accesskit(3000.0);
    settle(&mut h);
    assert!(h.state().plot_line().is_none(), "a plot time without a pen");
    // A width in mm first: the paper replaces it.
    h.get_by_label("Width mm").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.width_mm, Some(200.0));
    // A4, landscape, 15 mm margins, through the Paper section.
    open_paper_combo(&mut h);
    h.get_by_label("A4").click();
    h.run_steps(2);
    h.get_by_label("Landscape").click();
    h.run_steps(2);
    h.get_by_label("Margin").set_value_accesskit(15.0);
    h.run_steps(2);
    // The pen, with the paper as its page.
    h.get_by_label("Pen mm").click();
    settle(&mut h);
    let job = h.state().settings.job();
    assert_eq!(job.paper, Some("a4".parse().unwrap()));
    assert!(job.landscape);
    assert_eq!(job.margin, Some(15.0));
    assert_eq!(
        job.width_mm, None,
        "the paper and a width exclude each other"
    );
    assert_eq!(job.pen_mm, Some(0.3));
    let placement = h.state().placement().unwrap();
    assert_eq!(placement.sheet_mm, (297.0, 210.0));
    // The CLI's sheet, byte for byte, and its plot statistics.
    let app_svg = dir.path().join("app.svg");
    export(&mut h, &app_svg);
    let (png, cli_svg) = (png.display().to_string(), dir.path().join("cli.svg"));
    let cli_svg = cli_svg.display().to_string();
    let args = [
        "stipple",
        &png,
        "-o",
        &cli_svg,
        "--quiet",
        "--points",
        "3000",
        "--paper",
        "a4",
        "--landscape",
        "--margin",
        "15",
        "--pen-mm",
        "0.3",
        "--plot-stats",
    ];
    let table = cli_stdout(&args);
    let svg = std::fs::read_to_string(&app_svg).unwrap();
    assert!(
        svg.contains(r#"width="297mm" height="210mm""#),
        "{}",
        &svg[..300]
    );
    assert_eq!(svg, std::fs::read_to_string(&cli_svg).unwrap());
    // The plot time: the CLI's total, to the minute.
    let line = plot_line(&mut h);
    let (minutes, lifts) = plot_minutes_and_lifts(&line);
    let (cli_minutes, cli_lifts) = cli_plot_minutes_and_lifts(&table);
    eprintln!("app: {line}; cli: {cli_minutes} min, {cli_lifts} lifts");
    assert!(
        (minutes - cli_minutes).abs() <= 0.55,
        "app {line}, CLI {cli_minutes} min"
    );
    assert_eq!(lifts, cli_lifts);
    assert!(line.contains(" · 1 pen · "), "{line}");
    let font = egui::FontId::proportional(14.0);
    assert!(h.ctx.fonts_mut(|f| f.has_glyphs(&font, &line)), "{line}");
    // Circles instead of spirals: the CLI's file again, and a shorter plot.
    h.get_by_label("Circle").click();
    h.run_steps(2);
    assert!(!h.state().busy(), "the dot path re-sampled");
    assert_eq!(
        h.state().settings.job.dot_path,
        pixelpie::stipple::svg::DotPath::Circle
    );
    export(&mut h, &app_svg);
    let table = cli_stdout(&[&args[..], &["--dot-path", "circle"]].concat());
    assert_eq!(
        std::fs::read_to_string(&app_svg).unwrap(),
        std::fs::read_to_string(&cli_svg).unwrap()
    );
    let circles = plot_line(&mut h);
    let (circle_minutes, _) = plot_minutes_and_lifts(&circles);
    let (cli_circle_minutes, _) = cli_plot_minutes_and_lifts(&table);
    assert!(
        (circle_minutes - cli_circle_minutes).abs() <= 0.55,
        "{circles}"
    );
    assert!(cli_circle_minutes < cli_minutes);
    // No paper: the margin and the orientation go, and the pen with them
    // (it has no page in mm); no plot time.
    open_paper_combo(&mut h);
    h.get_by_label("None").click();
    settle(&mut h);
    let job = h.state().settings.job();
    assert_eq!((job.paper, job.margin, job.landscape), (None, None, false));
    assert_eq!(job.pen_mm, None);
    assert!(h.state().plot_line().is_none());
}

#[test]
fn the_view_shows_the_sheet_and_its_margins_around_the_drawing() {
    // A 4:3 picture, black at the left: on landscape A4 with 15 mm margins
    // it is 240 × 180 mm, 28.5 mm from the sheet's left edge.
    let (_dir, _, mut h) = ready(200, 150);
    {
        let job = &mut h.state_mut().settings.job;
        job.paper = Some("a4".parse().unwrap());
        job.landscape = true;
        job.margin = Some(15.0);
    }
    h.run_steps(3);
    assert!(!h.state().busy(), "the paper re-sampled");
    let backdrop = image::Rgba([90, 90, 90, 255]);
    let white = image::Rgba([255, 255, 255, 255]);
    let measure = |h: &mut Harness<'_, PixelPieApp>, name: &str| {
        let img = h.render().expect("render");
        let _ = img.save(format!("{}/{name}.png", env!("CARGO_TARGET_TMPDIR")));
        // The sheet on the middle row: its right edge is the last white
        // pixel, its left edge where the backdrop starts again.
        let y = img.height() / 2;
        let right = (0..img.width())
            .rev()
            .find(|&x| *img.get_pixel(x, y) == white)
            .unwrap();
        let left = (0..right)
            .rev()
            .find(|&x| (x.saturating_sub(4)..=x).all(|x| *img.get_pixel(x, y) == backdrop))
            .unwrap()
            + 1;
        // Its top and bottom, down a column in the blank left strip.
        let x = left + 3;
        let top = (0..y)
            .rev()
            .find(|&y| *img.get_pixel(x, y) != white)
            .unwrap()
            + 1;
        let bottom = (y..img.height())
            .find(|&y| *img.get_pixel(x, y) != white)
            .unwrap();
        (img, left, right + 1, top, bottom)
    };
    let (img, left, right, top, bottom) = measure(&mut h, "app-sheet");
    let (w, hgt) = ((right - left) as f64, (bottom - top) as f64);
    let aspect = w / hgt;
    eprintln!("sheet {w} × {hgt} px at x {left}, y {top}: aspect {aspect:.4}");
    assert!(
        (aspect - 297.0 / 210.0).abs() < 0.02,
        "sheet {w} × {hgt} px: aspect {aspect}"
    );
    let px = |mm: f64| (mm * w / 297.0).round() as u32;
    let mid = (top + bottom) / 2;
    // Outside the sheet: the backdrop; inside, left of the drawing: paper.
    for (x, y) in [(left - 3, mid), (left + px(100.0), top - 3)] {
        assert_eq!(*img.get_pixel(x, y), backdrop, "({x}, {y})");
    }
    for mm in [5.0, 10.0, 20.0, 26.0] {
        for y in [top + px(20.0), mid, bottom - px(20.0)] {
            let x = left + px(mm);
            assert_eq!(*img.get_pixel(x, y), white, "{mm} mm from the left");
        }
    }
    // The margins: a line 15 mm in.
    let line = (left + px(15.0) - 2..=left + px(15.0) + 2)
        .any(|x| img.get_pixel(x, mid).0[2] > img.get_pixel(x, mid).0[0] + 30);
    assert!(line, "no margin line 15 mm in");
    // The drawing from 28.5 mm: its black left edge is full of dots.
    let dark = |x0: u32, x1: u32| {
        (x0..x1)
            .flat_map(|x| (top + px(20.0)..bottom - px(20.0)).map(move |y| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 60)
            .count()
    };
    assert_eq!(
        dark(left + px(1.0), left + px(27.5)),
        0,
        "dots off the drawing"
    );
    assert!(
        dark(left + px(29.0), left + px(40.0)) > 200,
        "no dots at the left"
    );
    // The sheet follows the zoom, as the drawing does.
    h.state_mut().zoom_by(0.8);
    h.run_steps(2);
    let (_, l2, r2, t2, b2) = measure(&mut h, "app-sheet-zoomed");
    let w2 = (r2 - l2) as f64;
    assert!((w2 / w - 0.8).abs() < 0.01, "zoomed sheet {w2} px, was {w}");
    assert!(((b2 - t2) as f64 / (bottom - top) as f64 - 0.8).abs() < 0.01);
}

/// Milliseconds per frame (a UI step and its render) while the view zooms
/// in, pans and zooms out, after a first frame that draws the drawing: the
/// mean, the slowest frame and that first frame.
fn pan_zoom_frames(h: &mut Harness<'_, PixelPieApp>) -> (f64, f64, f64) {
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    h.step();
    h.render().expect("render");
    let first = ms(t);
    let mut times = Vec::new();
    for i in 0..30 {
        match i / 10 {
            0 => h.state_mut().zoom_by(1.08),
            1 => h.state_mut().pan_by(egui::vec2(12.0, -8.0)),
            _ => h.state_mut().zoom_by(1.0 / 1.08),
        }
        let t = Instant::now();
        h.step();
        h.render().expect("render");
        times.push(ms(t));
    }
    let mean = times.iter().sum::<f64>() / times.len() as f64;
    (mean, times.iter().copied().fold(0.0, f64::max), first)
}

#[test]
#[ignore = "a timing harness: cargo test --release --test app_ui -- --ignored --nocapture frame_times"]
fn frame_times_of_pan_and_zoom_at_10k_and_1m_dots() {
    let (_dir, _, mut h) = ready(600, 400);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    for n in [10_000, 1_000_000] {
        h.state_mut().settings.job.points = Some(n as usize);
        h.step();
        let t = Instant::now();
        settle(&mut h);
        let job = t.elapsed().as_secs_f64();
        let drawn = h.state().dots_drawn();
        assert!(
            drawn.abs_diff(n as usize) <= n as usize * 3 / 100,
            "{drawn} dots drawn for {n} asked"
        );
        press(&mut h, egui::Key::F, egui::Modifiers::NONE);
        let (mean, max, first) = pan_zoom_frames(&mut h);
        assert!(
            mean.is_finite() && mean > 0.0 && max >= mean && first > 0.0,
            "frame times {mean} / {max} / {first} ms"
        );
        eprintln!(
            "{} dots (job {job:.1} s): pan and zoom {mean:.1} ms a frame (slowest {max:.1} \
             ms), first frame {first:.1} ms, on {}",
            h.state().dots_drawn(),
            h.state().adapter().unwrap_or("no adapter")
        );
    }
    // The rest of the window alone: the drawing panned out of sight.
    h.state_mut().pan_by(egui::vec2(1e5, 1e5));
    let (mean, max, _) = pan_zoom_frames(&mut h);
    eprintln!(
        "the window without the drawing in sight: {mean:.1} ms a frame (slowest {max:.1} ms)"
    );
}

/// The mean grey (0 black, 1 white) of an image's pixels in `x0..x1`,
/// `y0..y1`, from its red channel.
fn mean_grey(img: &image::RgbaImage, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> f64 {
    let mut sum = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            sum += f64::from(img.get_pixel(x, y).0[0]) / 255.0;
        }
    }
    sum / f64::from((x1 - x0) * (y1 - y0))
}

/// Lets the view rest, so that the dots are drawn anew at its zoom.
fn rest(h: &mut Harness<'_, PixelPieApp>) {
    std::thread::sleep(app::SETTLE + Duration::from_millis(50));
    h.run_steps(2);
}

/// The mean grey of the drawing in the view `view` (the part in sight,
/// less a pixel at each edge) and of the same part of the exported PNG
/// `png`.
fn view_and_png_grey(
    h: &Harness<'_, PixelPieApp>,
    view: &image::RgbaImage,
    png: &image::RgbaImage,
) -> (f64, f64) {
    let ppp = h.ctx.pixels_per_point();
    let r = h.state().drawing_on_screen().unwrap();
    let seen = r.intersect(h.state().canvas_on_screen());
    let (x0, y0) = (
        (seen.min.x * ppp).ceil() + 1.0,
        (seen.min.y * ppp).ceil() + 1.0,
    );
    let (x1, y1) = (
        (seen.max.x * ppp).floor() - 1.0,
        (seen.max.y * ppp).floor() - 1.0,
    );
    let on_screen = mean_grey(view, (x0 as u32, y0 as u32, x1 as u32, y1 as u32));
    // Screen px to PNG px.
    let (sx, sy) = (
        png.width() as f32 / (r.width() * ppp),
        png.height() as f32 / (r.height() * ppp),
    );
    let (ox, oy) = (r.min.x * ppp, r.min.y * ppp);
    let part = (
        ((x0 - ox) * sx).round() as u32,
        ((y0 - oy) * sy).round() as u32,
        ((x1 - ox) * sx).round() as u32,
        ((y1 - oy) * sy).round() as u32,
    );
    (on_screen, mean_grey(png, part))
}

#[test]
fn the_view_has_the_exported_png_s_tones_at_10k_200k_and_1m_dots() {
    // A wide picture keeps the 1M-dot domain small.
    let (dir, _, mut h) = ready(200, 50);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    for n in [10_000, 200_000, 1_000_000] {
        h.state_mut().settings.job.points = Some(n as usize);
        h.step();
        settle(&mut h);
        press(&mut h, egui::Key::F, egui::Modifiers::NONE);
        rest(&mut h);
        let png = dir.path().join(format!("tones-{n}.png"));
        export(&mut h, &png);
        let png = image::open(&png).unwrap().to_rgba8();
        let view = h.render().expect("render");
        let _ = view.save(format!("{}/app-tones-{n}.png", env!("CARGO_TARGET_TMPDIR")));
        let (on_screen, exported) = view_and_png_grey(&h, &view, &png);
        eprintln!(
            "{} dots at fit zoom: view {on_screen:.4}, PNG {exported:.4} ({} × {} px), \
             difference {:+.4}",
            h.state().dots_drawn(),
            png.width(),
            png.height(),
            on_screen - exported
        );
        assert!(
            (on_screen - exported).abs() <= 0.02,
            "{n} dots: the view's mean grey {on_screen:.4}, the PNG's {exported:.4}"
        );
        if n != 200_000 {
            continue;
        }
        // Zoomed in (dots of a pixel or two), once the view rests.
        h.state_mut().zoom_by(4.0);
        h.run_steps(2);
        rest(&mut h);
        let view = h.render().expect("render");
        let _ = view.save(format!(
            "{}/app-tones-zoomed.png",
            env!("CARGO_TARGET_TMPDIR")
        ));
        let (on_screen, exported) = view_and_png_grey(&h, &view, &png);
        eprintln!(
            "{n} dots zoomed 4×: view {on_screen:.4}, PNG {exported:.4}, difference {:+.4}",
            on_screen - exported
        );
        assert!(
            (on_screen - exported).abs() <= 0.03,
            "{n} dots zoomed in: the view's mean grey {on_screen:.4}, the PNG's {exported:.4}"
        );
    }
}

#[test]
fn moving_the_view_draws_the_cached_dots_and_a_resting_view_draws_them_anew() {
    let (_dir, _, mut h) = ready(200, 150);
    rest(&mut h);
    let inked = |img: &image::RgbaImage| {
        img.enumerate_pixels()
            .filter(|(x, _, p)| *x > 320 && p[0] < 60)
            .count()
    };
    let made = h.state().dot_caches_made();
    for i in 0..6 {
        if i < 3 {
            h.state_mut().zoom_by(1.15);
        } else {
            h.state_mut().pan_by(egui::vec2(7.3, -4.1));
        }
        h.step();
        let img = h.render().expect("render");
        assert!(inked(&img) > 200, "no dots while the view moves");
    }
    assert_eq!(
        h.state().dot_caches_made(),
        made,
        "the dots were drawn anew while the view moved"
    );
    rest(&mut h);
    assert_eq!(h.state().dot_caches_made(), made + 1, "none once it rested");
    // A pan by whole pixels within the cache keeps it.
    h.state_mut().pan_by(egui::vec2(5.0, 3.0));
    h.run_steps(2);
    rest(&mut h);
    assert_eq!(h.state().dot_caches_made(), made + 1);
    // A new dot size draws a small drawing anew at once.
    h.state_mut().settings.job.dot_factor = Some(1.3);
    h.step();
    assert_eq!(h.state().dot_caches_made(), made + 2);
    let img = h.render().expect("render");
    let _ = img.save(concat!(env!("CARGO_TARGET_TMPDIR"), "/app-rested.png"));
}

#[test]
fn the_panel_warns_when_the_dots_are_too_small_to_print_or_to_see_in_the_png() {
    let (_dir, _, mut h) = ready(160, 120);
    assert!(!shows(&h, "Dots too small"));
    assert_eq!(h.state().dot_size_warning(), None);
    // A PNG at a tenth of the drawing's size: dots under a pixel.
    h.state_mut().settings.job.scale = 0.1;
    h.run_steps(2);
    assert!(shows(&h, "Dots too small"), "no warning at PNG ×0.1");
    let w = h.state().dot_size_warning().unwrap();
    // The job's own PNG warning, in the app's words.
    assert!(
        w.contains("PNG's dots") && w.contains("PNG ×0.1") && !w.contains("SVG"),
        "{w}"
    );
    assert!(!w.contains("--"), "{w}");
    // 10000 dots on 10 mm: under a tenth of a millimetre.
    h.state_mut().settings.job.scale = 1.0;
    h.state_mut().settings.job.width_mm = Some(10.0);
    h.run_steps(2);
    let w = h.state().dot_size_warning().unwrap();
    assert!(
        w.contains("mm across in the SVG") && !w.contains("PNG"),
        "{w}"
    );
    assert!(shows(&h, "in the SVG"));
    // On 200 mm they print.
    h.state_mut().settings.job.width_mm = Some(200.0);
    h.run_steps(2);
    assert!(!shows(&h, "Dots too small"));
}

/// Waits for the plot estimate and the plotted dots, then lets the view rest.
fn plotted(h: &mut Harness<'_, PixelPieApp>) {
    let start = Instant::now();
    while h.state().plot_pending() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no plot estimate"
        );
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    rest(h);
}

#[test]
fn with_a_pen_the_view_shows_the_plot_and_warns_with_a_one_click_count() {
    let (dir, _, mut h) = ready(300, 200);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    h.state_mut().settings.job.points = Some(30_000);
    h.state_mut().settings.job.width_mm = Some(150.0);
    h.state_mut().settings.job.dot = Some(pixelpie::job::DotMode::Sized);
    h.step();
    settle(&mut h);
    press(&mut h, egui::Key::F, egui::Modifiers::NONE);
    let mut greys = Vec::new();
    for pen in [0.3, 2.0] {
        h.state_mut().settings.job.pen_mm = Some(pen);
        h.step();
        plotted(&mut h);
        let view = h.render().expect("render");
        let _ = view.save(format!("{}/app-pen-{pen}.png", env!("CARGO_TARGET_TMPDIR")));
        // The CLI's --preview of the same drawing.
        let job = h.state().settings.job();
        let path = dir.path().join(format!("preview-{pen}.png"));
        job.write_preview(&h.state().outcome.as_ref().unwrap().drawing, &path)
            .unwrap();
        let preview = image::open(&path).unwrap().to_rgba8();
        let (on_screen, exported) = view_and_png_grey(&h, &view, &preview);
        eprintln!("{pen} mm pen: view {on_screen:.4}, --preview {exported:.4}");
        assert!(
            (on_screen - exported).abs() <= 0.02,
            "{pen} mm: the view's mean grey {on_screen:.4}, the preview's {exported:.4}"
        );
        greys.push(on_screen);
    }
    assert!(
        greys[1] < greys[0] - 0.05,
        "a 2 mm pen is not darker: {greys:?}"
    );
    // The 2 mm pen warns, and its one click asks for the count that draws
    // the tones true: then it no longer warns.
    let count = h.state().pen_warning().expect("a warning").true_count;
    assert!(shows(&h, "Pen too wide"));
    h.get_by_label(&format!("Use {count} dots")).click();
    h.step();
    assert_eq!(h.state().settings.job.points, Some(count));
    settle(&mut h);
    plotted(&mut h);
    assert!(
        h.state().pen_warning().is_none(),
        "{:?}",
        h.state()
            .pen_warning()
            .map(pixelpie::job::PenCheck::message)
    );
    // Without a pen, the view is the drawing as before.
    h.state_mut().settings.job.pen_mm = None;
    h.step();
    assert!(!shows(&h, "Pen too wide"));
}

#[test]
fn counts_out_of_range_are_refused_in_words_and_nothing_fails_silently() {
    let (dir, _, mut h) = ready(200, 150);
    for (n, says) in [(10_000_000, "at most 8000000"), (0, "at least 1 dot")] {
        h.state_mut().settings.job.points = Some(n);
        h.step();
        finish(&mut h);
        let e = h.state().error.clone().expect("a refusal");
        assert!(e.contains(says), "{n}: {e}");
        // Nothing stale is shown or exported.
        assert!(
            h.state().outcome.is_none() && h.state().dots_drawn() == 0,
            "{n}"
        );
        assert_eq!(
            h.state().settings.job.points,
            Some(n),
            "the field keeps what was typed"
        );
    }
    // Too few for the picture: a plain message with the least count.
    h.state_mut().settings.job.points = Some(1);
    h.step();
    finish(&mut h);
    let e = h.state().error.clone().expect("too few");
    assert!(e.contains("too few") && e.contains("at least"), "{e}");
    assert!(!e.contains("radius"), "{e}");
    // Back in range: drawn again, the error gone.
    h.state_mut().settings.job.points = Some(2000);
    h.step();
    settle(&mut h);
    assert!(h.state().error.is_none() && h.state().outcome.is_some());
    // An export while a new drawing is on its way says which it wrote.
    h.state_mut().settings.job.points = Some(3000);
    h.step();
    assert!(h.state().busy());
    h.state_mut().export_path = dir.path().join("mid").display().to_string();
    h.get_by_label("SVG").click();
    h.run_steps(1);
    let note = h.state().exported_note.clone().expect("a note");
    assert!(note.contains("last finished drawing"), "{note}");
    settle(&mut h);
    // A picture cut short shows with a warning.
    let bytes =
        std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/astronaut.jpg")).unwrap();
    let cut = dir.path().join("cut.jpg");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    let ctx = h.ctx.clone();
    h.state_mut().open(&ctx, &cut);
    settle(&mut h);
    let w = h
        .state()
        .source
        .as_ref()
        .unwrap()
        .warning
        .clone()
        .expect("a warning");
    assert!(w.contains("ends early"), "{w}");
    assert!(shows(&h, "ends early"));
}

#[test]
fn presets_crop_and_turn_round_trip_through_job_files() {
    let (dir, png, mut h) = ready(300, 200);
    h.state_mut().settings.job.points = Some(1500);
    h.state_mut().settings.job.relax = Some(1);
    h.step();
    settle(&mut h);
    // Turn a quarter and crop: the drawing takes the framed picture's shape.
    h.get_by_label("Turn 90° (0°)").click();
    h.step();
    assert_eq!(h.state().settings.job.rotate, Some(90));
    h.state_mut().settings.job.crop = Some("0,0,200,100".parse().unwrap());
    h.step();
    settle(&mut h);
    let (w, hh) = h.state().outcome.as_ref().unwrap().drawing.domain;
    // 200×100 turned: 100 wide, 200 high.
    assert!(
        (f64::from(hh) / f64::from(w) - 2.0).abs() < 0.01,
        "{w}x{hh}"
    );
    let view = h.render().expect("render");
    let _ = view.save(format!("{}/app-framed.png", env!("CARGO_TARGET_TMPDIR")));
    // A crop past the picture is refused in words.
    h.state_mut().settings.job.crop = Some("250,0,100,100".parse().unwrap());
    h.step();
    finish(&mut h);
    let e = h.state().error.clone().expect("a refusal");
    assert!(e.contains("reaches past the 300x200 picture"), "{e}");
    h.state_mut().settings.job.crop = Some("0,0,200,100".parse().unwrap());
    h.step();
    settle(&mut h);
    // Saved as a preset, it is the CLI's job file: the same drawing.
    let preset = dir.path().join("preset.toml");
    h.state_mut().preset_path = preset.display().to_string();
    h.get_by_label("Save").click();
    h.step();
    let app_svg = dir.path().join("app.svg");
    export(&mut h, &app_svg);
    let cli_svg = dir.path().join("cli.svg");
    cli(&[
        "stipple",
        png.to_str().unwrap(),
        "--job",
        preset.to_str().unwrap(),
        "-q",
        "-o",
        cli_svg.to_str().unwrap(),
    ]);
    assert_eq!(
        std::fs::read(&app_svg).unwrap(),
        std::fs::read(&cli_svg).unwrap()
    );
    // Loaded back after changes, the settings return.
    h.state_mut().settings.job.points = Some(900);
    h.state_mut().settings.job.rotate = None;
    h.get_by_label("Load").click();
    h.step();
    assert_eq!(h.state().settings.job.points, Some(1500));
    assert_eq!(h.state().settings.job.rotate, Some(90));
    assert_eq!(h.state().settings.job.relax, Some(1));
    // A file that is not a job says so.
    std::fs::write(&preset, "points = 5\n").unwrap();
    h.get_by_label("Load").click();
    h.step();
    let note = h.state().preset_note.clone().unwrap();
    assert!(
        note.starts_with("not loaded") && note.contains("pixelpie"),
        "{note}"
    );
}

#[test]
fn the_pen_travel_overlay_toggles_and_the_sections_fit_a_small_window() {
    let (_dir, _, mut h) = ready(300, 200);
    h.state_mut().settings.job.points = Some(800);
    h.step();
    settle(&mut h);
    let red = |img: &image::RgbaImage| {
        img.enumerate_pixels()
            .filter(|(x, _, p)| *x > 320 && p[0] > 150 && p[1] < 110 && p[2] < 110)
            .count()
    };
    rest(&mut h);
    let off = red(&h.render().expect("render"));
    // (The View section's checkbox, set as its click sets it.)
    h.state_mut().settings.show_travel = true;
    h.run_steps(2);
    let img = h.render().expect("render");
    let _ = img.save(format!("{}/app-travel.png", env!("CARGO_TARGET_TMPDIR")));
    let on = red(&img);
    assert!(off == 0 && on > 500, "red pixels: {off} off, {on} on");
    // At 1024×700 the Pens and Paper sections are in sight, first under
    // the count.
    h.set_size(egui::vec2(1024.0, 700.0));
    h.run_steps(3);
    let img = h.render().expect("render");
    let _ = img.save(format!("{}/app-1024x700.png", env!("CARGO_TARGET_TMPDIR")));
    let ppp = h.ctx.pixels_per_point();
    for name in ["Paper", "Pens", "Margin"] {
        // The first node of the name: the section's header (the margin row
        // is the Paper section's last).
        let r = h.get_all_by_label(name).next().unwrap().rect();
        assert!(r.max.y * ppp < 700.0 - 300.0, "{name} at {r:?}");
    }
}

#[test]
fn dots_sized_in_mm_and_warnings_that_name_a_count() {
    let (_dir, _, mut h) = ready(300, 200);
    // No size in mm: the dots' size in mm gives way to the count.
    h.state_mut().settings.job.dot_mm = Some(1.0);
    h.state_mut().settings.job.points = None;
    h.step();
    settle(&mut h);
    assert_eq!(h.state().settings.job().dot_mm, None);
    h.state_mut().settings.job.width_mm = Some(150.0);
    h.state_mut().settings.job.dot_mm = Some(1.0);
    h.state_mut().settings.job.points = None;
    h.step();
    settle(&mut h);
    let job = h.state().settings.job();
    assert_eq!((job.dot_mm, job.points), (Some(1.0), None));
    let drawing = &h.state().outcome.as_ref().unwrap().drawing;
    let mm = job.mm_per_px(drawing.domain).unwrap().unwrap();
    let largest = job
        .dots(drawing)
        .iter()
        .map(|d| d.radius)
        .fold(0.0, f32::max);
    assert!(
        (2.0 * f64::from(largest) * mm - 1.0).abs() < 0.01,
        "{largest} px"
    );
    // A PNG at a tenth of the size: the warning says which count reaches a pixel.
    h.state_mut().settings.job.width_mm = None;
    h.state_mut().settings.job.scale = 0.1;
    h.step();
    settle(&mut h);
    let w = h.state().dot_size_warning().expect("a warning");
    // (The job's own PNG warning, as the CLI prints it: "about N dots …".)
    let count = w
        .split("about ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse::<usize>().ok());
    assert!(count.is_some_and(|n| n > 0), "{w}");
}

/// `after` has `before`'s points with other dot sizes.
fn same_points_other_sizes(before: &pixelpie::job::Stipple, after: &pixelpie::job::Stipple) {
    assert_eq!(before.points.len(), after.points.len());
    assert!(
        before
            .points
            .iter()
            .zip(&after.points)
            .all(|(a, b)| (a.x, a.y) == (b.x, b.y)),
        "the same points"
    );
    assert_ne!(before.calibrated, after.calibrated, "other sizes");
}

/// The Dot size section's "Size for local spacing" box is the CLI's
/// `--spacing`: on by default; unticked, the dots are sized for their
/// sample radius alone (the same points, other sizes), and the job says so.
#[test]
fn the_local_spacing_box_switches_the_dot_sizing() {
    let (_dir, _png, mut h) = ready(240, 160);
    assert_eq!(
        h.state().settings.job.spacing,
        pixelpie::job::Spacing::Local
    );
    let before = h.state().outcome.as_ref().unwrap().drawing.clone();
    h.get_by_label("Size for local spacing").click();
    h.run_steps(2);
    settle(&mut h);
    let job = h.state().settings.job();
    assert_eq!(job.spacing, pixelpie::job::Spacing::Radius);
    same_points_other_sizes(&before, &h.state().outcome.as_ref().unwrap().drawing);
}

/// The Dot size section's "Correct tones by rendering" box is the CLI's
/// `--correction`: on by default; unticked, the same points (relaxed as
/// asked) with the calibration's sizes alone.
#[test]
fn the_correction_box_switches_the_correction() {
    let (_dir, _png, mut h) = ready(240, 160);
    assert_eq!(
        h.state().settings.job.correction,
        pixelpie::job::Correction::On
    );
    // Relaxed by choice, not by default (which needs the correction).
    h.state_mut().settings.job.relax = Some(3);
    h.step();
    settle(&mut h);
    let before = h.state().outcome.as_ref().unwrap().drawing.clone();
    h.get_by_label("Correct tones by rendering").click();
    h.run_steps(2);
    settle(&mut h);
    assert_eq!(
        h.state().settings.job().correction,
        pixelpie::job::Correction::Off
    );
    same_points_other_sizes(&before, &h.state().outcome.as_ref().unwrap().drawing);
}

/// "Auto relax" is the default (two Lloyd steps at the app's counts);
/// unticked, the slider sets the steps, and none gives the sampler's set.
#[test]
fn auto_relax_relaxes_and_the_slider_takes_over_when_unticked() {
    let (_dir, _png, mut h) = ready(240, 160);
    assert_eq!(h.state().settings.job.relax, None);
    let relaxed = h.state().outcome.as_ref().unwrap().drawing.clone();
    h.get_by_label("Auto relax").click();
    h.run_steps(2);
    assert_eq!(
        h.state().settings.job.relax,
        Some(pixelpie::job::AUTO_RELAX_STEPS),
        "unticked, the slider starts at the steps auto took"
    );
    h.state_mut().settings.job.relax = Some(0);
    h.step();
    settle(&mut h);
    let plain = &h.state().outcome.as_ref().unwrap().drawing;
    assert!(
        plain.set.maximal(),
        "not relaxed: the sampler's maximal set"
    );
    // The same sample, moved by the relaxation.
    assert_eq!(plain.set.points.len(), relaxed.set.points.len());
    let moved = plain
        .set
        .points
        .iter()
        .zip(&relaxed.set.points)
        .filter(|(a, b)| (a.x, a.y) != (b.x, b.y))
        .count();
    assert!(
        moved > plain.set.points.len() / 2,
        "relaxed: only {moved} points moved"
    );
}

/// One plan, every front end: the app's plan line is the line of `pixelpie
/// stipple --plan` for the same job and picture, and the drawing's whole
/// plan is the CLI's (the Python package's `plan()` is held to the CLI's in
/// python/tests).
#[test]
fn the_app_shows_the_plan_the_cli_prints() {
    let (dir, png, mut h) = ready(600, 400);
    for points in [10_000u32, 250_000] {
        h.state_mut().settings.job.points = Some(points as usize);
        h.step();
        settle(&mut h);
        let line = h.state().plan_line().expect("a plan line");
        let out = dir.path().join("x.svg");
        let json = cli_stdout(&[
            "stipple",
            &png.display().to_string(),
            "-o",
            &out.display().to_string(),
            "--points",
            &points.to_string(),
            "--plan",
        ]);
        let cli: serde_json::Value = serde_json::from_str(&json).expect("the plan is JSON");
        assert_eq!(cli["line"].as_str(), Some(line.as_str()), "{json}");
        let app = h
            .state()
            .outcome
            .as_ref()
            .unwrap()
            .drawing
            .plan
            .to_json()
            .unwrap();
        assert_eq!(app, json.trim_end(), "the whole plan");
        assert!(!out.exists(), "--plan draws nothing");
        assert!(shows(&h, &line), "the status shows the plan line");
    }
}

#[test]
fn a_picture_over_the_memory_budget_is_refused_in_the_panel() {
    use std::io::Write;
    let (dir, _, mut h) = ready(160, 120);
    // 20000² grey in a PNG of a few MB: about 7.5 GB to draw.
    let bomb = dir.path().join("bomb.png");
    let file = std::io::BufWriter::new(std::fs::File::create(&bomb).unwrap());
    let mut encoder = png::Encoder::new(file, 20_000, 20_000);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row = vec![0x80u8; 20_000];
    for _ in 0..20_000 {
        stream.write_all(&row).unwrap();
    }
    stream.finish().unwrap();
    h.state_mut().open_path = bomb.display().to_string();
    h.get_by_label("Open").click();
    let start = Instant::now();
    while h.state().open_error.is_none() && start.elapsed() < Duration::from_secs(10) {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    let e = h.state().open_error.clone().expect("the refusal");
    assert!(e.contains("20000×20000") && e.contains("allowed"), "{e}");
    assert!(start.elapsed() < Duration::from_secs(3));
    // The picture before it stays.
    assert!(h.state().error.is_none());
}

/// File dialogs whose pen-file dialog answers with a set path.
struct PenBoxDialog(PathBuf);

impl app::dialogs::FileDialogs for PenBoxDialog {
    fn pick_image(&mut self, _: Option<&Path>) -> app::dialogs::Answer {
        Ok(None)
    }
    fn save_drawing(&mut self, _: Option<&Path>, _: &str) -> app::dialogs::Answer {
        Ok(None)
    }
    fn pick_pens(&mut self, _: Option<&Path>) -> app::dialogs::Answer {
        Ok(Some(self.0.clone()))
    }
}

#[test]
fn a_pen_box_lists_its_pens_and_chooses_the_clis_for_the_photo() {
    let (_dir, png, mut h) = ready(200, 150);
    let pen_box = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/pens-24.toml");
    h.state_mut().dialogs = Box::new(PenBoxDialog(pen_box.clone()));
    h.get_by_label("Pen box…").click();
    h.run_steps(2);
    let listed = h.state().pen_box.clone().expect("a pen box").1;
    assert_eq!(listed.len(), 24);
    // The box's pens, listed under its header.
    h.get_by_label("Pen box: 24 pens (pens-24.toml)").click();
    h.run_steps(2);
    for p in listed.pens() {
        assert!(h.query_by_label(&p.name).is_some(), "{} not listed", p.name);
    }
    h.state_mut().choose_count = 3;
    h.run_steps(1);
    h.get_by_label("Choose 3 for this photo").click();
    h.run_steps(2);
    settle(&mut h);
    let note = match &h.state().choice_note {
        Some(Ok(note)) => note.clone(),
        other => panic!("{other:?}"),
    };
    assert!(note.contains("predicted ΔE00"), "{note}");
    let chosen = h.state().settings.job.pens.clone().expect("pens chosen");
    assert_eq!(chosen.len(), 3);
    // The CLI chooses the same pens for the same picture.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(["stipple", &png.display().to_string(), "-o"])
        .arg(png.with_extension("svg"))
        .args(["--points", "500", "--pens"])
        .arg(&pen_box)
        .args(["--choose", "3"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    let said = err.lines().find(|l| l.starts_with("chose 3")).expect(&err);
    for p in chosen.pens() {
        assert!(
            listed.pens().contains(p) && said.contains(&p.name),
            "{}: {said}",
            p.name
        );
        assert!(note.contains(&p.name), "{}: {note}", p.name);
    }
}

#[test]
fn the_paper_colour_reaches_the_clis_file() {
    let (dir, png, mut h) = ready(200, 150);
    h.get_by_label("Points").set_value_accesskit(3000.0);
    settle(&mut h);
    h.state_mut().settings.job.ink = pixelpie::job::Ink([255, 255, 255]);
    h.run_steps(2);
    h.get_by_label("Paper colour").click();
    h.run_steps(2);
    h.get_by_label("black").click();
    h.run_steps(2);
    settle(&mut h);
    assert_eq!(
        h.state().settings.job.paper_colour.map(|c| c.0),
        Some([0, 0, 0])
    );
    let (app_svg, cli_svg) = (dir.path().join("app.svg"), dir.path().join("cli.svg"));
    export(&mut h, &app_svg);
    let (png, cli_path) = (png.display().to_string(), cli_svg.display().to_string());
    cli(&[
        "stipple",
        &png,
        "-o",
        &cli_path,
        "--quiet",
        "--points",
        "3000",
        "--ink",
        "#ffffff",
        "--paper-colour",
        "black",
    ]);
    let svg = std::fs::read_to_string(&app_svg).unwrap();
    assert!(
        svg.contains(r#"inkscape:label="% paper (not plotted)""#),
        "{}",
        &svg[..400]
    );
    assert!(svg.contains(r##"fill="#ffffff""##), "{}", &svg[..600]);
    assert_eq!(svg, std::fs::read_to_string(&cli_svg).unwrap());
}

/// Whether the pointer over `node`'s centre hovers that very widget (not
/// one drawn over it, not a panel beside it).
fn hovers_itself(h: &mut Harness<'_, PixelPieApp>, name: &str) -> bool {
    let target = h.get_all_by_label(name).next().unwrap();
    let id = target.accesskit_node().locate().0;
    target.hover();
    h.run_steps(2);
    // (A disabled control contains the pointer without being hovered.)
    h.ctx.interaction_snapshot(|i| {
        i.hovered
            .iter()
            .chain(i.contains_pointer.iter())
            .any(|w| w.accesskit_id() == id)
    })
}

#[test]
fn cancel_restores_every_setting_of_the_last_drawing_the_turn_included() {
    let (_dir, _, mut h) = ready(200, 150);
    h.get_by_label_contains("Turn 90°").click();
    h.step();
    settle(&mut h);
    assert_eq!(h.state().settings.job.rotate, Some(90));
    let drawn = h
        .state()
        .outcome
        .as_ref()
        .unwrap()
        .drawing
        .set
        .points
        .clone();
    let domain = h.state().outcome.as_ref().unwrap().drawing.domain;
    assert!(domain.1 > domain.0, "turned: {domain:?}");
    // A 2M drawing, cancelled while it samples.
    h.state_mut().settings.job.points = Some(2_000_000);
    let start = Instant::now();
    while h
        .state()
        .progress_shown()
        .is_none_or(|p| p.starts_with("waiting"))
    {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(10), "no job started");
    }
    h.get_by_label("Cancel").click();
    h.run_steps(3);
    let s = h.state();
    assert!(
        !s.busy() && s.status.starts_with("cancelled"),
        "busy {}, status {:?}, error {:?}",
        s.busy(),
        s.status,
        s.error
    );
    assert_eq!(s.settings.job.rotate, Some(90), "the turn came back");
    assert_eq!(s.settings.job.points, Some(10_000));
    assert_eq!(s.outcome.as_ref().unwrap().drawing.set.points, drawn);
    assert_eq!(
        s.source.as_ref().unwrap().map.width(),
        150,
        "the photo stays turned"
    );
    // Nothing new starts: the controls are the drawing's.
    std::thread::sleep(Duration::from_millis(300));
    h.run_steps(3);
    assert!(!h.state().busy(), "a new drawing started after Cancel");
    assert_eq!(
        label(&h.get_by_label_contains("Turn 90°")).unwrap(),
        "Turn 90° (90°)"
    );
}

#[test]
fn every_control_is_in_reach_in_an_800_by_500_window() {
    let (_dir, _, mut h) = ready(200, 150);
    for (w, ht) in [(800.0, 500.0), (1024.0, 700.0)] {
        h.set_size(egui::vec2(w, ht));
        h.run_steps(3);
        let img = h.render().expect("render");
        let _ = img.save(format!("{}/app-{w}x{ht}.png", env!("CARGO_TARGET_TMPDIR")));
        let mut out_of_reach = Vec::new();
        for name in [
            "Undo",
            "Redo",
            "Reset",
            "?",
            "Open",
            "Crop",
            "Save",
            "Load",
            "Point count",
            "Radius range",
            "Points",
            "One ink",
            "CMYK",
            "Pen file",
            "Load pens",
            "Pen box…",
            "Landscape",
            "Margin",
            "Paper colour",
            "Style",
            "Line",
            "Smooth line",
            "Dots",
            "Dot mm",
            "Lightest / darkest dot",
            "Size for local spacing",
            "Correct tones by rendering",
            "Auto relax",
            "Relax (Lloyd steps)",
            "Black",
            "Red",
            "Radius",
            "Mapping",
            "Tones",
            "Policy",
            "Exact spacing",
            "Gamma",
            "Black level",
            "White level",
            "Invert",
            "White cutoff",
            "Sub-pixel bits",
            "Re-roll",
            "Seed",
            "Periodic (tileable)",
            "Show 2×2 tiles",
            "Backend",
            "Behind",
            "Coverage disks (Figure 4)",
            "Pen travel",
            "Fit view",
            "Along a curve",
            "Plotter (TSP)",
            "Width mm",
            "Pen mm",
            "Spiral",
            "Touch",
            "Export to",
            "SVG",
            "PNG",
            "CSV",
            "JSON",
        ] {
            let Some(node) = h.get_all_by_label(name).next() else {
                out_of_reach.push(format!("{name}: not found"));
                continue;
            };
            node.scroll_to_me();
            h.run_steps(3);
            let r = h.get_all_by_label(name).next().unwrap().rect();
            let inside =
                r.min.x >= 0.0 && r.max.x <= app::PANEL_WIDTH && r.min.y >= 0.0 && r.max.y <= ht;
            if !inside || !hovers_itself(&mut h, name) {
                out_of_reach.push(format!("{name} at {r:?}"));
            }
        }
        assert!(out_of_reach.is_empty(), "at {w}×{ht}: {out_of_reach:?}");
    }
    // Smaller still, the panel's parts do not overlap: the fixed bottom
    // (progress and statistics) lies below the scrolling controls.
    h.set_size(egui::vec2(400.0, 300.0));
    h.run_steps(3);
    let points = h.get_by_label("Points");
    points.scroll_to_me();
    h.run_steps(3);
    let p = h.get_by_label("Points").rect();
    let ready = h.get_by_label("ready").rect();
    assert!(
        p.max.y <= ready.min.y,
        "Points {p:?} over the status {ready:?}"
    );
}

/// Settings storage in memory, for the autosave.
#[derive(Default)]
struct Store(std::collections::HashMap<String, String>);

impl eframe::Storage for Store {
    fn get_string(&self, key: &str) -> Option<String> {
        self.0.get(key).cloned()
    }
    fn set_string(&mut self, key: &str, value: String) {
        self.0.insert(key.to_owned(), value);
    }
    fn remove_string(&mut self, key: &str) {
        self.0.remove(key);
    }
    fn flush(&mut self) {}
}

/// The settings the app saves now.
fn saved(h: &mut Harness<'_, PixelPieApp>) -> app::Settings {
    let mut store = Store::default();
    eframe::App::save(h.state_mut(), &mut store);
    eframe::get_value(&store, "pixelpie-settings").expect("saved settings")
}

#[test]
fn a_half_typed_count_is_never_drawn_or_saved() {
    let (_dir, _, mut h) = ready(200, 150);
    let drawn = h.state().dots_drawn();
    // Click the field (no drag): its text is edited, the old count selected.
    h.get_by_label("Points").click();
    h.run_steps(2);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.get_by_label("Points").type_text("20");
    h.run_steps(2);
    std::thread::sleep(app::DEBOUNCE * 2);
    h.run_steps(3);
    assert!(!h.state().busy(), "a half-typed count started a drawing");
    assert_eq!(h.state().settings.job.points, Some(10_000));
    assert_eq!(h.state().dots_drawn(), drawn);
    assert_eq!(
        saved(&mut h).job.points,
        Some(10_000),
        "the autosave kept 20"
    );
    h.get_by_label("Points").type_text("00");
    h.run_steps(2);
    assert_eq!(
        saved(&mut h).job.points,
        Some(10_000),
        "the autosave kept 2000"
    );
    // Enter takes it: drawn and saved.
    h.key_press(egui::Key::Enter);
    h.run_steps(2);
    assert_eq!(h.state().settings.job.points, Some(2000));
    settle(&mut h);
    let n = h.state().dots_drawn();
    assert!((1900..=2100).contains(&n), "{n}");
    assert_eq!(saved(&mut h).job.points, Some(2000));
}

/// The Export section's Pen mm width field: the number field right of the
/// Pen mm box.
fn pen_mm_field<'a>(h: &'a Harness<'_, PixelPieApp>) -> egui_kittest::Node<'a> {
    let pen = h.get_by_label("Pen mm").rect();
    h.query_all_by(|n| n.role() == egui::Role::SpinButton)
        .find(|n| {
            let r = n.rect();
            r.min.x >= pen.max.x && (r.center().y - pen.center().y).abs() < 4.0
        })
        .expect("the pen width field")
}

#[test]
fn a_typed_pen_box_and_pen_mm_say_what_they_do() {
    let (_dir, _, mut h) = ready(200, 150);
    fold(&mut h, &["Dot size", "Sampling", "View"]);
    let pen_box = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/pens-24.toml");
    // A pen box by its typed path (no file dialog needed).
    h.get_by_label("Pen file").focus();
    h.run_steps(1);
    h.get_by_label("Pen file")
        .type_text(&pen_box.display().to_string());
    h.run_steps(1);
    h.get_by_label("Load pens").click();
    h.run_steps(2);
    assert_eq!(h.state().pen_box.as_ref().map(|b| b.1.len()), Some(24));
    // Ticking Pen mm says that it makes the default Sized dots Fixed.
    h.get_by_label("Width mm").click();
    h.run_steps(2);
    assert_eq!(
        h.state().settings.job.dot_mode(),
        pixelpie::job::DotMode::Sized
    );
    h.get_by_label("Pen mm").click();
    h.run_steps(2);
    assert_eq!(
        h.state().settings.job.dot_mode(),
        pixelpie::job::DotMode::Fixed
    );
    assert!(
        shows(&h, "the dots are Fixed now"),
        "{:?}",
        h.state().pen_note
    );
    assert!(!pen_mm_field(&h).accesskit_node().is_disabled());
    // Pens chosen from the box carry their own widths: Pen mm's width is
    // not used, and greyed out with the reason.
    h.state_mut().choose_count = 2;
    h.run_steps(1);
    h.get_by_label("Choose 2 for this photo").click();
    h.run_steps(2);
    let pens = h.state().settings.job.pens.clone().expect("pens");
    assert!(pens.pens().iter().all(|p| p.width_mm.is_some()));
    h.ctx.all_styles_mut(|s| s.interaction.tooltip_delay = 0.0);
    let field = pen_mm_field(&h);
    assert!(field.accesskit_node().is_disabled());
    field.hover();
    h.run_steps(2);
    assert!(shows(&h, "every pen carries its own width"));
    settle(&mut h);
}

#[test]
fn messages_belong_to_the_drawing_and_undo_redo_and_say_when_cleared() {
    let (dir, png, mut h) = ready(200, 150);
    // A job file of the present settings, to load back later.
    let preset = dir.path().join("job.toml");
    h.state_mut().preset_path = preset.display().to_string();
    h.get_by_label("Save").click();
    h.run_steps(2);
    // A choice's note goes when another job is loaded.
    let pen_box = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/pens-24.toml");
    h.state_mut().load_pen_box(&pen_box);
    h.state_mut().choose_count = 2;
    h.run_steps(1);
    h.get_by_label("Choose 2 for this photo").click();
    h.run_steps(2);
    assert!(shows(&h, "predicted ΔE00"));
    h.get_by_label("Load").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.pens, None);
    assert!(!shows(&h, "predicted ΔE00"), "the old job's choice stayed");
    settle(&mut h);
    // A file that fails to open: the error names it, the path field names
    // the picture still shown.
    let bad = dir.path().join("bad.png");
    std::fs::write(&bad, b"not a picture").unwrap();
    h.state_mut().open_path = bad.display().to_string();
    h.get_by_label("Open").click();
    h.step();
    finish(&mut h);
    let e = h.state().open_error.clone().expect("an open error");
    assert!(e.contains("bad.png"), "{e}");
    assert_eq!(h.state().open_path, png.display().to_string());
    // Hover texts show once: a long message cut at the panel's edge.
    h.ctx.all_styles_mut(|s| s.interaction.tooltip_delay = 0.0);
    h.get_by_label_contains("bad.png").hover();
    h.run_steps(2);
    let copies = h
        .query_all_by(|n| n.value().is_some_and(|v| v == e) || n.label().is_some_and(|l| l == e))
        .count();
    assert_eq!(copies, 2, "the message and one tooltip");
    // Undo and Redo.
    h.get_by_label("Points").set_value_accesskit(3000.0);
    h.run_steps(2);
    h.get_by_label("Undo").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.points, Some(10_000));
    h.get_by_label("Redo").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.points, Some(3000));
    settle(&mut h);
    // A new photo starts a new history, and Undo says when.
    let other = dir.path().join("other.png");
    gradient_png(&other, 120, 90);
    let ctx = h.ctx.clone();
    h.state_mut().open(&ctx, &other);
    settle(&mut h);
    assert!(h.get_by_label("Undo").accesskit_node().is_disabled());
    h.get_by_label("Undo").hover();
    h.run_steps(2);
    assert!(shows(&h, "cleared when other.png opened"));
}

#[test]
fn local_spacing_serves_one_pen_and_errors_name_the_controls() {
    let (_dir, _, mut h) = ready(200, 150);
    fold(&mut h, &["Pens", "Paper"]);
    let one = pixelpie::colour::PenSet::new(vec![pixelpie::colour::Pen {
        name: "sepia".into(),
        colour: [112, 66, 20],
        width_mm: None,
        dot_gain: None,
        opacity: None,
    }])
    .unwrap();
    h.state_mut().settings.job.pens = Some(one);
    h.run_steps(2);
    let local = h.get_by_label("Size for local spacing");
    assert!(
        !local.accesskit_node().is_disabled(),
        "a one-pen set draws in grey"
    );
    local.click();
    h.run_steps(2);
    assert_eq!(
        h.state().settings.job.spacing,
        pixelpie::job::Spacing::Radius
    );
    settle(&mut h);
    // The library's refusal, in the app's words: the control's label.
    h.state_mut().settings.job.width = Some(0);
    h.step();
    finish(&mut h);
    let e = h.state().error.clone().expect("a refusal");
    assert!(e.contains("Domain width 0") && !e.contains("--"), "{e}");
}

/// Whether the control first named `name` is greyed out.
fn greyed(h: &Harness<'_, PixelPieApp>, name: &str) -> bool {
    h.get_all_by_label(name)
        .next()
        .unwrap_or_else(|| panic!("no {name}"))
        .accesskit_node()
        .is_disabled()
}

#[test]
fn choosing_line_sets_the_style_and_greys_out_what_only_dots_have() {
    let (_dir, _, mut h) = ready(300, 200);
    h.state_mut().settings.job.points = Some(1500);
    h.step();
    settle(&mut h);
    fold(&mut h, &["Pens", "Paper"]);
    let dot_only = [
        "Dot size (× calibrated)",
        "Lightest / darkest dot",
        "Dot mm",
        "Point count",
        "Radius range",
        "Size for local spacing",
        "Along a curve",
        "Plotter (TSP)",
        "Pen travel",
    ];
    assert!(greyed(&h, "Smooth line"), "a smooth line with dots");
    assert!(!greyed(&h, "Lightest / darkest dot"));
    h.get_by_label("Line").click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.style, pixelpie::job::Style::Line);
    let lit: Vec<&str> = dot_only
        .into_iter()
        .filter(|name| !greyed(&h, name))
        .collect();
    assert!(lit.is_empty(), "not greyed out for a line: {lit:?}");
    // The dots' mode: the combo box labelled Dots (the style's Dots button
    // comes first).
    let combo = h
        .get_all_by_label("Dots")
        .find(|n| n.accesskit_node().role() == egui::accesskit::Role::ComboBox)
        .expect("the Dots combo box");
    assert!(combo.accesskit_node().is_disabled());
    for name in [
        "Smooth line",
        "Points",
        "Correct tones by rendering",
        "Seed",
    ] {
        assert!(!greyed(&h, name), "{name} greyed out for a line");
    }
    // A line re-samples: its points lie on one stroke, no dot is drawn.
    settle(&mut h);
    let o = h.state().outcome.as_ref().expect("a drawing");
    assert_eq!(o.drawing.strokes.len(), 1);
    assert_eq!(o.drawing.strokes[0].points.len(), o.drawing.points.len());
    assert!(
        (o.drawing.points.len() as f64 - 1500.0).abs() <= 45.0,
        "{} points",
        o.drawing.points.len()
    );
    assert!(h.state().is_line() && h.state().dots_drawn() == 0);
    assert!(
        h.state().plan_line().unwrap().contains("one line through"),
        "{:?}",
        h.state().plan_line()
    );
    // Dots again: the dot controls come back.
    h.get_all_by_label("Dots").next().unwrap().click();
    h.run_steps(2);
    assert_eq!(h.state().settings.job.style, pixelpie::job::Style::Dots);
    assert!(!greyed(&h, "Lightest / darkest dot") && greyed(&h, "Smooth line"));
}

#[test]
fn a_line_shows_in_the_view_with_the_png_s_tones_and_smooths_without_sampling() {
    let (dir, _, mut h) = ready(300, 200);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    let job = &mut h.state_mut().settings.job;
    job.style = pixelpie::job::Style::Line;
    job.points = Some(3000);
    h.step();
    settle(&mut h);
    press(&mut h, egui::Key::F, egui::Modifiers::NONE);
    rest(&mut h);
    let view = h.render().expect("render");
    let _ = view.save(format!("{}/app-line.png", env!("CARGO_TARGET_TMPDIR")));
    // The stroke was painted, every vertex of it in sight.
    let points = h.state().outcome.as_ref().unwrap().drawing.points.len();
    let painted = h.state().line_vertices_painted();
    assert!(
        painted > points / 2 && painted <= points,
        "{painted} vertices painted of {points}"
    );
    // The view's grey is the exported PNG's (the line at its width).
    let png = dir.path().join("line.png");
    export(&mut h, &png);
    let png = image::open(&png).unwrap().to_rgba8();
    let (on_screen, exported) = view_and_png_grey(&h, &view, &png);
    eprintln!("a line of {points} points: view {on_screen:.4}, PNG {exported:.4}");
    assert!(
        (on_screen - exported).abs() <= 0.04,
        "the view's mean grey {on_screen:.4}, the PNG's {exported:.4}"
    );
    // The SVG: one stroked path, no dots.
    let svg = dir.path().join("line.svg");
    export(&mut h, &svg);
    let straight = std::fs::read_to_string(&svg).unwrap();
    assert!(
        straight.contains("<path") && !straight.contains("<circle"),
        "{}",
        &straight[..straight.len().min(600)]
    );
    // Smoothing the line draws the same points anew: no sampling; the view
    // and the SVG show curves.
    let before = h.state().outcome.as_ref().unwrap().drawing.points.clone();
    h.get_by_label("Smooth line").click();
    h.run_steps(2);
    assert!(h.state().settings.job.line_smooth);
    assert!(!h.state().busy(), "smoothing the line sampled anew");
    let o = h.state().outcome.as_ref().unwrap();
    assert!(o.drawing.strokes.iter().all(|s| s.smooth));
    assert_eq!(o.drawing.points, before);
    let smooth_view = h.render().expect("render");
    assert_ne!(
        smooth_view.as_raw(),
        view.as_raw(),
        "the view did not change"
    );
    export(&mut h, &svg);
    let smooth = std::fs::read_to_string(&svg).unwrap();
    assert_ne!(smooth, straight);
    assert!(smooth.contains('c'), "no curves in the smooth SVG");
}

#[test]
fn a_line_with_a_pen_is_the_pen_s_width_and_several_pens_draw_a_line_each() {
    let (_dir, _, mut h) = ready(300, 200);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    h.get_by_label("Line").click();
    h.run_steps(2);
    // A pen on a page: the pen's line sets the count, and its width is the
    // pen's.
    let job = &mut h.state_mut().settings.job;
    job.width_mm = Some(50.0);
    job.pen_mm = Some(0.5);
    h.run_steps(2);
    assert_eq!(h.state().settings.job.points, None);
    assert!(greyed(&h, "Points"));
    settle(&mut h);
    let plan = h.state().outcome.as_ref().unwrap().drawing.plan.clone();
    let line = plan.line.expect("a line's plan");
    assert!(
        (line.width_mm.unwrap() - 0.5).abs() < 1e-6,
        "{:?}",
        line.width_mm
    );
    assert!(
        (plan.dots as f64 - line.needed as f64).abs() <= 0.05 * line.needed as f64,
        "{} points for {} needed",
        plan.dots,
        line.needed
    );
    // No pen: the Points field's count again.
    let typed = h.state().typed_points;
    h.state_mut().settings.job.pen_mm = None;
    h.run_steps(2);
    assert_eq!(h.state().settings.job.points, Some(typed));
    h.state_mut().settings.job.points = Some(3000);
    // Several pens: a line for each, in its pen's colour.
    h.get_by_label("CMYK").scroll_to_me();
    h.run_steps(3);
    h.get_by_label("CMYK").click();
    h.run_steps(2);
    settle(&mut h);
    let d = h.state().outcome.as_ref().unwrap().drawing.clone();
    assert_eq!(d.pens.as_ref().map(|p| p.len()), Some(4));
    assert!(!d.strokes.is_empty() && d.strokes.len() <= 4);
    press(&mut h, egui::Key::F, egui::Modifiers::NONE);
    let all = h.state().line_vertices_painted();
    let img = h.render().expect("render");
    let _ = img.save(format!("{}/app-line-cmyk.png", env!("CARGO_TARGET_TMPDIR")));
    assert!(
        all > 0 && all <= d.points.len(),
        "{all} of {}",
        d.points.len()
    );
    // Hidden pens' lines are not painted.
    h.state_mut().settings.hidden_pens = vec![true; 4];
    h.run_steps(2);
    assert_eq!(h.state().line_vertices_painted(), 0);
    h.state_mut().settings.hidden_pens = vec![false; 4];
    h.run_steps(2);
    assert_eq!(h.state().line_vertices_painted(), all);
    // Dots draw the four pens again.
    h.get_all_by_label("Dots").next().unwrap().click();
    h.run_steps(2);
    settle(&mut h);
    let o = h.state().outcome.as_ref().unwrap();
    assert!(o.drawing.pens.is_some() && o.drawing.strokes.is_empty());
    assert!(h.state().dots_drawn() > 0 && h.state().line_vertices_painted() == 0);
}

/// Steps the UI until the view has made `n` rasters of its line.
fn rasters(h: &mut Harness<'_, PixelPieApp>, n: u64) {
    let start = Instant::now();
    while h.state().line_rasters_made() < n {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no raster of the line"
        );
        std::thread::sleep(Duration::from_millis(20));
        h.step();
    }
    h.run_steps(2);
}

#[test]
fn a_long_line_is_drawn_from_a_raster_made_when_the_view_rests() {
    let (dir, _, mut h) = ready(300, 200);
    let live = h.state().line_live_vertices();
    if live > 100_000 {
        eprintln!("a GPU draws {live} vertices as they are: no raster to test");
        return;
    }
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    let job = &mut h.state_mut().settings.job;
    job.style = pixelpie::job::Style::Line;
    job.points = Some(live + 5000);
    h.step();
    settle(&mut h);
    press(&mut h, egui::Key::F, egui::Modifiers::NONE);
    rest(&mut h);
    rasters(&mut h, 1);
    assert_eq!(h.state().line_vertices_painted(), 0, "drawn as paths");
    let view = h.render().expect("render");
    let _ = view.save(format!(
        "{}/app-line-raster.png",
        env!("CARGO_TARGET_TMPDIR")
    ));
    let png = dir.path().join("line.png");
    export(&mut h, &png);
    let png = image::open(&png).unwrap().to_rgba8();
    let (on_screen, exported) = view_and_png_grey(&h, &view, &png);
    eprintln!("a line from its raster: view {on_screen:.4}, PNG {exported:.4}");
    assert!(
        (on_screen - exported).abs() <= 0.03,
        "the view's mean grey {on_screen:.4}, the PNG's {exported:.4}"
    );
    // Zoomed out, the raster moves with the view (none made while it
    // moves), and a new one comes once the view rests.
    let made = h.state().line_rasters_made();
    h.state_mut().zoom_by(0.8);
    h.step();
    assert_eq!(h.state().line_rasters_made(), made);
    let moved = h.render().expect("render");
    assert_ne!(moved.as_raw(), view.as_raw(), "the view did not move");
    rest(&mut h);
    rasters(&mut h, made + 1);
}

#[test]
#[ignore = "a timing harness: cargo test --release --test app_ui -- --ignored --nocapture frame_times_of_a_line"]
fn frame_times_of_a_line_at_100k_points() {
    let (_dir, _, mut h) = ready(600, 400);
    h.state_mut().settings.backend = pixelpie::backend::BackendChoice::Cpu;
    h.state_mut().settings.job.style = pixelpie::job::Style::Line;
    for smooth in [false, true] {
        h.state_mut().settings.job.points = Some(100_000);
        h.state_mut().settings.job.line_smooth = smooth;
        h.step();
        let t = Instant::now();
        settle(&mut h);
        let job = t.elapsed().as_secs_f64();
        press(&mut h, egui::Key::F, egui::Modifiers::NONE);
        let (mean, max, first) = pan_zoom_frames(&mut h);
        // A raster of the view at rest: from the rest to its arrival.
        let made = h.state().line_rasters_made();
        // (Another scale than any raster held.)
        h.state_mut().zoom_by(if smooth { 1.03 } else { 1.01 });
        h.step();
        std::thread::sleep(app::SETTLE);
        let t = Instant::now();
        rasters(&mut h, made + 1);
        let raster = t.elapsed().as_secs_f64() * 1e3;
        eprintln!(
            "a line through {} points{} (job {job:.1} s): pan and zoom {mean:.1} ms a frame \
             (slowest {max:.1} ms), first frame {first:.1} ms, {} vertices painted, a raster \
             at rest {raster:.0} ms, on {}",
            h.state().outcome.as_ref().unwrap().drawing.points.len(),
            if smooth { ", smooth" } else { "" },
            h.state().line_vertices_painted(),
            h.state().adapter().unwrap_or("no adapter")
        );
        // egui's tessellation alone: the stroke at the fitted view's scale.
        let o = h.state().outcome.as_ref().unwrap();
        let k = h.state().zoom() / o.scale;
        let points: Vec<egui::Pos2> = o.drawing.strokes[0]
            .path(0.5)
            .iter()
            .map(|p| egui::pos2(p[0] as f32 * k + 340.0, p[1] as f32 * k))
            .collect();
        let width = o.drawing.strokes[0].width * k;
        let n = points.len();
        let shape = egui::epaint::ClippedShape::new(
            egui::Rect::EVERYTHING,
            egui::Shape::line(points, egui::Stroke::new(width, egui::Color32::BLACK)),
        );
        let t = Instant::now();
        let prims = h.ctx.tessellate(vec![shape], 1.0);
        let triangles: usize = prims
            .iter()
            .map(|p| match &p.primitive {
                egui::epaint::Primitive::Mesh(m) => m.indices.len() / 3,
                egui::epaint::Primitive::Callback(_) => 0,
            })
            .sum();
        eprintln!(
            "tessellating {n} vertices {width:.2} px wide: {:.1} ms, {triangles} triangles",
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    h.state_mut().pan_by(egui::vec2(1e5, 1e5));
    let (mean, max, _) = pan_zoom_frames(&mut h);
    eprintln!(
        "the window without the drawing in sight: {mean:.1} ms a frame (slowest {max:.1} ms)"
    );
}

/// A poster through the Paper section: the Poster row turns it on (with a
/// paper), the view draws the grid, and Export ▸ Poster writes the CLI's
/// folder, sheet for sheet.
#[test]
fn a_poster_is_set_drawn_and_exported_as_the_cli_cuts_it() {
    let (dir, png, mut h) = ready(300, 200);
    h.get_by_label("Points").set_value_accesskit(4000.0);
    settle(&mut h);
    assert!(h.state().poster_grid().is_none(), "a grid without a poster");
    open_paper_combo(&mut h);
    h.get_by_label("A4").click();
    h.run_steps(2);
    h.get_by_label("Poster").click();
    settle(&mut h);
    // Two A4 sheets by two, portrait: 420 × 594 mm.
    let job = h.state().settings.job();
    let poster = job.poster.clone().expect("the poster is on");
    assert_eq!((poster.width_mm, poster.height_mm), (420.0, 594.0));
    let grid = h.state().poster_grid().expect("the grid over the view");
    assert!(grid.rows * grid.cols > 1, "{grid:?}");
    assert!(shows(&h, &format!("{} sheets", grid.rows * grid.cols)));
    // The view's page is the poster.
    assert_eq!(h.state().placement().unwrap().sheet_mm, (420.0, 594.0));
    if let Ok(shot) = std::env::var("PIXELPIE_POSTER_SHOT") {
        h.render().expect("render").save(shot).unwrap();
    }
    let out = dir.path().join("app-poster");
    h.state_mut().export_path = out.display().to_string();
    h.state_mut().export_poster();
    assert!(
        h.state().export_error.is_none(),
        "{:?}",
        h.state().export_error
    );
    let cli_dir = dir.path().join("cli-poster");
    cli(&[
        "stipple",
        &png.display().to_string(),
        "-o",
        &format!("{}/", cli_dir.display()),
        "--points",
        "4000",
        "--paper",
        "a4",
        "--poster",
        "420x594",
        "--quiet",
    ]);
    let names = |d: &Path| {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let files = names(&out);
    assert_eq!(files, names(&cli_dir));
    assert_eq!(files.len(), grid.rows * grid.cols + 1, "{files:?}");
    for f in &files {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(cli_dir.join(f)).unwrap(),
            "{f}"
        );
    }
    // Without a paper there is no poster.
    open_paper_combo(&mut h);
    h.get_by_label("None").click();
    h.run_steps(3);
    assert_eq!(h.state().settings.job.poster, None);
}
