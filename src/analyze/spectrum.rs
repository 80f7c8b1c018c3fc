//! Fourier analysis of point sets after Schlömer & Deussen (2011), the PSA
//! tool the paper uses for Figures 7 and 10.
//!
//! Conventions (PSA's): the points are mapped to the unit torus,
//! u = x / width, v = y / height, and the **periodogram** at integer
//! frequency f = (k, l) is P(f) = |Σ_n exp(−2πi (k u_n + l v_n))|² / N,
//! computed exactly (no binning), so that a Poisson (white-noise) set has
//! P ≈ 1 at every f ≠ 0 and P(0) = N. Frequencies run over [−K, K]².
//! The **radially averaged power spectrum** averages P over the rings
//! i − ½ ≤ |f| < i + ½, i = 1…K; the **anisotropy** is the ring's variance
//! over its squared mean, in dB: 10 log₁₀(σ²/μ²). A single periodogram's
//! values are exponentially distributed, so an isotropic spectrum reads about
//! 0 dB; averaging M sets ([`average`]) lowers that to −10 log₁₀ M (PSA's
//! −10 dB reference is for 10 sets). Radial spikes, such as those of a grid,
//! read well above it.

use rayon::prelude::*;

/// A periodogram over the frequencies [−K, K]².
#[derive(Clone, Debug, PartialEq)]
pub struct Periodogram {
    /// K: the largest frequency per axis, in cycles per domain side.
    pub max_frequency: usize,
    /// P, row-major: row l = −K…K (top to bottom), column k = −K…K.
    pub power: Vec<f64>,
    /// The number of points (of each set, when averaged).
    pub count: usize,
    /// How many point sets' periodograms were averaged ([`average`]).
    pub sets: usize,
}

impl Periodogram {
    /// The side of the frequency grid, 2K + 1.
    #[must_use]
    pub fn side(&self) -> usize {
        2 * self.max_frequency + 1
    }

    /// P at frequency (k, l).
    #[must_use]
    pub fn at(&self, k: i64, l: i64) -> f64 {
        let kk = self.max_frequency as i64;
        self.power[((l + kk) as usize) * self.side() + (k + kk) as usize]
    }
}

/// A default K for N points: 2.5 √N, between 16 and 512. The principal peak
/// of a blue-noise set sits near √N, so this shows it and the flat tail.
#[must_use]
pub fn default_max_frequency(n: usize) -> usize {
    ((2.5 * (n as f64).sqrt()).ceil() as usize).clamp(16, 512)
}

/// The exact periodogram of `points` on a `width`×`height` domain.
///
/// ```
/// use pixelpie::analyze::spectrum::periodogram;
/// // Four points of a 2×2 grid: power only at even frequencies.
/// let pts = [[0.0, 0.0], [5.0, 0.0], [0.0, 5.0], [5.0, 5.0]];
/// let p = periodogram(&pts, (10.0, 10.0), 4);
/// assert!((p.at(0, 0) - 4.0).abs() < 1e-6);
/// assert!((p.at(2, 0) - 4.0).abs() < 1e-4);
/// assert!(p.at(1, 0).abs() < 1e-6);
/// ```
#[must_use]
pub fn periodogram(points: &[[f64; 2]], domain: (f64, f64), max_frequency: usize) -> Periodogram {
    let k = max_frequency as i64;
    let side = 2 * max_frequency + 1;
    let n = points.len();
    // exp(−2πi l v_n) for l = −K…K, per point: split real and imaginary
    // parts, f32, so that the inner loop vectorizes.
    let mut ey_re = vec![0f32; n * side];
    let mut ey_im = vec![0f32; n * side];
    ey_re
        .par_chunks_mut(side)
        .zip(ey_im.par_chunks_mut(side))
        .zip(points.par_iter())
        .for_each(|((re, im), p)| {
            let v = p[1] / domain.1;
            for (j, l) in (-k..=k).enumerate() {
                let (s, c) = (-2.0 * std::f64::consts::PI * (l as f64) * v).sin_cos();
                re[j] = c as f32;
                im[j] = s as f32;
            }
        });
    // Rows k ≥ 0 only: P(−f) = P(f).
    const CHUNK: usize = 256;
    let half: Vec<Vec<f64>> = (0..=k)
        .into_par_iter()
        .map(|kx| {
            let mut row = vec![0f64; 2 * side];
            let mut acc_re = vec![0f32; side];
            let mut acc_im = vec![0f32; side];
            for start in (0..n).step_by(CHUNK) {
                acc_re.iter_mut().for_each(|a| *a = 0.0);
                acc_im.iter_mut().for_each(|a| *a = 0.0);
                for i in start..(start + CHUNK).min(n) {
                    let u = points[i][0] / domain.0;
                    let (s, c) = (-2.0 * std::f64::consts::PI * (kx as f64) * u).sin_cos();
                    let (ar, ai) = (c as f32, s as f32);
                    let er = &ey_re[i * side..(i + 1) * side];
                    let ei = &ey_im[i * side..(i + 1) * side];
                    for j in 0..side {
                        acc_re[j] += ar * er[j] - ai * ei[j];
                        acc_im[j] += ar * ei[j] + ai * er[j];
                    }
                }
                for j in 0..side {
                    row[2 * j] += f64::from(acc_re[j]);
                    row[2 * j + 1] += f64::from(acc_im[j]);
                }
            }
            (0..side)
                .map(|j| (row[2 * j].powi(2) + row[2 * j + 1].powi(2)) / n.max(1) as f64)
                .collect()
        })
        .collect();
    let mut power = vec![0f64; side * side];
    for (kx, col) in half.iter().enumerate() {
        for (j, &p) in col.iter().enumerate() {
            let l = j as i64 - k;
            // (kx, l) and its mirror (−kx, −l).
            power[j * side + (kx as i64 + k) as usize] = p;
            power[((-l + k) as usize) * side + (-(kx as i64) + k) as usize] = p;
        }
    }
    Periodogram {
        max_frequency,
        power,
        count: n,
        sets: 1,
    }
}

/// The mean of periodograms of the same size, as PSA averages several
/// realizations: the noise of each frequency drops by √sets, and so does the
/// anisotropy of an isotropic spectrum, to −10 log₁₀(sets) dB.
///
/// ```
/// use pixelpie::analyze::spectrum::{average, periodogram};
/// let a = periodogram(&[[1.0, 2.0], [5.0, 3.0]], (8.0, 8.0), 4);
/// let b = periodogram(&[[7.0, 1.0], [2.0, 6.0]], (8.0, 8.0), 4);
/// let m = average(&[a.clone(), b.clone()]).unwrap();
/// assert_eq!(m.sets, 2);
/// assert!((m.at(1, 2) - (a.at(1, 2) + b.at(1, 2)) / 2.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn average(periodograms: &[Periodogram]) -> Option<Periodogram> {
    let first = periodograms.first()?;
    if periodograms
        .iter()
        .any(|p| p.max_frequency != first.max_frequency)
    {
        return None;
    }
    let sets: usize = periodograms.iter().map(|p| p.sets).sum();
    let mut power = vec![0f64; first.power.len()];
    for p in periodograms {
        for (acc, v) in power.iter_mut().zip(&p.power) {
            *acc += v * p.sets as f64;
        }
    }
    power.iter_mut().for_each(|v| *v /= sets as f64);
    Some(Periodogram {
        max_frequency: first.max_frequency,
        power,
        count: first.count,
        sets,
    })
}

/// The radial average and anisotropy of a periodogram, for rings 1…K.
#[derive(Clone, Debug, PartialEq)]
pub struct RadialSpectrum {
    /// Ring radii i = 1…K (cycles per domain side).
    pub frequency: Vec<f64>,
    /// Mean power in each ring.
    pub power: Vec<f64>,
    /// 10 log₁₀(variance / mean²) in each ring, in dB.
    pub anisotropy_db: Vec<f64>,
    /// The number of sets averaged: an isotropic spectrum's anisotropy is
    /// about −10 log₁₀(sets) dB.
    pub sets: usize,
}

/// Averages `p` over rings of width 1.
///
/// ```
/// use pixelpie::analyze::spectrum::{periodogram, radial};
/// let pts: Vec<[f64; 2]> = (0..64).map(|i| [(i % 8) as f64 + 0.5, (i / 8) as f64 + 0.5]).collect();
/// let r = radial(&periodogram(&pts, (8.0, 8.0), 8));
/// // An 8×8 grid has power only on its lattice: none in rings 1 to 7.
/// assert!(r.power[..7].iter().all(|&p| p < 1e-6));
/// assert!(r.power[7] > 1.0);
/// ```
#[must_use]
pub fn radial(p: &Periodogram) -> RadialSpectrum {
    let k = p.max_frequency as i64;
    let mut sum = vec![0f64; p.max_frequency + 1];
    let mut sum2 = vec![0f64; p.max_frequency + 1];
    let mut count = vec![0u64; p.max_frequency + 1];
    for l in -k..=k {
        for kx in -k..=k {
            let ring = ((kx * kx + l * l) as f64).sqrt().round() as usize;
            if ring == 0 || ring > p.max_frequency {
                continue;
            }
            let v = p.at(kx, l);
            sum[ring] += v;
            sum2[ring] += v * v;
            count[ring] += 1;
        }
    }
    let mut out = RadialSpectrum {
        frequency: Vec::new(),
        power: Vec::new(),
        anisotropy_db: Vec::new(),
        sets: p.sets,
    };
    for i in 1..=p.max_frequency {
        let c = count[i].max(1) as f64;
        let mean = sum[i] / c;
        let var = (sum2[i] / c - mean * mean).max(0.0);
        out.frequency.push(i as f64);
        out.power.push(mean);
        out.anisotropy_db.push(if mean > 0.0 && var > 0.0 {
            10.0 * (var / (mean * mean)).log10()
        } else {
            f64::NEG_INFINITY
        });
    }
    out
}

/// Summary numbers of a radial spectrum.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SpectrumSummary {
    /// K.
    pub max_frequency: usize,
    /// The ring with the highest mean power.
    pub peak_frequency: f64,
    /// Its mean power (1 = white noise).
    pub peak_power: f64,
    /// Mean power over rings below half the peak frequency (blue noise: ≪ 1).
    pub low_frequency_power: f64,
    /// Mean anisotropy over rings from half the peak to K, in dB.
    pub mean_anisotropy_db: f64,
}

/// Summarizes `r`.
///
/// ```
/// use pixelpie::analyze::spectrum::{RadialSpectrum, summary};
/// let r = RadialSpectrum {
///     frequency: vec![1.0, 2.0, 3.0, 4.0],
///     power: vec![0.1, 0.2, 1.8, 1.0],
///     anisotropy_db: vec![0.0; 4],
///     sets: 1,
/// };
/// let s = summary(&r);
/// assert_eq!((s.peak_frequency, s.peak_power), (3.0, 1.8));
/// assert!((s.low_frequency_power - 0.1).abs() < 1e-12);
/// ```
#[must_use]
pub fn summary(r: &RadialSpectrum) -> SpectrumSummary {
    let (mut peak_i, mut peak) = (0, f64::NEG_INFINITY);
    for (i, &p) in r.power.iter().enumerate() {
        if p > peak {
            (peak_i, peak) = (i, p);
        }
    }
    let peak_f = r.frequency.get(peak_i).copied().unwrap_or(0.0);
    let mean = |it: Vec<f64>| {
        if it.is_empty() {
            f64::NAN
        } else {
            it.iter().sum::<f64>() / it.len() as f64
        }
    };
    let low = mean(
        r.frequency
            .iter()
            .zip(&r.power)
            .filter(|(f, _)| **f < peak_f / 2.0)
            .map(|(_, p)| *p)
            .collect(),
    );
    let aniso = mean(
        r.frequency
            .iter()
            .zip(&r.anisotropy_db)
            .filter(|(f, a)| **f >= peak_f / 2.0 && a.is_finite())
            .map(|(_, a)| *a)
            .collect(),
    );
    SpectrumSummary {
        max_frequency: r.frequency.len(),
        peak_frequency: peak_f,
        peak_power: peak,
        low_frequency_power: low,
        mean_anisotropy_db: aniso,
    }
}
