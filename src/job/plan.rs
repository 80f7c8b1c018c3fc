//! `Job → Plan → run`: every decision of a drawing made once, from the job
//! and its picture, before anything is sampled ([`Job::plan`]). The run
//! ([`Planned::run`]) executes the plan and decides nothing; the front ends
//! show it (`pixelpie stipple --plan`, Python's `pixelpie.plan`, the app's
//! plan line), so that a user who asks why a drawing looks as it does reads
//! the answer in one place.
//!
//! The one rule for grey and colour alike ([`Job::corrects`], `decide`): sized dots
//! on a tone mapping with `--correction on` are corrected toward the
//! picture by rendering the drawing, and up to [`AUTO_RELAX_DOTS`] a
//! drawing is relaxed by default ([`AUTO_RELAX_STEPS`]; a colour drawing's
//! pens are first spread apart, [`Plan::spread`], and then each relaxed on
//! its own); a relaxed drawing is
//! always corrected (its dots overlap less than the calibration's, so only
//! the correction keeps its tones), its render made as fine as the
//! correction needs. Past [`AUTO_RELAX_DOTS`] the drawing is neither
//! relaxed nor, where its render cannot resolve the dots, corrected: the
//! calibration alone holds the tones there.

use serde::Serialize;

use super::colour::Separated;
use super::correct::GridSpec;
use super::run::Framed;
use super::{AUTO_RELAX_DOTS, AUTO_RELAX_STEPS, DotMode, Job, LayerOrder, Order, Picture};
use crate::importance::{MappingKind, Prepared};
use crate::text::grouped;

/// What a drawing will be: every decision of [`Job::plan`], in the words
/// the front ends show. Serialized (`--plan`, Python) it is a plain table.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct Plan {
    /// The picture's size after the crop and the turn, px.
    pub picture: (u32, u32),
    /// The domain the dots are sampled on, px.
    pub domain: (u32, u32),
    /// The dot count asked for (±3%), if the count sets the radii.
    pub points: Option<usize>,
    /// The dots expected: the count asked, or the count the radii predict.
    pub dots: usize,
    /// Pens: 1 for a grey drawing.
    pub pens: usize,
    /// The sample radius range, px: the range the count's fit starts from
    /// (the picture's predicted count scaled to the count asked).
    pub radius: (f32, f32),
    /// How the dots are sized.
    pub dot: DotMode,
    /// Whether sized dots take the spacing they have, not the one their
    /// tone asks ([`super::Spacing::Local`]: a grey drawing of sized dots
    /// on a tone mapping).
    pub local_spacing: bool,
    /// Weighted Lloyd steps after sampling.
    pub relax: u32,
    /// Whether a colour drawing's pens are spread apart after they are
    /// given out (each pen's dots evener): up to [`AUTO_RELAX_DOTS`] dots,
    /// where it costs little beside the rest (0.13 s at 200K dots; 0.65 s
    /// at 1M, nearly the drawing's own cost). Such a drawing is then
    /// relaxed pen by pen (`crate::stipple::relax_points`).
    pub spread: bool,
    /// Whether the dots are corrected toward the picture by rendering.
    pub corrected: bool,
    /// Why the drawing is or is not corrected and relaxed, in a few words.
    pub why: String,
    /// The correction's render, px (when corrected).
    pub render: Option<(u32, u32)>,
    /// The drawing order.
    pub order: Order,
    /// The pens' layer order (colour drawings).
    pub layer_order: Option<LayerOrder>,
    /// The pens chosen for the picture from a pen box (`choose`).
    pub chosen: Option<PenChoice>,
    /// The estimated seconds of the run on two CPU cores (sampling on the
    /// CPU), the picture's loading not included.
    pub seconds: f64,
    /// The predicted peak memory of the run in MB (the picture's decoding
    /// or the domain's maps, [`crate::importance::budget`]).
    pub memory_mb: u64,
    /// What the pen draws.
    pub style: super::Style,
    /// A line drawing's width and why its count is what it is (JSON
    /// `line_plan`: `line` is the plan's one-line summary).
    #[serde(rename = "line_plan", skip_serializing_if = "Option::is_none")]
    pub line: Option<super::line::LinePlan>,
    /// A poster's sheets (`--poster`): the frame, the grid, the overlap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub poster: Option<super::PosterPlan>,
}

/// The pens a plan chose from a pen box.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct PenChoice {
    /// Their names, in the box's order.
    pub pens: Vec<String>,
    /// The predicted mean ΔE00 of the drawing against the photo.
    pub predicted_de00: f64,
}

/// Grey correction: the fewest render pixels between dots; a
/// coarser render's one-pixel dots mislead it (3 px: 3–6 dB worse at 1M
/// dots; 3.7 px: mixed).
pub(crate) const MIN_PX_PER_SPACING: f64 = 4.5;
/// The picture prepared for the run: one map (grey) or one per pen.
pub(crate) enum Maps {
    Grey(Prepared),
    Colour(Separated),
    /// A line drawing's maps, one per pen (`line.rs`).
    Lines(Vec<Prepared>),
}

impl Maps {
    pub(crate) fn all(&self) -> &[Prepared] {
        match self {
            Self::Grey(g) => std::slice::from_ref(g),
            Self::Colour(s) => &s.maps,
            Self::Lines(maps) => maps,
        }
    }
}

/// A plan and what its run needs: the job, the prepared maps and the
/// correction's grid. Made by [`Job::plan`]; [`Self::run`] draws it.
pub struct Planned {
    /// The decisions.
    pub plan: Plan,
    pub(crate) job: Job,
    pub(crate) maps: Maps,
    /// How the correction's render is sized, when it runs.
    pub(crate) grid: Option<GridSpec>,
    /// A line drawing's darkness, for its run.
    pub(crate) line: Option<super::line::LineSetup>,
}

impl Planned {
    /// The job as it is drawn and written: with `choose`, the pens chosen.
    #[must_use]
    pub fn job(&self) -> &Job {
        &self.job
    }
}

impl Job {
    /// Makes every decision of a drawing of `picture` once: the framing,
    /// the domain and radii, the count, the dots, relaxation and the
    /// correction (one rule for grey and colour, the module's), the order.
    /// Prepares the picture's maps (the prepare stage); nothing is sampled.
    pub fn plan(&self, picture: Picture<'_>) -> crate::Result<Planned> {
        self.check()?;
        // A poster is drawn whole, then cut into sheets.
        if let Some(whole) = self.poster_whole(picture)? {
            let mut planned = whole.plan(picture)?;
            planned.plan.poster = self.poster_plan(&whole, &planned)?;
            return Ok(planned);
        }
        // The pen choice is the plan's first step: the rest plans the job
        // with the pens chosen, which [`Planned::job`] hands on to the
        // writers.
        if self.choose.is_some() {
            let (job, choice) = self.chosen(picture)?;
            let mut planned = job.plan(picture)?;
            planned.plan.chosen = choice.map(|c| PenChoice {
                pens: c.pens.pens().iter().map(|p| p.name.clone()).collect(),
                predicted_de00: c.predicted,
            });
            return Ok(planned);
        }
        if self.style == super::Style::Line {
            return self.plan_line(picture);
        }
        let (points, radii_scaled) = self.count();
        // The crop and the turn, first: the rest sees the framed picture.
        let framed = self.frame(picture)?;
        let picture = framed.as_ref().map_or(picture, Framed::picture);
        let (maps, size) = if self.colour() {
            let colour = picture.colour();
            let size = (colour.width(), colour.height());
            let domain = self.domain_for(size, points);
            crate::importance::budget::check_domain(domain)?;
            (
                Maps::Colour(self.separate(&colour, domain, radii_scaled)?),
                size,
            )
        } else {
            let map = picture.grey();
            let size = (map.width(), map.height());
            crate::importance::budget::check_domain(self.domain_for(size, points))?;
            let mut prepared = self.importance.prepare_map_on(
                &map,
                |w, h| self.domain_for((w, h), points),
                self.dot_mode().mapping(self.dot_ratio),
                radii_scaled,
                self.paper_levels(),
            )?;
            prepared.range = self.dot_range(prepared.range, prepared.domain())?;
            (Maps::Grey(prepared), size)
        };
        let all = maps.all();
        let domain = all[0].domain();
        let range = all[0].range;
        let dots = points.unwrap_or_else(|| {
            all.iter()
                .map(|m| m.predicted_points(1.0))
                .sum::<f64>()
                .round() as usize
        });
        let colour = matches!(maps, Maps::Colour(_));
        let decided = decide(self, colour, domain, dots);
        let plan = Plan {
            picture: size,
            domain,
            points,
            dots,
            pens: all.len(),
            radius: match points {
                Some(n) if dots > 0 => {
                    let predicted: f64 = all.iter().map(|m| m.predicted_points(1.0)).sum();
                    let s = (predicted / n as f64).sqrt() as f32;
                    (range.min * s, range.max * s)
                }
                _ => (range.min, range.max),
            },
            dot: self.dot_mode(),
            local_spacing: self.spacing == super::Spacing::Local && self.spacing_applies(),
            relax: decided.relax,
            spread: colour && dots <= AUTO_RELAX_DOTS,
            corrected: decided.grid.is_some(),
            why: decided.why,
            render: decided.grid.map(|g| g.grid(domain, dots).size),
            order: self.order,
            layer_order: colour.then_some(self.layer_order),
            chosen: None,
            seconds: 0.0,
            memory_mb: crate::importance::budget::peak_mb(size, domain, colour),
            style: super::Style::Dots,
            line: None,
            poster: None,
        };
        let plan = Plan {
            seconds: plan.estimate(),
            ..plan
        };
        Ok(Planned {
            plan,
            job: self.clone(),
            maps,
            grid: decided.grid,
            line: None,
        })
    }

    /// Whether this job's dots are of the kind the correction corrects:
    /// `--correction on`, sized dots, a tone mapping (grey and colour).
    #[must_use]
    pub fn corrects(&self) -> bool {
        self.correction == super::Correction::On
            && self.dot_mode() == DotMode::Sized
            && self.importance.mapping != Some(MappingKind::Linear)
    }
}

/// The relaxation and correction decisions.
struct Decided {
    relax: u32,
    grid: Option<GridSpec>,
    why: String,
}

/// The one rule (the module's) for a drawing of about `dots` dots on
/// `domain`.
fn decide(job: &Job, colour: bool, domain: (u32, u32), dots: usize) -> Decided {
    let wants = job.corrects();
    let dense = dots > AUTO_RELAX_DOTS;
    let relax = job
        .relax
        .unwrap_or(if wants && !dense { AUTO_RELAX_STEPS } else { 0 });
    if !wants {
        let why = if job.correction == super::Correction::Off {
            "the correction is off"
        } else if job.dot_mode() != DotMode::Sized {
            "only sized dots are corrected"
        } else {
            "a linear mapping is not corrected"
        };
        return Decided {
            relax,
            grid: None,
            why: why.into(),
        };
    }
    if colour {
        return Decided {
            relax,
            grid: Some(GridSpec::colour()),
            why: "sized colour dots".into(),
        };
    }
    if relax > 0 {
        // A relaxed drawing is always corrected, its render as fine as the
        // correction needs.
        return Decided {
            relax,
            grid: Some(GridSpec::grey(MIN_PX_PER_SPACING)),
            why: "relaxed, so corrected".into(),
        };
    }
    let spec = GridSpec::grey(0.0);
    if spec.grid(domain, dots).px_per_spacing() < MIN_PX_PER_SPACING {
        return Decided {
            relax,
            grid: None,
            why: format!(
                "over {} dots and not relaxed: the calibration holds the tones",
                grouped(AUTO_RELAX_DOTS)
            ),
        };
    }
    Decided {
        relax,
        grid: Some(spec),
        why: "sized grey dots".into(),
    }
}

impl Plan {
    /// The seconds a run of this plan takes on two CPU cores, estimated:
    /// sampling (about 1.2 runs of the count's fit at 2.2M points/s), the
    /// relaxation (by the domain's pixels), the correction (by its render's
    /// pixels and dots), spreading a colour drawing's pens and the writing
    /// (by the dots). Fitted to `pixelpie
    /// bench --stipple` on the 2-core VM within about a factor of 1.5.
    /// Decoding and preparing the picture, by its pixels, comes first: a
    /// 10000² photo takes 2.5 s as a JPEG, 3.9 s as a grey PNG, whatever
    /// the drawing (the 2-core VM).
    pub(crate) fn estimate(&self) -> f64 {
        let dots = self.dots as f64;
        let picture = f64::from(self.picture.0) * f64::from(self.picture.1);
        let decode = picture / 35e6;
        let domain = f64::from(self.domain.0) * f64::from(self.domain.1);
        let sample = 0.02 + 1.2 * dots / 2.2e6 + domain / 200e6;
        let relax = f64::from(self.relax) * (domain / 120e6 + dots / 2.0e6);
        let correct = self.render.map_or(0.0, |(w, h)| {
            3.0 * (f64::from(w) * f64::from(h) / 60e6 + dots / 4.0e6)
        });
        let colour = if self.pens > 1 { 0.6 * sample } else { 0.0 };
        // Spreading the pens: 0.13 s at 200K dots.
        let spread = if self.spread { dots / 1.5e6 } else { 0.0 };
        let order = match self.order {
            Order::Tsp => dots / 0.5e6,
            Order::None => 0.0,
        };
        // A line: its tour made twice, its render for the correction.
        let order = if self.line.is_some() {
            2.0 * order + domain / 100e6
        } else {
            order
        };
        let write = dots / 3.5e6;
        decode + sample + relax + correct + colour + spread + order + write
    }

    /// The plan in one line: "10 000 dots · 2 Lloyd steps · corrected ·
    /// ≈0.8 s".
    #[must_use]
    pub fn line(&self) -> String {
        let mut parts = vec![match &self.line {
            Some(l) if self.pens > 1 => format!(
                "{} lines, one a pen, through {} points, the thinnest {:.2} px wide",
                self.pens,
                grouped(self.dots),
                l.width_px
            ),
            Some(l) => format!(
                "one line through {} points, {:.2} px wide",
                grouped(self.dots),
                l.width_px
            ),
            None => format!("{} dots", grouped(self.dots)),
        }];
        if self.pens > 1 && self.line.is_none() {
            parts.push(format!("{} pens", self.pens));
        }
        parts.push(match self.relax {
            0 if self.spread => "pens spread apart".into(),
            0 => "not relaxed".into(),
            1 => "1 Lloyd step".into(),
            n => format!("{n} Lloyd steps"),
        });
        if self.spread && self.relax > 0 {
            parts.push("pens spread apart".into());
        }
        if let Some(p) = &self.poster {
            let (lo, hi) = p
                .sheet_dots
                .iter()
                .fold((usize::MAX, 0), |(lo, hi), &d| (lo.min(d), hi.max(d)));
            parts.push(format!(
                "{} sheets ({} × {}, overlapping {} mm), {}–{} {} a sheet",
                p.sheets,
                p.grid.rows,
                p.grid.cols,
                p.grid.overlap_mm,
                grouped(lo.min(hi)),
                grouped(hi),
                if self.line.is_some() {
                    "points"
                } else {
                    "dots"
                }
            ));
        }
        if let Some(c) = &self.chosen {
            parts.push(format!("pens chosen: {}", c.pens.join(", ")));
        }
        parts.push(if self.corrected {
            "corrected".into()
        } else {
            format!("not corrected ({})", self.why)
        });
        parts.push(if self.seconds < 10.0 {
            format!("≈{:.1} s", self.seconds)
        } else {
            format!("≈{:.0} s", self.seconds)
        });
        parts.join(" · ")
    }

    /// The plan as JSON (`--plan`, Python's `pixelpie.plan`): its line
    /// first, then every decision.
    pub fn to_json(&self) -> crate::Result<String> {
        #[derive(Serialize)]
        struct WithLine<'a> {
            line: String,
            #[serde(flatten)]
            plan: &'a Plan,
        }
        let with = WithLine {
            line: self.line(),
            plan: self,
        };
        serde_json::to_string_pretty(&with).map_err(|e| {
            crate::stipple::Error::InvalidParameter(format!("the plan as JSON: {e}")).into()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one rule: corrected up to the auto limit, for grey and colour
    /// alike, both relaxed with it (colour's pens spread first); a
    /// relaxed grey drawing is corrected at any count, its render grown;
    /// fixed dots are neither.
    #[test]
    fn relaxation_and_correction_go_together() {
        let job = Job::default();
        for (dots, domain) in [
            (20_000, (1414, 354)),
            (150_000, (3873, 968)),
            (199_000, (4461, 1115)),
        ] {
            for colour in [false, true] {
                let d = decide(&job, colour, domain, dots);
                assert_eq!(d.relax, AUTO_RELAX_STEPS, "{dots}, colour {colour}");
                let grid = d.grid.expect("corrected").grid(domain, dots);
                if !colour {
                    assert!(grid.px_per_spacing() >= MIN_PX_PER_SPACING, "{dots}");
                }
            }
        }
        let d = decide(&job, false, (8192, 2048), 1_000_000);
        assert_eq!((d.relax, d.grid.is_some()), (0, false));
        let relaxed = Job {
            relax: Some(3),
            ..Job::default()
        };
        let d = decide(&relaxed, false, (8192, 2048), 1_000_000);
        let grid = d
            .grid
            .expect("a relaxed drawing is corrected")
            .grid((8192, 2048), 1_000_000);
        assert!(grid.px_per_spacing() >= MIN_PX_PER_SPACING);
        let fixed = Job {
            dot: Some(DotMode::Fixed),
            ..Job::default()
        };
        for colour in [false, true] {
            let d = decide(&fixed, colour, (1024, 683), 10_000);
            assert_eq!((d.relax, d.grid.is_some()), (0, false));
        }
    }
}
