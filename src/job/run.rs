//! The one staged run of every drawing, grey or colour: prepare (one map
//! per pen; a grey drawing is one pen) → sample → relax → order → size.
//! The CLI, the app and the Python package all call [`Job::draw`] (through
//! [`Job::run`] for a file).

use std::borrow::Cow;
use std::path::Path;

use super::{Job, Order, count};
use crate::colour::PenSet;
use crate::importance::{Classes, ColourMap, Crop, ImportanceMap, Prepared, RadiusRange};
use crate::sampler::{Params, Point, SampleSet};
use crate::stipple::{Dot, relax, tsp};

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

/// A picture framed (cropped and turned) for a job, owned.
enum Framed {
    Grey(ImportanceMap),
    Colour(ColourMap),
    Both(ImportanceMap, ColourMap),
}

impl Framed {
    fn picture(&self) -> Picture<'_> {
        match self {
            Self::Grey(m) => Picture::Grey(m),
            Self::Colour(c) => Picture::Colour(c),
            Self::Both(m, c) => Picture::Both(m, c),
        }
    }
}

impl<'a> Picture<'a> {
    /// The picture cropped to `crop` and turned `degrees` clockwise.
    fn framed(self, crop: Option<Crop>, degrees: u16) -> crate::Result<Framed> {
        Ok(match self {
            Self::Grey(m) => Framed::Grey(m.framed(crop, degrees)?),
            Self::Colour(c) => Framed::Colour(c.framed(crop, degrees)?),
            Self::Both(m, c) => Framed::Both(m.framed(crop, degrees)?, c.framed(crop, degrees)?),
        })
    }

    /// The grey picture.
    fn grey(self) -> Cow<'a, ImportanceMap> {
        match self {
            Self::Grey(m) | Self::Both(m, _) => Cow::Borrowed(m),
            Self::Colour(c) => Cow::Owned(c.luminance()),
        }
    }

    /// The colour picture.
    fn colour(self) -> Cow<'a, ColourMap> {
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
    /// The dots, in drawing order.
    pub dots: Vec<Dot>,
    /// The sample points under the dots, in drawing order.
    pub points: Vec<Point>,
    /// Each point's calibrated dot radius (its tone's), in drawing order:
    /// what [`Job::dots`] scales.
    pub calibrated: Vec<f32>,
    /// The sampler's run (its points after the white cutoff and relaxation,
    /// in acceptance order).
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
    /// Seconds spent loading, sampling and relaxing.
    pub seconds: (f64, f64, f64),
    /// Seconds in each stage of [`Job::draw`], in order: prepare (the
    /// picture's loading not included), sample, relax, order and size.
    pub stages: Vec<(&'static str, f64)>,
    /// The pens of a colour drawing (each point's class is its pen).
    pub pens: Option<PenSet>,
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
        let (grey, colour);
        let picture = if self.colour() {
            colour = ColourMap::open(image, self.importance.hdr_white)?;
            Picture::Colour(&colour)
        } else {
            grey = ImportanceMap::open(image, self.importance.hdr_white)?;
            Picture::Grey(&grey)
        };
        let opened = t0.elapsed().as_secs_f64();
        let mut drawing = self.draw(picture, sample, progress)?;
        drawing.seconds.0 += opened;
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
    /// memory (borrowed: the app keeps its picture across jobs): prepare
    /// (one map per pen; a grey drawing is one pen) → sample → relax →
    /// order → size. The writers are [`Self::write`]. `sample` runs the
    /// sampler; `progress` hears each stage begin ([`Step::Stage`], within
    /// the long ones each part) and each relaxation step done, and returns
    /// false to stop (a stage: the run ends as cancelled; relaxation: it
    /// stops where it is).
    pub fn draw(
        &self,
        picture: Picture<'_>,
        sample: impl FnMut(&Params) -> crate::Result<SampleSet>,
        mut progress: impl FnMut(Step) -> bool,
    ) -> crate::Result<Stipple> {
        // Each stage's seconds, read as the next one begins.
        let mut last = std::time::Instant::now();
        let mut lap = || {
            let now = std::time::Instant::now();
            let seconds = (now - last).as_secs_f64();
            last = now;
            seconds
        };
        self.check()?;
        let (points, count_target) = self.count();
        stage(&mut progress, "prepare")?;
        // The crop and the turn, first: the rest sees the framed picture.
        let framed = match (self.crop, self.rotate) {
            (None, None) => None,
            (crop, turn) => Some(picture.framed(crop, turn.unwrap_or(0))?),
        };
        let picture = framed.as_ref().map_or(picture, Framed::picture);
        let (separated, grey) = if self.colour() {
            let colour = picture.colour();
            let domain = self.domain_for((colour.width(), colour.height()), points);
            (Some(self.separate(&colour, domain, count_target)?), None)
        } else {
            let map = picture.grey();
            let mut prepared = self.importance.prepare_map(
                &map,
                |w, h| self.domain_for((w, h), points),
                self.dot_mode().mapping(self.dot_ratio),
                count_target,
            )?;
            let domain = prepared.domain();
            prepared.range = self.dot_range(prepared.range, domain)?;
            (None, Some(prepared))
        };
        let maps: &[Prepared] = match (&separated, &grey) {
            (Some(s), _) => &s.maps,
            (None, Some(g)) => std::slice::from_ref(g),
            (None, None) => unreachable!("a drawing prepares a grey or a colour picture"),
        };
        let domain = maps[0].domain();
        let t_load = lap();
        stage(&mut progress, "sample")?;
        let base = self
            .sampler
            .apply(Params::new(domain.0, domain.1).with_policy(self.policy));
        let fitted = if separated.is_some() {
            count::sample_union(&Classes { maps }, &base, points, sample)?
        } else {
            count::sample_map(&maps[0], &base, points, sample)?
        };
        let (mut set, range) = (fitted.set, fitted.range);
        let t_sample = lap();
        let steps = self.relax_steps(set.points.len());
        if steps > 0 {
            stage(&mut progress, "relax")?;
            let options = relax::RelaxOptions {
                iterations: steps,
                periodic: self.sampler.periodic,
            };
            let moved = crate::stipple::relax_points(maps, range, &set.points, options, |n| {
                progress(Step::Relaxed(n, steps))
            })?;
            set = set.with_points(moved);
        }
        let t_relax = lap();
        stage(&mut progress, "order")?;
        let (points, tour) = self.ordered(&set.points, maps.len());
        let t_order = lap();
        stage(&mut progress, "size")?;
        let calibrated = match &separated {
            Some(s) => self.colour_sizes(s, &points, range, domain, &mut |name| {
                stage(&mut progress, name)
            })?,
            None => {
                let mut radii = maps[0].dot_radii(&points, range);
                // Sized dots for the spacing they have ([`Spacing::Local`]).
                if self.spacing == super::Spacing::Local
                    && matches!(maps[0].mapping, crate::importance::Mapping::ToneSized(_))
                {
                    super::density::local_spacing(&maps[0], &points, range, domain, &mut radii);
                }
                // Corrected toward the map's tones by rendering (sized
                // dots on a tone mapping, [`Job::corrected`]).
                if self.corrected() {
                    let limits = (
                        maps[0].mapping.dot_radius(1.0, range),
                        maps[0].mapping.dot_radius(0.0, range),
                    );
                    super::correct::correct_grey(
                        &maps[0],
                        &points,
                        range,
                        &mut radii,
                        limits,
                        &mut |name| stage(&mut progress, name),
                    )?;
                }
                radii
            }
        };
        let t_size = lap();
        let mut drawing = Stipple {
            dots: Vec::new(),
            points,
            calibrated,
            set,
            domain,
            range,
            runs: fitted.runs,
            short_of: fitted.short_of,
            tour,
            seconds: (t_load, t_sample, t_relax),
            stages: vec![
                ("prepare", t_load),
                ("sample", t_sample),
                ("relax", t_relax),
                ("order", t_order),
                ("size", t_size),
            ],
            pens: separated.and(self.pens.clone()),
        };
        drawing.dots = self.dots(&drawing);
        Ok(drawing)
    }

    /// The order stage: the points pen by pen in the pens' order, each
    /// pen's in the sampler's order or, with `--order tsp`, along its own
    /// tour (the tours joined, pen after pen).
    fn ordered(&self, points: &[Point], pens: usize) -> (Vec<Point>, Option<tsp::Tour>) {
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
            nearest_neighbour_length: 0.0,
            length: 0.0,
            moves: 0,
        };
        let mut ordered = Vec::with_capacity(points.len());
        for pen_points in by_pen {
            let xy: Vec<[f64; 2]> = pen_points
                .iter()
                .map(|p| [f64::from(p.x), f64::from(p.y)])
                .collect();
            let t = tsp::plan(&xy, tsp::TspOptions::default());
            let base = ordered.len();
            ordered.extend(t.order.iter().map(|&i| pen_points[i]));
            all.order.extend(t.order.iter().map(|&i| base + i));
            all.nearest_neighbour_length += t.nearest_neighbour_length;
            all.length += t.length;
            all.moves += t.moves;
        }
        (ordered, Some(all))
    }
}

/// What a drawing's run reports as it goes ([`Job::draw`]'s `progress`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Step {
    /// A stage begins: `prepare`, `sample`, `relax`, `order` or `size`, and
    /// within a colour drawing's sizing each part (`size: calibration`, `size:
    /// correction 1 of 3`, …), so that long work reports at least once a
    /// second.
    Stage(&'static str),
    /// Relaxation steps done so far, of how many.
    Relaxed(u32, u32),
}

/// Reports stage `name`; an `Err` (cancelled) when `progress` says stop.
fn stage(progress: &mut impl FnMut(Step) -> bool, name: &'static str) -> crate::Result<()> {
    if progress(Step::Stage(name)) {
        Ok(())
    } else {
        Err(crate::sampler::Error::Cancelled.into())
    }
}
