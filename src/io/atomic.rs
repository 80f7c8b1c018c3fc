//! Atomic writes: a temporary file beside the target, renamed into place, so a
//! failed run never leaves a partial output.

use std::io::{BufWriter, Write};
use std::path::Path;

use super::{Error, Result};

/// Any error a writer's `fill` may return.
pub type BoxError = Box<dyn std::error::Error + Send + Sync>;

/// Writes `path` through `fill`, atomically.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::result::Result<(), BoxError>,
) -> Result<()> {
    let fail = |source: BoxError| Error::Write {
        path: path.to_path_buf(),
        source,
    };
    // tempfile names its temporary file in its errors: keep the cause only,
    // so that a message speaks of the user's file.
    let plain = |e: std::io::Error| -> BoxError {
        // tempfile's wrapper hides the OS's error number: its kind says it.
        let code = e.raw_os_error().or_else(|| errno_of(e.kind()));
        match code {
            Some(code) => Box::new(std::io::Error::from_raw_os_error(code)),
            None => Box::new(std::io::Error::new(e.kind(), e.kind().to_string())),
        }
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = tempfile::Builder::new()
        .prefix(".pixelpie-")
        .tempfile_in(dir)
        .map_err(|e| fail(plain(e)))?;
    let mut w = BufWriter::new(tmp);
    fill(&mut w).map_err(fail)?;
    let tmp = w.into_inner().map_err(|e| fail(plain(e.into_error())))?;
    // Temporary files are private (0600); an output is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))
            .map_err(|e| fail(plain(e)))?;
    }
    tmp.persist(path).map_err(|e| fail(plain(e.error)))?;
    Ok(())
}

/// The POSIX error number of an error kind a write meets (the same on
/// Linux and macOS).
fn errno_of(kind: std::io::ErrorKind) -> Option<i32> {
    use std::io::ErrorKind as K;
    Some(match kind {
        K::NotFound => 2,
        K::PermissionDenied => 13,
        K::AlreadyExists => 17,
        K::NotADirectory => 20,
        K::IsADirectory => 21,
        K::StorageFull => 28,
        K::ReadOnlyFilesystem => 30,
        _ => return None,
    })
}
