//! File formats, kept out of the sampler: point sets (CSV, JSON), radius maps
//! (OpenEXR) and atomic writes, shared by the CLI and the app.

mod atomic;
mod exr_map;
mod points;

pub use atomic::write_atomic;
pub use exr_map::{ExrImage, read_exr, read_radius_map};
pub use points::{PointFormat, write_points};
