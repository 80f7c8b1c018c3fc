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
//! The drawing is then corrected by rendering its line ([`correct`]): the
//! blurred ink against the blurred picture scales the darkness the points
//! are spread for, the points take more Lloyd steps toward it, and the
//! tour is made again.

use super::count;
use super::plan::{Maps, Plan, Planned};
use super::run::{Stage, Step, along_curve, stage};
use super::{DEFAULT_POINTS, Job, Picture, Stipple, Style, default_domain};
use crate::importance::{ImportanceMap, Mapping, Prepared, RadiusRange};
use crate::sampler::{Params, Point, SampleSet};
use crate::stipple::{Stroke, line, relax, tsp};
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
/// Domain pixels across the line, where the domain is not given.
const LINE_PX: f64 = 4.0;
/// The shortest longer side of a line's domain, px.
const MIN_LINE_SIDE: f64 = 256.0;
/// Lloyd steps of the line's points before the tour.
pub(crate) const LINE_RELAX: u32 = 2;
/// The most points a line is corrected for: the correction's render,
/// Lloyd steps and second tour lifted the blurred PSNR by 0.3 dB at 4K
/// and 10K points of the bundled photo, and lowered it by 0.3 dB at 100K
/// (where the blur is finer than the correction's), at 2.5× the time.
pub(crate) const LINE_CORRECTED_UP_TO: usize = 30_000;
/// Render pixels across the line in the correction.
const CORRECT_PX: f64 = 2.0;
/// Lloyd steps after the correction's render.
const CORRECT_RELAX: u32 = 2;
/// How far a count may be from the one the pen's ink needs before a
/// warning says the tones are out of reach.
const COUNT_TOLERANCE: f64 = 0.15;

/// A line drawing's plan: the line's width and why its count is what it is.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct LinePlan {
    /// The line's width in domain px.
    pub width_px: f64,
    /// The line's width in mm, with a page.
    pub width_mm: Option<f64>,
    /// The count the tones need with this line width.
    pub needed: usize,
    /// Why the count is what it is.
    pub why: String,
}

/// The darkness of each domain pixel, and the line's map and set-up, made
/// by the plan for its run.
pub(crate) struct LineSetup {
    /// 1 − display grey per domain pixel, row by row.
    pub(crate) darkness: Vec<f32>,
    /// The darkness the points are spread for ([`spread_for`]).
    pub(crate) spread: Vec<f32>,
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
    /// The plan of a line drawing ([`Job::plan`] with `style = line`).
    pub(crate) fn plan_line(&self, picture: Picture<'_>) -> crate::Result<Planned> {
        let framed = self.frame(picture)?;
        let picture = framed.as_ref().map_or(picture, super::run::Framed::picture);
        let map = picture.grey();
        let size = (map.width(), map.height());
        // The count first, on the picture at a small size: it sets the
        // domain. With a pen it follows from the ink (N = ρ over the
        // area); without, the count sets the line's width.
        let probe = default_domain(size.0, size.1, DEFAULT_POINTS);
        let spread = spread_of(&self.darkness(&map, probe)?);
        let mean_sq = ink_squared(&spread) / spread.len().max(1) as f64;
        let pen_mm = self.pen_width();
        let area_mm = self.page_area_mm(probe)?;
        let needed_for_pen = match (pen_mm, area_mm) {
            (Some(pen), Some(area)) => {
                Some((DENSITY * mean_sq * area / (pen * pen)).round() as usize)
            }
            _ => None,
        };
        let points = self
            .points
            .or(needed_for_pen)
            .unwrap_or(DEFAULT_POINTS)
            .max(1);
        let mut domain = self.domain_for(size, Some(points));
        // The line's width in domain px: the pen's, or the one the count's
        // ink needs.
        let width_for = |domain: (u32, u32)| -> crate::Result<f64> {
            let pixels = f64::from(domain.0) * f64::from(domain.1);
            Ok(match (pen_mm, self.mm_per_px(domain)?) {
                (Some(pen), Some(mm)) => pen / mm,
                _ => (DENSITY * mean_sq * pixels / points as f64).sqrt(),
            })
        };
        let mut width_px = width_for(domain)?;
        // The domain as fine as the line needs, no finer: [`LINE_PX`]
        // across the line (a line's points lie about a line's width apart
        // at their closest, where dots' lie ten pixels apart).
        if self.width.is_none() && self.height.is_none() {
            let (w, h) = (f64::from(domain.0), f64::from(domain.1));
            let s = (LINE_PX / width_px)
                .min((super::MAX_DOMAIN_PIXELS as f64 / (w * h)).sqrt())
                .max(MIN_LINE_SIDE / w.max(h));
            domain = (
                ((w * s).round() as u32).max(1),
                ((h * s).round() as u32).max(1),
            );
            width_px = width_for(domain)?;
        }
        crate::importance::budget::check_domain(domain)?;
        let darkness = self.darkness(&map, domain)?;
        let spread = spread_of(&darkness);
        let sum_sq = ink_squared(&spread);
        let needed = (DENSITY * sum_sq / (width_px * width_px)).round() as usize;
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
        let prepared = line_map(&spread, domain)?;
        let mm = self.mm_per_px(domain)?;
        let line = LinePlan {
            width_px,
            width_mm: mm.map(|mm| width_px * mm),
            needed,
            why,
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
            pens: 1,
            radius: (prepared.range.min, prepared.range.max),
            dot: self.dot_mode(),
            local_spacing: false,
            relax,
            spread: false,
            corrected,
            why: if corrected {
                "the line is corrected by rendering it".into()
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
            layer_order: None,
            chosen: None,
            seconds: 0.0,
            memory_mb: crate::importance::budget::peak_mb(size, domain, false),
            style: Style::Line,
            line: Some(line),
        };
        let plan = Plan {
            seconds: plan.estimate(),
            ..plan
        };
        Ok(Planned {
            plan,
            job: self.clone(),
            maps: Maps::Grey(prepared),
            grid: None,
            line: Some(LineSetup { darkness, spread }),
        })
    }

    /// 1 − the adjusted display grey of `map` at each pixel of `domain`.
    fn darkness(&self, map: &ImportanceMap, domain: (u32, u32)) -> crate::Result<Vec<f32>> {
        let prepared = self.importance.prepare_map_on(
            map,
            |_, _| domain,
            Mapping::Linear,
            true,
            self.paper_levels(),
        )?;
        use rayon::prelude::*;
        Ok((0..domain.0 as usize * domain.1 as usize)
            .into_par_iter()
            .map(|i| (1.0 - prepared.value_index(i)).clamp(0.0, 1.0))
            .collect())
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

/// The run of a line drawing's plan: sample → relax → order → correct.
pub(crate) fn run_line(
    planned: Planned,
    setup: LineSetup,
    mut sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
    mut progress: impl FnMut(Step) -> bool,
) -> crate::Result<Stipple> {
    let Planned {
        plan, job, maps, ..
    } = planned;
    let Maps::Grey(map) = maps else {
        return Err(crate::stipple::Error::InvalidParameter("a line draws one pen".into()).into());
    };
    let line = plan.line.clone().ok_or_else(|| {
        crate::stipple::Error::InvalidParameter("a line drawing without its plan".into())
    })?;
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
    let fitted = count::sample_map(&map, &base, plan.points, &mut sample)?;
    let range = fitted.range;
    let mut set = fitted.set;
    let points = along_curve(std::mem::take(&mut set.points));
    set = set.with_points(points);
    let t_sample = lap();
    stage(&mut progress, Stage::Relax)?;
    let mut points = relaxed(
        &job,
        &map,
        range,
        set.points.clone(),
        plan.relax,
        &mut progress,
    )?;
    let t_relax = lap();
    stage(&mut progress, Stage::Order)?;
    let mut tour = toured(&points, &mut progress);
    let t_order = lap();
    stage(&mut progress, Stage::Size)?;
    if plan.corrected && points.len() > 2 {
        stage(&mut progress, Stage::Correct { round: 1, of: 1 })?;
        let ordered: Vec<Point> = tour.order.iter().map(|&i| points[i]).collect();
        let spread = correct(&setup, domain, &ordered, line.width_px);
        let corrected = line_map(&spread, domain)?;
        points = relaxed(
            &job,
            &corrected,
            range,
            ordered,
            CORRECT_RELAX,
            &mut progress,
        )?;
        tour = toured(&points, &mut progress);
    }
    let t_size = lap();
    let ordered: Vec<Point> = tour.order.iter().map(|&i| points[i]).collect();
    let stroke = Stroke {
        points: ordered.iter().map(|p| [p.x, p.y]).collect(),
        width: line.width_px as f32,
        smooth: job.line_smooth,
    };
    Ok(Stipple {
        dots: Vec::new(),
        calibrated: vec![(line.width_px / 2.0) as f32; ordered.len()],
        points: ordered,
        strokes: vec![stroke],
        set,
        domain,
        range,
        runs: fitted.runs,
        short_of: fitted.short_of,
        tour: Some(tour),
        stages: vec![
            (Stage::Prepare, 0.0),
            (Stage::Sample, t_sample),
            (Stage::Relax, t_relax),
            (Stage::Order, t_order),
            (Stage::Size, t_size),
        ],
        plan,
        pens: None,
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
    let (w, h) = map.domain();
    let spacing = f64::from(w) * f64::from(h) / points.len() as f64;
    let options = relax::RelaxOptions {
        iterations: steps,
        periodic: job.sampler.periodic,
        cells: relax::Cells::Polygons {
            edge: spacing.sqrt() as f32,
        },
        over: relax::OVER_RELAX,
    };
    Ok(crate::stipple::relax_points(
        std::slice::from_ref(map),
        range,
        &points,
        options,
        &mut |done| match done {
            Some(n) => progress(Step::Relaxed(n, steps)),
            None => progress(Step::Busy(Stage::Relax)),
        },
    )?)
}

/// The tour through `points`, without self-crossings.
fn toured(points: &[Point], progress: &mut impl FnMut(Step) -> bool) -> tsp::Tour {
    let xy: Vec<[f64; 2]> = points
        .iter()
        .map(|p| [f64::from(p.x), f64::from(p.y)])
        .collect();
    let mut tour = tsp::plan_until(&xy, tsp::TspOptions::default(), &mut || {
        !progress(Step::Busy(Stage::Order))
    });
    tsp::uncross(&xy, &mut tour.order);
    tour.length = tsp::path_length(&xy, &tour.order);
    tour
}

/// The darkness to spread the points for, corrected by rendering the line
/// through `ordered` `width` px wide on `domain`: each pixel's spread
/// times the blurred picture's darkness over the blurred line's ink
/// (within ½..2, at most [`MAX_SPREAD`]).
fn correct(setup: &LineSetup, domain: (u32, u32), ordered: &[Point], width: f64) -> Vec<f32> {
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
