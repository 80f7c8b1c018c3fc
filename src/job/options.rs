//! The job's option types: dot sizing, drawing order, output format and
//! ink colour, each with its command-line and file spelling.

use std::path::Path;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::importance::Mapping;
use crate::stipple::{DotSize, Error};

/// Dot sizing (the CLI's `--dot`, the app's Dots control).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum DotMode {
    /// All dots the same size (calibrated).
    Fixed,
    /// Dots sized by tone, small in light areas (calibrated).
    #[default]
    Sized,
    /// Dot radius proportional to the sample's radius (does not reproduce tones).
    Proportional,
}

impl DotMode {
    /// The calibrated tone mapping for these dots: sized dots with the
    /// lightest dots `ratio` of the darkest's, else equal dots.
    #[must_use]
    pub fn mapping(self, ratio: f32) -> Mapping {
        match self {
            Self::Sized => Mapping::ToneSized(ratio),
            Self::Fixed | Self::Proportional => Mapping::Tone,
        }
    }

    /// How the dots are drawn: `factor` × the calibrated radius, or × the
    /// sample's radius for proportional dots.
    #[must_use]
    pub fn size(self, factor: f32) -> DotSize {
        match self {
            Self::Fixed | Self::Sized => DotSize::Calibrated(factor),
            Self::Proportional => DotSize::Proportional(factor),
        }
    }

    /// The default factor of [`Self::size`]: 1 reproduces the tones; 0.5
    /// makes the closest proportional dots touch.
    #[must_use]
    pub fn default_factor(self) -> f32 {
        match self {
            Self::Fixed | Self::Sized => 1.0,
            Self::Proportional => 0.5,
        }
    }
}

/// The order of a drawing's pen layers in the SVG (`--layer-order`), the
/// order a plotter draws them in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum LayerOrder {
    /// From the lightest ink to the darkest, as printers lay them down: a
    /// dark ink smeared by a later light pen shows, the reverse hardly.
    #[default]
    LightFirst,
    /// In the pens' own order.
    Pens,
}

impl LayerOrder {
    /// Whether this is the default (left out of the job's files).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// Whether a drawing's dots are corrected toward the picture's tones by
/// rendering it (`--correction`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Correction {
    /// The drawing is rendered, blurred by its mean dot spacing and
    /// compared with the picture, blurred alike; each sized dot is resized
    /// for the ink its neighbourhood lacks, in two to five rounds
    /// (`job::correct::Schedule`). A line (`--style line`, up to 100 000
    /// points) is refined: its vertices move toward the picture's blurred
    /// tones, its tour kept near the shortest.
    #[default]
    On,
    /// The calibration's curves alone (the drawings of earlier versions).
    Off,
}

impl Correction {
    /// Whether this is the default (left out of the job's files).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// The spacing a sized dot is calibrated for (`--spacing`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Spacing {
    /// The spacing the dots have around each dot, counted against what a
    /// maximal set of their radii has: where an edge or the policy thins
    /// the dots out, each is drawn bigger for it, so the tones hold.
    #[default]
    Local,
    /// The spacing a maximal set of the dot's sample radius has, whatever
    /// the dots around it (the drawings of earlier versions).
    Radius,
}

impl Spacing {
    /// Whether this is the default (left out of the job's files).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// Drawing order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Order {
    /// Along a Hilbert curve through the dots (once the sampler's
    /// acceptance order): no pen path is planned, but the pen moves from
    /// each dot to one nearby.
    #[default]
    None,
    /// A Hilbert-curve tour improved by 2-opt.
    Tsp,
}

/// What the pen draws (`--style`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Style {
    /// Dots (stipples), one mark per point.
    #[default]
    Dots,
    /// One continuous pen-down line per pen through its points (TSP art),
    /// its ink calibrated to the picture's tones.
    Line,
}

impl Style {
    /// Whether this is the default (left out of the job's files).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// A drawing's file format, by extension (case-insensitive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Format {
    /// SVG: circles, or pen paths with `--pen-mm`.
    Svg,
    /// An anti-aliased PNG in the ink's colour.
    Png,
    /// The dots' sample points as `x,y,radius` rows, in drawing order.
    Csv,
    /// The job and the dots' sample points, in drawing order.
    Json,
}

impl Format {
    /// The point-file form of `Csv` and `Json` (the others write no
    /// points: CSV).
    pub(crate) const fn points(self) -> crate::io::PointFormat {
        match self {
            Self::Json => crate::io::PointFormat::Json,
            _ => crate::io::PointFormat::Csv,
        }
    }

    /// The file extension of the format.
    #[must_use]
    pub const fn extension(self) -> &'static str {
        match self {
            Self::Svg => "svg",
            Self::Png => "png",
            Self::Csv => "csv",
            Self::Json => "json",
        }
    }

    /// The format of `path`'s extension.
    pub fn from_path(path: &Path) -> Result<Self, Error> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Self::Svg),
            Some("png") => Ok(Self::Png),
            Some("csv") => Ok(Self::Csv),
            Some("json") => Ok(Self::Json),
            _ => Err(Error::InvalidParameter(format!(
                "unknown output extension of '{}': use .svg, .png, .csv or .json",
                path.display()
            ))),
        }
    }
}

/// An ink colour, sRGB: `black` or `#rrggbb` on the command line and in
/// files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Ink(pub [u8; 3]);

impl Ink {
    /// Black, the default ink.
    pub const BLACK: Self = Self([0, 0, 0]);
}

impl FromStr for Ink {
    type Err = Error;

    /// ```
    /// use pixelpie::job::Ink;
    /// assert_eq!("#d62728".parse::<Ink>().unwrap(), Ink([0xd6, 0x27, 0x28]));
    /// assert_eq!("black".parse::<Ink>().unwrap(), Ink::BLACK);
    /// assert!("#12345".parse::<Ink>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, Error> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("black") {
            return Ok(Self::BLACK);
        }
        let hex = t.strip_prefix('#').unwrap_or(t);
        let byte = |i: usize| {
            hex.get(i..i + 2)
                .and_then(|h| u8::from_str_radix(h, 16).ok())
        };
        match (hex.len(), byte(0), byte(2), byte(4)) {
            (6, Some(r), Some(g), Some(b)) => Ok(Self([r, g, b])),
            _ => Err(Error::InvalidParameter(format!(
                "ink '{s}' is not a colour: use black or #rrggbb"
            ))),
        }
    }
}

/// The paper's colour, sRGB: `white`, `black`, `kraft`, `grey` or
/// `#rrggbb`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PaperColour(pub [u8; 3]);

impl PaperColour {
    /// White paper, the default.
    pub const WHITE: Self = Self([255, 255, 255]);
    /// The named papers.
    pub const NAMES: [(&'static str, [u8; 3]); 4] = [
        ("white", [255, 255, 255]),
        ("black", [0, 0, 0]),
        ("kraft", [0xc4, 0xa2, 0x7a]),
        ("grey", [0x80, 0x80, 0x80]),
    ];
}

impl FromStr for PaperColour {
    type Err = Error;

    /// ```
    /// use pixelpie::job::PaperColour;
    /// assert_eq!("kraft".parse::<PaperColour>().unwrap().0, [0xc4, 0xa2, 0x7a]);
    /// assert_eq!("#102030".parse::<PaperColour>().unwrap().0, [0x10, 0x20, 0x30]);
    /// assert!("beige".parse::<PaperColour>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, Error> {
        let t = s.trim();
        if let Some((_, c)) = Self::NAMES.iter().find(|(n, _)| t.eq_ignore_ascii_case(n)) {
            return Ok(Self(*c));
        }
        match t.strip_prefix('#').map(|_| t.parse::<Ink>()) {
            Some(Ok(ink)) => Ok(Self(ink.0)),
            _ => Err(Error::InvalidParameter(format!(
                "paper colour '{s}' is not a colour: use white, black, kraft, grey or #rrggbb"
            ))),
        }
    }
}

impl std::fmt::Display for PaperColour {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match Self::NAMES.iter().find(|(_, c)| *c == self.0) {
            Some((name, _)) => f.write_str(name),
            None => Ink(self.0).fmt(f),
        }
    }
}

impl Serialize for PaperColour {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for PaperColour {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

impl std::fmt::Display for Ink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [r, g, b] = self.0;
        write!(f, "#{r:02x}{g:02x}{b:02x}")
    }
}

impl Serialize for Ink {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Ink {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}
