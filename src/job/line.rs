//! The line style (`--style line`): one continuous pen-down line per pen
//! through its points, TSP art whose ink reproduces the picture's tones.
//!
//! A line's ink is its length times the pen's width. Points spread at a
//! density ρ and joined by a short tour lay about √(2ρ/√3) of line per unit
//! area (a tour of a hexagonal grid walks its rows), so the ink is a
//! darkness D where ρ = (√3/2) D² / w² ([`DENSITY`] with the tour's own
//! edge factor, [`EDGE`]): the points' density follows the darkness
//! squared, not the darkness as dots' does (density ∝ darkness
//! over-inks the mid-tones: StippleGen's TSP art reads as a dark maze).
//! The sampler draws the points on a map whose radius is r₀/D (a linear
//! mapping from r₀ to r₀/[`MIN_DARKNESS`]; lighter pixels get no points,
//! the line crosses them), the Lloyd steps even them out on the same
//! weights, and [`crate::stipple::tsp`] orders them into a path without
//! self-crossings. At black the passes lie about one pen width apart.
//!
//! The drawing is then corrected by rendering its line. Where the pen sets
//! the count ([`correct`]), the blurred ink against the blurred picture
//! scales the darkness the points are spread for and recounts them, and
//! the line is sampled, relaxed and toured again. Then every line is
//! refined ([`refined`], [`crate::stipple::refine`]): its vertices move
//! down the gradient of the blurred tone error, as far as keeps its tour
//! within [`TOUR_SLACK`] of the best a search finds through them, and
//! clear of its other segments ([`CLEARANCE`]).

use super::count;
use super::plan::{Maps, Plan, Planned};
use super::run::{Stage, Step, along_curve, stage};
use super::{DEFAULT_POINTS, Job, Picture, Stipple, Style};
use crate::importance::{ImportanceMap, Mapping, Prepared, RadiusRange};
use crate::sampler::{Params, Point, SampleSet};
use crate::stipple::{Stroke, line, refine, tsp};
use crate::text::grouped;
use serde::Serialize;

/// The lightest darkness the line fills: lighter pixels get no points (the
/// line crosses them). Its radius ratio, 1/this, is the map's.
pub(crate) const MIN_DARKNESS: f32 = 1.0 / 24.0;
/// A tour's mean edge over the hexagonal spacing of its points' density:
/// Lloyd-relaxed points are not a perfect grid and the tour takes a longer
/// edge now and then (measured on the bundled photos, docs/drawing.md).
pub(crate) const EDGE: f64 = 1.0;
/// Points per pixel at darkness 1 and a line 1 px wide: ρ = this × D²/w².
pub(crate) const DENSITY: f64 = 0.866_025_403_784_438_6 / (EDGE * EDGE);
/// The longer side of the picture the count is first found on, px (the
/// mean of the darkness squared is within 1% of the domain's there).
const PROBE_SIDE: f64 = 256.0;
/// Domain pixels across the line, where the domain is not given.
const LINE_PX: f64 = 4.0;
/// The shortest longer side of a line's domain, px.
const MIN_LINE_SIDE: f64 = 256.0;
/// Lloyd steps of the line's points before the tour.
pub(crate) const LINE_RELAX: u32 = 2;
/// The most points a line is refined toward its tones by rendering it
/// ([`refined`]; `--plan`'s "corrected").
pub(crate) const LINE_CORRECTED_UP_TO: usize = 100_000;
/// The most points a line is drawn twice for its spread and, where its
/// pen sets it, its count ([`correct`]): the correction's render, Lloyd steps and
/// second tour lifted the blurred PSNR by 0.3 dB at 4K and 10K points of
/// the bundled photo, and lowered it by 0.3 dB at 100K (where the blur is
/// finer than the correction's), at 2.5× the time.
const LINE_RECOUNTED_UP_TO: usize = 30_000;
/// Render pixels across the line in the correction.
const CORRECT_PX: f64 = 2.0;
/// Render pixels across the line in its refinement ([`refined`]): 2 px
/// held the blurred PSNR of 3 px within 0.2 dB on five photos, at two
/// thirds of the time.
const REFINE_PX: f64 = 2.0;
/// Gradient steps of the refinement ([`refined`]).
const REFINE_STEPS: u32 = 4;
/// How much longer than the best tour 2-opt and Or-opt find through its
/// vertices a refined line may be ([`refined`]): its tour stays within
/// about 3% of an LKH-class tour's (the first tour is 1–2% over one).
const TOUR_SLACK: f64 = 0.007;
/// The parts of the way toward the refined line [`refined`] tries, most
/// first.
const BLENDS: [f64; 9] = [1.0, 0.7, 0.5, 0.35, 0.25, 0.18, 0.12, 0.08, 0.04];
/// How far a refined line's vertices keep from its other segments, in pen
/// widths: 0.03 mm of a 1 mm pen, three times what the file's 0.01 mm
/// grid moves a point.
const CLEARANCE: f64 = 0.03;
/// How far a count may be from the one the pen's ink needs before a
/// warning says the tones are out of reach.
const COUNT_TOLERANCE: f64 = 0.15;

/// A line drawing's plan: the line's width and why its count is what it is.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct LinePlan {
    /// The (thinnest) line's width in domain px.
    pub width_px: f64,
    /// The (thinnest) line's width in mm, with a page.
    pub width_mm: Option<f64>,
    /// The count the tones need with this line width.
    pub needed: usize,
    /// Why the count is what it is.
    pub why: String,
    /// Each pen's points (one for a grey drawing).
    pub pens: Vec<usize>,
}

/// What a line drawing's run needs from its plan: each pen's line.
pub(crate) struct LineSetup {
    /// One per pen, in the pens' order (one for a grey drawing).
    pub(crate) pens: Vec<PenLine>,
}

/// One pen's line in the plan.
pub(crate) struct PenLine {
    /// The darkness the pen lays, per domain pixel, row by row.
    darkness: Vec<f32>,
    /// The darkness its points are spread for ([`spread_for`]).
    spread: Vec<f32>,
    /// The points its width needs for its ink.
    needed: f64,
    /// The points it gets: its share of the count.
    points: usize,
    /// Its line's width in domain px.
    width_px: f64,
    /// Whether its count follows its ink (a pen and no count given): the
    /// correction then recounts.
    follows_ink: bool,
}

/// [`spread_for`] of every pixel.
fn spread_of(darkness: &[f32]) -> Vec<f32> {
    use rayon::prelude::*;
    darkness.par_iter().map(|&d| spread_for(d)).collect()
}

/// The most darkness the points are spread for: at it the passes lie
/// about 0.8 pen widths apart (rows of a hexagonal grid at 1.07/1.3 pen
/// widths), dark enough for the tour's bends to leave little paper, not
/// so close that passes pile up into blots.
pub(crate) const MAX_SPREAD: f32 = 1.3;

/// The darkness to spread the points for so that the line lays ink `d`:
/// up to [`KNEE`] the line's ink is the darkness it is spread for; past it
/// passes meet and overlap, and the ink nears 1 as
/// 1 − (1 − KNEE)·e^(−(x − KNEE)/(1 − KNEE)) (measured on the bundled
/// photos, docs/drawing.md), inverted here, up to [`MAX_SPREAD`].
fn spread_for(d: f32) -> f32 {
    if d <= KNEE {
        return d;
    }
    let rest = 1.0 - KNEE;
    let x = KNEE - rest * ((1.0 - d).max(1e-4) / rest).ln();
    x.min(MAX_SPREAD)
}

/// Where the line's ink leaves the darkness it is spread for.
const KNEE: f32 = 0.45;

/// The line's sampling map on `domain` for the darkness `spread` its points
/// are spread for: radius ∝ 1/spread, from 1/[`MAX_SPREAD`] to
/// 1/[`MIN_DARKNESS`] (the white cutoff past it).
fn line_map(spread: &[f32], domain: (u32, u32)) -> crate::Result<Prepared> {
    let (lo, hi) = (1.0 / MAX_SPREAD, 1.0 / MIN_DARKNESS);
    let values = spread
        .iter()
        .map(|&d| {
            if d <= MIN_DARKNESS {
                1.0
            } else {
                ((1.0 / d.min(MAX_SPREAD) - lo) / (hi - lo)).clamp(0.0, 1.0)
            }
        })
        .collect();
    let map = ImportanceMap::from_values(domain.0, domain.1, values)?;
    Ok(Prepared::new(
        map,
        Mapping::Linear,
        RadiusRange::new(lo, hi)?,
        Some(1.0 - 1e-6),
    ))
}

/// Σ D² over the pixels the line fills.
fn ink_squared(darkness: &[f32]) -> f64 {
    use rayon::prelude::*;
    darkness
        .par_chunks(65_536)
        .map(|c| {
            c.iter()
                .filter(|&&d| d > MIN_DARKNESS)
                .map(|&d| f64::from(d) * f64::from(d))
                .sum::<f64>()
        })
        .collect::<Vec<_>>()
        .iter()
        .sum()
}

impl Job {
    /// The plan of a line drawing ([`Job::plan`] with `style = line`): one
    /// line per pen, each pen's points spread for its own darkness (the
    /// grey picture's, or its share of the colour separation's).
    pub(crate) fn plan_line(&self, picture: Picture<'_>) -> crate::Result<Planned> {
        let framed = self.frame(picture)?;
        let picture = framed.as_ref().map_or(picture, super::run::Framed::picture);
        let size = match picture {
            Picture::Grey(m) | Picture::Both(m, _) => (m.width(), m.height()),
            Picture::Colour(c) => (c.width(), c.height()),
        };
        // The count first, on the picture at a small size: it sets the
        // domain. With a pen it follows from the ink (N = ρ over the
        // area); without, the count sets the line's width.
        let probe = {
            let s = PROBE_SIDE / f64::from(size.0.max(size.1).max(1));
            (
                ((f64::from(size.0) * s).round() as u32).max(1),
                ((f64::from(size.1) * s).round() as u32).max(1),
            )
        };
        let mean_sq: Vec<f64> = self
            .pen_darkness(picture, probe)?
            .iter()
            .map(|d| ink_squared(&spread_of(d)) / d.len().max(1) as f64)
            .collect();
        let pens_mm = self.line_pens_mm(mean_sq.len());
        let area_mm = self.page_area_mm(probe)?;
        let needed_for_pen = match (
            pens_mm.iter().copied().collect::<Option<Vec<f64>>>(),
            area_mm,
        ) {
            (Some(pens), Some(area)) => Some(
                mean_sq
                    .iter()
                    .zip(&pens)
                    .map(|(sq, pen)| DENSITY * sq * area / (pen * pen))
                    .sum::<f64>()
                    .round() as usize,
            ),
            _ => None,
        };
        let points = self
            .points
            .or(needed_for_pen)
            .unwrap_or(DEFAULT_POINTS)
            .max(1);
        let mut domain = self.domain_for(size, Some(points));
        // Each line's width in domain px: its pen's, or the one the
        // count's ink needs (the same for every pen).
        let all_sq: f64 = mean_sq.iter().sum();
        let widths_for = |domain: (u32, u32)| -> crate::Result<Vec<f64>> {
            let pixels = f64::from(domain.0) * f64::from(domain.1);
            let mm = self.mm_per_px(domain)?;
            Ok(pens_mm
                .iter()
                .map(|pen| match (pen, mm) {
                    (Some(pen), Some(mm)) => pen / mm,
                    _ => (DENSITY * all_sq * pixels / points as f64).sqrt(),
                })
                .collect())
        };
        let thinnest = |w: &[f64]| w.iter().copied().fold(f64::INFINITY, f64::min);
        let mut widths = widths_for(domain)?;
        // The domain as fine as the line needs, no finer: [`LINE_PX`]
        // across the thinnest line (a line's points lie about a line's
        // width apart at their closest, where dots' lie ten pixels apart).
        if self.width.is_none() && self.height.is_none() {
            let (w, h) = (f64::from(domain.0), f64::from(domain.1));
            let s = (LINE_PX / thinnest(&widths))
                .min((super::MAX_DOMAIN_PIXELS as f64 / (w * h)).sqrt())
                .max(MIN_LINE_SIDE / w.max(h));
            domain = (
                ((w * s).round() as u32).max(1),
                ((h * s).round() as u32).max(1),
            );
            widths = widths_for(domain)?;
        }
        crate::importance::budget::check_domain(domain)?;
        let mut pens = Vec::new();
        let mut maps = Vec::new();
        for (darkness, &width_px) in self.pen_darkness(picture, domain)?.into_iter().zip(&widths) {
            let spread = spread_of(&darkness);
            let needed = DENSITY * ink_squared(&spread) / (width_px * width_px);
            maps.push(line_map(&spread, domain)?);
            pens.push(PenLine {
                darkness,
                spread,
                needed,
                points: 0,
                width_px,
                follows_ink: self.points.is_none() && needed_for_pen.is_some(),
            });
        }
        let needed: f64 = pens.iter().map(|p| p.needed).sum();
        // Each pen's share of the count: its line's need.
        for p in &mut pens {
            p.points = ((p.needed * points as f64 / needed.max(1e-9)).round() as usize).max(1);
        }
        let needed = needed.round() as usize;
        let width_px = thinnest(&widths);
        let why = match (self.points, needed_for_pen) {
            (None, Some(_)) => format!(
                "the pen's line needs {} points for the picture's ink",
                grouped(needed)
            ),
            (Some(_), Some(_)) => format!(
                "the count asked; the pen's line needs {} for the picture's ink",
                grouped(needed)
            ),
            _ => format!("the count sets the line's width, {width_px:.2} px"),
        };
        let mm = self.mm_per_px(domain)?;
        let line = LinePlan {
            width_px,
            width_mm: mm.map(|mm| width_px * mm),
            needed,
            why,
            pens: pens.iter().map(|p| p.points).collect(),
        };
        // Relaxed as dots are, up to the same count: past it a Lloyd step
        // costs more than the sampling (2 s at 1M points).
        let relax = self.relax.unwrap_or(if points <= super::AUTO_RELAX_DOTS {
            LINE_RELAX
        } else {
            0
        });
        let corrected = self.correction == super::Correction::On && points <= LINE_CORRECTED_UP_TO;
        let plan = Plan {
            picture: size,
            domain,
            points: Some(points),
            dots: points,
            pens: pens.len(),
            radius: (maps[0].range.min, maps[0].range.max),
            dot: self.dot_mode(),
            local_spacing: false,
            relax,
            spread: false,
            corrected,
            why: if corrected {
                "the line is refined toward the picture's tones by rendering it".into()
            } else if self.correction == super::Correction::Off {
                "the correction is off".into()
            } else {
                format!(
                    "over {} points: the calibration holds the tones",
                    grouped(LINE_CORRECTED_UP_TO)
                )
            },
            render: corrected.then_some(domain),
            order: super::Order::Tsp,
            layer_order: self.colour().then_some(self.layer_order),
            chosen: None,
            seconds: 0.0,
            memory_mb: crate::importance::budget::peak_mb(size, domain, self.colour()),
            style: Style::Line,
            line: Some(line),
            poster: None,
        };
        let plan = Plan {
            seconds: plan.estimate(),
            ..plan
        };
        Ok(Planned {
            plan,
            job: self.clone(),
            maps: Maps::Lines(maps),
            grid: None,
            line: Some(LineSetup { pens }),
        })
    }

    /// Each pen's darkness at every pixel of `domain`: 1 − the adjusted
    /// display grey of the grey picture, or each pen's coverage in the
    /// colour separation (as its dots would lay it).
    fn pen_darkness(
        &self,
        picture: Picture<'_>,
        domain: (u32, u32),
    ) -> crate::Result<Vec<Vec<f32>>> {
        use rayon::prelude::*;
        let n = domain.0 as usize * domain.1 as usize;
        let of = |m: &Prepared| -> Vec<f32> {
            (0..n)
                .into_par_iter()
                .map(|i| (1.0 - m.value_index(i)).clamp(0.0, 1.0))
                .collect()
        };
        if self.colour() {
            // The separation's inks, whatever its radii: a line's width is
            // its pen's, not a dot's.
            let inks = Job {
                pen_mm: None,
                dot_mm: None,
                dot_radius: None,
                ..self.clone()
            };
            let separated = inks.separate(&picture.colour(), domain, true)?;
            return Ok(separated.maps.iter().map(of).collect());
        }
        let prepared = self.importance.prepare_map_on(
            &picture.grey(),
            |_, _| domain,
            Mapping::Linear,
            true,
            self.paper_levels(),
        )?;
        Ok(vec![of(&prepared)])
    }

    /// Each pen's width in mm, when known: a pen file's own width, else
    /// `pen_mm`.
    fn line_pens_mm(&self, pens: usize) -> Vec<Option<f64>> {
        match (&self.pens, self.colour()) {
            (Some(set), true) => set
                .pens()
                .iter()
                .map(|p| p.width_mm.or(self.pen_mm))
                .collect(),
            _ => vec![self.pen_width(); pens.max(1)],
        }
    }

    /// The drawing's area on the page in mm², when it has a size in mm.
    fn page_area_mm(&self, domain: (u32, u32)) -> crate::Result<Option<f64>> {
        Ok(self
            .mm_per_px(domain)?
            .map(|mm| f64::from(domain.0) * mm * f64::from(domain.1) * mm))
    }

    /// A warning when the count asked cannot reach the picture's tones with
    /// this pen: the pen's line needs `needed` points.
    pub(crate) fn line_count_warning(&self, plan: &Plan) -> Option<String> {
        let line = plan.line.as_ref()?;
        let (Some(asked), Some(_)) = (self.points, self.pen_mm) else {
            return None;
        };
        let ratio = asked as f64 / line.needed.max(1) as f64;
        if (ratio - 1.0).abs() <= COUNT_TOLERANCE {
            return None;
        }
        let (how, what) = if ratio > 1.0 {
            ("too dark", "the darkest areas saturate")
        } else {
            (
                "too light",
                "the line is too short to lay the picture's ink",
            )
        };
        Some(format!(
            "«points={asked}» with «pen_mm={}»: the line comes out {how} ({what}); \
             this pen's line needs about {} points, or leave out «points»",
            self.pen_mm.unwrap_or_default(),
            grouped(line.needed)
        ))
    }
}

/// The run of a line drawing's plan: sample → relax → order → correct,
/// each stage for every pen's line.
pub(crate) fn run_line(
    planned: Planned,
    setup: LineSetup,
    mut sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
    mut progress: impl FnMut(Step) -> bool,
) -> crate::Result<Stipple> {
    let Planned {
        plan, job, maps, ..
    } = planned;
    let Maps::Lines(maps) = maps else {
        return Err(crate::stipple::Error::InvalidParameter(
            "a line drawing without its maps".into(),
        )
        .into());
    };
    let mut last = std::time::Instant::now();
    let mut lap = || {
        let now = std::time::Instant::now();
        let s = (now - last).as_secs_f64();
        last = now;
        s
    };
    let domain = plan.domain;
    stage(&mut progress, Stage::Sample)?;
    let base = job
        .sampler
        .apply(Params::new(domain.0, domain.1).with_policy(job.policy));
    let (mut sets, mut ranges, mut runs, mut short_of) = (Vec::new(), Vec::new(), 0, None);
    for (k, (pen, map)) in setup.pens.iter().zip(&maps).enumerate() {
        // Each pen's own seed: its line is not the others' pattern.
        let params = base.clone().with_seed(base.seed.wrapping_add(k as u64));
        let fitted = count::sample_map(map, &params, Some(pen.points), &mut sample)?;
        runs += fitted.runs;
        short_of = short_of.or(fitted.short_of);
        ranges.push(fitted.range);
        let mut points = along_curve(fitted.set.points.clone());
        for p in &mut points {
            p.class = k as u32;
        }
        sets.push((fitted.set, points));
    }
    let t_sample = lap();
    // A line of up to [`LINE_RECOUNTED_UP_TO`] points is drawn twice: the
    // first tour is only rendered, for the spread (and, where the pen sets
    // the count, the count) the second is drawn with ([`correct`]). The
    // drawings' search does for it (its length within about 1.5% of the
    // line's own); where the count is given, it is neither relaxed nor
    // perturbed (what that changes in its ink scales the spread alike
    // everywhere, and the count is kept).
    let redrawn: Vec<bool> = (0..sets.len())
        .map(|k| plan.corrected && (3..=LINE_RECOUNTED_UP_TO).contains(&sets[k].1.len()))
        .collect();
    let recounted = (0..sets.len()).any(|k| redrawn[k] && setup.pens[k].follows_ink);
    stage(&mut progress, Stage::Relax)?;
    let mut lines = Vec::new();
    for (k, ((_, points), (map, &range))) in
        sets.iter_mut().zip(maps.iter().zip(&ranges)).enumerate()
    {
        let drafted = redrawn[k] && !setup.pens[k].follows_ink;
        let moved = relaxed(
            &job,
            map,
            range,
            std::mem::take(points),
            if drafted { 0 } else { plan.relax },
            &mut progress,
        )?;
        lines.push(moved);
    }
    let t_relax = lap();
    stage(&mut progress, Stage::Order)?;
    let first = match (redrawn.contains(&true), recounted) {
        (false, _) => tsp::TspOptions::line(),
        (true, true) => tsp::TspOptions::default(),
        (true, false) => tsp::TspOptions {
            kicks_per_dot: 0.0,
            ..tsp::TspOptions::default()
        },
    };
    let mut tours: Vec<tsp::Tour> = lines
        .iter()
        .map(|p| toured(p, first, &mut progress))
        .collect();
    let t_order = lap();
    stage(&mut progress, Stage::Size)?;
    // Each pen's line redrawn for its corrected spread (and count), then
    // fitted to its tones: the vertices moved down the blurred error's
    // gradient, the crossings that made undone.
    let of = setup.pens.len() as u8;
    for (k, pen) in setup.pens.iter().enumerate() {
        if !plan.corrected || lines[k].len() <= 2 {
            continue;
        }
        stage(
            &mut progress,
            Stage::Correct {
                round: k as u8 + 1,
                of,
            },
        )?;
        if redrawn[k] {
            let ordered: Vec<Point> = tours[k].order.iter().map(|&i| lines[k][i]).collect();
            let spread = correct(pen, domain, &ordered, pen.width_px);
            // Drawn again on the corrected spread: sampled afresh (Lloyd
            // steps from the first points moved too little to move ink
            // between areas), the count the corrected ink's where the pen
            // sets it.
            let points = if pen.follows_ink {
                ((DENSITY * ink_squared(&spread) / (pen.width_px * pen.width_px)).round() as usize)
                    .max(1)
            } else {
                pen.points
            };
            let mut corrected = line_map(&spread, domain)?;
            // One run, not a fit: the count at the scale the corrected map
            // predicts, with the first fit's bias (predicted against got).
            let first = maps[k].predicted_points(f64::from(ranges[k].max / maps[k].range.max));
            let bias = lines[k].len() as f64 / first.max(1.0);
            let mut scale = f64::from(ranges[k].max / corrected.range.max);
            for _ in 0..3 {
                let predicted = corrected.predicted_points(scale) * bias;
                scale *= (predicted / points as f64).sqrt();
            }
            corrected.range = corrected.range.scaled(scale);
            let params = base.clone().with_seed(base.seed.wrapping_add(k as u64));
            let fitted = count::sample_map(&corrected, &params, None, &mut sample)?;
            runs += fitted.runs;
            ranges[k] = fitted.range;
            let mut points = along_curve(fitted.set.points);
            for p in &mut points {
                p.class = k as u32;
            }
            lines[k] = relaxed(
                &job,
                &corrected,
                ranges[k],
                points,
                plan.relax,
                &mut progress,
            )?;
            tours[k] = toured(&lines[k], tsp::TspOptions::line(), &mut progress);
        }
        let line = std::mem::take(&mut lines[k]);
        let (moved, t) = refined(
            pen,
            domain,
            &line,
            &tours[k],
            job.line_smooth,
            &mut progress,
        );
        lines[k] = moved;
        tours[k] = t;
    }
    let t_size = lap();
    let mut all = Vec::new();
    let mut strokes = Vec::new();
    let mut tour = tsp::Tour {
        order: Vec::new(),
        start_length: 0.0,
        length: 0.0,
        moves: 0,
    };
    for ((line, t), pen) in lines.iter().zip(&tours).zip(&setup.pens) {
        let base = all.len();
        all.extend(t.order.iter().map(|&i| line[i]));
        tour.order.extend((0..t.order.len()).map(|i| base + i));
        tour.start_length += t.start_length;
        tour.length += t.length;
        tour.moves += t.moves;
        strokes.push(Stroke {
            points: t.order.iter().map(|&i| [line[i].x, line[i].y]).collect(),
            width: pen.width_px as f32,
            smooth: job.line_smooth,
        });
    }
    let calibrated = all
        .iter()
        .map(|p| (setup.pens[p.class as usize].width_px / 2.0) as f32)
        .collect();
    let set = sets
        .into_iter()
        .next()
        .map(|(set, _)| set.with_points(all.clone()))
        .ok_or_else(|| {
            crate::stipple::Error::InvalidParameter("a line drawing of no pen".into())
        })?;
    Ok(Stipple {
        dots: Vec::new(),
        calibrated,
        points: all,
        strokes,
        set,
        domain,
        range: ranges[0],
        runs,
        short_of,
        tour: Some(tour),
        stages: vec![
            (Stage::Prepare, 0.0),
            (Stage::Sample, t_sample),
            (Stage::Relax, t_relax),
            (Stage::Order, t_order),
            (Stage::Size, t_size),
        ],
        pens: job.colour().then(|| job.pens.clone()).flatten(),
        plan,
    })
}

/// `points` after `steps` weighted Lloyd steps on `map`'s density (1/r⁴ of
/// its radius r₀/D: a density ∝ D²).
fn relaxed(
    job: &Job,
    map: &Prepared,
    range: RadiusRange,
    points: Vec<Point>,
    steps: u32,
    progress: &mut impl FnMut(Step) -> bool,
) -> crate::Result<Vec<Point>> {
    if steps == 0 || points.len() < 3 {
        return Ok(points);
    }
    super::run::relaxed_points(
        job,
        std::slice::from_ref(map),
        range,
        map.domain(),
        &points,
        steps,
        progress,
    )
}

/// The tour through `points`, without self-crossings.
fn toured(
    points: &[Point],
    options: tsp::TspOptions,
    progress: &mut impl FnMut(Step) -> bool,
) -> tsp::Tour {
    let xy: Vec<[f64; 2]> = points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let mut tour = tsp::plan_until(&xy, options, &mut || !progress(Step::Busy(Stage::Order)));
    tsp::uncross(&xy, &mut tour.order);
    tour.length = tsp::path_length(&xy, &tour.order);
    tour
}

/// The line through `line` in `tour`'s order, `pen`'s width, its vertices
/// moved toward `pen`'s darkness ([`refine::refine`], rendered
/// [`REFINE_PX`] px across the line), then uncrossed: the points in their
/// new drawing order and its tour.
fn refined(
    pen: &PenLine,
    domain: (u32, u32),
    line: &[Point],
    tour: &tsp::Tour,
    smooth: bool,
    progress: &mut impl FnMut(Step) -> bool,
) -> (Vec<Point>, tsp::Tour) {
    let mut ordered: Vec<Point> = tour.order.iter().map(|&i| line[i]).collect();
    let mut xy: Vec<[f64; 2]> = ordered
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let scale = (REFINE_PX / pen.width_px).clamp(0.25, 1.0);
    let grid = (
        ((f64::from(domain.0) * scale).round() as u32).max(1),
        ((f64::from(domain.1) * scale).round() as u32).max(1),
    );
    let want = mean_on(&pen.darkness, domain, grid);
    let first = xy.clone();
    refine::refine(
        &mut xy,
        pen.width_px,
        &want,
        grid,
        scale,
        refine::RefineOptions {
            // Four steps: the redrawn lines' spread is already corrected,
            // and the time of a 10K- or 100K-point line stays within 2× its
            // dots' (docs/benchmarks.md).
            steps: REFINE_STEPS,
            smooth,
            ..refine::RefineOptions::default()
        },
        &mut || !progress(Step::Busy(Stage::Size)),
    );
    // A refined line lays ink by bending, so a search through its vertices
    // finds a shorter tour: it is taken only as far toward the refinement
    // as keeps it within [`TOUR_SLACK`] of that tour (whose length is
    // taken between the first tour's and the refined vertices' tour's).
    let along: Vec<usize> = (0..xy.len()).collect();
    let length = |p: &[[f64; 2]]| tsp::path_length(p, &along);
    let before = length(&first);
    let best = tsp::path_length(&xy, &tsp::improve(&xy, &along, tsp::TspOptions::default()));
    let blend = |a: f64| -> Vec<[f64; 2]> {
        first
            .iter()
            .zip(&xy)
            .map(|(p, q)| [p[0] + a * (q[0] - p[0]), p[1] + a * (q[1] - p[1])])
            .collect()
    };
    let xy = BLENDS
        .iter()
        .map(|&a| (a, blend(a)))
        .find(|(a, p)| {
            let searched = before + a * (best.min(before) - before);
            length(p) <= (1.0 + TOUR_SLACK) * searched
        })
        .map_or(first, |(_, p)| p);
    let (w, h) = (domain.0 as f32, domain.1 as f32);
    // The points moved to `xy`, within the domain's pixels as the sampler's
    // are, at the precision the drawing holds them; their places.
    let mut settle = |xy: &[[f64; 2]]| -> Vec<[f64; 2]> {
        ordered
            .iter_mut()
            .zip(xy)
            .map(|(p, q)| {
                p.x = (q[0] as f32).clamp(0.0, w.next_down());
                p.y = (q[1] as f32).clamp(0.0, h.next_down());
                [f64::from(p.x), f64::from(p.y)]
            })
            .collect()
    };
    let mut xy = settle(&xy);
    let mut order: Vec<usize> = (0..xy.len()).collect();
    // Clear of the line's other segments by a few hundredths of a mm
    // (a file rounds to 0.01 mm): no crossing appears when it is written.
    let eps = CLEARANCE * pen.width_px;
    for _ in 0..2 {
        tsp::uncross(&xy, &mut order);
        let mut path: Vec<[f64; 2]> = order.iter().map(|&i| xy[i]).collect();
        if refine::keep_clear(&mut path, eps) == 0 {
            break;
        }
        for (&i, q) in order.iter().zip(&path) {
            xy[i] = *q;
        }
    }
    let xy = settle(&xy);
    tsp::uncross(&xy, &mut order);
    let length = tsp::path_length(&xy, &order);
    (
        ordered,
        tsp::Tour {
            order,
            start_length: tour.start_length,
            length,
            moves: tour.moves,
        },
    )
}

/// The darkness to spread the points for, corrected by rendering the line
/// through `ordered` `width` px wide on `domain`: each pixel's spread
/// times the blurred picture's darkness over the blurred line's ink
/// (within ½..2, at most [`MAX_SPREAD`]).
fn correct(setup: &PenLine, domain: (u32, u32), ordered: &[Point], width: f64) -> Vec<f32> {
    use rayon::prelude::*;
    let xy: Vec<[f64; 2]> = ordered
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    // Rendered about two pixels across the line: fine enough for the
    // blurred tone, a quarter of the domain's pixels at most.
    let scale = (CORRECT_PX / width).clamp(0.25, 1.0);
    let grid = (
        ((f64::from(domain.0) * scale).round() as u32).max(1),
        ((f64::from(domain.1) * scale).round() as u32).max(1),
    );
    let img = line::render_polyline(&xy, width, grid, scale);
    let ink: Vec<f32> = img
        .as_raw()
        .par_iter()
        .map(|&v| 1.0 - f32::from(v) / 255.0)
        .collect();
    // Blurred over a few spacings: the tone a reader sees.
    let spacing = (f64::from(grid.0) * f64::from(grid.1) / ordered.len() as f64).sqrt();
    let radius = (1.5 * spacing).round().max(1.0) as usize;
    let want = box_blur(&mean_on(&setup.darkness, domain, grid), grid, radius);
    let got = box_blur(&ink, grid, radius);
    let factor: Vec<f32> = want
        .par_iter()
        .zip(&got)
        .map(|(&w, &g)| {
            if w <= 1e-3 {
                1.0
            } else if g > 1e-3 {
                (w / g).clamp(0.5, 2.0)
            } else {
                2.0
            }
        })
        .collect();
    let (dw, gw) = (domain.0 as usize, grid.0 as usize);
    setup
        .spread
        .par_chunks(dw)
        .enumerate()
        .flat_map_iter(|(y, row)| {
            let gy = (y * grid.1 as usize / domain.1 as usize).min(grid.1 as usize - 1);
            let factor = &factor[gy * gw..(gy + 1) * gw];
            row.iter().enumerate().map(move |(x, &v)| {
                let f = factor[(x * gw / dw).min(gw - 1)];
                (v * f).clamp(0.0, MAX_SPREAD)
            })
        })
        .collect()
}

/// `values` on `domain` averaged onto the coarser `grid` (each domain
/// pixel to the grid pixel that holds it).
fn mean_on(values: &[f32], domain: (u32, u32), grid: (u32, u32)) -> Vec<f32> {
    let (dw, dh) = (domain.0 as usize, domain.1 as usize);
    let (gw, gh) = (grid.0 as usize, grid.1 as usize);
    let mut sum = vec![0.0f64; gw * gh];
    let mut count = vec![0u32; gw * gh];
    for y in 0..dh {
        let gy = (y * gh / dh).min(gh - 1);
        for x in 0..dw {
            let g = gy * gw + (x * gw / dw).min(gw - 1);
            sum[g] += f64::from(values[y * dw + x]);
            count[g] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(&s, &c)| {
            if c > 0 {
                (s / f64::from(c)) as f32
            } else {
                0.0
            }
        })
        .collect()
}

/// Three passes of a box blur of `radius` px each way (nearly Gaussian).
fn box_blur(values: &[f32], (w, h): (u32, u32), radius: usize) -> Vec<f32> {
    use rayon::prelude::*;
    let (w, h) = (w as usize, h as usize);
    let pass_rows = |src: &[f32]| -> Vec<f32> {
        let mut out = vec![0.0; src.len()];
        out.par_chunks_mut(w)
            .zip(src.par_chunks(w))
            .for_each(|(o, s)| blur_line(s, o, radius));
        out
    };
    let transpose = |src: &[f32], (w, h): (usize, usize)| -> Vec<f32> {
        let mut out = vec![0.0; src.len()];
        out.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
            for (y, v) in col.iter_mut().enumerate() {
                *v = src[y * w + x];
            }
        });
        out
    };
    let mut a = values.to_vec();
    for _ in 0..3 {
        a = pass_rows(&a);
    }
    let mut t = transpose(&a, (w, h));
    let pass_cols = |src: &[f32]| -> Vec<f32> {
        let mut out = vec![0.0; src.len()];
        out.par_chunks_mut(h)
            .zip(src.par_chunks(h))
            .for_each(|(o, s)| blur_line(s, o, radius));
        out
    };
    for _ in 0..3 {
        t = pass_cols(&t);
    }
    transpose(&t, (h, w))
}

/// A running mean of `radius` each side along one line (clamped at the
/// ends: the window shrinks).
fn blur_line(src: &[f32], out: &mut [f32], radius: usize) {
    let n = src.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0f64);
    for &v in src {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + f64::from(v));
    }
    for (i, o) in out.iter_mut().enumerate() {
        let (a, b) = (i.saturating_sub(radius), (i + radius + 1).min(n));
        *o = ((prefix[b] - prefix[a]) / (b - a) as f64) as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spread is the darkness up to the knee, then grows past it
    /// (passes that meet lay less new ink), never past [`MAX_SPREAD`], and
    /// inverts the ink model it states.
    #[test]
    fn the_spread_inverts_the_lines_ink_model() {
        let ink = |x: f32| {
            if x <= KNEE {
                x
            } else {
                1.0 - (1.0 - KNEE) * (-(x - KNEE) / (1.0 - KNEE)).exp()
            }
        };
        let mut last = 0.0;
        for i in 0..=100 {
            let d = i as f32 / 100.0;
            let x = spread_for(d);
            assert!(x >= last && x <= MAX_SPREAD, "{d}: {x}");
            if x < MAX_SPREAD {
                assert!((ink(x) - d).abs() < 1e-4, "{d}: ink {} of {x}", ink(x));
            }
            if d <= KNEE {
                assert_eq!(x, d);
            }
            last = x;
        }
        assert_eq!(spread_for(1.0), MAX_SPREAD);
    }

    /// The line's map gives a radius ∝ 1/spread (a density ∝ spread²)
    /// and cuts the pixels lighter than [`MIN_DARKNESS`].
    #[test]
    fn the_maps_radius_is_inverse_to_the_spread() {
        let spread = [1.3, 0.65, 0.26, 0.13, 0.01];
        let map = line_map(&spread, (5, 1)).unwrap();
        let radius = ImportanceMap::radius_fn(map.mapping, map.range);
        for (i, &x) in spread.iter().enumerate().take(4) {
            let r = radius(map.value(i as u32, 0));
            assert!((r * x - 1.0).abs() < 1e-4, "{x}: r {r}");
        }
        let cut = map.cutoff().unwrap();
        assert!(map.value(4, 0) > cut && map.value(3, 0) <= cut);
    }

    /// The box blur keeps a constant and the mean, and spreads a spike.
    #[test]
    fn the_blur_keeps_the_mean() {
        let (w, h) = (40u32, 30u32);
        let mut v = vec![0.5f32; (w * h) as usize];
        assert!(
            box_blur(&v, (w, h), 3)
                .iter()
                .all(|&x| (x - 0.5).abs() < 1e-6)
        );
        v[(15 * w + 20) as usize] = 10.0;
        let b = box_blur(&v, (w, h), 2);
        let mean = |x: &[f32]| x.iter().map(|&a| f64::from(a)).sum::<f64>() / x.len() as f64;
        assert!((mean(&b) - mean(&v)).abs() < 1e-3);
        assert!(b[(15 * w + 20) as usize] < 1.0 && b[(15 * w + 22) as usize] > 0.5);
    }
}
