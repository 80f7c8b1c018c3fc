//! The app's built-in photo: it opens from a folder with no assets in
//! reach, and the binary holds no path into the source tree (issue 13,
//! bug 1). A file of its own, since it changes the working directory.

use egui_kittest::Harness;
use pixelpie::app::{self, PixelPieApp};

#[test]
fn the_built_in_photo_opens_from_any_folder() {
    let dir = tempfile::tempdir().unwrap();
    std::env::set_current_dir(dir.path()).unwrap();
    assert!(!std::path::Path::new("assets").exists());
    let mut h = Harness::builder()
        .with_size([1000.0, 800.0])
        .wgpu_setup(app::wgpu_setup())
        .build_eframe(|cc| PixelPieApp::new(cc, None));
    // The photo decodes on its own thread.
    let start = std::time::Instant::now();
    while h.state().source.is_none() {
        h.step();
        assert!(start.elapsed().as_secs() < 30, "the photo never decoded");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let app = h.state();
    assert!(app.error.is_none(), "error: {:?}", app.error);
    let src = app.source.as_ref().expect("the built-in photo is open");
    assert!(src.path.is_none(), "read from {:?}", src.path);
    assert_eq!((src.map.width(), src.map.height()), (512, 512));
    // An installed or copied binary finds no source tree: it must not name
    // one for its photo.
    let bin = std::fs::read(env!("CARGO_BIN_EXE_pixelpie")).unwrap();
    let source_path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/default.png");
    assert!(
        !bin.windows(source_path.len())
            .any(|w| w == source_path.as_bytes()),
        "the binary names {source_path}"
    );
}
