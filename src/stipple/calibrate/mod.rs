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

pub use chart::{Chart, ChartSpec};
pub use fit::{Fit, PenFit};
pub use homography::Homography;
pub use simulate::ScanOptions;

use super::{Error, Result};

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
