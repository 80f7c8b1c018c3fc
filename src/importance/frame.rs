//! Framing a picture before it is drawn: a crop (`--crop x,y,w,h`, in the
//! upright picture's pixels) and then a quarter turn (`--rotate 90|180|270`,
//! clockwise), for grey and colour maps alike.

use std::fmt;
use std::str::FromStr;

use super::{ColourMap, Error, ImportanceMap, Result};

/// A rectangle of a picture, in its pixels: left, top, width and height.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// Left edge.
    pub x: u32,
    /// Top edge.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

impl FromStr for Crop {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        let bad = || format!("crop '{s}' must be x,y,w,h in the picture's pixels (w, h > 0)");
        let [x, y, width, height] = parts.as_slice() else {
            return Err(bad());
        };
        let n = |v: &str| v.parse::<u32>().map_err(|_| bad());
        let c = Self {
            x: n(x)?,
            y: n(y)?,
            width: n(width)?,
            height: n(height)?,
        };
        if c.width == 0 || c.height == 0 {
            return Err(bad());
        }
        Ok(c)
    }
}

impl fmt::Display for Crop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{},{}", self.x, self.y, self.width, self.height)
    }
}

impl serde::Serialize for Crop {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Crop {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Checks a quarter turn: 0, 90, 180 or 270 degrees.
pub fn check_rotation(degrees: u16) -> Result<()> {
    if degrees.is_multiple_of(90) && degrees < 360 {
        Ok(())
    } else {
        Err(Error::InvalidParameter(format!(
            "rotate {degrees} must be 90, 180 or 270 (degrees clockwise)"
        )))
    }
}

/// The `w`×`h` grid `data` (rows from the top) cropped to `crop` and
/// turned `degrees` clockwise: its size and values. Any picture frames
/// alike (the app's display images too).
pub fn frame<T: Copy + Send + Sync>(
    (w, h): (u32, u32),
    data: &[T],
    crop: Option<Crop>,
    degrees: u16,
) -> Result<((u32, u32), Vec<T>)> {
    check_rotation(degrees)?;
    let c = crop.unwrap_or(Crop {
        x: 0,
        y: 0,
        width: w,
        height: h,
    });
    if u64::from(c.x) + u64::from(c.width) > u64::from(w)
        || u64::from(c.y) + u64::from(c.height) > u64::from(h)
    {
        return Err(Error::InvalidParameter(format!(
            "crop {c} reaches past the {w}x{h} picture"
        )));
    }
    let (cw, ch) = (c.width as usize, c.height as usize);
    let at = |x: usize, y: usize| data[(c.y as usize + y) * w as usize + c.x as usize + x];
    let (size, values): ((usize, usize), Vec<T>) = match degrees {
        0 => ((cw, ch), (0..cw * ch).map(|i| at(i % cw, i / cw)).collect()),
        // Clockwise: the new row y is the old column y, read bottom up.
        90 => (
            (ch, cw),
            (0..cw * ch)
                .map(|i| {
                    let (x, y) = (i % ch, i / ch);
                    at(y, ch - 1 - x)
                })
                .collect(),
        ),
        180 => (
            (cw, ch),
            (0..cw * ch)
                .map(|i| at(cw - 1 - i % cw, ch - 1 - i / cw))
                .collect(),
        ),
        _ => (
            (ch, cw),
            (0..cw * ch)
                .map(|i| {
                    let (x, y) = (i % ch, i / ch);
                    at(cw - 1 - y, x)
                })
                .collect(),
        ),
    };
    Ok(((size.0 as u32, size.1 as u32), values))
}

impl ImportanceMap {
    /// The map cropped to `crop` and turned `degrees` clockwise.
    ///
    /// ```
    /// use pixelpie::importance::ImportanceMap;
    /// let m = ImportanceMap::from_values(2, 1, vec![0.0, 1.0]).unwrap();
    /// let turned = m.framed(None, 90).unwrap();
    /// assert_eq!((turned.width(), turned.height()), (1, 2));
    /// assert_eq!((turned.value(0, 0), turned.value(0, 1)), (0.0, 1.0));
    /// ```
    pub fn framed(&self, crop: Option<Crop>, degrees: u16) -> Result<Self> {
        let ((w, h), values) = frame((self.width(), self.height()), self.values(), crop, degrees)?;
        Self::from_values(w, h, values)
    }
}

impl ColourMap {
    /// The picture cropped to `crop` and turned `degrees` clockwise.
    pub fn framed(&self, crop: Option<Crop>, degrees: u16) -> Result<Self> {
        let ((w, h), rgb) = frame((self.width(), self.height()), self.rgb(), crop, degrees)?;
        Self::from_linear(w, h, rgb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turns_compose_and_crops_stay_inside() {
        // 3×2: 0 1 2 / 3 4 5
        let data: Vec<u32> = (0..6).collect();
        let ((w, h), r90) = frame((3, 2), &data, None, 90).unwrap();
        assert_eq!((w, h), (2, 3));
        // Clockwise: the bottom-left comes to the top-left.
        assert_eq!(r90, [3, 0, 4, 1, 5, 2]);
        let (_, r180) = frame((3, 2), &data, None, 180).unwrap();
        assert_eq!(r180, [5, 4, 3, 2, 1, 0]);
        let (_, twice) = frame((2, 3), &r90, None, 90).unwrap();
        assert_eq!(twice, r180);
        let (_, r270) = frame((3, 2), &data, None, 270).unwrap();
        let (_, back) = frame((2, 3), &r270, None, 90).unwrap();
        assert_eq!(back, data);
        let crop = "1,0,2,2".parse().ok();
        assert_eq!(
            frame((3, 2), &data, crop, 0).unwrap(),
            ((2, 2), vec![1, 2, 4, 5])
        );
        assert!(frame((3, 2), &data, "2,0,2,2".parse().ok(), 0).is_err());
        assert!(frame((3, 2), &data, None, 45).is_err());
        assert!("1,2,0,3".parse::<Crop>().is_err() && "1,2,3".parse::<Crop>().is_err());
        assert_eq!("1, 2, 3, 4".parse::<Crop>().unwrap().to_string(), "1,2,3,4");
    }
}
