//! `pixelpie fidelity`: how closely a stipple drawing reproduces its photo,
//! by the measure of the stippling survey (Martín et al. 2017): both blurred
//! by a Gaussian of σ = the mean dot spacing, then PSNR and SSIM, on display
//! grey first and on linear light second.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use serde::Serialize;

use pixelpie::analyze::fidelity::{self, Grey};
use pixelpie::importance::{ImportanceMap, linear_to_srgb};
use pixelpie::stipple::{raster, read};

/// Arguments of `pixelpie fidelity`.
#[derive(Args, Debug)]
pub struct FidelityArgs {
    /// The photo the drawing was made from (any format `stipple` reads).
    photo: PathBuf,
    /// The drawing: an SVG or PNG written by `pixelpie stipple` (or the app).
    drawing: PathBuf,
    /// The blur's σ in photo pixels [default: the mean dot spacing,
    /// √(photo area / dots)].
    #[arg(long)]
    sigma: Option<f64>,
}

/// The report, as JSON on stdout.
#[derive(Serialize)]
struct Report {
    photo: (u32, u32),
    dots: usize,
    #[serde(flatten)]
    fidelity: fidelity::Fidelity,
}

pub fn run(a: &FidelityArgs) -> Result<()> {
    if let Some(s) = a.sigma
        && !(s.is_finite() && s >= 0.0)
    {
        bail!("--sigma {s} must be a number >= 0");
    }
    let map = ImportanceMap::open(&a.photo, None)?;
    let (w, h) = (map.width(), map.height());
    let photo = Grey {
        width: w,
        height: h,
        values: map.values().iter().map(|&v| linear_to_srgb(v)).collect(),
    };
    let (drawing, dots) = load_drawing(&a.drawing, (w, h))?;
    let sigma = a
        .sigma
        .unwrap_or_else(|| (f64::from(w) * f64::from(h) / dots.max(1) as f64).sqrt());
    let fidelity = fidelity::compare(&photo, &drawing, sigma)?;
    let report = Report {
        photo: (w, h),
        dots,
        fidelity,
    };
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}

/// The drawing at the photo's size as display grey, and its dot count.
fn load_drawing(path: &Path, (w, h): (u32, u32)) -> Result<(Grey, usize)> {
    let name = path.display();
    let bytes = std::fs::read(path).with_context(|| format!("cannot read drawing '{name}'"))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let (grey, dots) = match ext.as_deref() {
        Some("svg") => {
            let text = String::from_utf8(bytes)
                .map_err(|_| anyhow::anyhow!("drawing '{name}' is not UTF-8 text"))?;
            let d = read::read_svg(&text)
                .map_err(|e| anyhow::anyhow!("cannot read drawing '{name}': {e}"))?;
            let view = (d.view_width, d.view_height);
            check_aspect(&name, view, (w, h))?;
            let img = raster::render_view(&d.dots, view, (w, h))?;
            (img, d.dots.len())
        }
        Some("png") => {
            let dots = raster::read_png_dots(&bytes).ok_or_else(|| {
                anyhow::anyhow!("drawing '{name}' is not a pixelpie PNG (no dot count in it)")
            })?;
            let img = image::load_from_memory(&bytes)
                .map_err(|e| anyhow::anyhow!("cannot decode drawing '{name}': {e}"))?
                .to_luma8();
            let view = (f64::from(img.width()), f64::from(img.height()));
            check_aspect(&name, view, (w, h))?;
            let img = if img.dimensions() == (w, h) {
                img
            } else {
                image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle)
            };
            (img, dots)
        }
        _ => bail!("unknown drawing extension of '{name}': use .svg or .png"),
    };
    let values = grey
        .as_raw()
        .iter()
        .map(|&g| f32::from(g) / 255.0)
        .collect();
    Ok((
        Grey {
            width: w,
            height: h,
            values,
        },
        dots,
    ))
}

/// Refuses a drawing whose aspect differs from the photo's by more than a
/// pixel's rounding.
fn check_aspect(name: &impl std::fmt::Display, view: (f64, f64), (w, h): (u32, u32)) -> Result<()> {
    let want = f64::from(h) * view.0 / f64::from(w);
    if !(view.0 > 0.0 && view.1 > 0.0) || (view.1 - want).abs() > 1.0 + 0.005 * want {
        bail!(
            "drawing '{name}' is {} x {} but the photo is {w} x {h}: not the same picture's aspect",
            view.0,
            view.1
        );
    }
    Ok(())
}
