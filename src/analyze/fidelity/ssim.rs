//! Mean SSIM (Wang et al. 2004): an 11×11 Gaussian window with σ = 1.5,
//! applied separably in `f64` over the windows that lie fully inside the
//! image, in fixed bands of rows in parallel.

use std::collections::VecDeque;
use std::ops::Range;

use rayon::prelude::*;

use super::{Grey, assert_same_size};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::fidelity::test_images::{add_noise, at, random, smooth};

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
}
