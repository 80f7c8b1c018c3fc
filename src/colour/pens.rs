//! The pens a drawing uses: a preset (`black`, `cmyk`), a list of sRGB
//! colours (`"#000000,#d62728"`), or a TOML file of `[[pen]]` entries with
//! `name`, `colour` (`"#rrggbb"`), and optionally `width_mm` and
//! `dot_gain` (the plotted dot's diameter over the drawn one, as
//! `pixelpie calibrate fit` measures it); other keys are read past.

use std::path::Path;

use serde::{Deserialize, Serialize};

/// The most pens a drawing may use (the render model mixes 2^pens inks).
pub const MAX_PENS: usize = 8;
/// The most pens a set may hold: an inventory that `--choose K` picks a
/// drawing's pens from.
pub const MAX_INVENTORY: usize = 64;
/// The smallest dot gain a pen may have.
pub const MIN_GAIN: f64 = 0.25;
/// The largest dot gain a pen may have.
pub const MAX_GAIN: f64 = 4.0;

/// What is wrong with a pen set.
#[derive(Debug, thiserror::Error)]
#[error("pens: {0}")]
pub struct PenError(pub String);

/// One pen: its name (the SVG layer's label) and its ink's sRGB colour on
/// white paper.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pen {
    /// The pen's name.
    pub name: String,
    /// The ink's colour, 8-bit sRGB.
    #[serde(with = "hex", alias = "color")]
    pub colour: [u8; 3],
    /// The pen's width in mm, when the file gives one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_mm: Option<f64>,
    /// The plotted dot's diameter over the drawn one (ink spreading on the
    /// paper), when calibrated: the dots are drawn this much smaller.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dot_gain: Option<f64>,
    /// How much the ink covers what lies below it: 0 for a transparent
    /// felt-tip ink that multiplies, 1 for an opaque gel, paint or metallic
    /// pen. Unset: 0, unless the ink is lighter than the paper (which only
    /// an opaque ink can show on): then 1 ([`Pen::opacity_on`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub opacity: Option<f64>,
}

impl Pen {
    /// The pen's opacity on paper of colour `paper` (sRGB): its own, else
    /// 1 for an ink lighter than the paper and 0 for one that is not.
    #[must_use]
    pub fn opacity_on(&self, paper: [u8; 3]) -> f64 {
        self.opacity.unwrap_or(default_opacity(self.colour, paper))
    }
}

/// The opacity of an ink of colour `ink` on paper of colour `paper` whose
/// pen does not give one: 1 (it covers) where the ink is lighter than the
/// paper, 0 (it multiplies) otherwise.
#[must_use]
pub fn default_opacity(ink: [u8; 3], paper: [u8; 3]) -> f64 {
    if super::luminance(ink) > super::luminance(paper) {
        1.0
    } else {
        0.0
    }
}

/// The pens of a drawing, in layer order (at least one, colours distinct).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct PenSet(Vec<Pen>);

impl PenSet {
    /// The pens, checked: 1 to [`MAX_INVENTORY`] of them (a drawing takes
    /// at most [`MAX_PENS`]; more are an inventory to choose from), colours
    /// distinct, widths positive.
    pub fn new(pens: Vec<Pen>) -> Result<Self, PenError> {
        if pens.is_empty() {
            return Err(PenError("no pens given".into()));
        }
        if pens.len() > MAX_INVENTORY {
            return Err(PenError(format!(
                "{} pens given; at most {MAX_INVENTORY}",
                pens.len()
            )));
        }
        for (i, p) in pens.iter().enumerate() {
            if let Some(q) = pens[..i].iter().find(|q| q.colour == p.colour) {
                return Err(PenError(format!(
                    "pens '{}' and '{}' have the same colour {}",
                    q.name,
                    p.name,
                    hex_of(p.colour)
                )));
            }
            if let Some(w) = p.width_mm
                && !(w.is_finite() && w > 0.0)
            {
                return Err(PenError(format!(
                    "pen '{}' has width {w} mm; it must be positive",
                    p.name
                )));
            }
            if let Some(o) = p.opacity
                && !(o.is_finite() && (0.0..=1.0).contains(&o))
            {
                return Err(PenError(format!(
                    "pen '{}' has opacity {o}; it must be in [0, 1]",
                    p.name
                )));
            }
            if let Some(g) = p.dot_gain
                && !(g.is_finite() && (MIN_GAIN..=MAX_GAIN).contains(&g))
            {
                return Err(PenError(format!(
                    "pen '{}' has dot_gain {g}; it must be in [{MIN_GAIN}, {MAX_GAIN}]",
                    p.name
                )));
            }
        }
        Ok(Self(pens))
    }

    /// One black pen: the grey drawing's.
    #[must_use]
    pub fn black() -> Self {
        Self(vec![pen("black", [0, 0, 0])])
    }

    /// Cyan, magenta, yellow and black.
    #[must_use]
    pub fn cmyk() -> Self {
        Self(vec![
            pen("cyan", [0, 255, 255]),
            pen("magenta", [255, 0, 255]),
            pen("yellow", [255, 255, 0]),
            pen("black", [0, 0, 0]),
        ])
    }

    /// Parses a preset name, a comma-separated list of `#rrggbb` colours, or
    /// the path of a TOML pen file.
    ///
    /// ```
    /// use pixelpie::colour::PenSet;
    /// assert_eq!(PenSet::parse("cmyk").unwrap().len(), 4);
    /// let two = PenSet::parse("#000000, #d62728").unwrap();
    /// assert_eq!(two.pens()[1].colour, [0xd6, 0x27, 0x28]);
    /// assert!(PenSet::parse("rainbow").is_err());
    /// assert!(PenSet::parse("#000000,#000000").is_err());
    /// ```
    pub fn parse(spec: &str) -> Result<Self, PenError> {
        let spec = spec.trim();
        match spec.to_ascii_lowercase().as_str() {
            "black" | "k" => return Ok(Self::black()),
            "cmyk" => return Ok(Self::cmyk()),
            "" => return Err(PenError("no pens given".into())),
            _ => {}
        }
        if spec.to_ascii_lowercase().ends_with(".toml") {
            return Self::from_file(Path::new(spec));
        }
        if !spec.starts_with('#') {
            return Err(PenError(format!(
                "unknown pen set '{spec}': use black, cmyk, a list of #rrggbb colours or a .toml file"
            )));
        }
        Self::from_colours(spec.split(',').map(str::trim))
    }

    /// Pens of the given `#rrggbb` colours, named by their colour.
    pub fn from_colours<'a>(colours: impl IntoIterator<Item = &'a str>) -> Result<Self, PenError> {
        let pens = colours
            .into_iter()
            .map(|c| {
                let colour = parse_hex(c)?;
                Ok(pen(&name_of(colour), colour))
            })
            .collect::<Result<Vec<_>, PenError>>()?;
        Self::new(pens)
    }

    /// Reads a TOML pen file.
    pub fn from_file(path: &Path) -> Result<Self, PenError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| PenError(format!("cannot read '{}': {e}", path.display())))?;
        Self::from_toml(&text).map_err(|e| PenError(format!("'{}': {}", path.display(), e.0)))
    }

    /// Parses a pen file's text: `[[pen]]` entries.
    pub fn from_toml(text: &str) -> Result<Self, PenError> {
        #[derive(Deserialize)]
        struct File {
            #[serde(default)]
            pen: Vec<Pen>,
        }
        let file: File = toml::from_str(text).map_err(|e| PenError(toml_problem(text, &e)))?;
        Self::new(file.pen)
    }

    /// The pens.
    #[must_use]
    pub fn pens(&self) -> &[Pen] {
        &self.0
    }

    /// The number of pens.
    #[must_use]
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Always false: a set has at least one pen.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Whether this is one black pen: the grey drawing.
    #[must_use]
    pub fn is_black(&self) -> bool {
        self.0.len() == 1 && self.0[0].colour == [0, 0, 0]
    }
}

impl std::str::FromStr for PenSet {
    type Err = PenError;
    fn from_str(s: &str) -> Result<Self, PenError> {
        Self::parse(s)
    }
}

impl std::fmt::Display for PenSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if *self == Self::cmyk() {
            return f.write_str("cmyk");
        }
        let colours: Vec<String> = self.0.iter().map(|p| hex_of(p.colour)).collect();
        f.write_str(&colours.join(","))
    }
}

impl<'de> Deserialize<'de> for PenSet {
    /// A preset or list as one string, a list of colour strings, or a list
    /// of pens.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Entry {
            Colour(String),
            Pen(Pen),
        }
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Form {
            Spec(String),
            List(Vec<Entry>),
        }
        use serde::de::Error;
        let form = Form::deserialize(d).map_err(|_: D::Error| {
            D::Error::custom(
                "must be \"cmyk\", \"black\", a pen file's path (.toml), or a list of \
                 \"#rrggbb\" colours or of pens",
            )
        })?;
        match form {
            Form::Spec(s) => Self::parse(&s).map_err(D::Error::custom),
            Form::List(entries) => {
                let pens = entries
                    .into_iter()
                    .map(|e| match e {
                        Entry::Colour(c) => {
                            let colour = parse_hex(&c)?;
                            Ok(pen(&name_of(colour), colour))
                        }
                        Entry::Pen(p) => Ok(p),
                    })
                    .collect::<Result<Vec<_>, PenError>>()
                    .map_err(D::Error::custom)?;
                Self::new(pens).map_err(D::Error::custom)
            }
        }
    }
}

fn pen(name: &str, colour: [u8; 3]) -> Pen {
    Pen {
        name: name.to_owned(),
        colour,
        width_mm: None,
        dot_gain: None,
        opacity: None,
    }
}

/// A pen file's TOML error in a user's words: the pen (by its place in
/// the file), the line's key and value, and what the key takes ("pen 2:
/// width_mm = \"x\": expected a number"); the parser's own words, on one
/// line, where the error is not a value's.
fn toml_problem(text: &str, e: &toml::de::Error) -> String {
    let message = e.message();
    let plain = || one_line(&e.to_string());
    let (Some(span), Some(expected)) = (e.span(), crate::text::expected(message)) else {
        return plain();
    };
    let before = &text[..span.start.min(text.len())];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[line_start..]
        .find('\n')
        .map_or(text.len(), |i| line_start + i);
    let Some((key, value)) = text[line_start..line_end].split_once('=') else {
        return plain();
    };
    let pen = before.matches("[[pen]]").count();
    format!(
        "pen {pen}: {} = {}: expected {expected}",
        key.trim(),
        value.trim()
    )
}

/// `#rrggbb` of an 8-bit colour.
#[must_use]
pub fn hex_of(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// A colour's name: the preset pens' names, else its `#rrggbb`.
#[must_use]
pub fn name_of(c: [u8; 3]) -> String {
    match c {
        [0, 0, 0] => "black".into(),
        [0, 255, 255] => "cyan".into(),
        [255, 0, 255] => "magenta".into(),
        [255, 255, 0] => "yellow".into(),
        _ => hex_of(c),
    }
}

/// Parses `#rrggbb`.
pub fn parse_hex(s: &str) -> Result<[u8; 3], PenError> {
    let bad = || PenError(format!("'{s}' is not a colour: write #rrggbb"));
    let h = s.trim().strip_prefix('#').ok_or_else(bad)?;
    if h.len() != 6 || !h.chars().all(|c| c.is_ascii_hexdigit()) {
        return Err(bad());
    }
    let byte = |i: usize| u8::from_str_radix(&h[i..i + 2], 16).map_err(|_| bad());
    Ok([byte(0)?, byte(2)?, byte(4)?])
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

mod hex {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(c: &[u8; 3], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&super::hex_of(*c))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[u8; 3], D::Error> {
        let s = String::deserialize(d)?;
        super::parse_hex(&s).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pen_files_read_names_colours_and_widths_and_skip_other_keys() {
        let set = PenSet::from_toml(
            "[[pen]]\nname = \"fine black\"\ncolour = \"#101010\"\nwidth_mm = 0.3\ndot_gain = 1.4\n\
             [[pen]]\nname = \"red\"\ncolor = \"#d62728\"\n",
        )
        .unwrap();
        assert_eq!(set.len(), 2);
        assert_eq!(set.pens()[0].width_mm, Some(0.3));
        assert_eq!(set.pens()[1].colour, [0xd6, 0x27, 0x28]);
        for bad in [
            "",
            "[[pen]]\nname = \"x\"\n",
            "[[pen]]\nname = \"x\"\ncolour = \"red\"\n",
            "[[pen]]\nname = \"x\"\ncolour = \"#000000\"\nwidth_mm = -1\n",
            "[[pen",
        ] {
            assert!(PenSet::from_toml(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn a_set_reads_back_from_its_json_and_its_display() {
        for set in [PenSet::cmyk(), PenSet::parse("#000000,#1f77b4").unwrap()] {
            let json = serde_json::to_string(&set).unwrap();
            assert_eq!(serde_json::from_str::<PenSet>(&json).unwrap(), set);
            assert_eq!(PenSet::parse(&set.to_string()).unwrap(), set);
        }
        let list: PenSet = serde_json::from_str(r##"["#000000", "#ff7f0e"]"##).unwrap();
        assert_eq!(list.len(), 2);
        assert!(serde_json::from_str::<PenSet>("[]").is_err());
        assert!(serde_json::from_str::<PenSet>(r##""#12345""##).is_err());
    }
}
