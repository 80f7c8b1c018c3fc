//! The app driven through its UI with egui_kittest, rendered with wgpu (on
//! lavapipe in CI): controls change the drawing, dropped files replace the
//! map, exports read back with the CLI.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
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

/// Steps the UI until sampling is done (debounce, worker, reply).
fn settle(h: &mut Harness<'_, PixelPieApp>) {
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
    assert!(h.state().error.is_none(), "error: {:?}", h.state().error);
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
    let set = &outcome.set;
    assert_eq!((set.width, set.height), (1024, 683));
    assert!((outcome.scale - 1024.0 / 90.0).abs() < 1e-4);
    let (dw, dh) = (set.width as f32, set.height as f32);
    assert!(set.points.iter().all(|p| p.x < dw && p.y < dh));
    // A bad file shows an error and keeps the map.
    let bad = dir.path().join("bad.png");
    std::fs::write(&bad, b"not a png").unwrap();
    h.input_mut().dropped_files.push(Arc::new(Dropped(bad)));
    h.run_steps(2);
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
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 160, 120);
    let mut h = harness(&png);
    settle(&mut h);
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
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 200, 150);
    let mut h = harness(&png);
    settle(&mut h);
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
    let before = h.state().outcome.as_ref().unwrap().set.points.clone();
    // A long relaxation, then Cancel: the worker stops, the drawing stays.
    h.state_mut().settings.points = 60_000;
    h.state_mut().settings.relax = 30;
    let start = Instant::now();
    while !h.state().busy() {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(10), "no job started");
    }
    h.state_mut().cancel_job();
    h.run_steps(3);
    assert!(!h.state().busy());
    assert_eq!(h.state().status, "cancelled");
    assert_eq!(h.state().outcome.as_ref().unwrap().set.points, before);
    // A short relaxation finishes, with the count asked for.
    h.state_mut().settings.points = 2000;
    h.state_mut().settings.relax = 3;
    h.step();
    settle(&mut h);
    let relaxed = &h.state().outcome.as_ref().unwrap().set.points;
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
    h.run_steps(1);
    assert_eq!(h.state().source.as_ref().unwrap().map.width(), 128);
    assert_eq!(h.state().dots_drawn(), 0, "old dots over the new image");
    assert!(h.state().outcome.is_none());
    settle(&mut h);
    let set = &h.state().outcome.as_ref().unwrap().set;
    assert_eq!((set.width, set.height), (1024, 1024));
    assert!(h.state().dots_drawn() > 100);
}

#[test]
fn exports_use_the_dot_colour_and_the_png_scale() {
    // Bug: with red dots on screen the SVG said fill="black" and the PNG
    // was grey; the PNG had no size control.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 160, 120);
    let mut h = harness(&png);
    settle(&mut h);
    h.state_mut().settings.dot_color = [220, 30, 30];
    h.state_mut().settings.png_scale = 0.5;
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
    let set = &h.state().outcome.as_ref().unwrap().set;
    assert_eq!(img.dimensions(), (set.width / 2, set.height / 2));
    let inked: Vec<_> = img.pixels().filter(|p| p.0 != [255, 255, 255]).collect();
    assert!(inked.len() > 100);
    // Every inked pixel lies between the paper and the ink: reddish.
    assert!(inked.iter().all(|p| p.0[0] >= p.0[1] && p.0[1] == p.0[2]));
    assert!(inked.iter().any(|p| p.0[0] > 200 && p.0[1] < 80));
}

#[test]
fn errors_sit_by_their_action_and_go_when_it_succeeds() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("g.png");
    gradient_png(&png, 160, 120);
    let mut h = harness(&png);
    settle(&mut h);
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
    h.run_steps(2);
    assert!(h.state().open_error.is_none());
}
