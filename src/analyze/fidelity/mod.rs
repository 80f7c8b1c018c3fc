//! Tone fidelity of a stipple drawing to its photo, measured as in the
//! stippling survey (Martín et al. 2017): both images are blurred by a
//! Gaussian whose σ is the mean dot spacing, then compared by PSNR and by
//! mean SSIM. [`compare`] does both on display grey (sRGB-encoded values, as
//! the survey does) and on linear light (each pixel decoded with the sRGB
//! transfer function before blurring), where a dot pattern's average is its
//! physical ink coverage.
//!
//! # Blur
//!
//! [`blur`] is a separable, truncated Gaussian: taps at integer offsets
//! `|t| <= ceil(3σ)` with weights `exp(-t²/2σ²)` normalized to sum to 1
//! (the truncation drops 0.27% of the weight before normalizing, and about
//! 2% of the variance), lines in parallel with rayon. It works in `f32` as
//! `c + Σ_{t≥1} k_t·(p_t + q_t − 2c)`, so that a constant stays exactly
//! constant. Edges are *reflected* (half-sample symmetric,
//! `… c b a | a b c …`, again and again where the kernel is longer than the
//! line), so the blur keeps the sum of every image (up to rounding): the
//! reflected image is periodic and symmetric, and so is its blur. Clamping
//! the edges would give the border pixels extra weight instead. A kernel
//! longer than a line is folded onto it, so the cost per pixel stops growing
//! at σ ≈ side/3.
//!
//! `image::imageops::blur` (image 0.25.10) is not used: it takes its kernel
//! size from OpenCV's rule `ksize = 2((σ − 0.8)/0.3 + 1) + 1`, which truncates
//! small σ at about 2σ (σ = 1 gets a 5-tap kernel) and large σ at about
//! 3.3σ, turns σ = 0 into σ = 0.8, clamps the edges, and runs on one thread.
//!
//! # SSIM
//!
//! [`ssim`] follows Wang et al. (2004) and their reference `ssim_index.m`:
//! an 11×11 Gaussian window with σ = 1.5, normalized to sum 1,
//! C1 = (0.01·L)², C2 = (0.03·L)², L = 1, averaged over the windows lying
//! fully inside the image (MATLAB's `'valid'`). A side shorter than 11 pixels
//! uses the centred Gaussian window of that length (renormalized), so that
//! side has a single window position. The window is applied separably, in
//! `f64`, in bands of rows in parallel.
//!
//! The `image-compare` crate is not used: its SSIM (0.4.1 source; 0.5.0
//! declares the same window and constants) tiles the image into
//! non-overlapping 8×8 *uniform* windows, takes 8-bit values (which would
//! quantize the blurred images), and in 0.4.1 sums rather than averages the
//! (co)variances over a window, so C2 is not on their scale. Only its
//! K1 = 0.01, K2 = 0.03 match.

mod blur;
pub mod colour;
mod compare;
mod psnr;
mod ssim;
#[cfg(test)]
mod test_images;

pub use blur::blur;
pub use compare::compare;
pub use psnr::psnr;
pub use ssim::ssim;

use rayon::prelude::*;

/// A grey image with values in [0, 1] (1 = white), row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Grey {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` values, row by row.
    pub values: Vec<f32>,
}

impl Grey {
    /// An image from its values; Err if there are not `width × height`.
    ///
    /// ```
    /// use pixelpie::analyze::fidelity::Grey;
    /// assert!(Grey::new(2, 2, vec![1.0; 4]).is_ok());
    /// assert!(Grey::new(2, 2, vec![1.0; 3]).is_err());
    /// ```
    pub fn new(width: u32, height: u32, values: Vec<f32>) -> Result<Self, super::Error> {
        let img = Self {
            width,
            height,
            values,
        };
        img.check("image").map_err(super::Error::InvalidParameter)?;
        Ok(img)
    }

    /// A `width × height` image of one value.
    #[must_use]
    pub fn filled(width: u32, height: u32, value: f32) -> Self {
        Self {
            width,
            height,
            values: vec![value; pixel_count(width, height)],
        }
    }

    /// Width and height as `usize`.
    fn dims(&self) -> (usize, usize) {
        (self.width as usize, self.height as usize)
    }

    /// Err unless the values fill the image exactly.
    fn check(&self, what: &str) -> Result<(), String> {
        let n = pixel_count(self.width, self.height);
        if self.values.len() == n {
            Ok(())
        } else {
            Err(format!(
                "{what} has {} values for {}x{} pixels",
                self.values.len(),
                self.width,
                self.height
            ))
        }
    }

    /// Panics unless the values fill the image exactly.
    fn assert_valid(&self) {
        if let Err(e) = self.check("image") {
            panic!("{e}");
        }
    }

    /// The same image with every value mapped by `f`.
    pub(crate) fn map(&self, f: impl Fn(f32) -> f32 + Sync) -> Self {
        Self {
            width: self.width,
            height: self.height,
            values: self.values.par_iter().map(|&v| f(v)).collect(),
        }
    }
}

/// `width × height` as `usize`.
fn pixel_count(width: u32, height: u32) -> usize {
    width as usize * height as usize
}

/// The measures.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Fidelity {
    /// The blur's σ in photo pixels.
    pub sigma: f64,
    /// PSNR in dB on display grey (peak 1); `f64::INFINITY` when the
    /// blurred images are identical (serde_json writes it as `null`).
    pub psnr: f64,
    /// Mean SSIM on display grey.
    pub ssim: f64,
    /// PSNR in dB on linear light (peak 1); infinite as [`Fidelity::psnr`].
    pub psnr_linear: f64,
    /// Mean SSIM on linear light.
    pub ssim_linear: f64,
}

/// Panics unless `a` and `b` are valid images of the same size.
fn assert_same_size(a: &Grey, b: &Grey) {
    a.assert_valid();
    b.assert_valid();
    assert!(
        a.dims() == b.dims(),
        "images differ in size: {}x{} and {}x{}",
        a.width,
        a.height,
        b.width,
        b.height
    );
}
