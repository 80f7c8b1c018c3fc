//! Native file dialogs (rfd: the desktop's own, through the XDG portal on
//! Linux), behind a trait so that tests can answer them.

use std::path::{Path, PathBuf};

/// The image formats the app opens.
pub const IMAGE_EXTENSIONS: &[&str] = &["png", "jpg", "jpeg", "tif", "tiff", "bmp", "webp", "exr"];

/// Asks the user for a file.
pub trait FileDialogs {
    /// An image to open, starting in `folder`; `None` when cancelled.
    fn pick_image(&mut self, folder: Option<&Path>) -> Option<PathBuf>;
    /// Where to export, starting in `folder` with `name`; `None` when
    /// cancelled.
    fn save_drawing(&mut self, folder: Option<&Path>, name: &str) -> Option<PathBuf>;
}

/// The desktop's dialogs.
pub struct NativeDialogs;

impl FileDialogs for NativeDialogs {
    fn pick_image(&mut self, folder: Option<&Path>) -> Option<PathBuf> {
        let mut d = rfd::FileDialog::new()
            .set_title("Open an image")
            .add_filter("Images and EXR", IMAGE_EXTENSIONS);
        if let Some(f) = folder {
            d = d.set_directory(f);
        }
        d.pick_file()
    }

    fn save_drawing(&mut self, folder: Option<&Path>, name: &str) -> Option<PathBuf> {
        let mut d = rfd::FileDialog::new()
            .set_title("Export the drawing")
            .set_file_name(name)
            .add_filter("SVG drawing", &["svg"])
            .add_filter("PNG image", &["png"])
            .add_filter("Points (CSV)", &["csv"])
            .add_filter("Points (JSON)", &["json"]);
        if let Some(f) = folder {
            d = d.set_directory(f);
        }
        d.save_file()
    }
}
