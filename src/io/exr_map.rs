//! OpenEXR input through the `exr` crate: any channel layout, scanline or
//! tiled, half or float, returned as planar `f32` channels.

use std::path::Path;

use super::{Error, Result};
use exr::prelude::{FlatSamples, ReadChannels, ReadLayers};

/// The first valid layer of an EXR file, channel by channel.
pub struct ExrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `(name, samples)` per channel, samples row-major.
    pub channels: Vec<(String, Vec<f32>)>,
}

/// Reads every channel of the first layer of `path` at full resolution.
pub fn read_exr(path: &Path) -> Result<ExrImage> {
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| Error::Exr {
            path: path.to_path_buf(),
            source: e.to_string().into(),
        })?;
    let size = image.layer_data.size;
    let (width, height) = (size.width() as u32, size.height() as u32);
    let channels = image
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| {
            let samples = match &c.sample_data {
                FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
                FlatSamples::F32(v) => v.clone(),
                FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
            };
            (c.name.to_string(), samples)
        })
        .collect();
    Ok(ExrImage {
        width,
        height,
        channels,
    })
}

/// Reads a single-channel EXR of radii in pixels (any channel name).
pub fn read_radius_map(path: &Path) -> Result<(u32, u32, Vec<f32>)> {
    let img = read_exr(path)?;
    let [(_, samples)] = <[_; 1]>::try_from(img.channels).map_err(|c| {
        Error::Invalid(format!(
            "radius map '{}' has {} channels, expected one",
            path.display(),
            c.len()
        ))
    })?;
    if img.width == 0 || img.height == 0 {
        return Err(Error::Invalid(format!(
            "radius map '{}' is empty",
            path.display()
        )));
    }
    Ok((img.width, img.height, samples))
}
