//! `pixelpie fidelity`: how closely a stipple drawing reproduces its photo,
//! by the measure of the stippling survey (Martín et al. 2017): both blurred
//! by a Gaussian of σ = the mean dot spacing, then PSNR and SSIM, on display
//! grey first and on linear light second.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use serde::Serialize;

use pixelpie::analyze::fidelity::colour::{ColourFidelity, Rgb, compare_colour, luminance};
use pixelpie::analyze::fidelity::{self, Grey};
use pixelpie::colour::{PenSet, RenderModel};
use pixelpie::importance::ColourMap;
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

/// The report, as JSON on stdout: for a colour drawing the grey measure
/// is the luminance's, and `colour` holds CIEDE2000.
#[derive(Serialize)]
struct Report {
    photo: (u32, u32),
    dots: usize,
    #[serde(flatten)]
    fidelity: fidelity::Fidelity,
    #[serde(skip_serializing_if = "Option::is_none")]
    colour: Option<ColourFidelity>,
}

pub fn run(a: &FidelityArgs) -> Result<()> {
    if let Some(s) = a.sigma
        && !(s.is_finite() && s >= 0.0)
    {
        bail!("--sigma {s} must be a number >= 0");
    }
    if let Some((drawing, dots)) = load_colour_drawing(&a.drawing)? {
        return run_colour(a, &drawing, dots);
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
        colour: None,
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
            // Rendered finer and averaged down: dots a pixel or two wide
            // are measured by their true coverage.
            let values = raster::render_mean(&d.dots, view, (w, h))?;
            return Ok((
                Grey {
                    width: w,
                    height: h,
                    values,
                },
                d.dots.len(),
            ));
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

/// A colour drawing (an SVG with several pen layers, or a PNG that is not
/// grey) as sRGB channels at its own size, with its dot count; `None` for
/// a grey drawing.
fn load_colour_drawing(path: &Path) -> Result<Option<(image::RgbImage, usize)>> {
    let name = path.display();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = std::fs::read(path).with_context(|| format!("cannot read drawing '{name}'"))?;
    match ext.as_deref() {
        Some("svg") => {
            let Ok(text) = String::from_utf8(bytes) else {
                return Ok(None);
            };
            let Ok(d) = read::read_svg(&text) else {
                return Ok(None);
            };
            if d.layers.len() < 2 && d.paper.is_none() {
                return Ok(None);
            }
            // A one-ink drawing on coloured paper has no pen layers: its
            // dots are the ink's (layer 0).
            let colours: Vec<[u8; 3]> = if d.layers.is_empty() {
                vec![d.ink.unwrap_or([0, 0, 0])]
            } else {
                d.layers.iter().map(|(_, c)| *c).collect()
            };
            let pens = PenSet::from_colours(
                colours
                    .iter()
                    .map(|c| pixelpie::colour::pens::hex_of(*c))
                    .collect::<Vec<_>>()
                    .iter()
                    .map(String::as_str),
            )?;
            // At four times the view's size per unit, at most 4096 px wide.
            let k = (4096.0 / d.view_width).clamp(1e-3, 4.0);
            let size = (
                (d.view_width * k).round().max(1.0) as u32,
                (d.view_height * k).round().max(1.0) as u32,
            );
            let layers = (0..colours.len())
                .map(|l| {
                    let dots: Vec<_> = d
                        .dots
                        .iter()
                        .zip(&d.layer_of)
                        .filter(|(_, of)| **of == l)
                        .map(|(dot, _)| *dot)
                        .collect();
                    raster::render_view_union(&dots, (d.view_width, d.view_height), size)
                })
                .collect::<Result<Vec<_>, _>>()?;
            // On its paper, the layers in the file's (plotting) order.
            let order: Vec<usize> = (0..pens.len()).collect();
            let paper = d.paper.unwrap_or([255; 3]);
            let img =
                raster::composite(&layers, &RenderModel::on_paper(&pens, false, paper, &order))?;
            Ok(Some((img, d.dots.len())))
        }
        Some("png") => {
            let Some(dots) = raster::read_png_dots(&bytes) else {
                return Ok(None);
            };
            let img = image::load_from_memory(&bytes)
                .map_err(|e| anyhow::anyhow!("cannot decode drawing '{name}': {e}"))?
                .to_rgb8();
            let grey = img.pixels().all(|p| p.0[0] == p.0[1] && p.0[1] == p.0[2]);
            Ok((!grey).then_some((img, dots)))
        }
        _ => Ok(None),
    }
}

/// The colour measure of a colour drawing, and the grey one of its
/// luminance.
fn run_colour(a: &FidelityArgs, drawing: &image::RgbImage, dots: usize) -> Result<()> {
    let photo = ColourMap::open(&a.photo, None)?;
    let (w, h) = (photo.width(), photo.height());
    let name = a.drawing.display();
    check_aspect(
        &name,
        (f64::from(drawing.width()), f64::from(drawing.height())),
        (w, h),
    )?;
    let drawing = if drawing.dimensions() == (w, h) {
        drawing.clone()
    } else {
        image::imageops::resize(drawing, w, h, image::imageops::FilterType::Triangle)
    };
    let channel = |f: &dyn Fn(usize, usize) -> f32| -> Rgb {
        [0, 1, 2].map(|k| Grey {
            width: w,
            height: h,
            values: (0..(w * h) as usize).map(|i| f(i, k)).collect(),
        })
    };
    let photo_rgb = channel(&|i, k| linear_to_srgb(photo.rgb()[i][k]));
    let drawing_rgb = channel(&|i, k| f32::from(drawing.as_raw()[3 * i + k]) / 255.0);
    let sigma = a
        .sigma
        .unwrap_or_else(|| (f64::from(w) * f64::from(h) / dots.max(1) as f64).sqrt());
    let colour = compare_colour(&photo_rgb, &drawing_rgb, sigma)?;
    let fidelity = fidelity::compare(&luminance(&photo_rgb), &luminance(&drawing_rgb), sigma)?;
    let report = Report {
        photo: (w, h),
        dots,
        fidelity,
        colour: Some(colour),
    };
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}
