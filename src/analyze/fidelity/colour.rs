//! The colour measure of a colour drawing: both images blurred by the same
//! σ, channel by channel, then CIEDE2000 per pixel in CIELAB D65, its mean
//! and 95th percentile; on display values (sRGB-encoded, blurred as they
//! are) and on linear light (decoded before blurring).

use rayon::prelude::*;

use super::{Grey, blur};
use crate::colour::{Lab, delta_e00};

/// A colour image: three sRGB-encoded channels in [0, 1].
pub type Rgb = [Grey; 3];

/// The colour measure.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ColourFidelity {
    /// ΔE00 between the blurred images, mean over pixels (display values).
    pub delta_e00_mean: f64,
    /// Its 95th percentile.
    pub delta_e00_p95: f64,
    /// The mean on linear light.
    pub delta_e00_mean_linear: f64,
    /// Its 95th percentile.
    pub delta_e00_p95_linear: f64,
}

/// Blurs both colour images by `sigma` and measures their CIEDE2000
/// difference, under both conventions.
///
/// ```
/// use pixelpie::analyze::fidelity::{Grey, colour::compare_colour};
/// let grey = |v| [Grey::filled(16, 16, v), Grey::filled(16, 16, v), Grey::filled(16, 16, v)];
/// let f = compare_colour(&grey(0.5), &grey(0.5), 2.0).unwrap();
/// assert_eq!(f.delta_e00_mean, 0.0);
/// assert!(compare_colour(&grey(0.5), &grey(0.6), 2.0).unwrap().delta_e00_p95 > 1.0);
/// ```
pub fn compare_colour(
    photo: &Rgb,
    drawing: &Rgb,
    sigma: f64,
) -> Result<ColourFidelity, crate::analyze::Error> {
    for (p, d) in photo.iter().zip(drawing) {
        // The grey comparison's checks: sizes, values, σ.
        super::compare::validate(p, d, sigma).map_err(crate::analyze::Error::InvalidParameter)?;
    }
    let measure = |linear: bool| {
        let prep = |img: &Rgb| -> Vec<Grey> {
            img.par_iter()
                .map(|c| {
                    let c = if linear {
                        c.map(crate::colour::srgb_to_linear)
                    } else {
                        c.clone()
                    };
                    blur(&c, sigma)
                })
                .collect()
        };
        let (p, d) = (prep(photo), prep(drawing));
        let lab = |img: &[Grey], i: usize| {
            let c = [0, 1, 2].map(|k| f64::from(img[k].values[i]).clamp(0.0, 1.0));
            if linear {
                Lab::from_linear(c)
            } else {
                Lab::from_srgb(c)
            }
        };
        let mut e: Vec<f64> = (0..p[0].values.len())
            .into_par_iter()
            .map(|i| delta_e00(lab(&p, i), lab(&d, i)))
            .collect();
        let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
        let k = ((0.95 * e.len() as f64).ceil() as usize).clamp(1, e.len().max(1)) - 1;
        let p95 = if e.is_empty() {
            0.0
        } else {
            *e.select_nth_unstable_by(k, f64::total_cmp).1
        };
        (mean, p95)
    };
    let ((m, p), (ml, pl)) = rayon::join(|| measure(false), || measure(true));
    Ok(ColourFidelity {
        delta_e00_mean: m,
        delta_e00_p95: p,
        delta_e00_mean_linear: ml,
        delta_e00_p95_linear: pl,
    })
}

/// The display grey of a colour image: the sRGB encoding of its luminance.
#[must_use]
pub fn luminance(img: &Rgb) -> Grey {
    let lin = |k: usize, i: usize| crate::colour::srgb_to_linear(img[k].values[i]);
    let values = (0..img[0].values.len())
        .map(|i| {
            let y = 0.2126 * lin(0, i) + 0.7152 * lin(1, i) + 0.0722 * lin(2, i);
            crate::colour::linear_to_srgb(y.clamp(0.0, 1.0))
        })
        .collect();
    Grey {
        width: img[0].width,
        height: img[0].height,
        values,
    }
}
