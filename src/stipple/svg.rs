//! SVG output, in drawing order. By default one `<circle>` per dot inside a
//! viewBox in domain pixels; an optional physical size (millimetres) makes
//! the file plot at that size in pen-plotter tools (Inkscape/AxiDraw, vpype).
//!
//! With a pen width ([`SvgOptions::pen_mm`]) each dot is instead drawn as a
//! pen draws it: one stroked `<path>` per dot in an Inkscape layer, in a
//! viewBox in millimetres. A dot no wider than the pen is one touch of the
//! pen (a [`TOUCH_MM`]-long stroke: plotter tools drop zero-length paths); a
//! bigger one is filled by an Archimedean spiral from its centre outward and
//! one closing circle, so that the inked area is the dot's disk. The paths
//! are written in hundredths of a mm, whole numbers, in a group scaled to
//! mm (`<g transform="scale(0.01)">`), and each carries `data-dot="cx cy
//! r"` (centre and radius, in the same hundredths to a tenth) so that the
//! drawing can be read back ([`super::read`]).

use std::f64::consts::{PI, TAU};
use std::io::Write;

use super::{Dot, Error, Result, Stroke};

/// Length in mm of the stroke that draws a dot no wider than the pen: long
/// enough to survive three decimals, short enough to look like a dot.
pub const TOUCH_MM: f64 = 0.01;

/// The spiral's largest pitch (distance between turns) as a fraction of the
/// pen width: at 1 neighbouring turns touch and leave no gap (up to the
/// polyline's chord error), with the least path, hence the least plot time
/// (0.8 took 7% longer to plot for the same ink: docs/plotter.md).
pub const PITCH: f64 = 1.0;

/// The largest distance in mm between a pen path's polyline and the exact
/// spiral or circle it follows (chord error).
pub const CHORD_MM: f64 = 0.01;

/// The thinnest pen in mm: the files' resolution (three decimals).
pub const MIN_PEN_MM: f64 = 0.001;

/// How a pen draws a dot wider than itself (`--dot-path`). A dot no wider
/// than the pen is always one touch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum DotPath {
    /// An Archimedean spiral from the centre out, and one closing circle:
    /// the ink is the dot's disk.
    #[default]
    Spiral,
    /// The closing circle alone: a ring, fast to plot, lighter than the disk.
    Circle,
    /// One touch of the pen for every dot, whatever its size: the dot is the
    /// pen's own.
    Touch,
}

impl DotPath {
    /// Whether this is the default (left out of the job's JSON).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// Options of the SVG writer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SvgOptions {
    /// The domain in pixels: the viewBox is `0 0 width height` (without a
    /// pen; with one the viewBox is in mm).
    pub domain: (u32, u32),
    /// Width and height of the page in mm; `None` gives a size in px equal
    /// to the domain.
    pub size_mm: Option<(f64, f64)>,
    /// The pen's width in mm: draw each dot as a pen stroke of this width
    /// (needs `size_mm`); `None` draws filled circles.
    pub pen_mm: Option<f64>,
    /// The ink's colour (sRGB); black by default.
    pub ink: [u8; 3],
    /// The sheet the drawing lies on ([`super::paper`]): the page is then
    /// the sheet, in mm, and the drawing lies `size_mm` large at `origin_mm`.
    pub sheet_mm: Option<(f64, f64)>,
    /// The drawing's top-left corner on the sheet, in mm.
    pub origin_mm: (f64, f64),
    /// How a pen draws the dots wider than itself.
    pub dot_path: DotPath,
    /// The page's width and height in CSS px (96 per inch) rather than
    /// mm: the same page, for readers that drop units (saxi's command
    /// line reads `210mm` as 210 px).
    pub size_px: bool,
    /// The paper's colour, when it is not white: a rectangle under the
    /// drawing, on a layer of its own that plotters skip.
    pub paper: Option<[u8; 3]>,
    /// Whether the one ink of [`write`] multiplies the paper below it (a
    /// transparent ink on coloured paper), else it covers it.
    pub multiply: bool,
}

impl SvgOptions {
    /// Filled circles on a page sized in px like the domain.
    ///
    /// ```
    /// use pixelpie::stipple::svg::SvgOptions;
    /// let o = SvgOptions::new((400, 200));
    /// assert_eq!((o.size_mm, o.pen_mm), (None, None));
    /// ```
    #[must_use]
    pub fn new(domain: (u32, u32)) -> Self {
        Self {
            domain,
            size_mm: None,
            pen_mm: None,
            ink: [0, 0, 0],
            sheet_mm: None,
            origin_mm: (0.0, 0.0),
            dot_path: DotPath::Spiral,
            size_px: false,
            paper: None,
            multiply: false,
        }
    }

    /// The drawing placed on a sheet of paper: the page is the sheet, in
    /// mm, with the drawing at `placement`.
    ///
    /// ```
    /// use pixelpie::stipple::{Paper, svg::SvgOptions};
    /// let a4: Paper = "a4".parse().unwrap();
    /// let o = SvgOptions::on_paper((100, 100), &a4.place((100, 100), false, 10.0).unwrap());
    /// assert_eq!((o.sheet_mm, o.size_mm), (Some((210.0, 297.0)), Some((190.0, 190.0))));
    /// ```
    #[must_use]
    pub fn on_paper(domain: (u32, u32), placement: &super::paper::Placement) -> Self {
        Self {
            size_mm: Some(placement.size_mm),
            sheet_mm: Some(placement.sheet_mm),
            origin_mm: placement.origin_mm,
            ..Self::new(domain)
        }
    }

    /// These options on paper of colour `paper` (sRGB).
    #[must_use]
    pub fn with_paper(self, paper: [u8; 3]) -> Self {
        Self {
            paper: Some(paper),
            ..self
        }
    }

    /// These options with the one ink multiplying the paper (`true`) or
    /// covering it.
    #[must_use]
    pub fn with_multiply(self, multiply: bool) -> Self {
        Self { multiply, ..self }
    }

    /// These options on paper of colour `paper`, when it is not white.
    #[must_use]
    pub fn with_paper_if(self, paper: [u8; 3]) -> Self {
        if paper == [255; 3] {
            self
        } else {
            self.with_paper(paper)
        }
    }

    /// These options with the page's size in px (`true`) or mm.
    #[must_use]
    pub fn with_size_px(self, size_px: bool) -> Self {
        Self { size_px, ..self }
    }

    /// These options with pen paths of kind `dot_path`.
    #[must_use]
    pub fn with_dot_path(self, dot_path: DotPath) -> Self {
        Self { dot_path, ..self }
    }

    /// The page: its width and height attributes, its viewBox, and the
    /// dots' transform from domain px (scale, offset). On a sheet, or with a
    /// pen, the viewBox is in mm; else in domain px.
    fn frame(&self, pen: bool) -> (String, String, String, f64, (f64, f64)) {
        let (mut width, mut height, view, scale, offset) = self.frame_mm(pen);
        if self.size_px {
            for v in [&mut width, &mut height] {
                if let Some(mm) = v.strip_suffix("mm").and_then(|n| n.parse::<f64>().ok()) {
                    *v = num(mm * 96.0 / 25.4);
                }
            }
        }
        (width, height, view, scale, offset)
    }

    /// [`Self::frame`] with the size in mm.
    fn frame_mm(&self, pen: bool) -> (String, String, String, f64, (f64, f64)) {
        let (dw, dh) = self.domain;
        let mm_per_px = self
            .size_mm
            .map_or(1.0, |(mm, _)| mm / f64::from(dw.max(1)));
        match (self.sheet_mm, self.size_mm) {
            (Some((a, b)), _) => (
                format!("{}mm", num(a)),
                format!("{}mm", num(b)),
                format!("{} {}", num(a), num(b)),
                mm_per_px,
                self.origin_mm,
            ),
            (None, Some((a, b))) if pen => (
                format!("{}mm", num(a)),
                format!("{}mm", num(b)),
                format!("{} {}", num(a), num(b)),
                mm_per_px,
                (0.0, 0.0),
            ),
            (None, Some((a, b))) => (
                format!("{}mm", num(a)),
                format!("{}mm", num(b)),
                format!("{dw} {dh}"),
                1.0,
                (0.0, 0.0),
            ),
            (None, None) => (
                format!("{dw}px"),
                format!("{dh}px"),
                format!("{dw} {dh}"),
                1.0,
                (0.0, 0.0),
            ),
        }
    }

    /// These options with ink of colour `ink` (sRGB).
    ///
    /// ```
    /// use pixelpie::stipple::svg::SvgOptions;
    /// assert_eq!(SvgOptions::new((4, 4)).with_ink([255, 0, 0]).ink_name(), "#ff0000");
    /// assert_eq!(SvgOptions::new((4, 4)).ink_name(), "black");
    /// ```
    #[must_use]
    pub fn with_ink(self, ink: [u8; 3]) -> Self {
        Self { ink, ..self }
    }

    /// The ink as an SVG colour: `black`, or `#rrggbb`.
    #[must_use]
    pub fn ink_name(&self) -> String {
        match self.ink {
            [0, 0, 0] => "black".into(),
            [r, g, b] => format!("#{r:02x}{g:02x}{b:02x}"),
        }
    }

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
            size_mm: Some((width_mm, h)),
            ..Self::new(domain)
        })
    }

    /// These options drawing with a pen `pen_mm` wide. Err unless `pen_mm`
    /// is a number of at least [`MIN_PEN_MM`] and the page has a size in mm.
    ///
    /// ```
    /// use pixelpie::stipple::svg::SvgOptions;
    /// let o = SvgOptions::with_width_mm((400, 200), 100.0).unwrap();
    /// assert_eq!(o.with_pen_mm(0.3).unwrap().pen_mm, Some(0.3));
    /// assert!(o.with_pen_mm(0.0).is_err());
    /// assert!(SvgOptions::new((400, 200)).with_pen_mm(0.3).is_err());
    /// ```
    pub fn with_pen_mm(self, pen_mm: f64) -> Result<Self> {
        let o = Self {
            pen_mm: Some(pen_mm),
            ..self
        };
        o.pen()?;
        Ok(o)
    }

    /// The page's frame in mm, when it has a size in mm: mm per domain
    /// pixel and the domain's origin on the page (as pen paths are
    /// written).
    #[must_use]
    pub fn mm_frame(&self) -> Option<(f64, (f64, f64))> {
        self.size_mm?;
        let (_, _, _, scale, offset) = self.frame(true);
        Some((scale, offset))
    }

    /// The pen width and the page size in mm, if drawing with a pen; Err if
    /// the pen width is not a positive number or the page has no size in mm.
    fn pen(&self) -> Result<Option<(f64, (f64, f64))>> {
        let Some(pen) = self.pen_mm else {
            return Ok(None);
        };
        if !(pen.is_finite() && pen >= MIN_PEN_MM) {
            return Err(Error::InvalidParameter(format!(
                "pen width {pen} mm must be a number of at least {MIN_PEN_MM} mm"
            )));
        }
        match self.size_mm {
            Some(size) => Ok(Some((pen, size))),
            None => Err(Error::InvalidParameter(
                "«pen_mm» needs «width_mm» or «paper»".into(),
            )),
        }
    }
}

/// Writes `dots` as an SVG document, in their order. Err if the options'
/// pen width is invalid (see [`SvgOptions::with_pen_mm`]), if drawing with a
/// pen a dot is not finite, or if writing fails.
///
/// ```
/// use pixelpie::stipple::{Dot, svg};
/// let mut out = Vec::new();
/// let opts = svg::SvgOptions::new((10, 10));
/// svg::write(&mut out, &[Dot { x: 5.0, y: 5.0, radius: 1.0 }], &opts).unwrap();
/// assert!(String::from_utf8(out).unwrap().contains(r#"<circle cx="5" cy="5" r="1"/>"#));
/// ```
///
/// With a pen, on a page 100 mm wide (1 mm per domain pixel here):
///
/// ```
/// use pixelpie::stipple::{Dot, svg};
/// let opts = svg::SvgOptions::with_width_mm((100, 50), 100.0)?.with_pen_mm(0.5)?;
/// let mut out = Vec::new();
/// svg::write(&mut out, &[Dot { x: 10.0, y: 20.0, radius: 0.2 }], &opts)?;
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.contains(r#"viewBox="0 0 100 50""#));
/// // In hundredths of a mm: a touch of 0.01 mm at (10, 20) mm, radius 0.2 mm.
/// assert!(text.contains(r#"<g transform="scale(0.01)" stroke-width="50">"#));
/// assert!(text.contains(r#"<path d="M1000 2000l1 0" data-dot="1000 2000 20"/>"#));
/// # Ok::<(), pixelpie::stipple::Error>(())
/// ```
pub fn write(w: &mut dyn Write, dots: &[Dot], opts: &SvgOptions) -> Result<()> {
    if let Some((pen, _)) = opts.pen()? {
        return write_pen(w, dots, opts, pen);
    }
    let (width, height, view, scale, offset) = opts.frame(false);
    // Inkscape's namespace for the paper's layer.
    let ns = if opts.paper.is_some() {
        r#" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape""#
    } else {
        ""
    };
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg"{ns} version="1.1" width="{width}" height="{height}" viewBox="0 0 {view}">"#
    )?;
    writeln!(w, "<!-- {} dots, made by pixelpie -->", dots.len())?;
    write_paper(w, opts, &view)?;
    writeln!(
        w,
        r#"<g fill="{}" stroke="none"{}>"#,
        opts.ink_name(),
        ink_style(opts)
    )?;
    write_circles(w, dots, scale, offset)?;
    writeln!(w, "</g>")?;
    writeln!(w, "</svg>")?;
    Ok(())
}

/// Dots per chunk that one thread formats.
const CHUNK: usize = 16_384;
/// Chunks formatted before they are written: the text in memory is bounded.
const CHUNKS_AT_ONCE: usize = 16;

/// Writes one line per dot, `line(dot, buffer)` appending it, in order:
/// chunks of dots are formatted in parallel and written as they come, so
/// that a million dots stream out at the speed of the cores.
fn write_lines(
    w: &mut dyn Write,
    dots: &[Dot],
    line: impl Fn(&Dot, &mut Vec<u8>) + Sync,
) -> Result<()> {
    use rayon::prelude::*;
    for group in dots.chunks(CHUNK * CHUNKS_AT_ONCE) {
        let texts: Vec<Vec<u8>> = group
            .par_chunks(CHUNK)
            .map(|chunk| {
                let mut buf = Vec::with_capacity(chunk.len() * 48);
                for d in chunk {
                    line(d, &mut buf);
                }
                buf
            })
            .collect();
        for t in texts {
            w.write_all(&t)?;
        }
    }
    Ok(())
}

/// One `<circle>` per dot, scaled by `scale` and moved by `offset`.
fn write_circles(w: &mut dyn Write, dots: &[Dot], scale: f64, offset: (f64, f64)) -> Result<()> {
    write_lines(w, dots, |d, buf| {
        buf.extend_from_slice(br#"<circle cx=""#);
        push_num(buf, offset.0 + f64::from(d.x) * scale);
        buf.extend_from_slice(br#"" cy=""#);
        push_num(buf, offset.1 + f64::from(d.y) * scale);
        buf.extend_from_slice(br#"" r=""#);
        push_num(buf, f64::from(d.radius) * scale);
        buf.extend_from_slice(b"\"/>\n");
    })
}

/// One pen's dots in a colour drawing: an Inkscape layer of its own.
#[derive(Clone, Copy, Debug)]
pub struct Layer<'a> {
    /// The layer's label (the pen's name).
    pub name: &'a str,
    /// The pen's colour.
    pub ink: [u8; 3],
    /// The pen's width in mm, when it differs from the options' pen.
    pub pen_mm: Option<f64>,
    /// Whether the ink covers what lies below it (drawn over it), else it
    /// multiplies.
    pub opaque: bool,
    /// The pen's dots, in drawing order.
    pub dots: &'a [Dot],
    /// The pen's strokes, drawn after its dots.
    pub strokes: &'a [Stroke],
}

/// The label of the `index`-th plotted layer (from 0), named `name`, as
/// plotter software reads it: after the first, a leading `!`, on which
/// AxiDraw's software pauses before the layer (for the pen change or the
/// refill between layers; saxi and vpype ignore it, and vpype still
/// numbers the layer by the label's first digits). A leading `%` or `!` of
/// the name itself is dropped: `%` would make the layer one that plotters
/// skip.
#[must_use]
pub fn layer_label(index: usize, name: &str) -> String {
    let name = name.trim_start_matches(['%', '!']);
    if index == 0 {
        name.to_owned()
    } else {
        format!("!{name}")
    }
}

/// Writes a colour drawing: one Inkscape layer per pen
/// (`<g inkscape:groupmode="layer" inkscape:label="cyan" fill="#00ffff">`,
/// or `stroke` with a pen), in the layers' order, labelled by
/// [`layer_label`] (`"!magenta"`: a pause before each layer after the
/// first). The options' ink is not
/// used; each layer has its own. Each layer multiplies what lies below it
/// (`style="mix-blend-mode:multiply"`), as transparent inks do on paper
/// and in the PNG, so that browsers and Inkscape show what the plot will;
/// plotters and vpype ignore the style.
pub fn write_layers(w: &mut dyn Write, layers: &[Layer<'_>], opts: &SvgOptions) -> Result<()> {
    let pen = opts.pen()?;
    let all: Vec<Dot> = layers.iter().flat_map(|l| l.dots.iter().copied()).collect();
    check_finite(&all)?;
    let pen_layers = layers
        .iter()
        .filter(|l| !l.name.contains("registration"))
        .count();
    let (width, height, view, scale, offset) = opts.frame(pen.is_some());
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" version="1.1" width="{width}" height="{height}" viewBox="0 0 {view}">"#
    )?;
    // A poster's crosses are not the drawing's marks.
    let marked = |l: &&Layer<'_>| !l.name.contains("registration");
    let strokes: usize = layers.iter().filter(marked).map(|l| l.strokes.len()).sum();
    if strokes == 0 {
        writeln!(
            w,
            "<!-- {} dots in {} pens, made by pixelpie -->",
            all.len(),
            pen_layers
        )?;
    } else {
        let vertices: usize = layers
            .iter()
            .filter(marked)
            .flat_map(|l| l.strokes)
            .map(|s| s.points.len())
            .sum();
        writeln!(
            w,
            "<!-- {strokes} lines through {vertices} points in {} pens, made by pixelpie -->",
            pen_layers
        )?;
    }
    write_paper(w, opts, &view)?;
    let mut pens = 0;
    for l in layers {
        let ink = super::super::colour::pens::hex_of(l.ink);
        // A poster's crosses are no pen's layer: the pens keep their ids,
        // and the first pen follows the crosses without a pause (the
        // crosses are drawn with it).
        let (id, index) = if l.name.contains("registration") {
            ("registration".to_owned(), 0)
        } else {
            pens += 1;
            (format!("layer{pens}"), pens - 1)
        };
        let label = layer_label(index, l.name).replace(['"', '<', '>', '&'], "_");
        let blend = if l.opaque {
            ""
        } else {
            r#" style="mix-blend-mode:multiply""#
        };
        match pen {
            None => {
                writeln!(
                    w,
                    r#"<g inkscape:groupmode="layer" id="{id}" inkscape:label="{label}" fill="{ink}" stroke="none"{blend}>"#
                )?;
                write_circles(w, l.dots, scale, offset)?;
                for s in l.strokes {
                    writeln!(
                        w,
                        r#"<g fill="none" stroke="{ink}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round" transform="scale({})">"#,
                        num(f64::from(s.width) * scale * PATH_UNITS_PER_MM),
                        num(1.0 / PATH_UNITS_PER_MM)
                    )?;
                    write_stroke(w, s, scale, offset)?;
                    writeln!(w, "</g>")?;
                }
            }
            Some((pen, _)) => {
                let pen = l.pen_mm.unwrap_or(pen);
                writeln!(
                    w,
                    r#"<g inkscape:groupmode="layer" id="{id}" inkscape:label="{label}" fill="none" stroke="{ink}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round"{blend}>"#,
                    num(pen)
                )?;
                write_pen_dots(w, l.dots, (scale, offset), pen, opts.dot_path)?;
                if !l.strokes.is_empty() {
                    writeln!(
                        w,
                        r#"<g transform="scale({})" stroke-width="{}">"#,
                        num(1.0 / PATH_UNITS_PER_MM),
                        num(pen * PATH_UNITS_PER_MM)
                    )?;
                    for s in l.strokes {
                        write_stroke(w, s, scale, offset)?;
                    }
                    writeln!(w, "</g>")?;
                }
            }
        }
        writeln!(w, "</g>")?;
    }
    writeln!(w, "</svg>")?;
    Ok(())
}

/// The paper, for viewers, when it is not white: a rectangle over the
/// viewBox (`view`: its width and height) on a layer whose name starts
/// with `%`, which the AxiDraw's software skips; it holds no path.
fn write_paper(w: &mut dyn Write, opts: &SvgOptions, view: &str) -> Result<()> {
    if let Some(paper) = opts.paper {
        write_paper_layer(w, view, &super::super::colour::pens::hex_of(paper))?;
    }
    Ok(())
}

/// The paper's layer: a rectangle of colour `fill` over the viewBox
/// (`view`: its width and height) on a layer whose name starts with `%`,
/// which the AxiDraw's software skips; it holds no path.
pub(crate) fn write_paper_layer(w: &mut dyn Write, view: &str, fill: &str) -> std::io::Result<()> {
    let size = view.replace(' ', "\" height=\"");
    writeln!(
        w,
        r#"<g inkscape:groupmode="layer" id="paper" inkscape:label="% paper (not plotted)"><rect x="0" y="0" width="{size}" fill="{fill}"/></g>"#
    )
}

/// The style of the one ink's group: multiplied over coloured paper when
/// it is transparent.
fn ink_style(opts: &SvgOptions) -> &'static str {
    if opts.paper.is_some() && opts.multiply {
        r#" style="mix-blend-mode:multiply""#
    } else {
        ""
    }
}

/// Err for the first dot that is not finite.
fn check_finite(dots: &[Dot]) -> Result<()> {
    if let Some((i, d)) = dots
        .iter()
        .enumerate()
        .find(|(_, d)| !(d.x.is_finite() && d.y.is_finite() && d.radius.is_finite()))
    {
        return Err(Error::InvalidParameter(format!(
            "dot {i} ({}, {}, radius {}) is not finite",
            d.x, d.y, d.radius
        )));
    }
    Ok(())
}

/// The pen-plotter document: a viewBox in mm, one Inkscape layer, one path
/// per dot.
fn write_pen(w: &mut dyn Write, dots: &[Dot], opts: &SvgOptions, pen: f64) -> Result<()> {
    check_finite(dots)?;
    let (width, height, view, scale, offset) = opts.frame(true);
    let ink = opts.ink_name();
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        w,
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" version="1.1" width="{width}" height="{height}" viewBox="0 0 {view}">"#
    )?;
    writeln!(w, "<!-- {} dots, made by pixelpie -->", dots.len())?;
    write_paper(w, opts, &view)?;
    writeln!(
        w,
        r#"<g inkscape:groupmode="layer" id="layer1" inkscape:label="1 stipple" fill="none" stroke="{}" stroke-width="{}" stroke-linecap="round" stroke-linejoin="round"{}>"#,
        ink,
        num(pen),
        ink_style(opts)
    )?;
    write_pen_dots(w, dots, (scale, offset), pen, opts.dot_path)?;
    writeln!(w, "</g>")?;
    writeln!(w, "</svg>")?;
    Ok(())
}

/// One stroked path per dot, as a pen `pen` mm wide draws it, the dots
/// scaled by `scale` mm per domain pixel and moved by `offset` mm.
fn write_pen_dots(
    w: &mut dyn Write,
    dots: &[Dot],
    (scale, offset): (f64, (f64, f64)),
    pen: f64,
    path: DotPath,
) -> Result<()> {
    // The paths in hundredths of a mm, whole numbers: a group scaled to
    // mm, its stroke as wide in its own units.
    writeln!(
        w,
        r#"<g transform="scale({})" stroke-width="{}">"#,
        num(1.0 / PATH_UNITS_PER_MM),
        num(pen * PATH_UNITS_PER_MM)
    )?;
    write_lines(w, dots, |d, buf| {
        let (cx, cy, r) = (
            offset.0 + f64::from(d.x) * scale,
            offset.1 + f64::from(d.y) * scale,
            f64::from(d.radius) * scale,
        );
        buf.extend_from_slice(br#"<path d=""#);
        push_path(buf, &pen_path(cx, cy, r, pen, path));
        buf.extend_from_slice(br#"" data-dot=""#);
        push_tenths(buf, cx);
        buf.push(b' ');
        push_tenths(buf, cy);
        buf.push(b' ');
        push_tenths(buf, r);
        buf.extend_from_slice(b"\"/>\n");
    })?;
    writeln!(w, "</g>")?;
    Ok(())
}

/// One `<path>` for `stroke`, its points scaled by `scale` and moved by
/// `offset` into the page's units and written in hundredths of them, on
/// the grid as dots' paths are ([`push_path`]): straight between its
/// points, or, smooth, as relative cubic Béziers (`c`) through them.
fn write_stroke(w: &mut dyn Write, stroke: &Stroke, scale: f64, offset: (f64, f64)) -> Result<()> {
    let page = |p: [f64; 2]| (offset.0 + p[0] * scale, offset.1 + p[1] * scale);
    let pts: Vec<[f64; 2]> = stroke
        .points
        .iter()
        .map(|p| [f64::from(p[0]), f64::from(p[1])])
        .collect();
    if pts.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
        return Err(Error::InvalidParameter(
            "a stroke's point is not finite".into(),
        ));
    }
    let mut buf = Vec::with_capacity(pts.len() * 12 + 32);
    buf.extend_from_slice(br#"<path d=""#);
    if stroke.smooth && pts.len() > 2 {
        let curves: Vec<[(f64, f64); 4]> = super::line::catmull_rom(&pts)
            .into_iter()
            .map(|c| c.map(page))
            .collect();
        push_curves(&mut buf, &curves);
    } else {
        let on_page: Vec<(f64, f64)> = pts.into_iter().map(page).collect();
        push_path(&mut buf, &on_page);
        if on_page.len() == 1 {
            // One point: a touch, as a dot no wider than the pen.
            buf.extend_from_slice(b"l1 0");
        }
    }
    buf.extend_from_slice(b"\"/>\n");
    w.write_all(&buf)?;
    Ok(())
}

/// Appends cubic Béziers joined end to start as a path's `d` in
/// hundredths of the page's units: `M` the first point, then relative
/// `c` segments on the grid (each point rounded, the steps the rounded
/// differences, so no error adds up).
fn push_curves(buf: &mut Vec<u8>, curves: &[[(f64, f64); 4]]) {
    let unit = |p: (f64, f64)| {
        (
            (p.0 * PATH_UNITS_PER_MM).round() as i64,
            (p.1 * PATH_UNITS_PER_MM).round() as i64,
        )
    };
    let Some(first) = curves.first() else {
        return;
    };
    let mut at = unit(first[0]);
    buf.push(b'M');
    push_int(buf, at.0);
    push_int(buf, at.1);
    buf.push(b'c');
    for c in curves {
        let (c1, c2, end) = (unit(c[1]), unit(c[2]), unit(c[3]));
        for p in [c1, c2, end] {
            push_int(buf, p.0 - at.0);
            push_int(buf, p.1 - at.1);
        }
        at = end;
    }
}

/// Appends `mm` in hundredths of a mm to a tenth (0.001 mm): `12345.6`
/// for 123.456 mm, `61` for 0.61.
fn push_tenths(buf: &mut Vec<u8>, mm: f64) {
    let n = (mm * PATH_UNITS_PER_MM * 10.0).round();
    if !n.is_finite() || n.abs() >= 1e15 {
        buf.extend_from_slice(num(mm * PATH_UNITS_PER_MM).as_bytes());
        return;
    }
    let n = n as i64;
    if n < 0 {
        buf.push(b'-');
    }
    let (int, tenth) = (n.unsigned_abs() / 10, n.unsigned_abs() % 10);
    buf.extend_from_slice(int.to_string().as_bytes());
    if tenth != 0 {
        buf.push(b'.');
        buf.push(b'0' + tenth as u8);
    }
}

/// Units of a pen path's coordinates per mm: the 0.01 mm a plotter
/// resolves.
pub const PATH_UNITS_PER_MM: f64 = 100.0;

/// `pts` as the file holds them: each point on the 0.01 mm grid, none
/// repeating the one before ([`push_path`]'s points, in mm).
pub(crate) fn on_grid(pts: &mut Vec<(f64, f64)>) {
    let unit = |v: f64| (v * PATH_UNITS_PER_MM).round();
    let mut last: Option<(f64, f64)> = None;
    pts.retain_mut(|p| {
        let q = (unit(p.0), unit(p.1));
        if last == Some(q) {
            return false;
        }
        last = Some(q);
        *p = (q.0 / PATH_UNITS_PER_MM, q.1 / PATH_UNITS_PER_MM);
        true
    });
}

/// Appends a pen path's `d` in hundredths of a mm, whole numbers: the
/// first point absolute (`M1205 8793`), then each step relative
/// (`l10 2-5 10…`), all on the 0.01 mm grid. Each point is rounded on the
/// grid and the steps are the differences of the rounded points, so no
/// error adds up along the path: every point is within 0.005 mm of its
/// place on each axis. Steps that round to nothing are left out, and a
/// separator is written only where SVG's number syntax needs one (before
/// a number that is not negative).
fn push_path(buf: &mut Vec<u8>, pts: &[(f64, f64)]) {
    let unit = |v: f64| (v * PATH_UNITS_PER_MM).round() as i64;
    let Some(&(x0, y0)) = pts.first() else {
        return;
    };
    let mut at = (unit(x0), unit(y0));
    buf.push(b'M');
    push_int(buf, at.0);
    push_int(buf, at.1);
    let mut first = true;
    for &(x, y) in &pts[1..] {
        let p = (unit(x), unit(y));
        let step = (p.0 - at.0, p.1 - at.1);
        if step == (0, 0) {
            continue;
        }
        if first {
            buf.push(b'l');
            first = false;
        }
        push_int(buf, step.0);
        push_int(buf, step.1);
        at = p;
    }
}

/// Appends the whole number `n`, preceded by a space where it would run
/// into the number before (a `-` starts a number of its own).
fn push_int(buf: &mut Vec<u8>, n: i64) {
    if n >= 0 && buf.last().is_some_and(u8::is_ascii_digit) {
        buf.push(b' ');
    }
    buf.extend_from_slice(n.to_string().as_bytes());
}

/// The polyline a pen `pen` wide follows to ink the disk of centre
/// (`cx`, `cy`) and radius `r` (all in mm), at least two points.
///
/// A disk no wider than the pen (2r ≤ pen, both rounded to 0.001 mm) is one
/// touch: the centre and a point [`TOUCH_MM`] to its right. Otherwise the
/// pen's centre runs an Archimedean spiral from the disk's centre out to
/// radius R = r − pen/2 at a pitch ≤ [`PITCH`] × pen, then once round the
/// circle of radius R: every point of the disk is then within pen/2 of the
/// path and the path stays within R, so the ink is the disk (up to about
/// [`CHORD_MM`] / 2 at its edge, where the circle is a polygon). R is at
/// least [`TOUCH_MM`], so that a disk barely wider than the pen is still a
/// visible loop; when R ≤ pen/2 the circle alone covers the disk and the
/// spiral is left out.
///
/// [`DotPath::Circle`] leaves the spiral out always (a ring), and
/// [`DotPath::Touch`] makes every dot a touch.
pub(crate) fn pen_path(cx: f64, cy: f64, r: f64, pen: f64, path: DotPath) -> Vec<(f64, f64)> {
    let mut pts = Vec::new();
    pen_path_into(&mut pts, cx, cy, r, pen, path);
    pts
}

/// [`pen_path`], appended to `pts`.
pub(crate) fn pen_path_into(
    pts: &mut Vec<(f64, f64)>,
    cx: f64,
    cy: f64,
    r: f64,
    pen: f64,
    path: DotPath,
) {
    // Decided on the numbers as written (three decimals): a reader of the
    // file finds a touch exactly where 2 × data-dot's r ≤ stroke-width.
    if path == DotPath::Touch || 2.0 * (r * 1000.0).round() <= (pen * 1000.0).round() {
        pts.extend([(cx, cy), (cx + TOUCH_MM, cy)]);
        return;
    }
    let big = (r - pen / 2.0).max(TOUCH_MM);
    let turns = if big <= pen / 2.0 || path == DotPath::Circle {
        0.0
    } else {
        (big / (PITCH * pen)).ceil()
    };
    // The closing circle is a polygon whose vertices lie a little outside R
    // and whose chords' midpoints lie as much inside: its edge strays at
    // most about CHORD_MM / 2 either way, so the ink's edge does too.
    let n = circle_segments(big);
    let outer = 2.0 * big / (1.0 + (PI / f64::from(n)).cos());
    let end = TAU * turns;
    if turns > 0.0 {
        // ρ = aθ, θ in [0, end]: the pitch is 2πa = outer / turns.
        let a = outer / end;
        let mut theta = 0.0;
        pts.push((cx, cy));
        while theta < end {
            let rho = a * theta;
            // Chord error ≈ dθ² (ρ² + 2a²) / (8 √(ρ² + a²)), from the
            // spiral's curvature at ρ.
            let q = rho.hypot(a);
            let step = (8.0 * CHORD_MM * q / (rho * rho + 2.0 * a * a))
                .sqrt()
                .min(PI / 2.0);
            theta = (theta + step).min(end);
            pts.push((cx + a * theta * theta.cos(), cy + a * theta * theta.sin()));
        }
    } else {
        pts.push((cx + outer, cy));
    }
    for k in 1..=n {
        let phi = end + TAU * f64::from(k) / f64::from(n);
        pts.push((cx + outer * phi.cos(), cy + outer * phi.sin()));
    }
}

/// Segments of a polygon inscribed in a circle of radius `r` whose chords
/// stay within [`CHORD_MM`] of the circle (at least 8).
fn circle_segments(r: f64) -> u32 {
    if r <= CHORD_MM {
        return 8;
    }
    let n = (PI / (1.0 - CHORD_MM / r).acos()).ceil();
    // About 700 for a radius of 1 m.
    (n as u32).max(8)
}

/// Appends [`num`]`(v)` to `buf`, without its allocations: the common case
/// in integer arithmetic, the rest (near a rounding tie, huge, not finite)
/// through [`num`], so that the text is the same byte for byte.
fn push_num(buf: &mut Vec<u8>, v: f64) {
    let t = v * 1000.0;
    let frac = t - t.floor();
    if !t.is_finite() || t.abs() >= 1e12 {
        buf.extend_from_slice(num(v).as_bytes());
        return;
    }
    let n = if (frac - 0.5).abs() >= 1e-6 {
        t.round() as i64
    } else if frac == 0.5 && v.mul_add(1000.0, -t) == 0.0 {
        // An exact tie (v·1000 exact, ending in .5: a dart coordinate on
        // the 1/256 px grid, one in 32) rounds half to even, as `format!`
        // does.
        let below = t.floor() as i64;
        below + (below & 1)
    } else {
        buf.extend_from_slice(num(v).as_bytes());
        return;
    };
    if n < 0 {
        buf.push(b'-');
    }
    let n = n.unsigned_abs();
    let (int, mut dec) = (n / 1000, n % 1000);
    let mut digits = [0u8; 20];
    let mut i = digits.len();
    let mut k = int;
    loop {
        i -= 1;
        digits[i] = b'0' + (k % 10) as u8;
        k /= 10;
        if k == 0 {
            break;
        }
    }
    buf.extend_from_slice(&digits[i..]);
    if dec != 0 {
        buf.push(b'.');
        let mut width = 3;
        while dec % 10 == 0 {
            dec /= 10;
            width -= 1;
        }
        let start = buf.len();
        for _ in 0..width {
            buf.push(b'0');
        }
        for j in (0..width).rev() {
            buf[start + j] = b'0' + (dec % 10) as u8;
            dec /= 10;
        }
    }
}

/// A number with at most three decimals and no trailing zeros.
fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render(dots: &[Dot], opts: &SvgOptions) -> String {
        let mut out = Vec::new();
        write(&mut out, dots, opts).expect("write");
        String::from_utf8(out).expect("utf-8")
    }

    fn pen_opts(domain: (u32, u32), width_mm: f64, pen: f64) -> SvgOptions {
        SvgOptions::with_width_mm(domain, width_mm)
            .and_then(|o| o.with_pen_mm(pen))
            .expect("valid options")
    }

    /// A path read back: the points of its `d`, and its `data-dot`.
    type PenPath = (Vec<(f64, f64)>, [f64; 3]);

    /// The paths of a pen drawing, in order.
    fn paths(text: &str) -> Vec<PenPath> {
        text.lines()
            .filter(|l| l.starts_with("<path "))
            .map(|l| {
                let attr = |name: &str| {
                    let start = l.find(&format!(" {name}=\"")).expect(name) + name.len() + 3;
                    let len = l[start..].find('"').expect("closing quote");
                    &l[start..start + len]
                };
                // One moveto, then one run of relative steps.
                let d = attr("d");
                assert!(d.starts_with('M') && d.matches(char::is_alphabetic).count() <= 2);
                // In hundredths of a mm (the group's scale), read in mm.
                let mm = |v: f64| v / PATH_UNITS_PER_MM;
                let pts = crate::stipple::read::polyline(d).expect("a polyline");
                let pts = pts.into_iter().map(|(x, y)| (mm(x), mm(y))).collect();
                let dot: Vec<f64> = attr("data-dot")
                    .split(' ')
                    .map(|t| mm(t.parse().expect("number")))
                    .collect();
                (pts, [dot[0], dot[1], dot[2]])
            })
            .collect()
    }

    /// Distance from `p` to the segment `a`–`b`.
    fn seg_dist(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
    }

    fn poly_dist(p: (f64, f64), pts: &[(f64, f64)]) -> f64 {
        pts.windows(2)
            .map(|s| seg_dist(p, s[0], s[1]))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn push_num_writes_what_num_writes() {
        let mut state = 0x1234_5678_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut values = vec![
            0.0,
            -0.0,
            0.0005,
            0.0015,
            0.0025,
            -0.0005,
            -0.0004,
            -0.0006,
            1.0005,
            2.5e-4,
            0.1,
            0.25,
            999.9995,
            1e11,
            -1e11,
            1e13,
            f64::NAN,
            f64::INFINITY,
            123.456,
            0.0625,
            -0.0625,
            0.1875,
            -0.1875,
            2.0 / 256.0,
        ];
        for _ in 0..200_000 {
            let bits = next();
            let v = match bits % 5 {
                0 => f64::from(f32::from_bits((next() as u32) & 0x4fff_ffff)),
                1 => (bits >> 11) as f64 / (1u64 << 40) as f64 * 1e4,
                2 => f64::from(((bits >> 20) % 2_000_000) as f32 / 64.0) * (210.0 / 5016.0),
                // Dart coordinates: the 1/256 px grid, exact ties included.
                3 => ((bits >> 30) % 4_000_000) as f64 / 256.0 - 2000.0,
                _ => ((bits >> 30) % 100_000) as f64 / 2000.0 - 25.0,
            };
            values.push(v);
        }
        for v in values {
            let mut buf = Vec::new();
            push_num(&mut buf, v);
            assert_eq!(String::from_utf8(buf).unwrap(), num(v), "{v:e}");
        }
    }

    #[test]
    fn without_a_pen_the_output_is_unchanged() {
        let dots = [
            Dot {
                x: 1.5,
                y: 2.25,
                radius: 0.5,
            },
            Dot {
                x: 3.0,
                y: 4.0,
                radius: 1.0 / 3.0,
            },
        ];
        let expected = r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="200mm" height="100mm" viewBox="0 0 20 10">
<!-- 2 dots, made by pixelpie -->
<g fill="black" stroke="none">
<circle cx="1.5" cy="2.25" r="0.5"/>
<circle cx="3" cy="4" r="0.333"/>
</g>
</svg>
"#;
        let opts = SvgOptions::with_width_mm((20, 10), 200.0).expect("valid");
        assert_eq!(render(&dots, &opts), expected);
        let px = render(&dots, &SvgOptions::new((20, 10)));
        assert!(px.contains(r#"width="20px" height="10px" viewBox="0 0 20 10""#));
    }

    #[test]
    fn pen_mode_has_one_layer_in_millimetres() {
        let text = render(
            &[Dot {
                x: 50.0,
                y: 25.0,
                radius: 2.0,
            }],
            &pen_opts((100, 50), 200.0, 0.3),
        );
        for needle in [
            r#"xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape""#,
            r#"width="200mm" height="100mm" viewBox="0 0 200 100""#,
            "<!-- 1 dots, made by pixelpie -->",
            r#"<g inkscape:groupmode="layer" id="layer1" inkscape:label="1 stipple" fill="none" stroke="black" stroke-width="0.3" stroke-linecap="round" stroke-linejoin="round">"#,
            r#"<g transform="scale(0.01)" stroke-width="30">"#,
            r#"data-dot="10000 5000 400""#,
        ] {
            assert!(text.contains(needle), "{needle} missing in\n{text}");
        }
        assert_eq!(text.matches("<g").count(), 2);
        assert!(!text.contains("<circle"));
        assert!(text.ends_with("</g>\n</g>\n</svg>\n"));
    }

    #[test]
    fn one_path_per_dot_in_order() {
        let dots: Vec<Dot> = (0..50)
            .map(|i| Dot {
                x: (i * 7 % 100) as f32,
                y: (i * 13 % 50) as f32,
                radius: 0.05 * i as f32,
            })
            .collect();
        let text = render(&dots, &pen_opts((100, 50), 100.0, 0.5));
        let p = paths(&text);
        assert_eq!(p.len(), dots.len());
        assert_eq!(text.matches("<path").count(), dots.len());
        assert_eq!(text.matches("data-dot=").count(), dots.len());
        for ((pts, dot), d) in p.iter().zip(&dots) {
            assert_eq!(
                *dot,
                [
                    f64::from(d.x),
                    f64::from(d.y),
                    num(f64::from(d.radius)).parse().unwrap()
                ]
            );
            assert!(pts.len() >= 2);
            // Every path has some length, so that plotter tools keep it.
            assert!(pts.iter().any(|q| *q != pts[0]), "{pts:?}");
        }
        // Touches up to 2r = 0.5 (i ≤ 5), spirals beyond.
        assert!(p[..=5].iter().all(|(pts, _)| pts.len() == 2));
        assert!(p[6..].iter().all(|(pts, _)| pts.len() > 8));
    }

    #[test]
    fn written_paths_are_the_pen_paths_on_the_plotters_grid() {
        // Every written point within half a grid diagonal of its place on
        // the exact path, none left out but those that round onto the one
        // before; the numbers read back whatever separators they need.
        let grid = 0.5f64.hypot(0.5) / PATH_UNITS_PER_MM + 1e-9;
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..400 {
            let (cx, cy) = (next() * 300.0 - 20.0, next() * 200.0);
            let r = 0.05 + next() * 2.0;
            let path = [DotPath::Spiral, DotPath::Circle, DotPath::Touch][k % 3];
            let exact = pen_path(cx, cy, r, 0.3, path);
            let mut buf = Vec::new();
            push_path(&mut buf, &exact);
            let d = String::from_utf8(buf).unwrap();
            // Read in hundredths, back in mm.
            let written: Vec<(f64, f64)> = crate::stipple::read::polyline(&d)
                .expect(&d)
                .into_iter()
                .map(|(x, y)| (x / PATH_UNITS_PER_MM, y / PATH_UNITS_PER_MM))
                .collect();
            let mut kept = vec![exact[0]];
            let unit = |p: (f64, f64)| ((p.0 * 100.0).round(), (p.1 * 100.0).round());
            for &p in &exact[1..] {
                if unit(p) != unit(*kept.last().unwrap()) {
                    kept.push(p);
                }
            }
            assert_eq!(written.len(), kept.len(), "{d}");
            for (w, e) in written.iter().zip(&kept) {
                assert!((w.0 - e.0).hypot(w.1 - e.1) <= grid, "{d}: {w:?} vs {e:?}");
            }
        }
    }

    #[test]
    fn a_dot_no_wider_than_the_pen_is_one_touch() {
        // 2 mm per px: r = 0.15 mm, as wide as the pen.
        let text = render(
            &[Dot {
                x: 3.0,
                y: 4.0,
                radius: 0.075,
            }],
            &pen_opts((10, 10), 20.0, 0.3),
        );
        assert!(
            text.contains(r#"<path d="M600 800l1 0" data-dot="600 800 15"/>"#),
            "{text}"
        );
    }

    #[test]
    fn a_big_dot_is_inked_exactly() {
        // (radius, pen) in mm: barely wider than the pen (R clamped to
        // TOUCH_MM), circle only (R ≤ pen/2), one turn, many turns.
        for (r, pen) in [
            (0.151, 0.3),
            (0.2, 0.3),
            (0.29, 0.3),
            (0.45, 0.3),
            (1.087, 0.3),
            (3.0, 0.3),
            (2.0, 1.0),
            (1.0, 0.05),
        ] {
            let (cx, cy) = (10.0, 20.0);
            // 1 mm per px.
            let text = render(
                &[Dot {
                    x: cx as f32,
                    y: cy as f32,
                    radius: r as f32,
                }],
                &pen_opts((100, 100), 100.0, pen),
            );
            let p = paths(&text);
            let pts = &p[0].0;
            assert!(pts.len() > 2, "r {r} pen {pen}");
            // The ink stays inside the disk (up to the clamp, and rounding
            // on the 0.01 mm grid: half its diagonal).
            let grid = 0.5f64.hypot(0.5) / PATH_UNITS_PER_MM;
            let inner = (r - pen / 2.0).max(TOUCH_MM) + CHORD_MM / 2.0 + grid;
            for q in pts {
                let d = (q.0 - cx).hypot(q.1 - cy);
                assert!(d <= inner, "r {r} pen {pen}: vertex at {d} > {inner}");
            }
            // Every point of the disk is within pen/2 of the path (up to
            // half the chord error: turns a pen apart only touch).
            let margin = CHORD_MM / 2.0 + 0.002;
            let n = 60;
            let step = 2.0 * r / f64::from(n);
            let mut checked = 0;
            for i in 0..=n {
                for j in 0..=n {
                    let q = (cx - r + step * f64::from(i), cy - r + step * f64::from(j));
                    if (q.0 - cx).hypot(q.1 - cy) > r - margin {
                        continue;
                    }
                    checked += 1;
                    let d = poly_dist(q, pts);
                    assert!(
                        d <= pen / 2.0 + CHORD_MM / 2.0 + grid,
                        "r {r} pen {pen}: {q:?} is {d} from the path"
                    );
                }
            }
            assert!(checked > 2000);
        }
    }

    #[test]
    fn pen_paths_start_at_the_centre() {
        let text = render(
            &[Dot {
                x: 10.0,
                y: 10.0,
                radius: 2.0,
            }],
            &pen_opts((20, 20), 20.0, 0.3),
        );
        let p = paths(&text);
        assert_eq!(p[0].0[0], (10.0, 10.0));
        // The spiral ends on the closing circle of radius r - pen/2.
        let last = *p[0].0.last().unwrap();
        assert!(((last.0 - 10.0).hypot(last.1 - 10.0) - 1.85).abs() < CHORD_MM);
    }

    #[test]
    fn invalid_pen_widths_are_refused() {
        let page = SvgOptions::with_width_mm((100, 50), 100.0).expect("valid");
        for bad in [0.0, -0.3, 4e-4, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = page.with_pen_mm(bad).expect_err("refused").to_string();
            assert!(e.contains(&format!("{bad}")), "{e}");
            assert!(!e.contains('\n'));
            // Set directly, the writer refuses it too.
            let opts = SvgOptions {
                pen_mm: Some(bad),
                ..page
            };
            assert!(write(&mut Vec::new(), &[], &opts).is_err());
        }
        let e = SvgOptions::new((100, 50))
            .with_pen_mm(0.3)
            .expect_err("needs a page size")
            .to_string();
        assert!(e.contains("«pen_mm» needs «width_mm»"), "{e}");
        let opts = SvgOptions {
            pen_mm: Some(0.3),
            ..SvgOptions::new((100, 50))
        };
        assert!(write(&mut Vec::new(), &[], &opts).is_err());
        let nan = Dot {
            x: 1.0,
            y: f32::NAN,
            radius: 1.0,
        };
        let mut out = Vec::new();
        let e = write(&mut out, &[nan], &page.with_pen_mm(0.3).expect("valid"));
        assert!(e.expect_err("not finite").to_string().contains("dot 0"));
        assert!(out.is_empty(), "nothing written before the error");
        assert_eq!(page.with_pen_mm(1e-3).expect("valid").pen_mm, Some(1e-3));
    }

    #[test]
    fn pen_drawings_read_back() {
        let dots = [
            Dot {
                x: 10.0,
                y: 20.0,
                radius: 0.1,
            },
            Dot {
                x: 30.0,
                y: 5.0,
                radius: 3.0,
            },
        ];
        // 0.5 mm per px.
        let text = render(&dots, &pen_opts((40, 30), 20.0, 0.4));
        let drawing = super::super::read::read_svg(&text).expect("ours");
        assert_eq!((drawing.view_width, drawing.view_height), (20.0, 15.0));
        assert_eq!(
            drawing.dots,
            [
                Dot {
                    x: 5.0,
                    y: 10.0,
                    radius: 0.05
                },
                Dot {
                    x: 15.0,
                    y: 2.5,
                    radius: 1.5
                },
            ]
        );
    }
}
