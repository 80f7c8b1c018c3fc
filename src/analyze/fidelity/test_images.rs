//! Test images shared by the unit tests (pseudo-random, checkerboard,
//! smooth, noisy) and small helpers to read them.

use super::{Grey, pixel_count};

/// A deterministic pseudo-random value in [0, 1) (an LCG).
fn lcg(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 40) as f32 / (1u64 << 24) as f32
}

pub(super) fn random(width: u32, height: u32, seed: u64) -> Grey {
    let mut s = seed;
    let values = (0..pixel_count(width, height))
        .map(|_| lcg(&mut s))
        .collect();
    Grey {
        width,
        height,
        values,
    }
}

/// Black and white pixels alternating in both directions (50% black).
pub(super) fn checkerboard(width: u32, height: u32) -> Grey {
    let values = (0..height)
        .flat_map(|y| (0..width).map(move |x| ((x + y) % 2) as f32))
        .collect();
    Grey {
        width,
        height,
        values,
    }
}

/// A smooth image: a diagonal ramp with a sine ripple.
pub(super) fn smooth(width: u32, height: u32) -> Grey {
    let values = (0..height)
        .flat_map(|y| {
            (0..width).map(move |x| {
                let (x, y) = (x as f32, y as f32);
                0.5 + 0.3 * ((x + y) / (width + height) as f32 - 0.5) + 0.1 * (x / 5.0).sin()
            })
        })
        .collect();
    Grey {
        width,
        height,
        values,
    }
}

pub(super) fn add_noise(img: &Grey, amplitude: f32, seed: u64) -> Grey {
    let mut s = seed;
    let mut out = img.clone();
    for v in &mut out.values {
        *v += amplitude * (lcg(&mut s) - 0.5);
    }
    out
}

pub(super) fn at(img: &Grey, x: usize, y: usize) -> f32 {
    img.values[y * img.width as usize + x]
}

pub(super) fn sum(img: &Grey) -> f64 {
    img.values.iter().map(|&v| f64::from(v)).sum()
}
