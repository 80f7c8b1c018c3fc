//! The random start: points drawn with probability proportional to the
//! weights (CDF inversion), positions uniform inside the chosen pixel, from
//! a counter-based splitmix64 generator, so the result depends on the seed
//! alone. The relaxation tests draw their random numbers from it too.

use super::Density;

/// `n` points drawn at random with probability proportional to the weights
/// (CDF inversion), positions uniform inside the chosen pixel, from `seed`
/// (deterministic). This is the "random start" of StippleGen's method, used as
/// the baseline the project compares against.
///
/// Weights that are negative or not finite count as zero. If no weight is
/// positive (or the density has the wrong number of weights), the points are
/// uniform over the domain.
pub fn random_start(n: usize, density: &Density<'_>, seed: u64) -> Vec<[f32; 2]> {
    let (w, h) = (density.width as usize, density.height as usize);
    let cdf = Cdf::new(density);
    (0..n as u64)
        .map(|i| {
            let u = |j: u64| unit(seed, 3 * i + j);
            match &cdf {
                Some(cdf) => {
                    let pixel = cdf.pick(u(0));
                    [in_cell(pixel % w, u(1)), in_cell(pixel / w, u(2))]
                }
                None => [(u(1) * w as f64) as f32, (u(2) * h as f64) as f32],
            }
        })
        .collect()
}

/// `cell + u` as `f32`, kept below `cell + 1` (`u` in `[0, 1)`).
fn in_cell(cell: usize, u: f64) -> f32 {
    let end = (cell + 1) as f32;
    let v = (cell as f64 + u) as f32;
    if v >= end { end.next_down() } else { v }
}

/// The splitmix64 finaliser: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform number in `[0, 1)` from the counter `(seed, i)`.
pub(super) fn unit(seed: u64, i: u64) -> f64 {
    let h = mix(mix(seed ^ 0x9e37_79b9_7f4a_7c15).wrapping_add(i));
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Cumulative weights over the pixels in row-major order.
struct Cdf {
    /// `sums[i]`: the sum of the weights of pixels `0..=i`.
    sums: Vec<f64>,
    /// The last pixel with a positive weight.
    last: usize,
}

impl Cdf {
    /// `None` if the density is malformed or has no positive weight.
    fn new(density: &Density<'_>) -> Option<Cdf> {
        let len = density.width as usize * density.height as usize;
        if len == 0 || density.weights.len() != len {
            return None;
        }
        let mut total = 0.0f64;
        let mut last = None;
        let sums = (density.weights.iter().enumerate())
            .map(|(i, &v)| {
                if v.is_finite() && v > 0.0 {
                    total += f64::from(v);
                    last = Some(i);
                }
                total
            })
            .collect();
        last.map(|last| Cdf { sums, last })
    }

    /// The pixel whose weight interval holds `u * total` (`u` in `[0, 1)`).
    fn pick(&self, u: f64) -> usize {
        let target = u * self.sums[self.last];
        self.sums.partition_point(|&s| s <= target).min(self.last)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_start_follows_the_density() {
        let (w, h) = (64, 48);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| if i % w < w / 2 { 0.0 } else { 2.0 })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let points = random_start(2000, &density, 42);
        assert_eq!(points.len(), 2000);
        assert!(
            points
                .iter()
                .all(|p| p[0] >= 32.0 && p[0] < 64.0 && p[1] >= 0.0 && p[1] < 48.0)
        );
        assert_eq!(points, random_start(2000, &density, 42));
        assert_ne!(points, random_start(2000, &density, 43));
        let ramp: Vec<f32> = (0..w * h).map(|i| (i % w) as f32 + 0.5).collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &ramp,
        };
        let points = random_start(20000, &density, 1);
        let right = points.iter().filter(|p| p[0] >= 32.0).count() as f64 / 20000.0;
        assert!(
            (0.73..0.77).contains(&right),
            "fraction on the right: {right}"
        );
    }

    #[test]
    fn random_start_without_weight_is_uniform_over_the_domain() {
        let weights = vec![0.0f32; 30 * 20];
        let density = Density {
            width: 30,
            height: 20,
            weights: &weights,
        };
        let points = random_start(1000, &density, 5);
        assert!(
            points
                .iter()
                .all(|p| (0.0..30.0).contains(&p[0]) && (0.0..20.0).contains(&p[1]))
        );
        assert!(points.iter().filter(|p| p[0] < 15.0).count() > 400);
        let short = Density {
            width: 30,
            height: 20,
            weights: &weights[..10],
        };
        assert_eq!(random_start(7, &short, 5).len(), 7);
    }
}
