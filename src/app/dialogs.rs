//! Native file dialogs (rfd: the desktop's own, through the XDG portal on
//! Linux), behind a trait so that tests can answer them. Where the desktop
//! has no dialog to offer (Linux without a session bus for the portal and
//! without zenity), the dialogs say so, and the app shows why nothing
//! opened instead of doing nothing.

use std::path::{Path, PathBuf};

/// The image formats the app opens.
pub const IMAGE_EXTENSIONS: &[&str] = &["png", "jpg", "jpeg", "tif", "tiff", "bmp", "webp", "exr"];

/// What a dialog gives: a path, `None` when cancelled, or why no dialog
/// could open.
pub type Answer = Result<Option<PathBuf>, String>;

/// Asks the user for a file.
pub trait FileDialogs {
    /// An image to open, starting in `folder`.
    fn pick_image(&mut self, folder: Option<&Path>) -> Answer;
    /// Where to export, starting in `folder` with `name`.
    fn save_drawing(&mut self, folder: Option<&Path>, name: &str) -> Answer;
    /// A pen file (`.toml`: a pen box to choose from), starting in `folder`.
    fn pick_pens(&mut self, folder: Option<&Path>) -> Answer {
        let _ = folder;
        Err("no dialog for pen files here".into())
    }
}

/// The desktop's dialogs.
pub struct NativeDialogs;

/// Why this desktop cannot show a native dialog, if it cannot: on Linux rfd
/// needs the XDG desktop portal (on the session bus) or zenity.
#[must_use]
pub fn unavailable() -> Option<String> {
    if !cfg!(target_os = "linux") {
        return None;
    }
    let bus = std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|v| !v.is_empty());
    let zenity = std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|d| d.join("zenity").is_file()));
    (!bus && !zenity).then(|| {
        "no file dialog on this desktop (no XDG desktop portal, no zenity): type the path \
         in the field"
            .to_owned()
    })
}

impl FileDialogs for NativeDialogs {
    fn pick_image(&mut self, folder: Option<&Path>) -> Answer {
        if let Some(why) = unavailable() {
            return Err(why);
        }
        let mut d = rfd::FileDialog::new()
            .set_title("Open an image")
            .add_filter("Images and EXR", IMAGE_EXTENSIONS);
        if let Some(f) = folder {
            d = d.set_directory(f);
        }
        Ok(d.pick_file())
    }

    fn pick_pens(&mut self, folder: Option<&Path>) -> Answer {
        if let Some(why) = unavailable() {
            return Err(why);
        }
        let mut d = rfd::FileDialog::new()
            .set_title("Open a pen box (a pen file)")
            .add_filter("Pen files", &["toml"]);
        if let Some(f) = folder {
            d = d.set_directory(f);
        }
        Ok(d.pick_file())
    }

    fn save_drawing(&mut self, folder: Option<&Path>, name: &str) -> Answer {
        if let Some(why) = unavailable() {
            return Err(why);
        }
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
        Ok(d.save_file())
    }
}
