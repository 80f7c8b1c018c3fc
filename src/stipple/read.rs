//! Reading pixelpie's own SVG drawings back ([`read_svg`]), e.g. to measure
//! a drawing against its photo after the fact.
//!
//! A drawing is ours when it holds the comment `<!-- N dots, made by
//! pixelpie -->` that [`super::svg`] writes. Its dots are the `<circle cx cy
//! r>` elements, and the `<path>` elements that carry a `data-dot="cx cy r"`
//! attribute (the pen-plotter output: one path per dot; its `d` is not
//! read). Paths without `data-dot` are ignored, so are elements inside
//! `<defs>`, `<symbol>`, `<clipPath>`, `<mask>`, `<pattern>`, `<marker>` and
//! `<metadata>`. Groups may nest, carry any other attributes (Inkscape's
//! layers, labels) and `transform`s: those are applied to the centres, and
//! the radius is scaled by `sqrt(|det|)` of the transform (exact for
//! translations, rotations and uniform scales; an area-preserving circle for
//! the rest). Coordinates are returned relative to the viewBox's top-left
//! corner, in viewBox units. Lengths may carry a `px` suffix; other units
//! and percentages are refused.

use quick_xml::Reader;
use quick_xml::XmlVersion;
use quick_xml::events::{BytesStart, Event};

use super::Dot;

/// A drawing read back: its viewBox size and dots in viewBox units.
#[derive(Clone, Debug, PartialEq)]
pub struct Drawing {
    /// The viewBox's width.
    pub view_width: f64,
    /// The viewBox's height.
    pub view_height: f64,
    /// The dots in document order, relative to the viewBox's top-left corner.
    pub dots: Vec<Dot>,
    /// The Inkscape layers, in document order: label and colour (its
    /// `fill`, else its `stroke`; black when neither is a `#rrggbb` colour).
    /// A colour drawing has one per pen.
    pub layers: Vec<(String, [u8; 3])>,
    /// The layer of each dot (an index into `layers`; 0 outside layers).
    pub layer_of: Vec<usize>,
    /// Each dot's pen path in viewBox units, as the plotter follows it
    /// (empty for a `<circle>`, or a path of curves).
    pub paths: Vec<Vec<(f64, f64)>>,
    /// The paper's colour, from the rectangle of a layer plotters skip
    /// (its label starts with `%`), when there is one.
    pub paper: Option<[u8; 3]>,
    /// The colour (`fill`, else `stroke`, a `#rrggbb` colour) of the group
    /// around the first dot outside every layer: a one-ink drawing's ink.
    pub ink: Option<[u8; 3]>,
}

/// Parses an SVG written by pixelpie. Err with a one-line message if it is
/// not XML/SVG, or not ours (ours contain the comment
/// `<!-- N dots, made by pixelpie -->`), or has no viewBox, or a dot cannot
/// be read.
///
/// ```
/// use pixelpie::stipple::read::read_svg;
/// let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 8">
/// <!-- 1 dots, made by pixelpie -->
/// <g fill="black"><circle cx="5" cy="4" r="1.5"/></g></svg>"#;
/// let d = read_svg(svg).unwrap();
/// assert_eq!((d.view_width, d.view_height, d.dots.len()), (10.0, 8.0, 1));
/// assert_eq!(d.dots[0].radius, 1.5);
/// ```
pub fn read_svg(text: &str) -> Result<Drawing, ReadError> {
    parse(text).map_err(ReadError)
}

/// Why an SVG is not a pixelpie drawing, on one line.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct ReadError(pub String);

/// [`read_svg`], its error a message.
fn parse(text: &str) -> Result<Drawing, String> {
    let mut reader = Reader::from_str(text);
    let mut doc = Document::default();
    loop {
        let event = reader.read_event().map_err(|e| {
            crate::text::single_line(&format!(
                "not valid XML (near byte {}): {e}",
                reader.error_position()
            ))
        })?;
        match event {
            Event::Start(e) => doc.element(&e, &reader, true)?,
            Event::Empty(e) => doc.element(&e, &reader, false)?,
            Event::End(_) => {
                doc.stack.pop();
            }
            Event::Comment(c) => doc.ours |= is_our_comment(&String::from_utf8_lossy(&c)),
            Event::Text(t) if doc.stack.is_empty() && !t.iter().all(u8::is_ascii_whitespace) => {
                return Err("not XML: text outside the root element".into());
            }
            Event::Eof => break,
            _ => {}
        }
    }
    doc.finish()
}

/// Whether a comment's text is `N dots, made by pixelpie`.
fn is_our_comment(text: &str) -> bool {
    let words: Vec<&str> = text.split_whitespace().collect();
    let digits = |n: &str| n.bytes().all(|b| b.is_ascii_digit());
    match words.as_slice() {
        [n, "dots,", "made", "by", "pixelpie"] => digits(n),
        [n, "dots", "in", k, "pens,", "made", "by", "pixelpie"] => digits(n) && digits(k),
        _ => false,
    }
}

/// The viewBox: origin and size.
#[derive(Clone, Copy, Debug)]
struct ViewBox {
    x: f64,
    y: f64,
    width: f64,
    height: f64,
}

/// One open element: the transform to the root's user space, and whether
/// its content is not drawn.
#[derive(Clone, Copy, Debug)]
struct Frame {
    transform: Affine,
    hidden: bool,
    /// The Inkscape layer it is in.
    layer: Option<usize>,
    /// Whether it is in a layer plotters skip (label `%…`).
    skipped: bool,
    /// The colour of the innermost group around it that has one.
    colour: Option<[u8; 3]>,
}

/// What the parse has found so far.
#[derive(Default)]
struct Document {
    /// Open elements, the root first.
    stack: Vec<Frame>,
    /// Whether the root element has been seen.
    root_seen: bool,
    /// The root's viewBox, if it has one, or why it cannot be read.
    view_box: Option<Result<ViewBox, String>>,
    /// Whether our comment has been seen.
    ours: bool,
    /// The dots read so far, in viewBox units.
    dots: Vec<Dot>,
    /// The first dot that could not be read; reported only for our files.
    bad_dot: Option<String>,
    /// The Inkscape layers found.
    layers: Vec<(String, [u8; 3])>,
    /// Each dot's layer.
    layer_of: Vec<usize>,
    /// Each dot's pen path.
    paths: Vec<Vec<(f64, f64)>>,
    /// The paper's colour.
    paper: Option<[u8; 3]>,
    /// The one-ink drawing's ink.
    ink: Option<[u8; 3]>,
}

impl Document {
    /// Handles an element's start (`opens`: it has content and an end tag).
    fn element(
        &mut self,
        e: &BytesStart<'_>,
        reader: &Reader<&[u8]>,
        opens: bool,
    ) -> Result<(), String> {
        let name = e.local_name();
        let name = String::from_utf8_lossy(name.as_ref());
        let attrs = Attrs::read(e, reader)?;
        let frame = match self.stack.last().copied() {
            None => self.root(&name, &attrs)?,
            Some(parent) => self.child(parent, &name, &attrs),
        };
        if opens {
            self.stack.push(frame);
        }
        Ok(())
    }

    /// Checks the root element and reads its viewBox.
    fn root(&mut self, name: &str, attrs: &Attrs) -> Result<Frame, String> {
        if self.root_seen {
            return Err("not XML: more than one root element".into());
        }
        if name != "svg" {
            return Err(format!("not an SVG document: the root element is <{name}>"));
        }
        self.root_seen = true;
        self.view_box = attrs.get("viewBox").map(parse_view_box);
        Ok(Frame {
            transform: Affine::IDENTITY,
            hidden: false,
            layer: None,
            skipped: false,
            colour: None,
        })
    }

    /// Handles an element inside the root; returns its frame.
    fn child(&mut self, parent: Frame, name: &str, attrs: &Attrs) -> Frame {
        let transform = match attrs.get("transform").map(parse_transform).transpose() {
            Ok(t) => parent.transform.then(t.unwrap_or(Affine::IDENTITY)),
            Err(e) => {
                self.fail(e);
                parent.transform
            }
        };
        let mut hidden = parent.hidden || NOT_DRAWN.contains(&name);
        let mut layer = parent.layer;
        let mut skipped = parent.skipped;
        if skipped && name == "rect" && self.paper.is_none() {
            self.paper = attrs
                .get("fill")
                .and_then(|c| crate::colour::pens::parse_hex(c).ok());
        }
        let colour = if name == "g" {
            [attrs.get("fill"), attrs.get("stroke")]
                .into_iter()
                .flatten()
                .find_map(|c| crate::colour::pens::parse_hex(c).ok())
                .or(parent.colour)
        } else {
            parent.colour
        };
        let label = attrs.get("inkscape:label").unwrap_or_default();
        if name == "g" && attrs.get("inkscape:groupmode") == Some("layer") && label.starts_with('%')
        {
            // A layer plotters skip (the paper): no pen, no dots.
            (hidden, skipped) = (true, true);
        } else if name == "g" && attrs.get("inkscape:groupmode") == Some("layer") {
            let colour = [attrs.get("fill"), attrs.get("stroke")]
                .into_iter()
                .flatten()
                .find_map(|c| crate::colour::pens::parse_hex(c).ok())
                .unwrap_or([0, 0, 0]);
            // A pen's name, without the pause mark of the layers after
            // the first (svg::layer_label).
            let label = attrs.get("inkscape:label").unwrap_or_default();
            let label = label.strip_prefix('!').unwrap_or(label).to_owned();
            self.layers.push((label, colour));
            layer = Some(self.layers.len() - 1);
        }
        if !hidden {
            match self.dot(name, attrs, transform) {
                Ok(Some(d)) => {
                    if layer.is_none() && self.ink.is_none() {
                        self.ink = colour;
                    }
                    self.dots.push(d);
                    self.layer_of.push(layer.unwrap_or(0));
                    let (ox, oy) = match &self.view_box {
                        Some(Ok(v)) => (v.x, v.y),
                        _ => (0.0, 0.0),
                    };
                    let path = match (name, attrs.get("d")) {
                        ("path", Some(d)) => polyline(d).unwrap_or_default(),
                        _ => Vec::new(),
                    };
                    self.paths.push(
                        path.into_iter()
                            .map(|(x, y)| {
                                let (x, y) = transform.apply(x, y);
                                (x - ox, y - oy)
                            })
                            .collect(),
                    );
                }
                Ok(None) => {}
                Err(e) => self.fail(e),
            }
        }
        Frame {
            transform,
            hidden,
            layer,
            skipped,
            colour,
        }
    }

    /// Remembers the first error about a dot.
    fn fail(&mut self, message: String) {
        self.bad_dot.get_or_insert(message);
    }

    /// The dot an element draws, if it is one.
    fn dot(&self, name: &str, attrs: &Attrs, transform: Affine) -> Result<Option<Dot>, String> {
        let [cx, cy, r] = match name {
            "circle" => circle(attrs)?,
            "path" => match attrs.get("data-dot") {
                Some(v) => data_dot(v)?,
                None => return Ok(None),
            },
            "svg" => return Err("nested <svg> elements are not supported".into()),
            _ => return Ok(None),
        };
        let (x, y) = transform.apply(cx, cy);
        let (ox, oy) = match &self.view_box {
            Some(Ok(v)) => (v.x, v.y),
            _ => (0.0, 0.0),
        };
        Ok(Some(Dot {
            x: (x - ox) as f32,
            y: (y - oy) as f32,
            radius: (r * transform.scale()) as f32,
        }))
    }

    /// The drawing, or why the document is not one of ours.
    fn finish(self) -> Result<Drawing, String> {
        if !self.root_seen {
            return Err("not an SVG document: no root element".into());
        }
        if !self.stack.is_empty() {
            return Err("not valid XML: the root element is not closed".into());
        }
        if !self.ours {
            return Err("not a pixelpie drawing: no \"N dots, made by pixelpie\" comment".into());
        }
        let view_box = self.view_box.ok_or("the <svg> element has no viewBox")??;
        if let Some(e) = self.bad_dot {
            return Err(e);
        }
        Ok(Drawing {
            view_width: view_box.width,
            view_height: view_box.height,
            dots: self.dots,
            layers: self.layers,
            layer_of: self.layer_of,
            paths: self.paths,
            paper: self.paper,
            ink: self.ink,
        })
    }
}

/// Elements whose content is not drawn where it stands.
const NOT_DRAWN: [&str; 7] = [
    "defs", "symbol", "clipPath", "mask", "pattern", "marker", "metadata",
];

/// An element's attributes, unescaped (names with their prefixes).
struct Attrs(Vec<(String, String)>);

impl Attrs {
    /// Reads and unescapes the attributes of `e`.
    fn read(e: &BytesStart<'_>, reader: &Reader<&[u8]>) -> Result<Self, String> {
        let bad =
            |e: &dyn std::fmt::Display| crate::text::single_line(&format!("not valid XML: {e}"));
        let mut out = Vec::new();
        for attr in e.attributes() {
            let attr = attr.map_err(|e| bad(&e))?;
            let value = attr
                .decoded_and_normalized_value(XmlVersion::Implicit1_0, reader.decoder())
                .map_err(|e| bad(&e))?;
            let key = String::from_utf8_lossy(attr.key.as_ref()).into_owned();
            out.push((key, value.into_owned()));
        }
        Ok(Self(out))
    }

    /// The value of attribute `key`.
    fn get(&self, key: &str) -> Option<&str> {
        self.0
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// `cx`, `cy`, `r` of a `<circle>` (absent ones are 0, as in SVG).
fn circle(attrs: &Attrs) -> Result<[f64; 3], String> {
    let get = |k: &str| attrs.get(k).map_or(Ok(0.0), |v| length(k, v));
    let dot = [get("cx")?, get("cy")?, get("r")?];
    check_radius(dot, "<circle>")
}

/// The three numbers of a `data-dot` attribute.
fn data_dot(value: &str) -> Result<[f64; 3], String> {
    let n = numbers(value).map_err(|e| format!("data-dot \"{value}\": {e}"))?;
    let dot: [f64; 3] = n
        .try_into()
        .map_err(|_| format!("data-dot \"{value}\" must hold three numbers: cx cy r"))?;
    check_radius(dot, "data-dot")
}

/// Err if the radius is negative.
fn check_radius(dot: [f64; 3], what: &str) -> Result<[f64; 3], String> {
    if dot[2] >= 0.0 {
        Ok(dot)
    } else {
        Err(format!("{what} radius {} is negative", dot[2]))
    }
}

/// A length attribute: a number, optionally in `px`.
fn length(key: &str, value: &str) -> Result<f64, String> {
    let v = value.trim();
    let v = v.strip_suffix("px").unwrap_or(v);
    match numbers(v).as_deref() {
        Ok([x]) => Ok(*x),
        _ => Err(format!("{key}=\"{value}\" is not a length in px")),
    }
}

/// Parses `viewBox="min-x min-y width height"`.
fn parse_view_box(value: &str) -> Result<ViewBox, String> {
    let bad = || format!("viewBox \"{value}\" must be four numbers with positive width and height");
    let n = numbers(value).map_err(|_| bad())?;
    match n.as_slice() {
        &[x, y, width, height] if width > 0.0 && height > 0.0 => Ok(ViewBox {
            x,
            y,
            width,
            height,
        }),
        _ => Err(bad()),
    }
}

/// The points of a path's `d` made of straight segments (`M`, `L`, `H`,
/// `V`, `Z`, absolute or relative, a moveto's further pairs linetos),
/// through one subpath; `None` for anything else (curves, a second
/// moveto, a number missing).
#[must_use]
pub fn polyline(d: &str) -> Option<Vec<(f64, f64)>> {
    let b = d.as_bytes();
    let (mut i, mut out) = (0, Vec::new());
    let (mut at, mut start, mut command) = ((0.0, 0.0), (0.0, 0.0), 0u8);
    let number = |i: &mut usize| -> Option<f64> {
        *i = skip_separators(b, *i);
        let end = number_end(b, *i);
        let v = d
            .get(*i..end)?
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())?;
        *i = end;
        Some(v)
    };
    loop {
        i = skip_separators(b, i);
        if i == b.len() {
            return (!out.is_empty()).then_some(out);
        }
        if b[i].is_ascii_alphabetic() {
            command = b[i];
            i += 1;
            if command.eq_ignore_ascii_case(&b'z') {
                at = start;
                out.push(at);
                continue;
            }
        }
        let relative = command.is_ascii_lowercase();
        let base = if relative { at } else { (0.0, 0.0) };
        at = match command.to_ascii_uppercase() {
            b'M' | b'L' => {
                let x = number(&mut i)?;
                let y = number(&mut i)?;
                (base.0 + x, base.1 + y)
            }
            b'H' => (base.0 + number(&mut i)?, at.1),
            b'V' => (at.0, base.1 + number(&mut i)?),
            _ => return None,
        };
        if command.eq_ignore_ascii_case(&b'm') {
            if !out.is_empty() {
                return None;
            }
            start = at;
            // Further pairs are linetos.
            command = if relative { b'l' } else { b'L' };
        }
        out.push(at);
    }
}

/// The numbers of an SVG number list: separated by whitespace and/or one
/// comma, or by nothing before a sign or a second decimal point (`1-2`,
/// `.5.5`); Err on anything else or a non-finite value.
fn numbers(s: &str) -> Result<Vec<f64>, String> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    loop {
        i = skip_separators(b, i);
        if i == b.len() {
            return Ok(out);
        }
        let end = number_end(b, i);
        let token = &s[i..end];
        match token.parse::<f64>() {
            Ok(v) if v.is_finite() => out.push(v),
            _ => return Err(format!("\"{}\" is not a number", &s[i..])),
        }
        i = end;
    }
}

/// Skips whitespace and commas from `i`.
fn skip_separators(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && (b[i].is_ascii_whitespace() || b[i] == b',') {
        i += 1;
    }
    i
}

/// The end of the number token starting at `i`: sign, digits, one decimal
/// point, exponent.
fn number_end(b: &[u8], mut i: usize) -> usize {
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    i = digits(i);
    if i < b.len() && b[i] == b'.' {
        i = digits(i + 1);
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            i = digits(j);
        }
    }
    i
}

/// A 2-D affine map `(x, y) ↦ (a x + c y + e, b x + d y + f)`, as SVG's
/// `matrix(a b c d e f)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Affine([f64; 6]);

impl Affine {
    const IDENTITY: Self = Self([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);

    /// `self` after `inner`: applies `inner` first.
    fn then(self, inner: Self) -> Self {
        let [a, b, c, d, e, f] = self.0;
        let [p, q, r, s, t, u] = inner.0;
        Self([
            a * p + c * q,
            b * p + d * q,
            a * r + c * s,
            b * r + d * s,
            a * t + c * u + e,
            b * t + d * u + f,
        ])
    }

    /// The image of `(x, y)`.
    fn apply(self, x: f64, y: f64) -> (f64, f64) {
        let [a, b, c, d, e, f] = self.0;
        (a * x + c * y + e, b * x + d * y + f)
    }

    /// The linear scale factor of areas' square root: `sqrt(|det|)`.
    fn scale(self) -> f64 {
        let [a, b, c, d, ..] = self.0;
        (a * d - b * c).abs().sqrt()
    }
}

/// Parses an SVG `transform` list: `matrix`, `translate`, `scale`,
/// `rotate`, `skewX`, `skewY`, applied right to left.
fn parse_transform(value: &str) -> Result<Affine, String> {
    let bad = |why: &str| format!("transform \"{value}\": {why}");
    let mut total = Affine::IDENTITY;
    let mut rest = value.trim_start_matches(|c: char| c.is_whitespace() || c == ',');
    while !rest.is_empty() {
        let open = rest.find('(').ok_or_else(|| bad("missing '('"))?;
        let close = rest.find(')').ok_or_else(|| bad("missing ')'"))?;
        if close < open {
            return Err(bad("unbalanced parentheses"));
        }
        let name = rest[..open].trim();
        let args = numbers(&rest[open + 1..close]).map_err(|e| bad(&e))?;
        total = total.then(
            transform_function(name, &args)
                .ok_or_else(|| bad("unknown function or wrong arguments"))?,
        );
        rest = rest[close + 1..].trim_start_matches(|c: char| c.is_whitespace() || c == ',');
    }
    Ok(total)
}

/// One transform function with its arguments.
fn transform_function(name: &str, args: &[f64]) -> Option<Affine> {
    let tan = |deg: f64| deg.to_radians().tan();
    Some(match (name, args) {
        ("matrix", &[a, b, c, d, e, f]) => Affine([a, b, c, d, e, f]),
        ("translate", &[x]) => Affine([1.0, 0.0, 0.0, 1.0, x, 0.0]),
        ("translate", &[x, y]) => Affine([1.0, 0.0, 0.0, 1.0, x, y]),
        ("scale", &[s]) => Affine([s, 0.0, 0.0, s, 0.0, 0.0]),
        ("scale", &[x, y]) => Affine([x, 0.0, 0.0, y, 0.0, 0.0]),
        ("rotate", &[deg]) => rotation(deg),
        ("rotate", &[deg, x, y]) => Affine([1.0, 0.0, 0.0, 1.0, x, y])
            .then(rotation(deg))
            .then(Affine([1.0, 0.0, 0.0, 1.0, -x, -y])),
        ("skewX", &[deg]) => Affine([1.0, 0.0, tan(deg), 1.0, 0.0, 0.0]),
        ("skewY", &[deg]) => Affine([1.0, tan(deg), 0.0, 1.0, 0.0, 0.0]),
        _ => return None,
    })
}

/// A rotation by `deg` degrees (clockwise on screen, as in SVG).
fn rotation(deg: f64) -> Affine {
    let (s, c) = deg.to_radians().sin_cos();
    Affine([c, s, -s, c, 0.0, 0.0])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A one-ink drawing's ink is its group's colour, read whether the
    /// drawing is on coloured paper or not; dots in layers give none.
    #[test]
    fn a_one_ink_drawing_gives_its_ink() {
        let on_black = r##"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" viewBox="0 0 10 8">
<!-- 1 dots, made by pixelpie -->
<g inkscape:groupmode="layer" inkscape:label="% paper (not plotted)"><rect x="0" y="0" width="10" height="8" fill="#000000"/></g>
<g fill="#ffffff" stroke="none"><circle cx="5" cy="4" r="1.5"/></g></svg>"##;
        let d = read_svg(on_black).unwrap();
        assert_eq!((d.paper, d.ink), (Some([0, 0, 0]), Some([255, 255, 255])));
        assert!(d.layers.is_empty() && d.layer_of == [0]);
        let layered = r##"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" viewBox="0 0 10 8">
<!-- 1 dots, made by pixelpie -->
<g inkscape:groupmode="layer" inkscape:label="1 cyan" fill="#00ffff"><circle cx="5" cy="4" r="1.5"/></g></svg>"##;
        let d = read_svg(layered).unwrap();
        assert_eq!((d.ink, d.layers.len()), (None, 1));
    }

    #[test]
    fn polylines_read_absolute_and_relative_commands() {
        let want = vec![(1.0, 2.0), (4.0, 2.0), (4.0, -1.5), (3.5, -1.0), (1.0, 2.0)];
        for d in [
            "M 1 2 L 4 2 L 4 -1.5 L 3.5 -1 Z",
            "M1,2 4,2 4-1.5 3.5-1z",
            "m1 2h3v-3.5l-.5.5Z",
            "m1 2 3 0 0-3.5-.5.5z",
            "M 1 2 H 4 V -1.5 l -0.5 0.5 L 1 2",
        ] {
            assert_eq!(polyline(d), Some(want.clone()), "{d}");
        }
        for bad in [
            "",
            "M 1",
            "M 1 2 A 1 1 0 1 1 3 2",
            "M 1 2 L 3 x",
            "M 1 2 M 3 4",
            "L",
        ] {
            assert_eq!(polyline(bad), None, "{bad:?}");
        }
    }

    /// A document as `svg::write` makes it.
    const CIRCLES: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="100mm" height="50mm" viewBox="0 0 400 200">
<!-- 3 dots, made by pixelpie -->
<g fill="black" stroke="none">
<circle cx="5" cy="6.5" r="1.25"/>
<circle cx="399.999" cy="0" r="0.5"/>
<circle cx="200" cy="100" r="3"/>
</g>
</svg>
"#;

    /// Pen-plotter output: one path per dot in Inkscape layers.
    const PATHS: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg"
     xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
     width="120mm" height="80mm" viewBox="0,0,120,80">
<!-- 2 dots, made by pixelpie -->
<g inkscape:groupmode="layer" inkscape:label="1 dots" id="layer1" fill="none" stroke="black">
  <g id="pen">
    <path d="M 11 10 A 1 1 0 1 1 9 10 A 1 1 0 1 1 11 10" data-dot="10 10 1"/>
    <path d="M 52.5 40 a 2.5 2.5 0 1 1 -5 0 a 2.5 2.5 0 1 1 5 0" data-dot="50,40,2.5"></path>
    <path d="M 0 0 L 120 80"/>
  </g>
</g>
<defs><circle cx="1" cy="1" r="9"/></defs>
</svg>
"#;

    fn dot(x: f32, y: f32, radius: f32) -> Dot {
        Dot { x, y, radius }
    }

    #[test]
    fn reads_circles() {
        let d = read_svg(CIRCLES).unwrap();
        assert_eq!((d.view_width, d.view_height), (400.0, 200.0));
        assert_eq!(
            d.dots,
            [
                dot(5.0, 6.5, 1.25),
                dot(399.999, 0.0, 0.5),
                dot(200.0, 100.0, 3.0)
            ]
        );
    }

    #[test]
    fn reads_pen_plotter_paths() {
        let d = read_svg(PATHS).unwrap();
        assert_eq!((d.view_width, d.view_height), (120.0, 80.0));
        assert_eq!(d.dots, [dot(10.0, 10.0, 1.0), dot(50.0, 40.0, 2.5)]);
    }

    #[test]
    fn applies_group_transforms_and_the_view_box_origin() {
        let svg = r#"<svg viewBox="-10 -20 100 100"><!-- 2 dots, made by pixelpie -->
            <g transform="translate(10, 20) scale(2)"><circle cx="1" cy="2" r="0.5"/>
            <g transform="rotate(90)"><circle cx="1" cy="0" r="1" transform="translate(1 0)"/></g></g>
            </svg>"#;
        let d = read_svg(svg).unwrap();
        // (1, 2) → scale (2, 4) → translate (12, 24) → origin (22, 44).
        assert_eq!(d.dots[0], dot(22.0, 44.0, 1.0));
        // (1, 0) → (2, 0) → rotate (0, 2) → scale (0, 4) → (10, 24) → (20, 44).
        let r = d.dots[1];
        assert!((r.x - 20.0).abs() < 1e-5 && (r.y - 44.0).abs() < 1e-5 && r.radius == 2.0);
    }

    #[test]
    fn refuses_foreign_svg() {
        let foreign = CIRCLES.replace("made by pixelpie", "made by hand");
        let e = read_svg(&foreign).unwrap_err().0;
        assert!(e.contains("not a pixelpie drawing"), "{e}");
        let e = read_svg(r#"<svg viewBox="0 0 1 1"><circle r="1"/></svg>"#)
            .unwrap_err()
            .0;
        assert!(e.contains("not a pixelpie drawing"), "{e}");
    }

    #[test]
    fn refuses_garbage() {
        for text in [
            "",
            "hello, world",
            "<<<>>>",
            "\u{0}\u{1}binary",
            "<svg viewBox=\"0 0 1 1\"><!-- 0 dots, made by pixelpie --><g></svg>",
            "<svg viewBox=\"0 0 1 1\"><!-- 0 dots, made by pixelpie -->",
            "<html><!-- 0 dots, made by pixelpie --></html>",
            "<svg viewBox=\"0 0 1 1\"/><svg/>",
        ] {
            let e = read_svg(text).unwrap_err().0;
            assert!(!e.contains('\n'), "{e}");
            assert!(e.starts_with("not"), "{text:?}: {e}");
        }
    }

    #[test]
    fn refuses_a_missing_or_bad_view_box() {
        let e = read_svg(&CIRCLES.replace(r#" viewBox="0 0 400 200""#, ""))
            .unwrap_err()
            .0;
        assert!(e.contains("no viewBox"), "{e}");
        for vb in ["0 0 400", "0 0 -1 5", "a b c d", "0 0 0 5"] {
            let text = CIRCLES.replace("0 0 400 200", vb);
            assert!(read_svg(&text).unwrap_err().0.contains("viewBox"), "{vb}");
        }
    }

    #[test]
    fn refuses_bad_dots_in_our_files() {
        for (from, to) in [
            (r#"r="1.25""#, r#"r="-1""#),
            (r#"cx="5""#, r#"cx="5mm""#),
            (r#"cy="6.5""#, r#"cy="nan""#),
        ] {
            assert!(read_svg(&CIRCLES.replace(from, to)).is_err(), "{to}");
        }
        assert!(read_svg(&PATHS.replace("10 10 1", "10 10")).is_err());
        assert!(read_svg(&PATHS.replace(r#"id="pen""#, r#"transform="warp(2)""#)).is_err());
        // A px suffix and entities are fine.
        let d = read_svg(&CIRCLES.replace(r#"cx="5""#, r#"cx="5px""#)).unwrap();
        assert_eq!(d.dots[0].x, 5.0);
        let d = read_svg(&PATHS.replace("10 10 1", "10&#32;10 1")).unwrap();
        assert_eq!(d.dots[0], dot(10.0, 10.0, 1.0));
    }

    #[test]
    fn number_lists() {
        assert_eq!(
            numbers(" 1,2 -3e1-4.5.5 ").unwrap(),
            [1.0, 2.0, -30.0, -4.5, 0.5]
        );
        assert!(numbers("1 x").is_err());
        assert!(numbers("inf").is_err());
        assert!(numbers("1e999").is_err());
        assert!(numbers("-").is_err());
        assert!(is_our_comment(" 12 dots, made by pixelpie "));
        assert!(!is_our_comment(" many dots, made by pixelpie "));
    }
}
