//! The library's error: one enum over the modules' own errors, each kept
//! whole as the source.

/// Anything the library can fail with.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The sampler's parameters, or a cancelled or failed run.
    #[error(transparent)]
    Sampler(#[from] crate::sampler::Error),
    /// Reading or preparing an importance map.
    #[error(transparent)]
    Importance(#[from] crate::importance::Error),
    /// Drawing a stipple.
    #[error(transparent)]
    Stipple(#[from] crate::stipple::Error),
    /// Reading or measuring a point set.
    #[error(transparent)]
    Analyze(#[from] crate::analyze::Error),
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] crate::io::Error),
    /// A pen set that cannot be used.
    #[error(transparent)]
    Pens(#[from] crate::colour::pens::PenError),
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
