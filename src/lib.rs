//! PixelPie: maximal Poisson-disk sampling with rasterization (Ip et al. 2013)
//! and importance-map stippling.
//!
//! * [`sampler`]: the headless core, its semantics and the CPU reference backend;
//! * [`backend`]: backend selection;
//! * [`job`]: the drawing and point-set jobs, one staged run each, and the
//!   point-count fit ([`job::count`]);
//! * [`stipple`]: dots, their formats (SVG, PNG), relaxation, TSP, paper and plots;
//! * [`io`]: file formats.
//!
//! # Example
//!
//! ```
//! use pixelpie::sampler::Params;
//!
//! // 8.5 px disks on 1024², tileable, exact (no sub-pixel slack, no gaps).
//! let set = Params::new(1024, 1024)
//!     .with_radius(8.5)
//!     .with_periodic(true)
//!     .with_exact(true)
//!     .with_seed(7)
//!     .generate()?;
//! assert!(set.maximal());
//! println!("{} points, {:.3} s", set.points.len(), set.stats.seconds);
//! # Ok::<(), pixelpie::sampler::Error>(())
//! ```
//!
//! # Features
//!
//! The default builds everything. With `default-features = false` the
//! library is the CPU sampler (pixel and exact modes), importance maps,
//! stipple drawings and the analysis; `gpu` adds the wgpu backend, `cli`
//! the binary's argument parsing and progress bars, `app` the interactive
//! app (with `gpu`), `plots` the analysis figures.

#![warn(missing_docs)]

pub mod analyze;
#[cfg(feature = "app")]
pub mod app;
pub mod backend;
pub mod colour;
mod error;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod importance;
pub mod io;
pub mod job;
pub mod sampler;
pub mod stipple;
mod text;

pub use error::{Error, Result};
#[doc(hidden)]
pub use text::single_line;
pub use text::{given, one_line, raw_line, setting, setting_error, spell_cli, spell_rust, spelled};
