//! SVG output: one `<circle>` per dot, in drawing order, inside a viewBox in
//! domain pixels. An optional physical size (millimetres) makes the file
//! plot at that size in pen-plotter tools (Inkscape/AxiDraw, vpype).

use std::io::Write;

use super::{Dot, Error, Result};

/// Options of the SVG writer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SvgOptions {
    /// The domain in pixels: the viewBox is `0 0 width height`.
    pub domain: (u32, u32),
    /// Width and height of the page in mm; `None` gives a size in px equal
    /// to the domain.
    pub size_mm: Option<(f64, f64)>,
}

impl SvgOptions {
    /// A page `width_mm` wide, its height following the domain's aspect.
    ///
    /// ```
    /// use pixelpie::stipple::svg::SvgOptions;
    /// let o = SvgOptions::with_width_mm((400, 200), 100.0).unwrap();
    /// assert_eq!(o.size_mm, Some((100.0, 50.0)));
    /// ```
    pub fn with_width_mm(domain: (u32, u32), width_mm: f64) -> Result<Self> {
        if !(width_mm.is_finite() && width_mm > 0.0) {
            return Err(Error::InvalidParameter(format!(
                "page width {width_mm} mm must be a positive number"
            )));
        }
        let h = width_mm * f64::from(domain.1) / f64::from(domain.0.max(1));
        Ok(Self {
            domain,
            size_mm: Some((width_mm, h)),
        })
    }
}

/// Writes `dots` as an SVG document.
///
/// ```
/// use pixelpie::stipple::{Dot, svg};
/// let mut out = Vec::new();
/// let opts = svg::SvgOptions { domain: (10, 10), size_mm: None };
/// svg::write(&mut out, &[Dot { x: 5.0, y: 5.0, radius: 1.0 }], &opts).unwrap();
/// assert!(String::from_utf8(out).unwrap().contains(r#"<circle cx="5" cy="5" r="1"/>"#));
/// ```
pub fn write(w: &mut dyn Write, dots: &[Dot], opts: &SvgOptions) -> Result<()> {
    let (dw, dh) = opts.domain;
    let (width, height) = match opts.size_mm {
        Some((a, b)) => (format!("{}mm", num(a)), format!("{}mm", num(b))),
        None => (format!("{dw}px"), format!("{dh}px")),
    };
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width}" height="{height}" viewBox="0 0 {dw} {dh}">"#
    )?;
    writeln!(w, "<!-- {} dots, made by pixelpie -->", dots.len())?;
    writeln!(w, r#"<g fill="black" stroke="none">"#)?;
    for d in dots {
        writeln!(
            w,
            r#"<circle cx="{}" cy="{}" r="{}"/>"#,
            num(f64::from(d.x)),
            num(f64::from(d.y)),
            num(f64::from(d.radius))
        )?;
    }
    writeln!(w, "</g>")?;
    writeln!(w, "</svg>")?;
    Ok(())
}

/// A number with at most three decimals and no trailing zeros.
fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}
