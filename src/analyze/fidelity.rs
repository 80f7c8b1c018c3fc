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

use std::collections::VecDeque;
use std::ops::Range;

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
    pub fn new(width: u32, height: u32, values: Vec<f32>) -> Result<Self, String> {
        let img = Self {
            width,
            height,
            values,
        };
        img.check("image")?;
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
    fn map(&self, f: impl Fn(f32) -> f32 + Sync) -> Self {
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

// ---------------------------------------------------------------- blur ----

/// Gaussian blur with standard deviation `sigma` (pixels): separable, radius
/// `ceil(3σ)`, edges reflected (half-sample symmetric; see the module doc).
/// `sigma = 0` returns a copy of the input.
///
/// # Panics
///
/// If `sigma` is negative or not finite, or the values do not fill the
/// image ([`compare`] checks both and returns an error instead).
///
/// ```
/// use pixelpie::analyze::fidelity::{blur, Grey};
/// let flat = Grey::filled(20, 10, 0.5);
/// assert!(blur(&flat, 3.0).values.iter().all(|&v| (v - 0.5).abs() < 1e-7));
/// ```
#[must_use]
pub fn blur(img: &Grey, sigma: f64) -> Grey {
    assert!(
        sigma.is_finite() && sigma >= 0.0,
        "blur sigma {sigma} must be a finite number >= 0"
    );
    img.assert_valid();
    let (w, h) = img.dims();
    if sigma == 0.0 || w == 0 || h == 0 {
        return img.clone();
    }
    let rows = blur_rows(&img.values, w, &line_kernel(sigma, w));
    Grey {
        width: img.width,
        height: img.height,
        values: blur_columns(&rows, w, h, &line_kernel(sigma, h)),
    }
}

/// The Gaussian's weights at offsets 0..=ceil(3σ) (each used on both
/// sides), normalized so that the full kernel sums to 1.
fn half_kernel(sigma: f64) -> Vec<f64> {
    // ceil(3σ) of a finite σ > 0; ≥ 1 so that tiny σ still gives a kernel.
    let radius = (3.0 * sigma).ceil().max(1.0) as usize;
    let mut k: Vec<f64> = (0..=radius)
        .map(|t| {
            let t = t as f64;
            (-t * t / (2.0 * sigma * sigma)).exp()
        })
        .collect();
    let total = k[0] + 2.0 * k[1..].iter().sum::<f64>();
    k.iter_mut().for_each(|v| *v /= total);
    k
}

/// [`half_kernel`] folded onto a reflected line of `n` values, so that its
/// radius is at most `n`. The reflected line is periodic with period `2n`
/// and symmetric, so offsets `±t` read the same values as the offsets
/// `±s`, `s = min(t mod 2n, 2n − t mod 2n)`: their weights add up there
/// (doubled at `s = 0`, where the two sides meet the centre). The result is
/// the same blur, at a cost per value that stops growing at σ ≈ n/3.
fn line_kernel(sigma: f64, n: usize) -> Vec<f32> {
    let full = half_kernel(sigma);
    let period = 2 * n;
    let mut folded = vec![0.0f64; full.len().min(n + 1)];
    for (t, &k) in full.iter().enumerate() {
        let s = t % period;
        let s = s.min(period - s);
        folded[s] += if t > 0 && s == 0 { 2.0 * k } else { k };
    }
    folded.iter().map(|&k| k as f32).collect()
}

/// Index `i` of a reflected (half-sample symmetric) sequence of length `n`.
fn reflect(i: isize, n: usize) -> usize {
    let n = n as isize;
    let m = i.rem_euclid(2 * n);
    (if m < n { m } else { 2 * n - 1 - m }) as usize
}

/// Reusable buffers of one blur task.
#[derive(Default)]
struct Scratch {
    /// A row with its reflected margins.
    pad: Vec<f32>,
    /// The weighted sum of the taps.
    acc: Vec<f32>,
    /// Twice the centre line.
    twice: Vec<f32>,
}

/// Blurs every row of `src` (rows of `width` values) with the half kernel.
fn blur_rows(src: &[f32], width: usize, kernel: &[f32]) -> Vec<f32> {
    let r = kernel.len() - 1;
    let mut dst = vec![0.0f32; src.len()];
    dst.par_chunks_mut(width)
        .zip(src.par_chunks(width))
        .for_each_init(Scratch::default, |scratch, (out, row)| {
            let Scratch { pad, acc, twice } = scratch;
            pad_reflected(row, r, pad);
            let pairs = (1..=r).map(|t| (&pad[r - t..][..width], &pad[r + t..][..width]));
            convolve(row, pairs, kernel, (acc, twice), out);
        });
    dst
}

/// Blurs every column of `src` (`height` rows of `width` values), one
/// output row at a time from whole input rows.
fn blur_columns(src: &[f32], width: usize, height: usize, kernel: &[f32]) -> Vec<f32> {
    let row = |i: isize| &src[reflect(i, height) * width..][..width];
    let mut dst = vec![0.0f32; src.len()];
    dst.par_chunks_mut(width)
        .enumerate()
        .for_each_init(Scratch::default, |scratch, (y, out)| {
            let y = y as isize;
            let pairs = (1..kernel.len() as isize).map(|t| (row(y - t), row(y + t)));
            convolve(
                row(y),
                pairs,
                kernel,
                (&mut scratch.acc, &mut scratch.twice),
                out,
            );
        });
    dst
}

/// `row` with `r` reflected values on each side, into `pad`.
fn pad_reflected(row: &[f32], r: usize, pad: &mut Vec<f32>) {
    let n = row.len();
    let side = |from: isize| (from..from + r as isize).map(move |i| row[reflect(i, n)]);
    pad.clear();
    pad.extend(side(-(r as isize)));
    pad.extend_from_slice(row);
    pad.extend(side(n as isize));
}

/// One line of the symmetric convolution:
/// `out = c + Σ_{t≥1} k_t·(p_t + q_t − 2c)`, where `c` is the line itself
/// and `p_t`, `q_t` the lines `t` before and after it. This equals
/// `Σ_t k_t·line_t` with `k_0 = 1 − 2Σ_{t≥1} k_t`, so the weights sum to 1
/// exactly, and the blur of a constant is that constant even in `f32`.
/// Taps go two per sweep over the line.
fn convolve<'a>(
    centre: &[f32],
    pairs: impl Iterator<Item = (&'a [f32], &'a [f32])>,
    kernel: &[f32],
    (acc, twice): (&mut Vec<f32>, &mut Vec<f32>),
    out: &mut [f32],
) {
    acc.clear();
    acc.resize(centre.len(), 0.0);
    twice.clear();
    twice.extend(centre.iter().map(|&c| c + c));
    let mut taps = pairs.zip(&kernel[1..]).map(|((p, q), &k)| (p, q, k));
    while let Some(first) = taps.next() {
        match taps.next() {
            Some(second) => sweep(acc, twice, [first, second]),
            None => sweep(acc, twice, [first]),
        }
    }
    for ((o, &a), &c) in out.iter_mut().zip(acc.iter()).zip(centre) {
        *o = c + a;
    }
}

/// Adds `Σ k·(p + q − twice)` over the `N` taps `(p, q, k)` to `acc`.
fn sweep<const N: usize>(acc: &mut [f32], twice: &[f32], taps: [(&[f32], &[f32], f32); N]) {
    let n = acc.len();
    let twice = &twice[..n];
    let taps = taps.map(|(p, q, k)| (&p[..n], &q[..n], k));
    for x in 0..n {
        let mut s = 0.0;
        for (p, q, k) in &taps {
            s += k * ((p[x] + q[x]) - twice[x]);
        }
        acc[x] += s;
    }
}

// ---------------------------------------------------------------- PSNR ----

/// PSNR in dB with peak value 1: `10·log10(1 / MSE)`; `f64::INFINITY` when
/// the images are identical (or empty).
///
/// # Panics
///
/// If the sizes differ or the values do not fill the images.
///
/// ```
/// use pixelpie::analyze::fidelity::{psnr, Grey};
/// let p = psnr(&Grey::filled(4, 4, 0.5), &Grey::filled(4, 4, 0.6));
/// assert!((p - 20.0).abs() < 1e-5);
/// ```
#[must_use]
pub fn psnr(a: &Grey, b: &Grey) -> f64 {
    assert_same_size(a, b);
    let mse = mean_squared_error(a, b);
    if mse == 0.0 {
        f64::INFINITY
    } else {
        -10.0 * mse.log10()
    }
}

/// The mean of the squared differences, in `f64`; 0 for empty images.
/// Rows are summed in parallel, then in order, so the result is
/// reproducible.
fn mean_squared_error(a: &Grey, b: &Grey) -> f64 {
    let (w, _) = a.dims();
    if a.values.is_empty() {
        return 0.0;
    }
    let rows: Vec<f64> = a
        .values
        .par_chunks(w)
        .zip(b.values.par_chunks(w))
        .map(|(p, q)| {
            p.iter()
                .zip(q)
                .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
                .sum()
        })
        .collect();
    rows.iter().sum::<f64>() / a.values.len() as f64
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

// ---------------------------------------------------------------- SSIM ----

/// SSIM window side (Wang et al. 2004).
const SSIM_SIDE: usize = 11;
/// SSIM window σ.
const SSIM_SIGMA: f64 = 1.5;
/// C1 = (K1·L)², K1 = 0.01, L = 1.
const C1: f64 = 0.01 * 0.01;
/// C2 = (K2·L)², K2 = 0.03, L = 1.
const C2: f64 = 0.03 * 0.03;
/// Output rows per parallel SSIM task (fixed, so that the sum's rounding
/// does not depend on the number of threads).
const BAND: usize = 128;

/// Mean SSIM: 11×11 Gaussian window, σ = 1.5, normalized;
/// C1 = (0.01·L)², C2 = (0.03·L)², L = 1 (Wang et al. 2004). Only windows
/// fully inside the image count (MATLAB's `'valid'`); a side shorter than 11
/// pixels uses a centred window of that length. 1 for empty images.
///
/// # Panics
///
/// If the sizes differ or the values do not fill the images.
///
/// ```
/// use pixelpie::analyze::fidelity::{ssim, Grey};
/// let a = Grey::filled(16, 16, 0.5);
/// assert_eq!(ssim(&a, &a), 1.0);
/// // Constants: only the luminance term, (2·0.5·0.25 + C1) / (0.5² + 0.25² + C1).
/// let s = ssim(&a, &Grey::filled(16, 16, 0.25));
/// assert!((s - 0.2501 / 0.3126).abs() < 1e-9);
/// ```
#[must_use]
pub fn ssim(a: &Grey, b: &Grey) -> f64 {
    assert_same_size(a, b);
    let (w, h) = a.dims();
    if w == 0 || h == 0 {
        return 1.0;
    }
    let kx = ssim_window(w);
    let ky = ssim_window(h);
    let out_h = h - ky.len() + 1;
    let out_w = w - kx.len() + 1;
    let starts: Vec<usize> = (0..out_h).step_by(BAND).collect();
    let sums: Vec<f64> = starts
        .par_iter()
        .map(|&y0| {
            let rows = y0..(y0 + BAND).min(out_h);
            ssim_band(a, b, &kx, &ky, rows)
        })
        .collect();
    sums.iter().sum::<f64>() / (out_w * out_h) as f64
}

/// The normalized Gaussian SSIM window along a side of `n > 0` pixels:
/// 11 taps, or `n` taps centred on the side when it is shorter.
fn ssim_window(n: usize) -> Vec<f64> {
    let m = n.min(SSIM_SIDE);
    let centre = (m as f64 - 1.0) / 2.0;
    let w: Vec<f64> = (0..m)
        .map(|i| {
            let d = i as f64 - centre;
            (-d * d / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp()
        })
        .collect();
    let total: f64 = w.iter().sum();
    w.iter().map(|v| v / total).collect()
}

/// The five local moments E[x], E[y], E[x²], E[y²], E[xy], one row each.
struct Moments([Vec<f64>; 5]);

impl Moments {
    /// Five rows of `n` zeros.
    fn zeros(n: usize) -> Self {
        Self(std::array::from_fn(|_| vec![0.0; n]))
    }
}

/// The sum of the SSIM map over the output rows `rows` (window top rows).
/// The horizontal window sums of the `ky.len()` input rows under the
/// window are kept in a ring, one new row per output row.
fn ssim_band(a: &Grey, b: &Grey, kx: &[f64], ky: &[f64], rows: Range<usize>) -> f64 {
    let (w, _) = a.dims();
    let out_w = w - kx.len() + 1;
    let mut sources = Moments::zeros(w);
    let mut horizontal = |y: usize, out: &mut Moments| {
        let span = y * w..(y + 1) * w;
        row_moments(
            &a.values[span.clone()],
            &b.values[span],
            kx,
            &mut sources,
            out,
        );
    };
    let mut ring: VecDeque<Moments> = (rows.start..rows.start + ky.len())
        .map(|y| {
            let mut m = Moments::zeros(out_w);
            horizontal(y, &mut m);
            m
        })
        .collect();
    let mut vertical = Moments::zeros(out_w);
    let mut total = 0.0;
    for y in rows.clone() {
        for (c, acc) in vertical.0.iter_mut().enumerate() {
            symmetric_sum(acc, ky, |j| &ring[j].0[c]);
        }
        total += ssim_row_sum(&vertical);
        if y + 1 < rows.end
            && let Some(mut oldest) = ring.pop_front()
        {
            horizontal(y + ky.len(), &mut oldest);
            ring.push_back(oldest);
        }
    }
    total
}

/// Horizontal window sums of the five moments of one image row pair into
/// `out`; `sources` is scratch space of the row's length.
fn row_moments(a: &[f32], b: &[f32], kx: &[f64], sources: &mut Moments, out: &mut Moments) {
    let [x, y, xx, yy, xy] = &mut sources.0;
    for (i, (&p, &q)) in a.iter().zip(b).enumerate() {
        let (p, q) = (f64::from(p), f64::from(q));
        (x[i], y[i], xx[i], yy[i], xy[i]) = (p, q, p * p, q * q, p * q);
    }
    for (acc, src) in out.0.iter_mut().zip(&sources.0) {
        let n = acc.len();
        symmetric_sum(acc, kx, |j| &src[j..j + n]);
    }
}

/// `acc = Σ_j k_j·line(j)` for a symmetric window `k`, adding the lines
/// `j` and `len − 1 − j` before weighting them.
fn symmetric_sum<'a>(acc: &mut [f64], k: &[f64], line: impl Fn(usize) -> &'a [f64]) {
    let m = k.len();
    acc.fill(0.0);
    for (j, &kj) in k.iter().enumerate().take(m / 2) {
        for ((a, &p), &q) in acc.iter_mut().zip(line(j)).zip(line(m - 1 - j)) {
            *a += kj * (p + q);
        }
    }
    if m % 2 == 1 {
        for (a, &p) in acc.iter_mut().zip(line(m / 2)) {
            *a += k[m / 2] * p;
        }
    }
}

/// The sum of the SSIM values of one row of window moments.
fn ssim_row_sum(m: &Moments) -> f64 {
    let [mx, my, xx, yy, xy] = &m.0;
    (0..mx.len())
        .map(|i| {
            let (ux, uy) = (mx[i], my[i]);
            let vx = xx[i] - ux * ux;
            let vy = yy[i] - uy * uy;
            let cov = xy[i] - ux * uy;
            ((2.0 * ux * uy + C1) * (2.0 * cov + C2)) / ((ux * ux + uy * uy + C1) * (vx + vy + C2))
        })
        .sum()
}

// ------------------------------------------------------------- compare ----

/// Blurs both images by `sigma` and measures them, on display grey and on
/// linear light (each pixel decoded with the sRGB transfer function before
/// blurring).
///
/// Errors if the values do not fill an image, the images are empty or of
/// different sizes, or `sigma` is not a finite number `>= 0`.
///
/// ```
/// use pixelpie::analyze::fidelity::{compare, Grey};
/// let photo = Grey::filled(32, 32, 0.5);
/// let f = compare(&photo, &Grey::filled(32, 32, 0.25), 4.0).unwrap();
/// assert!((f.psnr - 20.0 * 4f64.log10()).abs() < 1e-6);
/// assert!(compare(&photo, &Grey::filled(32, 31, 0.5), 4.0).is_err());
/// ```
pub fn compare(photo: &Grey, drawing: &Grey, sigma: f64) -> Result<Fidelity, String> {
    validate(photo, drawing, sigma)?;
    let ((psnr, ssim), (psnr_linear, ssim_linear)) = rayon::join(
        || measure(photo, drawing, sigma),
        || {
            let (p, d) = rayon::join(|| photo.map(srgb_to_linear), || drawing.map(srgb_to_linear));
            measure(&p, &d, sigma)
        },
    );
    Ok(Fidelity {
        sigma,
        psnr,
        ssim,
        psnr_linear,
        ssim_linear,
    })
}

/// The errors of [`compare`].
fn validate(photo: &Grey, drawing: &Grey, sigma: f64) -> Result<(), String> {
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(format!("blur sigma {sigma} must be a finite number >= 0"));
    }
    photo.check("photo")?;
    drawing.check("drawing")?;
    if photo.dims() != drawing.dims() {
        return Err(format!(
            "photo is {}x{} but drawing is {}x{}",
            photo.width, photo.height, drawing.width, drawing.height
        ));
    }
    if photo.values.is_empty() {
        return Err(format!(
            "images are empty ({}x{})",
            photo.width, photo.height
        ));
    }
    Ok(())
}

/// PSNR and SSIM of the two images blurred by `sigma`.
fn measure(a: &Grey, b: &Grey, sigma: f64) -> (f64, f64) {
    let (a, b) = rayon::join(|| blur(a, sigma), || blur(b, sigma));
    rayon::join(|| psnr(&a, &b), || ssim(&a, &b))
}

/// The sRGB transfer function's inverse: display grey to linear light.
fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random value in [0, 1) (an LCG).
    fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 40) as f32 / (1u64 << 24) as f32
    }

    fn random(width: u32, height: u32, seed: u64) -> Grey {
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
    fn checkerboard(width: u32, height: u32) -> Grey {
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
    fn smooth(width: u32, height: u32) -> Grey {
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

    fn add_noise(img: &Grey, amplitude: f32, seed: u64) -> Grey {
        let mut s = seed;
        let mut out = img.clone();
        for v in &mut out.values {
            *v += amplitude * (lcg(&mut s) - 0.5);
        }
        out
    }

    fn at(img: &Grey, x: usize, y: usize) -> f32 {
        img.values[y * img.width as usize + x]
    }

    fn sum(img: &Grey) -> f64 {
        img.values.iter().map(|&v| f64::from(v)).sum()
    }

    /// Direct 2-D SSIM with the full 11×11 window, for reference.
    fn naive_ssim(a: &Grey, b: &Grey) -> f64 {
        let (w, h) = a.dims();
        let k = ssim_window(SSIM_SIDE);
        let mut total = 0.0;
        let mut count = 0;
        for y0 in 0..=h - SSIM_SIDE {
            for x0 in 0..=w - SSIM_SIDE {
                let mut m = [0.0f64; 5];
                for (j, ky) in k.iter().enumerate() {
                    for (i, kx) in k.iter().enumerate() {
                        let p = f64::from(at(a, x0 + i, y0 + j));
                        let q = f64::from(at(b, x0 + i, y0 + j));
                        let wt = kx * ky;
                        m[0] += wt * p;
                        m[1] += wt * q;
                        m[2] += wt * p * p;
                        m[3] += wt * q * q;
                        m[4] += wt * p * q;
                    }
                }
                let (vx, vy, c) = (m[2] - m[0] * m[0], m[3] - m[1] * m[1], m[4] - m[0] * m[1]);
                total += ((2.0 * m[0] * m[1] + C1) * (2.0 * c + C2))
                    / ((m[0] * m[0] + m[1] * m[1] + C1) * (vx + vy + C2));
                count += 1;
            }
        }
        total / f64::from(count)
    }

    #[test]
    fn identical_images_are_perfect() {
        let a = random(40, 30, 1);
        assert_eq!(ssim(&a, &a), 1.0);
        assert_eq!(psnr(&a, &a), f64::INFINITY);
        let f = compare(&a, &a, 3.0).unwrap();
        assert_eq!((f.psnr, f.psnr_linear), (f64::INFINITY, f64::INFINITY));
        assert_eq!((f.ssim, f.ssim_linear), (1.0, 1.0));
        let json = serde_json::to_string(&f).unwrap();
        assert!(json.contains(r#""psnr":null"#), "{json}");
    }

    #[test]
    fn fine_checkerboard_matches_its_grey_after_blur() {
        let grey = Grey::filled(128, 128, 0.5);
        let f = compare(&grey, &checkerboard(128, 128), 4.0).unwrap();
        assert!(f.psnr > 30.0, "{f:?}");
        assert!(f.ssim > 0.9, "{f:?}");
    }

    #[test]
    fn constants_give_the_exact_psnr() {
        let f = compare(&Grey::filled(64, 48, 0.5), &Grey::filled(64, 48, 0.25), 4.0).unwrap();
        assert!(
            (f.psnr - 20.0 * (1.0f64 / 0.25).log10()).abs() < 1e-6,
            "{f:?}"
        );
        assert!((f.psnr - 12.041_199_826_559_248).abs() < 1e-6);
    }

    #[test]
    fn psnr_of_a_constant_offset() {
        let a = random(50, 40, 2).map(|v| 0.8 * v);
        for (offset, db) in [(0.1f32, 20.0), (0.01, 40.0)] {
            let b = a.map(|v| v + offset);
            assert!(
                (psnr(&a, &b) - db).abs() < 1e-4,
                "{offset}: {}",
                psnr(&a, &b)
            );
        }
    }

    #[test]
    fn ssim_falls_as_noise_grows() {
        let a = smooth(60, 50);
        let values: Vec<f64> = [0.0, 0.02, 0.1, 0.3, 0.6]
            .iter()
            .map(|&amp| ssim(&a, &add_noise(&a, amp, 7)))
            .collect();
        assert_eq!(values[0], 1.0);
        assert!(values.windows(2).all(|w| w[1] < w[0]), "{values:?}");
    }

    #[test]
    fn ssim_matches_the_direct_window_sum() {
        let a = random(37, 23, 3);
        let b = add_noise(&smooth(37, 23), 0.2, 4);
        let (fast, slow) = (ssim(&a, &b), naive_ssim(&a, &b));
        assert!((fast - slow).abs() < 1e-12, "{fast} vs {slow}");
        // Bands: more than one BAND of output rows.
        let a = random(20, 2 * BAND as u32 + 15, 5);
        let b = add_noise(&a, 0.3, 6);
        assert!((ssim(&a, &b) - naive_ssim(&a, &b)).abs() < 1e-12);
    }

    #[test]
    fn ssim_constants_give_the_luminance_term() {
        let s = ssim(&Grey::filled(20, 20, 0.5), &Grey::filled(20, 20, 0.25));
        assert!((s - (0.25 + C1) / (0.3125 + C1)).abs() < 1e-12, "{s}");
    }

    #[test]
    fn ssim_of_small_images_uses_what_fits() {
        let a = random(5, 3, 8);
        assert_eq!(ssim(&a, &a), 1.0);
        assert!(ssim(&a, &add_noise(&a, 0.5, 9)) < 1.0);
        let one = Grey::filled(1, 1, 0.5);
        let s = ssim(&one, &Grey::filled(1, 1, 0.25));
        assert!((s - (0.25 + C1) / (0.3125 + C1)).abs() < 1e-12);
        assert_eq!(ssim_window(4).len(), 4);
        assert!((ssim_window(4)[0] - ssim_window(4)[3]).abs() < 1e-15);
    }

    #[test]
    fn blur_keeps_constants_and_sums() {
        let flat = blur(&Grey::filled(30, 20, 0.3), 2.5);
        assert!(flat.values.iter().all(|&v| (v - 0.3).abs() < 1e-7));
        let a = random(37, 23, 10);
        // σ = 20 reaches across the image more than once.
        for sigma in [0.4, 1.0, 5.0, 20.0] {
            let b = blur(&a, sigma);
            assert!(
                (sum(&b) - sum(&a)).abs() < 1e-4,
                "σ {sigma}: {} vs {}",
                sum(&b),
                sum(&a)
            );
        }
        let k = half_kernel(3.7);
        assert_eq!(k.len(), 13); // ceil(3 · 3.7) + 1
        assert!((k[0] + 2.0 * k[1..].iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn blur_of_an_impulse_is_the_gaussian() {
        let sigma = 4.0;
        let mut img = Grey::filled(61, 61, 0.0);
        img.values[30 * 61 + 30] = 1.0;
        let b = blur(&img, sigma);
        assert!((sum(&b) - 1.0).abs() < 1e-6);
        let c = f64::from(at(&b, 30, 30));
        for (dx, dy) in [(4usize, 0usize), (0, 4), (3, 4), (8, 0)] {
            let want = (-((dx * dx + dy * dy) as f64) / (2.0 * sigma * sigma)).exp();
            let got = f64::from(at(&b, 30 + dx, 30 + dy)) / c;
            assert!((got - want).abs() < 1e-5, "({dx}, {dy}): {got} vs {want}");
        }
        assert_eq!(at(&b, 30 + 13, 30), 0.0); // beyond ceil(3σ) = 12
        // Variance along x: σ² less what the truncation at 3σ cuts (2%).
        let var: f64 = (0..61)
            .map(|x| f64::from(at(&b, x, 30)) / c * ((x as f64 - 30.0).powi(2)))
            .sum::<f64>()
            / (0..61).map(|x| f64::from(at(&b, x, 30)) / c).sum::<f64>();
        assert!((var / (sigma * sigma) - 0.981).abs() < 0.002, "{var}");
    }

    #[test]
    fn folded_kernels_give_the_direct_sum() {
        // σ = 4: radius 12 reaches past a line of 5 values, several times.
        let sigma = 4.0;
        let line = [0.1f32, 0.9, 0.4, 0.0, 0.7];
        let k = half_kernel(sigma);
        let direct: Vec<f64> = (0..5isize)
            .map(|x| {
                (-12..=12isize)
                    .map(|t| k[t.unsigned_abs()] * f64::from(line[reflect(x + t, 5)]))
                    .sum()
            })
            .collect();
        assert_eq!(line_kernel(sigma, 5).len(), 6);
        assert_eq!(line_kernel(sigma, 40).len(), 13);
        let b = blur(&Grey::new(5, 1, line.to_vec()).unwrap(), sigma);
        for (got, want) in b.values.iter().zip(&direct) {
            assert!((f64::from(*got) - want).abs() < 1e-6, "{got} vs {want}");
        }
        // A single pixel stays itself.
        assert_eq!(blur(&Grey::filled(1, 1, 0.3), 50.0).values, [0.3]);
    }

    #[test]
    fn blur_reflects_at_the_edges() {
        // A step at the border: reflection sees the edge value continue.
        let mut img = Grey::filled(9, 1, 0.0);
        img.values[0] = 1.0;
        let b = blur(&img, 1.0);
        let k = half_kernel(1.0);
        // Pixel 0 gets k0 from itself and k1 from its mirror at -1.
        assert!((f64::from(b.values[0]) - (k[0] + k[1])).abs() < 1e-7);
        assert_eq!(reflect(-1, 5), 0);
        assert_eq!(reflect(5, 5), 4);
        assert_eq!(reflect(-7, 5), 3);
        assert_eq!(reflect(12, 5), 2);
    }

    #[test]
    fn zero_sigma_is_the_identity() {
        let a = random(13, 7, 11);
        assert_eq!(blur(&a, 0.0), a);
        let f = compare(&a, &add_noise(&a, 0.1, 12), 0.0).unwrap();
        assert!(f.psnr < 40.0 && f.ssim < 1.0);
    }

    #[test]
    fn linear_and_display_grey_differ_as_expected() {
        // Half the pixels black: 50% linear light, shown as display grey 0.735.
        let board = checkerboard(128, 128);
        let display_half = 1.055 * 0.5f64.powf(1.0 / 2.4) - 0.055;
        assert!((f64::from(srgb_to_linear(display_half as f32)) - 0.5).abs() < 1e-6);
        let f = compare(&Grey::filled(128, 128, display_half as f32), &board, 4.0).unwrap();
        assert!(f.psnr_linear > 30.0 && f.psnr < 15.0, "{f:?}");
        assert!(f.ssim_linear > f.ssim);
        // A photo of display grey 0.5 matches in display grey only.
        let f = compare(&Grey::filled(128, 128, 0.5), &board, 4.0).unwrap();
        assert!(f.psnr > 30.0 && f.psnr_linear < 15.0, "{f:?}");
        // The transfer function's ends and its continuity at the knee.
        assert_eq!((srgb_to_linear(0.0), srgb_to_linear(1.0)), (0.0, 1.0));
        assert!((srgb_to_linear(0.040_45) - srgb_to_linear(0.040_46)).abs() < 1e-5);
    }

    #[test]
    fn compare_refuses_bad_input() {
        let a = Grey::filled(8, 8, 0.5);
        assert!(compare(&a, &Grey::filled(8, 9, 0.5), 1.0).is_err());
        for sigma in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(compare(&a, &a, sigma).is_err(), "{sigma}");
        }
        let short = Grey {
            width: 8,
            height: 8,
            values: vec![0.5; 63],
        };
        assert!(compare(&a, &short, 1.0).unwrap_err().contains("63 values"));
        let empty = Grey::filled(0, 5, 0.5);
        assert!(compare(&empty, &empty, 1.0).is_err());
        assert!(Grey::new(3, 3, vec![0.0; 9]).is_ok());
    }
}
