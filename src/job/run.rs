//! The one staged run of every drawing, grey or colour: prepare (one map
//! per pen; a grey drawing is one pen; [`Job::plan`]) → sample → relax →
//! order → size ([`Planned::run`], which executes the plan and decides
//! nothing).
//! The CLI, the app and the Python package all call [`Job::draw`] (through
//! [`Job::run`] for a file).

use std::borrow::Cow;
use std::path::Path;

use super::correct;
use super::plan::{Maps, Plan, Planned};
use super::{Job, Order, count};
use crate::colour::PenSet;
use crate::importance::{Classes, ColourMap, Crop, ImportanceMap, Prepared, RadiusRange};
use crate::sampler::{Params, Point, SampleSet};
use crate::stipple::{Dot, Stroke, relax, tsp};

/// A picture to draw, in memory: grey, colour, or both (the app keeps
/// both). A grey job draws the grey (a colour picture's luminance when
/// only colour is given); a colour job the colour (a grey picture's grey
/// as colour when only grey is given).
#[derive(Clone, Copy, Debug)]
pub enum Picture<'a> {
    /// A grey picture.
    Grey(&'a ImportanceMap),
    /// A colour picture.
    Colour(&'a ColourMap),
    /// The same picture loaded both ways.
    Both(&'a ImportanceMap, &'a ColourMap),
}

/// A picture decoded as a job draws it: grey, or colour for a colour job
/// (every front end loads pictures through it).
#[derive(Clone, Debug)]
pub enum Decoded {
    /// A grey picture.
    Grey(ImportanceMap),
    /// A colour picture.
    Colour(ColourMap),
}

impl Decoded {
    /// The picture file at `path`, decoded for `job`.
    pub fn open(job: &Job, path: &Path) -> crate::Result<Self> {
        let hdr = job.importance.hdr_white;
        Ok(if job.colour() {
            Self::Colour(ColourMap::open(path, hdr)?)
        } else {
            Self::Grey(ImportanceMap::open(path, hdr)?)
        })
    }

    /// The encoded picture `bytes` (any format the files take; `name` for
    /// the messages), decoded for `job`.
    pub fn decode(job: &Job, bytes: &[u8], name: &Path) -> crate::Result<Self> {
        let hdr = job.importance.hdr_white;
        Ok(if job.colour() {
            Self::Colour(ColourMap::from_encoded(bytes, name, hdr)?)
        } else {
            Self::Grey(ImportanceMap::from_encoded(bytes, name, hdr)?)
        })
    }

    /// The picture, borrowed.
    #[must_use]
    pub fn picture(&self) -> Picture<'_> {
        match self {
            Self::Grey(m) => Picture::Grey(m),
            Self::Colour(c) => Picture::Colour(c),
        }
    }
}

/// A picture framed (cropped and turned) for a job, owned.
pub(crate) enum Framed {
    Grey(ImportanceMap),
    Colour(ColourMap),
    Both(ImportanceMap, ColourMap),
}

impl Framed {
    pub(crate) fn picture(&self) -> Picture<'_> {
        match self {
            Self::Grey(m) => Picture::Grey(m),
            Self::Colour(c) => Picture::Colour(c),
            Self::Both(m, c) => Picture::Both(m, c),
        }
    }
}

impl Job {
    /// `picture` cropped and turned as this job asks (`crop`, `rotate`):
    /// what every stage sees, the pen choice as the drawing. `None` when
    /// the picture is drawn as it is.
    pub(crate) fn frame(&self, picture: Picture<'_>) -> crate::Result<Option<Framed>> {
        Ok(match (self.crop, self.rotate) {
            (None, None) => None,
            (crop, turn) => Some(picture.framed(crop, turn.unwrap_or(0))?),
        })
    }
}

impl<'a> Picture<'a> {
    /// The picture cropped to `crop` and turned `degrees` clockwise.
    pub(crate) fn framed(self, crop: Option<Crop>, degrees: u16) -> crate::Result<Framed> {
        Ok(match self {
            Self::Grey(m) => Framed::Grey(m.framed(crop, degrees)?),
            Self::Colour(c) => Framed::Colour(c.framed(crop, degrees)?),
            Self::Both(m, c) => Framed::Both(m.framed(crop, degrees)?, c.framed(crop, degrees)?),
        })
    }

    /// The grey picture.
    pub(crate) fn grey(self) -> Cow<'a, ImportanceMap> {
        match self {
            Self::Grey(m) | Self::Both(m, _) => Cow::Borrowed(m),
            Self::Colour(c) => Cow::Owned(c.luminance()),
        }
    }

    /// The colour picture.
    pub(crate) fn colour(self) -> Cow<'a, ColourMap> {
        match self {
            Self::Colour(c) | Self::Both(_, c) => Cow::Borrowed(c),
            Self::Grey(m) => Cow::Owned(m.colours()),
        }
    }
}

/// A finished drawing: its dots in drawing order, and how it was made.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Stipple {
    /// The dots, in drawing order (none in a line drawing).
    pub dots: Vec<Dot>,
    /// The strokes of a line drawing (`--style line`): stroke k is pen k's
    /// line, in the pens' order (the layers and the writers rely on it);
    /// none in a drawing of dots.
    pub strokes: Vec<Stroke>,
    /// The sample points under the dots, in drawing order.
    pub points: Vec<Point>,
    /// Each point's calibrated dot radius (its tone's), in drawing order:
    /// what [`Job::dots`] scales.
    pub calibrated: Vec<f32>,
    /// The sampler's run (its points after the white cutoff and relaxation,
    /// along a Hilbert curve: `job::plan`).
    pub set: SampleSet,
    /// The domain in pixels.
    pub domain: (u32, u32),
    /// The sample radius range used.
    pub range: RadiusRange,
    /// Sampler runs made to reach the dot count.
    pub runs: usize,
    /// The count asked for, when the domain could not hold it at radii of
    /// at least 1 px.
    pub short_of: Option<usize>,
    /// The pen-plotter tour, with `Order::Tsp`.
    pub tour: Option<tsp::Tour>,
    /// Seconds in each stage of [`Job::draw`], in order: prepare (with
    /// the picture's loading by [`Job::run`]), sample, relax, order and
    /// size.
    pub stages: Vec<(Stage, f64)>,
    /// The plan the drawing was made by.
    pub plan: super::Plan,
    /// The pens of a colour drawing (each point's class is its pen).
    pub pens: Option<PenSet>,
}

impl Stipple {
    /// The seconds of `stage` (0 when it did not run).
    #[must_use]
    pub fn seconds(&self, stage: Stage) -> f64 {
        self.stages
            .iter()
            .find(|(s, _)| *s == stage)
            .map_or(0.0, |(_, t)| *t)
    }
}

impl Job {
    /// Draws `image` (a file) with `sample` running the sampler; `progress`
    /// hears each stage begin and each relaxation step done, and returns
    /// false to stop.
    pub fn run(
        &self,
        image: &Path,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        progress: impl FnMut(Step) -> bool,
    ) -> crate::Result<Stipple> {
        let t0 = std::time::Instant::now();
        let picture = Decoded::open(self, image)?;
        let opened = t0.elapsed().as_secs_f64();
        let mut drawing = self.draw(picture.picture(), sample, progress)?;
        drawing.stages[0].1 += opened;
        Ok(drawing)
    }

    /// [`Self::draw`] of a grey picture.
    pub fn run_map(
        &self,
        map: &ImportanceMap,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        progress: impl FnMut(Step) -> bool,
    ) -> crate::Result<Stipple> {
        self.draw(Picture::Grey(map), sample, progress)
    }

    /// The one staged run of every drawing, grey or colour, of a picture in
    /// memory (borrowed: the app keeps its picture across jobs): the plan
    /// ([`Self::plan`], the prepare stage) and its run ([`Planned::run`]).
    /// `sample` runs the sampler; `progress` hears each stage begin
    /// ([`Step::Stage`], within the long ones each part) and each
    /// relaxation step done, and returns false to stop (a stage: the run
    /// ends as cancelled; relaxation: it stops where it is).
    pub fn draw(
        &self,
        picture: Picture<'_>,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        mut progress: impl FnMut(Step) -> bool,
    ) -> crate::Result<Stipple> {
        let t0 = std::time::Instant::now();
        stage(&mut progress, Stage::Prepare)?;
        let planned = self.plan(picture)?;
        let prepared = t0.elapsed().as_secs_f64();
        let mut drawing = planned.run(sample, progress)?;
        drawing.stages[0].1 += prepared;
        Ok(drawing)
    }
    /// The order stage: the points pen by pen in the pens' order, each
    /// pen's along a Hilbert curve (the drawing's own order) or, with
    /// `--order tsp`, along its own tour (the tours joined, pen after pen).
    /// `stop` is asked every few milliseconds of a tour whether to end it
    /// early (a shorter-worked tour of every dot).
    pub(crate) fn ordered(
        &self,
        points: &[Point],
        pens: usize,
        stop: &mut dyn FnMut() -> bool,
    ) -> (Vec<Point>, Option<tsp::Tour>) {
        let mut by_pen: Vec<Vec<Point>> = vec![Vec::new(); pens.max(1)];
        for p in points {
            if let Some(pen) = by_pen.get_mut(p.class as usize) {
                pen.push(*p);
            }
        }
        if self.order == Order::None {
            return (by_pen.concat(), None);
        }
        let mut all = tsp::Tour {
            order: Vec::with_capacity(points.len()),
            start_length: 0.0,
            length: 0.0,
            moves: 0,
        };
        let mut ordered = Vec::with_capacity(points.len());
        for pen_points in by_pen {
            let xy: Vec<[f64; 2]> = pen_points
                .iter()
                .map(|p| [f64::from(p.x), f64::from(p.y)])
                .collect();
            let t = tsp::plan_until(&xy, tsp::TspOptions::default(), stop);
            let base = ordered.len();
            ordered.extend(t.order.iter().map(|&i| pen_points[i]));
            all.order.extend(t.order.iter().map(|&i| base + i));
            all.start_length += t.start_length;
            all.length += t.length;
            all.moves += t.moves;
        }
        (ordered, Some(all))
    }
}

/// A stage of a drawing's run, as [`Step::Stage`] reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Stage {
    /// The plan: the picture framed, separated (colour) and prepared.
    Prepare,
    /// The sampler's runs, fitting the count.
    Sample,
    /// Weighted Lloyd relaxation.
    Relax,
    /// The drawing order.
    Order,
    /// The dots' sizes.
    Size,
    /// Within a colour drawing's sizing: the pens' calibration.
    Calibrate,
    /// Within the sizing: a round of the correction by rendering.
    Correct {
        /// This round, from 1.
        round: u8,
        /// Of how many.
        of: u8,
    },
}

impl Stage {
    /// Whether the stage is the sizing or a part of it.
    #[must_use]
    pub fn sizing(self) -> bool {
        matches!(self, Self::Size | Self::Calibrate | Self::Correct { .. })
    }
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Prepare => f.write_str("prepare"),
            Self::Sample => f.write_str("sample"),
            Self::Relax => f.write_str("relax"),
            Self::Order => f.write_str("order"),
            Self::Size => f.write_str("size"),
            Self::Calibrate => f.write_str("size: calibration"),
            Self::Correct { round, of } => write!(f, "size: correction {round} of {of}"),
        }
    }
}

/// What a drawing's run reports as it goes ([`Job::draw`]'s `progress`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Step {
    /// A stage begins.
    Stage(Stage),
    /// Relaxation steps done so far, of how many.
    Relaxed(u32, u32),
    /// Still at work in a stage: said every few milliseconds of the long
    /// loops (the tour, within a relaxation step), so that a false answer
    /// stops them in time.
    Busy(Stage),
}

/// Reports `stage`; an `Err` (cancelled) when `progress` says stop.
pub(crate) fn stage(progress: &mut impl FnMut(Step) -> bool, stage: Stage) -> crate::Result<()> {
    if progress(Step::Stage(stage)) {
        Ok(())
    } else {
        Err(crate::sampler::Error::Cancelled.into())
    }
}

/// A correction's set-up, made from the maps and the grid alone.
enum Setup<'a> {
    Grey(correct::GreyCorrection<'a>),
    Colour(correct::ColourCorrection),
}

impl<'a> Setup<'a> {
    fn new(maps: &'a Maps, grid: correct::Grid) -> crate::Result<Self> {
        Ok(match maps {
            Maps::Grey(map) => Self::Grey(correct::GreyCorrection::new(grid, map)),
            Maps::Colour(s) => Self::Colour(correct::ColourCorrection::new(
                &s.picture,
                &s.separation,
                grid,
            )?),
            Maps::Lines(_) => return Err(not_dots()),
        })
    }
}

/// The error of a line drawing's maps in the dots' run (which
/// [`Planned::run`] hands to the line's own).
fn not_dots() -> crate::Error {
    crate::stipple::Error::InvalidParameter("a line drawing is drawn by its own run".into()).into()
}

/// The relaxation stage of [`Planned::run`]: `plan.relax` weighted Lloyd
/// steps of `set`'s points on the maps `all` (none when it is 0).
fn relax_stage(
    job: &Job,
    plan: &Plan,
    all: &[Prepared],
    range: crate::importance::RadiusRange,
    set: &mut SampleSet,
    progress: &mut impl FnMut(Step) -> bool,
) -> crate::Result<()> {
    if plan.relax == 0 {
        return Ok(());
    }
    stage(progress, Stage::Relax)?;
    let moved = relaxed_points(
        job,
        all,
        range,
        plan.domain,
        &set.points,
        plan.relax,
        progress,
    )?;
    *set = std::mem::take(set).with_points(moved);
    Ok(())
}

/// `points` on `domain` after `steps` weighted Lloyd steps on `maps` (one
/// map, or one per pen), each step reported. The one relaxation of dots
/// and lines.
pub(crate) fn relaxed_points(
    job: &Job,
    maps: &[Prepared],
    range: crate::importance::RadiusRange,
    domain: (u32, u32),
    points: &[Point],
    steps: u32,
    progress: &mut impl FnMut(Step) -> bool,
) -> crate::Result<Vec<Point>> {
    // Cells as polygons, integrated at the mean spacing: as good as pixel
    // cells (docs/drawing.md) at a cost that follows the dots; a periodic
    // domain takes pixel cells.
    let spacing = f64::from(domain.0) * f64::from(domain.1) / points.len().max(1) as f64;
    let options = relax::RelaxOptions {
        iterations: steps,
        periodic: job.sampler.periodic,
        cells: relax::Cells::Polygons {
            edge: spacing.sqrt() as f32,
        },
        over: relax::OVER_RELAX,
    };
    Ok(crate::stipple::relax_points(
        maps,
        range,
        points,
        options,
        &mut |done| match done {
            Some(n) => progress(Step::Relaxed(n, steps)),
            None => progress(Step::Busy(Stage::Relax)),
        },
    )?)
}

/// `points` along a Hilbert curve through their pixels (ties, points in
/// one pixel, in the sampler's order): neighbours on the paper are then
/// neighbours in memory. The drawing's passes over its dots read the
/// domain's maps and the correction's grids at the dots' places, so in the
/// sampler's order (scattered) they wait on memory: at 100K and 200K dots
/// the relaxation took about 0.9× and the size stage 0.75× the time in
/// this order. Unordered drawings are plotted along the curve, too: a
/// shorter path than the sampler's order.
pub(crate) fn along_curve(points: Vec<Point>) -> Vec<Point> {
    use rayon::prelude::*;
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (crate::stipple::spatial::pixel_key(p.x, p.y, 0), i as u32))
        .collect();
    keyed.par_sort_unstable();
    keyed
        .into_par_iter()
        .map(|(_, i)| points[i as usize])
        .collect()
}

impl Planned {
    /// Runs the plan: sample → relax → order → size, deciding nothing.
    /// `sample` runs the sampler; `progress` hears each stage begin and
    /// each relaxation step done, and returns false to stop.
    pub fn run(
        self,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        mut progress: impl FnMut(Step) -> bool,
    ) -> crate::Result<Stipple> {
        let mut planned = self;
        if let Some(setup) = planned.line.take() {
            return super::line::run_line(planned, setup, sample, progress);
        }
        let Self {
            plan,
            job,
            maps,
            grid,
            ..
        } = planned;
        // Each stage's seconds, read as the next one begins.
        let mut last = std::time::Instant::now();
        let mut lap = || {
            let now = std::time::Instant::now();
            let seconds = (now - last).as_secs_f64();
            last = now;
            seconds
        };
        let all = maps.all();
        let domain = plan.domain;
        stage(&mut progress, Stage::Sample)?;
        let base = job
            .sampler
            .apply(Params::new(domain.0, domain.1).with_policy(job.policy));
        let fitted = match &maps {
            Maps::Colour(_) => {
                let classes = Classes { maps: all };
                count::sample_union(&classes, &base, plan.points, plan.spread, sample)?
            }
            Maps::Grey(map) => count::sample_map(map, &base, plan.points, sample)?,
            Maps::Lines(_) => return Err(not_dots()),
        };
        let (mut set, range) = (fitted.set, fitted.range);
        // Along a Hilbert curve from here on: every later pass over the
        // dots (the Lloyd steps, the correction's renders and updates, the
        // sizes) then reads the maps near where it last read them.
        let points = along_curve(std::mem::take(&mut set.points));
        set = set.with_points(points);
        let t_sample = lap();
        // The correction's set-up needs the maps and the grid, no dot: it
        // is made while the dots are relaxed, as a task beside the
        // relaxation's (the same values either way).
        let count = set.points.len();
        let mut setup = None;
        rayon::in_place_scope(|scope| -> crate::Result<()> {
            if let Some(g) = grid {
                let (maps, setup) = (&maps, &mut setup);
                scope.spawn(move |_| *setup = Some(Setup::new(maps, g.grid(domain, count))));
            }
            self::relax_stage(&job, &plan, all, range, &mut set, &mut progress)
        })?;
        let t_relax = lap();
        stage(&mut progress, Stage::Order)?;
        let (points, tour) = job.ordered(&set.points, all.len(), &mut || {
            !progress(Step::Busy(Stage::Order))
        });
        let t_order = lap();
        stage(&mut progress, Stage::Size)?;
        // Ordering keeps every dot; were one dropped, the grid would follow
        // the count and the set-up be made again.
        let setup = match (grid, setup) {
            (Some(_), Some(made)) if points.len() == count => Some(made?),
            (Some(g), _) => Some(Setup::new(&maps, g.grid(domain, points.len()))?),
            (None, _) => None,
        };
        let mut report = |s| stage(&mut progress, s);
        let calibrated = match &maps {
            Maps::Colour(s) => {
                let correction = match &setup {
                    Some(Setup::Colour(c)) => Some(c),
                    _ => None,
                };
                job.colour_sizes(s, &points, range, correction, &mut report)?
            }
            Maps::Lines(_) => return Err(not_dots()),
            Maps::Grey(map) => {
                let mut radii = map.dot_radii(&points, range);
                // Sized dots for the spacing they have ([`Spacing::Local`]).
                if plan.local_spacing {
                    super::density::local_spacing(map, &points, range, domain, &mut radii);
                }
                if let Some(Setup::Grey(correction)) = &setup {
                    let limits = (
                        map.mapping.dot_radius(1.0, range),
                        map.mapping.dot_radius(0.0, range),
                    );
                    correction.apply(&points, range, &mut radii, limits, &mut report)?;
                }
                radii
            }
        };
        let t_size = lap();
        let mut drawing = Stipple {
            dots: Vec::new(),
            strokes: Vec::new(),
            points,
            calibrated,
            set,
            domain,
            range,
            runs: fitted.runs,
            short_of: fitted.short_of,
            tour,
            stages: vec![
                (Stage::Prepare, 0.0),
                (Stage::Sample, t_sample),
                (Stage::Relax, t_relax),
                (Stage::Order, t_order),
                (Stage::Size, t_size),
            ],
            pens: matches!(maps, Maps::Colour(_))
                .then(|| job.pens.clone())
                .flatten(),
            plan,
        };
        drawing.dots = job.dots(&drawing);
        Ok(drawing)
    }
}
