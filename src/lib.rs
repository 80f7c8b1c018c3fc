//! PixelPie: maximal Poisson-disk sampling with rasterization (Ip et al. 2013)
//! and importance-map stippling.
//!
//! * [`sampler`]: the headless core, its semantics and the CPU reference backend;
//! * [`backend`]: backend selection;
//! * [`io`]: file formats; [`count`]: point-count targeting.

pub mod analyze;
pub mod app;
pub mod backend;
pub mod count;
pub mod gpu;
pub mod importance;
pub mod io;
pub mod sampler;
pub mod stipple;
