//! The job's sizes: the dot mode, the count to fit, the domain, the
//! radius range (from a count, the dots' radius, their size in mm or the
//! pen), and the page (placement, millimetres per pixel, the pens' dot
//! gain and width).

use super::{DEFAULT_POINTS, DotMode, Job, MAX_DOMAIN_PIXELS, MIN_DOMAIN_SIDE, PEN_DOT_PX};
use crate::importance::{DEFAULT_RADIUS_RATIO, Mapping, RadiusRange, fit_size};
use crate::stipple::Error;
use crate::stipple::paper::{DEFAULT_MARGIN_MM, Placement};

/// The default domain: the image scaled so its longer side is
/// max(1024, 10 √N) px, about ten pixels between dots or more, but at most
/// [`MAX_DOMAIN_PIXELS`] pixels.
///
/// ```
/// use pixelpie::job::default_domain;
/// assert_eq!(default_domain(600, 400, 10_000), (1024, 683));
/// assert_eq!(default_domain(600, 400, 100_000), (3163, 2109));
/// let (w, h) = default_domain(600, 400, 1_000_000);
/// assert!(u64::from(w) * u64::from(h) <= 4096 * 4096 && w == 5016);
/// ```
#[must_use]
pub fn default_domain(w: u32, h: u32, points: usize) -> (u32, u32) {
    let side = f64::from(MIN_DOMAIN_SIDE)
        .max(10.0 * (points as f64).sqrt())
        .ceil();
    let (lw, lh) = (f64::from(w.max(1)), f64::from(h.max(1)));
    let long = lw.max(lh);
    // The largest longer side whose domain stays within the pixel budget.
    let cap = (MAX_DOMAIN_PIXELS as f64 * long / lw.min(lh))
        .sqrt()
        .floor();
    let side = side.min(cap.max(f64::from(MIN_DOMAIN_SIDE)));
    let s = side / f64::from(w.max(h));
    (
        ((f64::from(w) * s).round() as u32).max(1),
        ((f64::from(h) * s).round() as u32).max(1),
    )
}

impl Job {
    /// The dot mode: `dot`, or fixed with a pen, else sized.
    #[must_use]
    pub fn dot_mode(&self) -> DotMode {
        self.dot.unwrap_or(if self.pen_mm.is_some() {
            DotMode::Fixed
        } else {
            DotMode::Sized
        })
    }

    /// Whether [`super::Spacing`] matters: a grey drawing of sized dots on
    /// a tone mapping (the plan takes `Spacing::Local` only then,
    /// [`super::Plan::local_spacing`]; the app greys the control out
    /// otherwise).
    #[must_use]
    pub fn spacing_applies(&self) -> bool {
        !self.colour()
            && self.dot_mode() == DotMode::Sized
            && self.importance.mapping != Some(crate::importance::MappingKind::Linear)
    }

    /// Whether the pen sets the sample radii: it does only when nothing
    /// else does (a count, the minimum radius, the dots' own size).
    pub(crate) fn pen_sized(&self) -> bool {
        self.pen_mm.is_some()
            && self.points.is_none()
            && self.importance.min_radius.is_none()
            && self.dot_radius.is_none()
            && self.dot_mm.is_none()
    }

    /// The dot count to fit, if any, and whether something scales the
    /// radii (a count, the dots' radius or the pen): then a missing radius
    /// range may default.
    pub(crate) fn count(&self) -> (Option<usize>, bool) {
        // The dots' own radius sets the sample radii, or the count does; a
        // pen alone sets the darkest dots to its width.
        let by_dot = self.dot_radius.is_some() || self.dot_mm.is_some() || self.pen_sized();
        let points = match (self.points, self.importance.min_radius) {
            (Some(n), _) => Some(n),
            _ if by_dot => None,
            (None, Some(_)) => None,
            (None, None) => Some(DEFAULT_POINTS),
        };
        (points, points.is_some() || by_dot)
    }

    /// The domain for a picture of `size`: the asked size, or the default.
    pub(crate) fn domain_for(&self, size: (u32, u32), points: Option<usize>) -> (u32, u32) {
        match (self.width, self.height) {
            (None, None) => {
                let domain = default_domain(size.0, size.1, points.unwrap_or(DEFAULT_POINTS));
                self.pen_domain(domain).unwrap_or(domain)
            }
            (wd, hd) => fit_size(size, wd, hd),
        }
    }

    /// When the pen sizes the dots (no count, no radius given), `domain`
    /// enlarged so that the pen's plotted dot spans [`PEN_DOT_PX`] pixels
    /// (within [`MAX_DOMAIN_PIXELS`]): a fine pen on a large sheet is
    /// sampled, not refused. `None` when it spans that already.
    fn pen_domain(&self, domain: (u32, u32)) -> Option<(u32, u32)> {
        if !self.pen_sized() || self.dot_radius.is_some() {
            return None;
        }
        let mm = self.mm_per_px(domain).ok()??;
        let across = self.pen_width()? * self.dot_gain(0) / mm;
        if across >= PEN_DOT_PX {
            return None;
        }
        let (w, h) = (f64::from(domain.0), f64::from(domain.1));
        let grow = PEN_DOT_PX / across;
        let fit = (MAX_DOMAIN_PIXELS as f64 / (w * h)).sqrt();
        let s = grow.min(fit).max(1.0);
        Some((
            ((w * s).round() as u32).max(1),
            ((h * s).round() as u32).max(1),
        ))
    }

    /// `range`, or the range whose darkest dots have the asked dot radius
    /// (or the pen's, on a domain `width` px wide).
    pub(crate) fn dot_range(
        &self,
        range: RadiusRange,
        domain: (u32, u32),
    ) -> crate::Result<RadiusRange> {
        let pen_dot = match (self.pen_mm, self.mm_per_px(domain)?) {
            (Some(_), Some(mm)) if self.pen_sized() && self.dot_radius.is_none() => {
                let pen = self.pen_width().unwrap_or_default();
                // The dot as plotted: the pen's width times its gain.
                Some((pen * self.dot_gain(0) / 2.0 / mm) as f32)
            }
            _ => None,
        };
        // The darkest dots' diameter in mm, as a radius in domain px.
        let mm_dot = match (self.dot_mm, self.mm_per_px(domain)?) {
            (Some(d), Some(mm)) => Some((d / 2.0 / mm) as f32),
            _ => None,
        };
        let Some(rho) = self.dot_radius.or(mm_dot).or(pen_dot) else {
            return Ok(range);
        };
        let min = Mapping::range_for_dot(rho, 1.0)?.min;
        if pen_dot.is_some() && self.dot_radius.is_none() && min < 1.0 {
            return Err(Error::InvalidParameter(format!(
                "the pen's dots are {:.2} px wide on this {} px wide domain, too small to \
                 sample: give «points», or a wider domain with «width»",
                2.0 * rho,
                domain.0
            ))
            .into());
        }
        let max = self
            .importance
            .max_radius
            .unwrap_or(min * DEFAULT_RADIUS_RATIO);
        Ok(RadiusRange::new(min, max.max(min))?)
    }

    /// The margin on the paper, mm: `--margin` or [`DEFAULT_MARGIN_MM`].
    #[must_use]
    pub fn margin(&self) -> f64 {
        self.margin.unwrap_or(DEFAULT_MARGIN_MM)
    }

    /// Where a drawing of `domain` px lies on the job's paper (a
    /// poster's whole on the poster), if any.
    pub fn placement(&self, domain: (u32, u32)) -> crate::Result<Option<Placement>> {
        if let Some(sheet) = &self.sheet {
            return Ok(Some(sheet.placement));
        }
        // A poster's whole drawing lies on the poster, its frame centred
        // (the sheets' own placements come with [`Job::poster`]).
        if let Some(poster) = &self.poster {
            let wide = poster.width_mm > poster.height_mm;
            return Ok(Some(poster.place(domain, wide, 0.0)?));
        }
        match &self.paper {
            Some(paper) => Ok(Some(paper.place(domain, self.landscape, self.margin())?)),
            None => Ok(None),
        }
    }

    /// Millimetres per domain pixel, when the drawing has a size in mm
    /// (`--width-mm` or `--paper`).
    pub fn mm_per_px(&self, domain: (u32, u32)) -> crate::Result<Option<f64>> {
        if let Some(p) = self.placement(domain)? {
            return Ok(Some(p.mm_per_px(domain.0)));
        }
        Ok(self.width_mm.map(|mm| mm / f64::from(domain.0.max(1))))
    }

    /// The dot gain of pen `class` (its plotted dot's diameter over the
    /// drawn one, from `pixelpie calibrate fit`), 1 when not calibrated. A
    /// one-ink drawing takes its single pen's.
    #[must_use]
    pub fn dot_gain(&self, class: u32) -> f64 {
        self.pens
            .as_ref()
            .and_then(|set| set.pens().get(class as usize))
            .and_then(|p| p.dot_gain)
            .unwrap_or(1.0)
    }

    /// The grey drawing's pen width with `--pen-mm`: its one pen's own
    /// width if the pen file gives one.
    #[must_use]
    pub fn pen_width(&self) -> Option<f64> {
        self.pen_mm
            .map(|w| self.one_pen().and_then(|p| p.width_mm).unwrap_or(w))
    }
}
