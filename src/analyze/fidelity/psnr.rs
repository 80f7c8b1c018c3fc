//! PSNR with peak value 1, from the mean squared error summed row by row in
//! a fixed order, so that it is reproducible.

use rayon::prelude::*;

use super::{Grey, assert_same_size};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::fidelity::test_images::random;

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
}
