//! File formats, kept out of the sampler: point sets (CSV, JSON), radius maps
//! (OpenEXR) and atomic writes, shared by the CLI and the app.

mod atomic;
mod exr_map;
mod points;

use std::path::PathBuf;

pub use atomic::{BoxError, write_atomic};
pub use exr_map::{ExrImage, read_exr, read_radius_map};
pub use points::{PointFormat, points_to, write_points, write_points_pens};

/// What can go wrong reading or writing a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An output could not be written; nothing was left at its path.
    #[error("cannot write '{}'", path.display())]
    Write {
        /// The output.
        path: PathBuf,
        /// The cause.
        #[source]
        source: BoxError,
    },
    /// An OpenEXR file could not be read.
    #[error("cannot read EXR '{}'", path.display())]
    Exr {
        /// The file.
        path: PathBuf,
        /// The decoder's error (its message; the decoder's own type stays
        /// private).
        #[source]
        source: BoxError,
    },
    /// A file that was read but holds the wrong thing, or a path of the
    /// wrong kind.
    #[error("{0}")]
    Invalid(String),
}

/// The result type of this module.
pub type Result<T, E = Error> = std::result::Result<T, E>;
