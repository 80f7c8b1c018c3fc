//! The job's checks: the options that exclude or need each other, and
//! their ranges, refused in words before anything is drawn.

use super::{Format, Job};
use crate::colour::pens::MAX_PENS;
use crate::stipple::Error;
use crate::stipple::svg::DotPath;

impl Job {
    /// Checks the options that do not depend on the picture, for an output
    /// of `format`.
    pub fn validate(&self, format: Format) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if format == Format::Svg && self.scale != 1.0 {
            return bad("«scale» applies to PNG output; use «width_mm» to size an SVG".into());
        }
        self.check()
    }

    /// Checks the options that depend on neither the picture nor the
    /// output's format.
    pub fn check(&self) -> Result<(), Error> {
        let bad = |m: String| Err(Error::InvalidParameter(m));
        if let (Some(k), None) = (self.choose, &self.pens) {
            return bad(format!(
                "{} needs «pens»: the pen box to choose from",
                crate::text::given("choose", k)
            ));
        }
        if let Some(set) = &self.pens {
            let (n, most) = (set.len(), set.len().min(MAX_PENS));
            match self.choose {
                None if n > MAX_PENS => {
                    return bad(format!(
                        "«pens» holds {n} pens and a drawing takes at most {MAX_PENS}: add \
                         «choose=K» to pick K of them for the picture"
                    ));
                }
                Some(k) if k == 0 || k > most => {
                    return bad(format!("«choose={k}»: choose 1 to {most} of the {n} pens"));
                }
                _ => {}
            }
        }
        if let Err(crate::importance::Error::InvalidParameter(m)) = self.importance.check() {
            return bad(m);
        }
        let bits = self.sampler.subpixel_bits;
        if bits > crate::sampler::fixed::MAX_SUBPIXEL_BITS {
            return bad(format!(
                "{} must be 0 to {}",
                crate::text::given("subpixel_bits", bits),
                crate::sampler::fixed::MAX_SUBPIXEL_BITS
            ));
        }
        if self.points == Some(0) {
            return bad(format!(
                "{}: ask for at least 1 dot",
                crate::text::given("points", 0)
            ));
        }
        for (name, size) in [("width", self.width), ("height", self.height)] {
            if size == Some(0) {
                return bad(format!(
                    "{} must be at least 1 px (or left out: the picture's aspect sets it)",
                    crate::text::given(name, 0)
                ));
            }
        }
        if let Some(pen) = self.pen_mm {
            if !(pen.is_finite() && pen > 0.0) {
                return bad(format!("«pen_mm={pen}» must be a positive number"));
            }
            if self.width_mm.is_none() && self.paper.is_none() {
                return bad(
                    "«pen_mm» needs «width_mm» or «paper»: the page size turns pixels into millimetres"
                        .into(),
                );
            }
        }
        if self.width_mm.is_some() && self.paper.is_some() {
            return bad(
                "«width_mm» and «paper» exclude each other: the paper sizes the drawing".into(),
            );
        }
        if self.poster.is_some() && self.paper.is_none() {
            return bad(
                "«poster» needs «paper»: the sheets the poster is plotted on (e.g. a4)".into(),
            );
        }
        if self.paper.is_none() && (self.margin.is_some() || self.landscape) {
            return bad("«margin» and «landscape» need «paper»".into());
        }
        if let Some(r) = self.rotate
            && !matches!(r, 90 | 180 | 270)
        {
            return bad(format!(
                "«rotate={r}» must be 90, 180 or 270 (degrees clockwise)"
            ));
        }
        if let Some(l) = self.refill_mm {
            if self.pen_mm.is_none() {
                return bad("«refill_mm» needs «pen_mm»: it splits the pen's drawing".into());
            }
            if !(l.is_finite() && l > 0.0) {
                return bad(format!("«refill_mm={l}» must be a positive number"));
            }
        }
        if self.line_smooth && self.style != super::Style::Line {
            return bad("«line_smooth» needs «style=line»: it is how the line is drawn".into());
        }
        if self.dot_path != DotPath::Spiral && self.pen_mm.is_none() {
            return bad("«dot_path» needs «pen_mm»: it is how the pen draws each dot".into());
        }
        if let Some(paper) = &self.paper {
            // The margins must leave room whatever the drawing's aspect.
            paper.place((1, 1), self.landscape, self.margin())?;
        }
        if !(self.dot_ratio.is_finite() && self.dot_ratio > 0.0 && self.dot_ratio <= 1.0) {
            return bad(format!("«dot_ratio={}» must be in (0, 1]", self.dot_ratio));
        }
        if let Some(r) = self.dot_radius {
            if !(r.is_finite() && r > 0.0) {
                return bad(format!("«dot_radius={r}» must be a positive number"));
            }
            if self.points.is_some() || self.importance.min_radius.is_some() {
                return bad(
                    "«dot_radius» excludes «points» and «min_radius»: it sets the radii itself"
                        .into(),
                );
            }
        }
        if let Some(d) = self.dot_mm {
            if !(d.is_finite() && d > 0.0) {
                return bad(format!("«dot_mm={d}» must be a positive number"));
            }
            if self.width_mm.is_none() && self.paper.is_none() {
                return bad("«dot_mm» needs «width_mm» or «paper»: the page's size in mm".into());
            }
            if self.points.is_some()
                || self.importance.min_radius.is_some()
                || self.dot_radius.is_some()
            {
                return bad(
                    "«dot_mm» excludes «points», «min_radius» and «dot_radius»: it sets the radii \
                     itself"
                        .into(),
                );
            }
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return bad(format!("«scale={}» must be a positive number", self.scale));
        }
        if let Some(mm) = self.width_mm
            && !(mm.is_finite() && mm > 0.0)
        {
            return bad(format!("«width_mm={mm}» must be a positive number"));
        }
        self.dot_size().validate()
    }
}
