//! The Gaussian blur: separable, truncated at `ceil(3σ)`, edges reflected
//! (half-sample symmetric), a kernel longer than a line folded onto it, in
//! `f32` with a constant kept exactly constant, lines in parallel.

use rayon::prelude::*;

use super::Grey;

/// Gaussian blur with standard deviation `sigma` (pixels): separable, radius
/// `ceil(3σ)`, edges reflected (half-sample symmetric; see the module doc).
/// `sigma = 0` returns a copy of the input.
///
/// # Panics
///
/// If `sigma` is negative or not finite, or the values do not fill the
/// image ([`compare`](super::compare) checks both and returns an error instead).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::fidelity::test_images::{at, random, sum};

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
}
