//! The calibration chart: for each pen a row of patches of known ink, drawn
//! with the dots our stipples use at that pen's width (one pen touch each,
//! on a maximal Poisson-disk set spaced by the ink curve), a solid patch of
//! the pen's ink, four round fiducial marks in the corners and a 16-bit
//! code that tells this chart from another.
//!
//! The SVG carries the chart's specification in its `<metadata>`; the
//! fit ([`super::fit`]) rebuilds the same chart from it, dots included
//! (the dots are seeded), so the chart file is all it needs besides the
//! scan.

use std::io::Write;

use serde::{Deserialize, Serialize};

use crate::colour::{PenSet, pens::hex_of};
use crate::importance::ink;
use crate::sampler::Params;
use crate::stipple::svg::{DotPath, pen_path};
use crate::stipple::{Error, Placement, Result};

/// A patch's side, mm.
pub const PATCH_MM: f64 = 12.0;
/// The gap between patches, mm.
pub const GAP_MM: f64 = 3.0;
/// The column of pen names left of the patches, mm.
pub const LABEL_MM: f64 = 22.0;
/// One pen's row: a patch and its labels, mm.
pub const ROW_MM: f64 = 20.0;
/// The fiducial marks' radius, mm.
pub const MARK_RADIUS_MM: f64 = 4.0;
/// A code bit's side, mm, and the pitch of the bits.
pub const BIT_MM: f64 = 3.0;
/// The distance between code bits' centres, mm.
pub const BIT_PITCH_MM: f64 = 4.0;
/// The number of code bits.
pub const BITS: usize = 16;
/// The patches' ink fractions: paper, nine stipples, solid ink.
pub const FRACTIONS: [f64; 11] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];
/// The resolution the patches' dots are sampled at, px per mm.
pub const PX_PER_MM: f64 = 20.0;
/// The chart format's version.
const VERSION: u32 = 1;
/// The pen width used for pens that have none, mm.
pub const DEFAULT_PEN_MM: f64 = 0.3;

/// One pen of a chart.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChartPen {
    /// The pen's name.
    pub name: String,
    /// Its nominal colour, `#rrggbb`.
    pub colour: String,
    /// Its width, mm.
    pub width_mm: f64,
}

/// What a chart is made of: all the fit needs to rebuild it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChartSpec {
    /// The chart format's version.
    pub version: u32,
    /// The sheet, mm.
    pub sheet_mm: (f64, f64),
    /// The margin, mm.
    pub margin_mm: f64,
    /// The pens, one row each.
    pub pens: Vec<ChartPen>,
    /// The seed of the patches' dots.
    pub seed: u64,
    /// The paper's colour, `#rrggbb` (white when absent): the marks and
    /// the code are drawn by the pen that stands out most from it, and the
    /// fit reads them light on dark where that pen is lighter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paper: Option<String>,
}

/// One patch: its pen, ink fraction, square and dots (centres in mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// The pen's index.
    pub pen: usize,
    /// The ink fraction the dots put down (0: paper, 1: solid ink).
    pub fraction: f64,
    /// The top-left corner, mm.
    pub origin_mm: (f64, f64),
    /// The dots' centres, mm (none for paper and solid patches).
    pub dots: Vec<(f64, f64)>,
}

impl Patch {
    /// The centre, mm.
    #[must_use]
    pub fn centre(&self) -> (f64, f64) {
        (
            self.origin_mm.0 + PATCH_MM / 2.0,
            self.origin_mm.1 + PATCH_MM / 2.0,
        )
    }
}

/// A calibration chart, laid out.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Its specification.
    pub spec: ChartSpec,
    /// Its code.
    pub code: u16,
    /// The fiducial marks' centres, mm: top left, top right, bottom left,
    /// bottom right.
    pub marks: [(f64, f64); 4],
    /// The patches, pen by pen, in [`FRACTIONS`] order.
    pub patches: Vec<Patch>,
}

impl ChartSpec {
    /// A chart of `pens` on a sheet placed by `placement` (its sheet and
    /// margin); pens without a width take `pen_mm`.
    pub fn new(pens: &PenSet, pen_mm: f64, placement: &Placement, seed: u64) -> Result<Self> {
        if !(pen_mm.is_finite() && (0.05..=5.0).contains(&pen_mm)) {
            return Err(Error::InvalidParameter(format!(
                "pen width {pen_mm} mm must be in [0.05, 5]"
            )));
        }
        Ok(Self {
            version: VERSION,
            sheet_mm: placement.sheet_mm,
            margin_mm: placement.margin_mm,
            pens: pens
                .pens()
                .iter()
                .map(|p| ChartPen {
                    name: p.name.clone(),
                    colour: hex_of(p.colour),
                    width_mm: p.width_mm.unwrap_or(pen_mm),
                })
                .collect(),
            seed,
            paper: None,
        })
    }

    /// The chart on paper of colour `paper` (sRGB; white leaves the chart
    /// as it is, its code too).
    #[must_use]
    pub fn with_paper(mut self, paper: [u8; 3]) -> Self {
        self.paper = (paper != [255, 255, 255]).then(|| hex_of(paper));
        self
    }

    /// The paper's colour, sRGB (white when the chart names none).
    #[must_use]
    pub fn paper_rgb(&self) -> [u8; 3] {
        self.paper
            .as_deref()
            .and_then(|h| crate::colour::pens::parse_hex(h).ok())
            .unwrap_or([255, 255, 255])
    }

    /// The chart's code: a hash of its specification.
    #[must_use]
    pub fn code(&self) -> u16 {
        let text = serde_json::to_string(self).unwrap_or_default();
        // FNV-1a, folded to 16 bits.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in text.bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        ((h >> 48) ^ (h >> 32) ^ (h >> 16) ^ h) as u16
    }
}

impl Chart {
    /// Lays out the chart of `spec` and samples its patches' dots. Err when
    /// it does not fit the sheet.
    pub fn new(spec: ChartSpec) -> Result<Self> {
        if spec.version != VERSION {
            return Err(Error::InvalidParameter(format!(
                "chart version {} is not {VERSION}: make the chart again",
                spec.version
            )));
        }
        let (w, h) = spec.sheet_mm;
        let m = spec.margin_mm;
        let r = MARK_RADIUS_MM;
        let top = m + 2.0 * r + 4.0;
        let need_w = 2.0 * m + LABEL_MM + FRACTIONS.len() as f64 * (PATCH_MM + GAP_MM);
        let need_h = top + spec.pens.len() as f64 * ROW_MM + 2.0 * r + 4.0 + m;
        let code_w = BITS as f64 * BIT_PITCH_MM + 4.0 * r + 8.0;
        if need_w > w || need_h > h || code_w + 2.0 * m > w {
            return Err(Error::InvalidParameter(format!(
                "a chart of {} pens needs {need_w:.0} × {need_h:.0} mm with its margins; \
                 the sheet is {w} × {h} mm",
                spec.pens.len()
            )));
        }
        let marks = [
            (m + r, m + r),
            (w - m - r, m + r),
            (m + r, h - m - r),
            (w - m - r, h - m - r),
        ];
        let mut patches = Vec::new();
        for (i, pen) in spec.pens.iter().enumerate() {
            let y = top + i as f64 * ROW_MM;
            for (j, &fraction) in FRACTIONS.iter().enumerate() {
                let x = m + LABEL_MM + j as f64 * (PATCH_MM + GAP_MM);
                let dots = if fraction > 0.0 && fraction < 1.0 {
                    patch_dots(fraction, pen.width_mm, spec.seed ^ ((i * 64 + j) as u64))?
                        .into_iter()
                        .map(|(dx, dy)| (x + dx, y + dy))
                        .collect()
                } else {
                    Vec::new()
                };
                patches.push(Patch {
                    pen: i,
                    fraction,
                    origin_mm: (x, y),
                    dots,
                });
            }
        }
        let code = spec.code();
        Ok(Self {
            spec,
            code,
            marks,
            patches,
        })
    }

    /// The code bits' centres, mm, and their values (most significant
    /// first), in a row between the top marks.
    #[must_use]
    pub fn bits(&self) -> Vec<((f64, f64), bool)> {
        let (w, _) = self.spec.sheet_mm;
        let y = self.spec.margin_mm + MARK_RADIUS_MM;
        let x0 = w / 2.0 - (BITS as f64 - 1.0) * BIT_PITCH_MM / 2.0;
        (0..BITS)
            .map(|j| {
                let on = self.code >> (BITS - 1 - j) & 1 == 1;
                ((x0 + j as f64 * BIT_PITCH_MM, y), on)
            })
            .collect()
    }

    /// The pen that draws the marks and the code: the one that stands out
    /// most from the paper in lightness (on white, the darkest; the first
    /// of equals).
    #[must_use]
    pub fn mark_pen(&self) -> usize {
        let paper = crate::colour::Lab::from_srgb8(self.spec.paper_rgb()).l;
        let contrast = |hex: &str| {
            crate::colour::pens::parse_hex(hex)
                .map_or(0.0, |c| (crate::colour::Lab::from_srgb8(c).l - paper).abs())
        };
        (0..self.spec.pens.len())
            .rev()
            .max_by(|&a, &b| {
                contrast(&self.spec.pens[a].colour).total_cmp(&contrast(&self.spec.pens[b].colour))
            })
            .unwrap_or(0)
    }

    /// Whether the marks are lighter than the paper (a light pen on dark
    /// paper): the fit then looks for light marks.
    #[must_use]
    pub fn light_marks(&self) -> bool {
        let pen = &self.spec.pens[self.mark_pen()];
        let ink = crate::colour::pens::parse_hex(&pen.colour).unwrap_or([0, 0, 0]);
        crate::colour::luminance(ink) > crate::colour::luminance(self.spec.paper_rgb())
    }

    /// The patches of pen `pen`.
    pub fn pen_patches(&self, pen: usize) -> impl Iterator<Item = &Patch> {
        self.patches.iter().filter(move |p| p.pen == pen)
    }

    /// Writes the chart as an SVG: the sheet in mm, one Inkscape layer per
    /// pen (its patches; the darkest pen's also the marks and the code)
    /// drawn as pen paths, and a layer of labels (text, not plotted).
    pub fn write_svg(&self, w: &mut dyn Write) -> Result<()> {
        let (sw, sh) = self.spec.sheet_mm;
        let json = serde_json::to_string(&self.spec)
            .map_err(|e| Error::InvalidParameter(format!("chart: {e}")))?;
        writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
        writeln!(
            w,
            r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" version="1.1" width="{sw}mm" height="{sh}mm" viewBox="0 0 {sw} {sh}">"#
        )?;
        writeln!(
            w,
            "<!-- pixelpie calibration chart {:04x}: plot every layer, scan or photograph the sheet, then run pixelpie calibrate fit -->",
            self.code
        )?;
        writeln!(
            w,
            r#"<metadata id="pixelpie-chart">{}</metadata>"#,
            escape(&json)
        )?;
        if let Some(paper) = &self.spec.paper {
            crate::stipple::svg::write_paper_layer(w, &format!("{sw} {sh}"), paper)?;
        }
        let mark_pen = self.mark_pen();
        for (i, pen) in self.spec.pens.iter().enumerate() {
            let wd = pen.width_mm;
            writeln!(
                w,
                r#"<g inkscape:groupmode="layer" id="layer{}" inkscape:label="{}" fill="none" stroke="{}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round">"#,
                i + 1,
                escape(&crate::stipple::svg::layer_label(i, &pen.name)),
                pen.colour,
                num(wd)
            )?;
            for p in self.pen_patches(i) {
                if p.fraction >= 1.0 {
                    path(w, &hatch(p.origin_mm, (PATCH_MM, PATCH_MM), wd))?;
                }
                for &(x, y) in &p.dots {
                    path(w, &pen_path(x, y, wd / 2.0, wd, DotPath::Touch))?;
                }
            }
            if i == mark_pen {
                for &(x, y) in &self.marks {
                    path(w, &pen_path(x, y, MARK_RADIUS_MM, wd, DotPath::Spiral))?;
                }
                for ((x, y), on) in self.bits() {
                    if on {
                        let o = (x - BIT_MM / 2.0, y - BIT_MM / 2.0);
                        path(w, &hatch(o, (BIT_MM, BIT_MM), wd))?;
                    }
                }
            }
            writeln!(w, "</g>")?;
        }
        writeln!(
            w,
            r##"<g inkscape:groupmode="layer" id="labels" inkscape:label="% labels (not plotted)" fill="#777777" font-family="sans-serif" font-size="2.5">"##
        )?;
        for (i, pen) in self.spec.pens.iter().enumerate() {
            let y = self.patches[i * FRACTIONS.len()].origin_mm.1;
            writeln!(
                w,
                r#"<text x="{}" y="{}">{} {} mm</text>"#,
                num(self.spec.margin_mm),
                num(y + PATCH_MM / 2.0),
                escape(&pen.name),
                num(pen.width_mm)
            )?;
            for p in self.pen_patches(i) {
                writeln!(
                    w,
                    r#"<text x="{}" y="{}">{}%</text>"#,
                    num(p.origin_mm.0),
                    num(p.origin_mm.1 + PATCH_MM + 3.5),
                    (p.fraction * 100.0).round()
                )?;
            }
        }
        writeln!(w, "</g>")?;
        writeln!(w, "</svg>")?;
        Ok(())
    }

    /// The chart an SVG written by [`Self::write_svg`] holds. Err when it
    /// is not a chart.
    pub fn read_svg(text: &str) -> Result<Self> {
        let not = || {
            Error::InvalidParameter(
                "not a pixelpie calibration chart (no chart metadata): make one with \
                 pixelpie calibrate chart"
                    .into(),
            )
        };
        let start = text
            .find(r#"<metadata id="pixelpie-chart">"#)
            .ok_or_else(not)?;
        let body = &text[start + r#"<metadata id="pixelpie-chart">"#.len()..];
        let end = body.find("</metadata>").ok_or_else(not)?;
        let spec: ChartSpec = serde_json::from_str(&unescape(&body[..end]))
            .map_err(|e| Error::InvalidParameter(format!("chart metadata: {e}")))?;
        Self::new(spec)
    }
}

/// The dots of a patch of ink `fraction` for a pen `pen_mm` wide: a maximal
/// Poisson-disk set over the patch, spaced so that touches of the pen put
/// down `fraction` ink ([`ink::sample_radius`]), centres in mm from the
/// patch's corner.
fn patch_dots(fraction: f64, pen_mm: f64, seed: u64) -> Result<Vec<(f64, f64)>> {
    let rho = pen_mm / 2.0 * PX_PER_MM;
    let r = ink::sample_radius(fraction, rho);
    let side = (PATCH_MM * PX_PER_MM).round() as u32;
    let set = Params::new(side, side)
        .with_radius(r as f32)
        .with_seed(seed)
        .generate()
        .map_err(|e| Error::InvalidParameter(format!("chart patch: {e}")))?;
    Ok(set
        .points
        .iter()
        .map(|p| (f64::from(p.x) / PX_PER_MM, f64::from(p.y) / PX_PER_MM))
        .collect())
}

/// A serpentine that fills the rectangle at `origin` of `size` (mm) with a
/// pen `pen` wide: rows at most 0.8 pen apart, the pen's edge on the
/// rectangle's.
pub(crate) fn hatch(origin: (f64, f64), size: (f64, f64), pen: f64) -> Vec<(f64, f64)> {
    let (x0, x1) = (origin.0 + pen / 2.0, origin.0 + size.0 - pen / 2.0);
    let (y0, y1) = (origin.1 + pen / 2.0, origin.1 + size.1 - pen / 2.0);
    let rows = ((y1 - y0) / (0.8 * pen)).ceil().max(1.0) as usize;
    let mut pts = Vec::with_capacity(2 * rows + 2);
    for k in 0..=rows {
        let y = y0 + (y1 - y0) * k as f64 / rows as f64;
        if k % 2 == 0 {
            pts.extend([(x0, y), (x1, y)]);
        } else {
            pts.extend([(x1, y), (x0, y)]);
        }
    }
    pts
}

fn path(w: &mut dyn Write, pts: &[(f64, f64)]) -> Result<()> {
    let mut line = String::from(r#"<path d=""#);
    for (k, (x, y)) in pts.iter().enumerate() {
        line.push_str(match k {
            0 => "M ",
            1 => " L ",
            _ => " ",
        });
        line.push_str(&format!("{} {}", num(*x), num(*y)));
    }
    line.push_str(r#""/>"#);
    writeln!(w, "{line}")?;
    Ok(())
}

fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn unescape(s: &str) -> String {
    s.replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart() -> Chart {
        let a4: crate::stipple::Paper = "a4".parse().unwrap();
        let place = a4.place((1, 1), false, 10.0).unwrap();
        Chart::new(ChartSpec::new(&PenSet::cmyk(), 0.3, &place, 1).unwrap()).unwrap()
    }

    #[test]
    fn the_chart_reads_back_from_its_svg_and_its_patches_hold_their_ink() {
        let c = chart();
        let mut out = Vec::new();
        c.write_svg(&mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(Chart::read_svg(&text).unwrap(), c);
        assert_eq!(c.patches.len(), 4 * FRACTIONS.len());
        assert_eq!(c.mark_pen(), 3, "black draws the marks");
        // The dots' ink, measured by rasterizing their touches: within
        // 0.03 of each patch's fraction, away from the patch's edge.
        for p in c
            .patches
            .iter()
            .filter(|p| p.fraction > 0.0 && p.fraction < 1.0)
        {
            let rho = 0.15;
            let n = 200;
            let mut hit = 0;
            for i in 0..n {
                for j in 0..n {
                    let x = p.origin_mm.0 + 1.0 + 10.0 * (i as f64 + 0.5) / n as f64;
                    let y = p.origin_mm.1 + 1.0 + 10.0 * (j as f64 + 0.5) / n as f64;
                    if p.dots.iter().any(|d| (d.0 - x).hypot(d.1 - y) <= rho) {
                        hit += 1;
                    }
                }
            }
            let k = f64::from(hit) / f64::from(n * n);
            assert!((k - p.fraction).abs() < 0.03, "{} {k}", p.fraction);
        }
        // Another chart has another code.
        let mut other = c.spec.clone();
        other.seed = 2;
        assert_ne!(other.code(), c.code);
        assert!(Chart::read_svg("<svg/>").is_err());
    }
}
