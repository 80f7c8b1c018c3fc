//! Regenerates the importance maps in `assets/` (see `assets/README.md`).
//!
//! ```text
//! cargo run --release --example make_assets -- [SKIMAGE_DATA_DIR]
//! ```
//!
//! Without an argument it writes the synthetic maps only: `gradient.exr`
//! (the paper's Figure 15a quadratic gradient, HDR with a highlight) and
//! `rings.png` (a 16-bit zone plate). With scikit-image's `skimage/data`
//! folder it also converts the public-domain NASA and SpaceX photographs into
//! `default.png` and `rocket.jpg`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use exr::prelude::{Image, SpecificChannels, WritableImage, f16};
use image::{ImageBuffer, Luma};
use pixelpie::importance;
use pixelpie::stipple::raster::linear_to_srgb;

fn main() -> Result<()> {
    let out = PathBuf::from("assets");
    std::fs::create_dir_all(&out)?;
    gradient_exr(&out.join("gradient.exr"))?;
    rings_png(&out.join("rings.png"))?;
    if let Some(dir) = std::env::args().nth(1) {
        let dir = PathBuf::from(dir);
        photo_gray(&dir.join("astronaut.png"), &out.join("default.png"), 512)?;
        rocket_jpeg(&dir.join("rocket.jpg"), &out.join("rocket.jpg"))?;
    }
    Ok(())
}

/// Quadratic ramp of luminance 0 (left) to 4 (right), half floats, with a
/// disk of luminance 100 (0.3% of the pixels) that the 99.5th-percentile
/// white point clips away.
fn gradient_exr(path: &Path) -> Result<()> {
    let (w, h) = (256usize, 256usize);
    let pixels =
        SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(|pos: exr::math::Vec2<usize>| {
                let u = (pos.0 as f32 + 0.5) / w as f32;
                let (dx, dy) = (pos.0 as f32 - 200.0, pos.1 as f32 - 60.0);
                let y = if dx * dx + dy * dy < 64.0 {
                    100.0
                } else {
                    4.0 * u * u
                };
                (f16::from_f32(y),)
            });
    Image::from_channels((w, h), pixels)
        .write()
        .to_file(path)
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// A 16-bit zone plate: sin(k r²) rings, sRGB-encoded.
fn rings_png(path: &Path) -> Result<()> {
    let n = 256u32;
    let img = ImageBuffer::from_fn(n, n, |x, y| {
        let (dx, dy) = (x as f32 - 127.5, y as f32 - 127.5);
        let v = 0.5 + 0.5 * (0.0025 * (dx * dx + dy * dy)).cos();
        Luma([(linear_to_srgb(v) * 65535.0).round() as u16])
    });
    img.save(path)
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    println!("wrote {}", path.display());
    Ok(())
}

/// A photograph as 8-bit grey (linear luminance, sRGB-encoded), at most
/// `side` px on its longer side.
fn photo_gray(src: &Path, dst: &Path, side: u32) -> Result<()> {
    let map = importance::ImportanceMap::open(src, None)?;
    let s = f64::from(side) / f64::from(map.width().max(map.height()));
    let map = if s < 1.0 {
        map.resized(
            (f64::from(map.width()) * s).round() as u32,
            (f64::from(map.height()) * s).round() as u32,
        )?
    } else {
        map
    };
    let img: ImageBuffer<Luma<u8>, Vec<u8>> = ImageBuffer::from_raw(
        map.width(),
        map.height(),
        map.values()
            .iter()
            .map(|&v| (linear_to_srgb(v) * 255.0).round() as u8)
            .collect(),
    )
    .context("image size")?;
    img.save(dst)
        .with_context(|| format!("cannot write '{}'", dst.display()))?;
    println!("wrote {} from {}", dst.display(), src.display());
    // Round trip check: decoding gives back the linear values.
    let back = importance::ImportanceMap::open(dst, None)?;
    let err = back
        .values()
        .iter()
        .zip(map.values())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(err < 0.01, "round trip error {err}");
    Ok(())
}

/// The rocket photograph, colour, shrunk to 480 px wide, JPEG quality 85.
fn rocket_jpeg(src: &Path, dst: &Path) -> Result<()> {
    let img = image::open(src).with_context(|| format!("cannot read '{}'", src.display()))?;
    let small = img
        .resize(480, 480, image::imageops::FilterType::Triangle)
        .to_rgb8();
    let file = std::fs::File::create(dst)?;
    let mut enc = image::codecs::jpeg::JpegEncoder::new_with_quality(file, 85);
    enc.encode_image(&small)?;
    println!("wrote {} from {}", dst.display(), src.display());
    Ok(())
}
