//! The memory a picture may take, decided from its header before it is
//! decoded: a small file can hold a huge picture (a 1.6 MB PNG of 40000²
//! grey took 20 GB to draw), so a picture whose decoding and drawing would
//! need more than the budget is refused in words, in milliseconds.
//!
//! The budget is [`default_budget`] (4 GB, or half the machine's memory
//! when that is less), the process's own when a front end sets one
//! ([`set_max_memory`]: the CLI's `--max-memory`), or one call's on this
//! thread ([`within`]: Python's `max_memory=`).

use std::cell::Cell;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use super::{Error, Result};

/// Bytes a pixel of a grey picture costs at the drawing's peak: its decoded
/// samples, the luminance, the normalized map and the drawing's own maps
/// (measured: 19 bytes a pixel for a 24-Mpx photo drawn at 10K dots, 13
/// for the 40000² PNG).
pub const GREY_BYTES_PER_PIXEL: u64 = 20;
/// Bytes a pixel of a colour picture costs at the drawing's peak (31
/// measured for the 24-Mpx photo in CMYK).
pub const COLOUR_BYTES_PER_PIXEL: u64 = 32;

/// Bytes a pixel of the drawing's domain costs at its peak: the map, the
/// radius map, the sampler's coverage and empty list, the relaxation's
/// weights and pyramid (measured: 302 MB for 1M dots on 4096², 18 a
/// pixel).
pub const DOMAIN_BYTES_PER_PIXEL: u64 = 20;

/// The budget when nothing sets one: 4 GB at most.
const DEFAULT_MAX: u64 = 4 << 30;

/// The process's budget (0: the default).
static PROCESS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// This thread's budget for the call in [`within`].
    static THREAD: Cell<Option<u64>> = const { Cell::new(None) };
}

/// 4 GB, or half of the machine's memory when that is less (Linux's
/// `/proc/meminfo`, read once; elsewhere 4 GB).
#[must_use]
pub fn default_budget() -> u64 {
    static DEFAULT: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *DEFAULT.get_or_init(|| {
        let total = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| {
                let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
                let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
                Some(kb * 1024)
            });
        total.map_or(DEFAULT_MAX, |t| DEFAULT_MAX.min(t / 2))
    })
}

/// The budget in force on this thread.
#[must_use]
pub fn max_memory() -> u64 {
    THREAD
        .get()
        .unwrap_or_else(|| match PROCESS.load(Ordering::Relaxed) {
            0 => default_budget(),
            b => b,
        })
}

/// Sets the process's budget in bytes (`None`: the default).
pub fn set_max_memory(bytes: Option<u64>) {
    PROCESS.store(bytes.unwrap_or(0), Ordering::Relaxed);
}

/// Runs `work` with this thread's budget `bytes` (`None`: the process's).
pub fn within<T>(bytes: Option<u64>, work: impl FnOnce() -> T) -> T {
    let before = THREAD.replace(bytes.or(THREAD.get()));
    let out = work();
    THREAD.set(before);
    out
}

/// A size in bytes from "4G", "4 GB", "512M", "1.5g", "300000000".
///
/// ```
/// use pixelpie::importance::budget::parse_size;
/// assert_eq!(parse_size("4G"), Ok(4 << 30));
/// assert_eq!(parse_size("512 MB"), Ok(512 << 20));
/// assert_eq!(parse_size("1000"), Ok(1000));
/// assert!(parse_size("lots").is_err());
/// ```
pub fn parse_size(text: &str) -> std::result::Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let value: f64 = number.parse().map_err(|_| {
        format!("'{text}' is not a size: write it as 4G, 512M or a number of bytes")
    })?;
    let scale: u64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        _ => {
            return Err(format!(
                "'{text}' is not a size: its unit must be K, M, G or T"
            ));
        }
    };
    let bytes = value * scale as f64;
    if !(bytes.is_finite() && bytes >= 1.0) {
        return Err(format!("'{text}' is not a size of at least one byte"));
    }
    Ok(bytes as u64)
}

/// A size for people: "20 GB", "730 MB".
fn said(bytes: u64) -> String {
    let gb = bytes as f64 / f64::from(1u32 << 30);
    if gb >= 1.0 {
        format!("{gb:.1} GB").replace(".0 GB", " GB")
    } else if bytes >= 1 << 20 {
        format!("{} MB", bytes >> 20)
    } else {
        format!("{bytes} bytes")
    }
}

/// Refuses a picture `name` of `size` pixels that would need more than the
/// budget at `per_pixel` bytes a pixel.
pub(crate) fn check(name: &Path, size: (u32, u32), per_pixel: u64) -> Result<()> {
    let pixels = u64::from(size.0) * u64::from(size.1);
    let needed = pixels.saturating_mul(per_pixel);
    let allowed = max_memory();
    if needed <= allowed {
        return Ok(());
    }
    let mpx = pixels as f64 / 1e6;
    let count = if mpx >= 1000.0 {
        format!("{:.1} Gpx", mpx / 1000.0)
    } else {
        format!("{mpx:.0} Mpx")
    };
    Err(Error::TooLarge {
        path: name.to_owned(),
        message: format!(
            "is {}×{} ({count}): drawing it needs about {}, more than the {} allowed; \
             pass «max_memory» or shrink it",
            size.0,
            size.1,
            said(needed),
            said(allowed)
        ),
    })
}

/// Bytes a pixel of a point set's domain costs in the sampler: its
/// coverage, empty list and darts (8.6 measured), and a radius map's 4.
pub const SAMPLE_BYTES_PER_PIXEL: u64 = 13;

/// Refuses a drawing's domain that would need more than the budget.
pub fn check_domain(domain: (u32, u32)) -> Result<()> {
    check_pixels("a drawing", domain, DOMAIN_BYTES_PER_PIXEL)
}

/// Refuses `what` ("a drawing", "a point set") on a domain that would need
/// more than the budget at `per_pixel` bytes a pixel.
pub fn check_pixels(what: &str, domain: (u32, u32), per_pixel: u64) -> Result<()> {
    let pixels = u64::from(domain.0) * u64::from(domain.1);
    let needed = pixels.saturating_mul(per_pixel);
    let allowed = max_memory();
    if needed <= allowed {
        return Ok(());
    }
    Err(Error::Memory(format!(
        "{what} on a {}×{} domain needs about {}, more than the {} allowed; give a \
         smaller «width»/«height» or fewer «points», or pass «max_memory»",
        domain.0,
        domain.1,
        said(needed),
        said(allowed)
    )))
}

/// The predicted peak memory in MB of a drawing of a picture of `picture`
/// pixels on a domain of `domain` pixels, in colour or grey.
#[must_use]
pub fn peak_mb(picture: (u32, u32), domain: (u32, u32), colour: bool) -> u64 {
    let per_pixel = if colour {
        COLOUR_BYTES_PER_PIXEL
    } else {
        GREY_BYTES_PER_PIXEL
    };
    let px = |s: (u32, u32)| u64::from(s.0) * u64::from(s.1);
    let bytes = (px(picture) * per_pixel).max(px(domain) * DOMAIN_BYTES_PER_PIXEL);
    bytes.div_ceil(1 << 20)
}

/// The size of the picture in `bytes` from its header, when its format
/// says it (PNG, JPEG, TIFF, BMP, WebP).
pub(crate) fn encoded_size(bytes: &[u8]) -> Option<(u32, u32)> {
    image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .ok()?
        .into_dimensions()
        .ok()
}

/// The size of the picture file at `path` from its header (an EXR's
/// first layer, or a raster format's), when it can be read.
pub(crate) fn file_size(path: &Path, exr: bool) -> Option<(u32, u32)> {
    if exr {
        let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
        let header = meta.headers.first()?;
        let size = header.layer_size;
        return Some((u32::try_from(size.0).ok()?, u32::try_from(size.1).ok()?));
    }
    image::ImageReader::open(path)
        .ok()?
        .with_guessed_format()
        .ok()?
        .into_dimensions()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_picture_over_the_budget_is_refused_in_words_and_a_call_may_raise_it() {
        let big = (40_000, 40_000);
        let e = within(Some(4 << 30), || {
            check(Path::new("bomb.png"), big, GREY_BYTES_PER_PIXEL)
        })
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("bomb.png") && e.contains("40000×40000 (1.6 Gpx)"),
            "{e}"
        );
        assert!(e.contains("29.8 GB") && e.contains("4 GB allowed"), "{e}");
        assert!(
            within(Some(1 << 40), || check(
                Path::new("b"),
                big,
                GREY_BYTES_PER_PIXEL
            ))
            .is_ok()
        );
        // The call's budget ends with it.
        within(Some(1), || ());
        assert!(check(Path::new("small"), (512, 512), COLOUR_BYTES_PER_PIXEL).is_ok());
    }
}
