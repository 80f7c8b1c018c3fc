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
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `e`'s message followed by its sources, `: `-separated: the one line the
/// CLI prints (as anyhow's `{:#}`), for front ends without anyhow.
#[must_use]
pub fn one_line(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    single_line(&text)
}

/// `text` on one line: each run of whitespace, line breaks included, becomes
/// one space (wgpu's and some decoders' messages span lines).
#[must_use]
pub fn single_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}
