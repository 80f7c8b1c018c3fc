//! Paper: a sheet size (`--paper a4|a3|letter|WxHmm`), its orientation
//! (`--landscape`) and margins (`--margin`). The drawing fits the sheet's
//! printable area, centred, keeping the picture's aspect
//! ([`Paper::place`]); the SVG is then the whole sheet, in millimetres.

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::Error;

/// The margin in mm when `--paper` is given without `--margin`.
pub const DEFAULT_MARGIN_MM: f64 = 10.0;

/// Named sheets, portrait, in mm.
const SHEETS: [(&str, f64, f64); 9] = [
    ("a5", 148.0, 210.0),
    ("a4", 210.0, 297.0),
    ("a3", 297.0, 420.0),
    ("a2", 420.0, 594.0),
    ("a1", 594.0, 841.0),
    ("letter", 215.9, 279.4),
    ("legal", 215.9, 355.6),
    ("tabloid", 279.4, 431.8),
    ("a6", 105.0, 148.0),
];

/// A sheet of paper: a named size or `WxHmm`, as given (width × height).
#[derive(Clone, Debug, PartialEq)]
pub struct Paper {
    /// The name it was given by (`a4`, or `300x200mm`).
    pub name: String,
    /// Width in mm, as named (A and US sizes are portrait).
    pub width_mm: f64,
    /// Height in mm.
    pub height_mm: f64,
}

impl FromStr for Paper {
    type Err = Error;

    /// ```
    /// use pixelpie::stipple::Paper;
    /// let a4: Paper = "A4".parse().unwrap();
    /// assert_eq!((a4.width_mm, a4.height_mm), (210.0, 297.0));
    /// let custom: Paper = "300x200mm".parse().unwrap();
    /// assert_eq!((custom.width_mm, custom.height_mm), (300.0, 200.0));
    /// assert!("b7".parse::<Paper>().is_err());
    /// assert!("0x200mm".parse::<Paper>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Self, Error> {
        let t = s.trim().to_ascii_lowercase();
        if let Some(&(name, w, h)) = SHEETS.iter().find(|(n, _, _)| *n == t) {
            return Ok(Self {
                name: name.to_owned(),
                width_mm: w,
                height_mm: h,
            });
        }
        let bad = || {
            Error::InvalidParameter(format!(
                "paper '{s}' is not a1 to a6, letter, legal, tabloid or WxHmm (e.g. 300x200mm)"
            ))
        };
        let dims = t.strip_suffix("mm").unwrap_or(&t);
        let (w, h) = dims.split_once('x').ok_or_else(bad)?;
        let (w, h): (f64, f64) = (
            w.trim().parse().map_err(|_| bad())?,
            h.trim().parse().map_err(|_| bad())?,
        );
        if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0 && w <= 10_000.0 && h <= 10_000.0)
        {
            return Err(Error::InvalidParameter(format!(
                "paper '{s}': width and height must be positive numbers of mm, at most 10000"
            )));
        }
        Ok(Self {
            name: format!("{w}x{h}mm"),
            width_mm: w,
            height_mm: h,
        })
    }
}

impl std::fmt::Display for Paper {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name)
    }
}

impl Serialize for Paper {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Paper {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Where a drawing lies on its sheet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// The sheet, oriented, in mm.
    pub sheet_mm: (f64, f64),
    /// The drawing's top-left corner on the sheet, in mm.
    pub origin_mm: (f64, f64),
    /// The drawing's size in mm.
    pub size_mm: (f64, f64),
    /// The margin in mm.
    pub margin_mm: f64,
}

impl Placement {
    /// Millimetres per domain pixel for a domain `width` px wide.
    #[must_use]
    pub fn mm_per_px(&self, width: u32) -> f64 {
        self.size_mm.0 / f64::from(width.max(1))
    }
}

impl Paper {
    /// The sheet's size in mm, landscape (wider than tall) or portrait.
    #[must_use]
    pub fn oriented(&self, landscape: bool) -> (f64, f64) {
        let (a, b) = (
            self.width_mm.min(self.height_mm),
            self.width_mm.max(self.height_mm),
        );
        if landscape { (b, a) } else { (a, b) }
    }

    /// Places a domain of `domain` px on this sheet, oriented, inside
    /// margins of `margin_mm`: as large as the printable area allows,
    /// centred, keeping the aspect. Err when the margins leave no room.
    ///
    /// ```
    /// use pixelpie::stipple::Paper;
    /// let a4: Paper = "a4".parse().unwrap();
    /// // A square drawing on portrait A4 with 10 mm margins: 190 mm wide,
    /// // centred vertically.
    /// let p = a4.place((1000, 1000), false, 10.0).unwrap();
    /// assert_eq!(p.sheet_mm, (210.0, 297.0));
    /// assert_eq!(p.size_mm, (190.0, 190.0));
    /// assert_eq!(p.origin_mm, (10.0, 53.5));
    /// assert!(a4.place((1000, 1000), false, 105.0).is_err());
    /// ```
    pub fn place(
        &self,
        domain: (u32, u32),
        landscape: bool,
        margin_mm: f64,
    ) -> Result<Placement, Error> {
        let (sw, sh) = self.oriented(landscape);
        if !(margin_mm.is_finite() && margin_mm >= 0.0) {
            return Err(Error::InvalidParameter(format!(
                "«margin={margin_mm}» must be a number of mm, at least 0"
            )));
        }
        let (aw, ah) = (sw - 2.0 * margin_mm, sh - 2.0 * margin_mm);
        if aw <= 0.0 || ah <= 0.0 {
            return Err(Error::InvalidParameter(format!(
                "«margin={margin_mm}» mm leaves no room on {} paper ({sw} × {sh} mm)",
                self.name
            )));
        }
        let (dw, dh) = (f64::from(domain.0.max(1)), f64::from(domain.1.max(1)));
        let s = (aw / dw).min(ah / dh);
        let (w, h) = (dw * s, dh * s);
        Ok(Placement {
            sheet_mm: (sw, sh),
            origin_mm: ((sw - w) / 2.0, (sh - h) / 2.0),
            size_mm: (w, h),
            margin_mm,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn landscape_turns_the_sheet_and_the_drawing_keeps_its_aspect() {
        let a4: Paper = "a4".parse().unwrap();
        let p = a4.place((300, 200), true, 15.0).unwrap();
        assert_eq!(p.sheet_mm, (297.0, 210.0));
        // 267 × 180 printable: the width limits a 3:2 drawing.
        assert!((p.size_mm.0 - 267.0).abs() < 1e-9, "{p:?}");
        assert!((p.size_mm.1 - 178.0).abs() < 1e-9, "{p:?}");
        // Centred: equal space either side.
        let right = p.sheet_mm.0 - p.origin_mm.0 - p.size_mm.0;
        assert!((right - p.origin_mm.0).abs() < 1e-9);
        let bottom = p.sheet_mm.1 - p.origin_mm.1 - p.size_mm.1;
        assert!((bottom - p.origin_mm.1).abs() < 1e-9);
        // A landscape sheet named landscape stays so in portrait order.
        let wide: Paper = "300x200mm".parse().unwrap();
        assert_eq!(wide.oriented(false), (200.0, 300.0));
        assert_eq!(wide.oriented(true), (300.0, 200.0));
        assert!(a4.place((10, 10), false, f64::NAN).is_err());
        assert_eq!("Letter".parse::<Paper>().unwrap().to_string(), "letter");
    }
}
