//! Pen calibration from a real plot. Ink spreads: a pen's dot on paper is
//! wider than the dot drawn, by a factor that depends on the pen, the ink
//! and the paper (its *dot gain*), so tones calibrated on screen come out
//! dark on paper. The loop:
//!
//! 1. [`chart`]: `pixelpie calibrate chart` writes, for each pen, patches
//!    of known ink made of the dots our stipples use at that pen's width,
//!    with four round marks and a code;
//! 2. the user plots it and scans or photographs it;
//! 3. [`fit`]: `pixelpie calibrate fit` finds the marks, undoes the
//!    perspective, measures each patch and fits each pen's dot gain and
//!    ink colour, and writes the pen file that `--pens` reads;
//! 4. `pixelpie stipple --pens pens.toml` draws each dot smaller by its
//!    pen's gain ([`crate::job::Job::dot_gain`]), so that the plotted
//!    tones come out right.
//!
//! [`simulate`] makes synthetic plots and scans with known gains and inks:
//! the tests' ground truth, and a way to try the loop without a plotter.

pub mod chart;
pub mod fit;
mod homography;
pub mod simulate;

use std::path::Path;

pub use chart::{Chart, ChartSpec};
pub use fit::{Fit, PenFit};
pub use homography::Homography;
pub use simulate::ScanOptions;

use super::{Error, Result};

/// Reads the chart of the SVG file at `path`.
pub fn read_chart(path: &Path) -> crate::Result<Chart> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Error::InvalidParameter(format!("cannot read chart '{}': {e}", path.display()))
    })?;
    Ok(Chart::read_svg(&text)?)
}

/// Reads a scan or photograph (PNG, JPEG, TIFF, BMP, WebP).
pub fn read_scan(path: &Path) -> crate::Result<image::RgbImage> {
    let img = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| {
            Error::InvalidParameter(format!("cannot read scan '{}': {e}", path.display()))
        })?
        .decode()
        .map_err(|e| {
            Error::InvalidParameter(format!(
                "cannot decode scan '{}': {}",
                path.display(),
                crate::one_line(&e)
            ))
        })?;
    Ok(img.to_rgb8())
}

/// Writes `chart` as SVG to `path`, atomically.
pub fn write_chart(chart: &Chart, path: &Path) -> crate::Result<()> {
    crate::io::write_atomic(path, |w| Ok(chart.write_svg(w)?))?;
    Ok(())
}

/// The pen file of `fit`, TOML: what `--pens` reads.
pub fn pen_toml(fit: &Fit, scan: &str) -> Result<String> {
    #[derive(serde::Serialize)]
    struct File<'a> {
        pen: &'a [crate::colour::Pen],
    }
    let set = fit.pen_set()?;
    let body = toml::to_string(&File { pen: set.pens() })
        .map_err(|e| Error::InvalidParameter(format!("pen file: {e}")))?;
    Ok(format!(
        "# Pens calibrated by pixelpie calibrate fit from {} (chart {:04x}).\n\
         # dot_gain: the plotted dot's diameter over the drawn one.\n{body}",
        scan.replace(['\n', '\r'], " "),
        fit.code
    ))
}

/// Writes `fit`'s pen file to `path`, atomically.
pub fn write_pens(fit: &Fit, scan: &str, path: &Path) -> crate::Result<()> {
    let text = pen_toml(fit, scan)?;
    crate::io::write_atomic(path, |w| Ok(w.write_all(text.as_bytes())?))?;
    Ok(())
}
