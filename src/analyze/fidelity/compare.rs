//! The comparison of a drawing with its photo: both blurred by the same σ,
//! then measured by PSNR and SSIM on display grey and on linear light.

use super::{Fidelity, Grey, blur, psnr, ssim};

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
pub fn compare(
    photo: &Grey,
    drawing: &Grey,
    sigma: f64,
) -> Result<Fidelity, crate::analyze::Error> {
    validate(photo, drawing, sigma).map_err(crate::analyze::Error::InvalidParameter)?;
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
pub(super) fn validate(photo: &Grey, drawing: &Grey, sigma: f64) -> Result<(), String> {
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
    use crate::analyze::fidelity::test_images::{add_noise, checkerboard, random};

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
        assert!(
            compare(&a, &short, 1.0)
                .unwrap_err()
                .to_string()
                .contains("63 values")
        );
        let empty = Grey::filled(0, 5, 0.5);
        assert!(compare(&empty, &empty, 1.0).is_err());
        assert!(Grey::new(3, 3, vec![0.0; 9]).is_ok());
    }
}
