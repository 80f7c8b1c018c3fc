//! Plot statistics: what a pen plotter does to draw a pen drawing
//! (`--pen-mm`), pen by pen: its dots, its pen lifts, the distance drawn
//! with the pen down and travelled with it up, and the time an AxiDraw's
//! motion planner takes.
//!
//! Each pen's layer is a plot of its own (a pen change between layers): it
//! starts at the home corner, draws its paths in the drawing's order —
//! each path one travel, one drop, one stroke and one lift — and returns
//! home.
//!
//! Two planners time it ([`Plotter`]): AxiDraw's own software's, the
//! default ([`AxiDraw`], in `plot/axidraw.rs`: 25 ms slices, whole motor
//! steps), and saxi's, below.
//!
//! # saxi's motion model
//!
//! Each stroke and each travel starts and ends at rest. Along it the
//! carriage accelerates and brakes at the profile's constant acceleration
//! up to its top speed (a trapezoidal velocity profile), and passes each
//! corner of a polyline no faster than the junction-deviation limit of
//! grbl's planner (Jeon's "improving grbl's cornering algorithm", 2011):
//! for unit directions `d1`, `d2` meeting at a corner, with
//! `s = √((1 + d1·d2) / 2)` (the sine of half the angle between the
//! reversed first direction and the second),
//! `v ≤ √(a · c · s / (1 − s))` for the profile's cornering factor `c`
//! (mm), and 0 where the path turns back on itself. The speeds at the
//! corners are the largest that a forward and a backward pass allow: from
//! each corner the next can be reached, and the stroke stopped at its end,
//! within the acceleration. The pen takes a fixed time to drop and to lift.
//!
//! saxi's defaults: pen down 200 mm/s² up to 50 mm/s with cornering
//! factor 0.127 mm, pen up 400 mm/s² up to 200 mm/s, 0.12 s to drop and to
//! lift. `docs/plotter.md` compares both estimates with the programs' own.

use super::Error;

mod axidraw;
pub use axidraw::AxiDraw;

/// How the carriage moves with the pen in one position.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    /// Acceleration and braking, mm/s².
    pub acceleration: f64,
    /// Top speed, mm/s.
    pub max_velocity: f64,
    /// Cornering factor (junction deviation), mm: 0 stops at every corner.
    pub cornering: f64,
}

impl Motion {
    /// The seconds to travel a straight `distance` mm from rest to rest.
    #[must_use]
    pub fn straight_s(&self, distance: f64) -> f64 {
        segment_s(distance, 0.0, 0.0, self.acceleration, self.max_velocity)
    }

    /// The seconds to follow the polyline `points` (mm) from rest to rest.
    /// Repeated points are skipped.
    pub fn path_s(&self, points: &[(f64, f64)], scratch: &mut Scratch) -> f64 {
        let (a, top) = (self.acceleration, self.max_velocity);
        // Segments of non-zero length: (length, unit direction).
        let Scratch { segs, speeds } = scratch;
        segs.clear();
        let mut at = match points.first() {
            Some(&p) => p,
            None => return 0.0,
        };
        for &p in &points[1..] {
            let (dx, dy) = (p.0 - at.0, p.1 - at.1);
            let len = (dx * dx + dy * dy).sqrt();
            if len > EPSILON_MM {
                segs.push((len, (dx / len, dy / len)));
                at = p;
            }
        }
        if segs.is_empty() {
            return 0.0;
        }
        // speeds[i]: at the start of segment i; speeds[n]: at the end (0).
        let n = segs.len();
        speeds.clear();
        speeds.push(0.0);
        for w in segs.windows(2) {
            speeds.push(self.corner_limit(w[0].1, w[1].1));
        }
        speeds.push(0.0);
        // Backward: each corner slow enough to brake to the next in time.
        for i in (0..n).rev() {
            let reach = (speeds[i + 1] * speeds[i + 1] + 2.0 * a * segs[i].0).sqrt();
            speeds[i] = speeds[i].min(reach);
        }
        // Forward: each corner no faster than accelerating from the last.
        for i in 0..n {
            let reach = (speeds[i] * speeds[i] + 2.0 * a * segs[i].0).sqrt();
            speeds[i + 1] = speeds[i + 1].min(reach);
        }
        segs.iter()
            .enumerate()
            .map(|(i, s)| segment_s(s.0, speeds[i], speeds[i + 1], a, top))
            .sum()
    }

    /// The fastest speed through a corner from direction `d1` to `d2`.
    fn corner_limit(&self, d1: (f64, f64), d2: (f64, f64)) -> f64 {
        // cos of the angle between the reversed first direction and the
        // second: 1 where the path turns back, -1 where it goes straight on.
        let cosine = -(d1.0 * d2.0 + d1.1 * d2.1);
        if (cosine - 1.0).abs() < 1e-9 {
            return 0.0;
        }
        let sine = ((1.0 - cosine) / 2.0).max(0.0).sqrt();
        if (sine - 1.0).abs() < 1e-9 {
            return self.max_velocity;
        }
        (self.acceleration * self.cornering * sine / (1.0 - sine))
            .sqrt()
            .min(self.max_velocity)
    }

    /// Checks that the numbers are finite, the acceleration and top speed
    /// positive and the cornering factor at least 0.
    fn check(&self, what: &str) -> Result<(), String> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !ok(self.acceleration) {
            return Err(format!(
                "{what}_acceleration = {}: expected a number of mm/s² above 0",
                self.acceleration
            ));
        }
        if !ok(self.max_velocity) {
            return Err(format!(
                "{what}_max_velocity = {}: expected a number of mm/s above 0",
                self.max_velocity
            ));
        }
        if !(self.cornering.is_finite() && self.cornering >= 0.0) {
            return Err(format!(
                "{what}_cornering_factor = {}: expected a number of mm, at least 0",
                self.cornering
            ));
        }
        Ok(())
    }
}

/// Working memory of [`Motion::path_s`].
#[derive(Debug, Default)]
pub struct Scratch {
    /// Segments: length and unit direction.
    segs: Vec<(f64, (f64, f64))>,
    /// Speeds at their ends.
    speeds: Vec<f64>,
}

/// Points closer than this (mm) are one point.
const EPSILON_MM: f64 = 1e-9;

/// The seconds to cover `len` from speed `v0` to `v1` (reachable within
/// the acceleration `a`), no faster than `top`.
fn segment_s(len: f64, v0: f64, v1: f64, a: f64, top: f64) -> f64 {
    if len <= 0.0 {
        return 0.0;
    }
    // The peak of accelerating from v0 and braking to v1 over len.
    let peak = ((2.0 * a * len + v0 * v0 + v1 * v1) / 2.0).sqrt();
    if peak <= top {
        ((peak - v0) + (peak - v1)).max(0.0) / a
    } else {
        let up = (top * top - v0 * v0) / (2.0 * a);
        let down = (top * top - v1 * v1) / (2.0 * a);
        (top - v0) / a + (top - v1) / a + (len - up - down) / top
    }
}

/// saxi's motion profile for an AxiDraw: the model above.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Saxi {
    /// Drawing, with the pen down.
    pub pen_down: Motion,
    /// Travel, with the pen up.
    pub pen_up: Motion,
    /// Seconds to drop the pen onto the paper.
    pub pen_drop_s: f64,
    /// Seconds to lift it.
    pub pen_lift_s: f64,
}

impl Default for Saxi {
    /// saxi's defaults.
    fn default() -> Self {
        Self {
            pen_down: Motion {
                acceleration: 200.0,
                max_velocity: 50.0,
                cornering: 0.127,
            },
            pen_up: Motion {
                acceleration: 400.0,
                max_velocity: 200.0,
                cornering: 0.0,
            },
            pen_drop_s: 0.12,
            pen_lift_s: 0.12,
        }
    }
}

impl Saxi {
    /// Checks every number: a one-line message naming the key.
    fn check(&self) -> Result<(), String> {
        let delays = [
            ("pen_drop_duration", self.pen_drop_s),
            ("pen_lift_duration", self.pen_lift_s),
        ];
        self.pen_down
            .check("pen_down")
            .and_then(|()| self.pen_up.check("pen_up"))
            .and_then(
                |()| match delays.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
                    Some((key, v)) => Err(format!("{key} = {v}: expected seconds, at least 0")),
                    None => Ok(()),
                },
            )
    }
}

/// A plotter's motion profile: AxiDraw's own planner (the default, as
/// AxiDraw's software estimates a plot) or saxi's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Plotter {
    /// AxiDraw's planner ([`AxiDraw`]).
    AxiDraw(AxiDraw),
    /// saxi's ([`Saxi`]).
    Saxi(Saxi),
}

impl Default for Plotter {
    fn default() -> Self {
        Self::AxiDraw(AxiDraw::default())
    }
}

/// A plotter profile file's keys, all optional: AxiDraw's option names or
/// saxi's (with underscores), not both; the planner's defaults fill in
/// the rest.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileFile {
    speed_pendown: Option<f64>,
    speed_penup: Option<f64>,
    accel: Option<f64>,
    pen_pos_up: Option<f64>,
    pen_pos_down: Option<f64>,
    pen_rate_lower: Option<f64>,
    pen_rate_raise: Option<f64>,
    pen_delay_down: Option<f64>,
    pen_delay_up: Option<f64>,
    const_speed: Option<bool>,
    model: Option<u8>,
    resolution: Option<u8>,
    pen_down_acceleration: Option<f64>,
    pen_down_max_velocity: Option<f64>,
    pen_down_cornering_factor: Option<f64>,
    pen_up_acceleration: Option<f64>,
    pen_up_max_velocity: Option<f64>,
    pen_drop_duration: Option<f64>,
    pen_lift_duration: Option<f64>,
}

/// A profile file's keys for AxiDraw's planner: its software's option
/// names (speeds and rates in %, delays in ms).
pub const AXIDRAW_KEYS: [&str; 12] = [
    "speed_pendown",
    "speed_penup",
    "accel",
    "pen_pos_up",
    "pen_pos_down",
    "pen_rate_lower",
    "pen_rate_raise",
    "pen_delay_down",
    "pen_delay_up",
    "const_speed",
    "model",
    "resolution",
];

/// A profile file's keys for saxi's planner (mm and s).
pub const PROFILE_KEYS: [&str; 7] = [
    "pen_down_acceleration",
    "pen_down_max_velocity",
    "pen_down_cornering_factor",
    "pen_up_acceleration",
    "pen_up_max_velocity",
    "pen_drop_duration",
    "pen_lift_duration",
];

impl Plotter {
    /// The built-in profiles' names, for `--plotter NAME`.
    pub const NAMES: [&str; 2] = ["axidraw", "saxi"];

    /// The built-in profile `name` (`axidraw` or `saxi`), with its
    /// software's defaults.
    #[must_use]
    pub fn named(name: &str) -> Option<Self> {
        match name {
            "axidraw" => Some(Self::AxiDraw(AxiDraw::default())),
            "saxi" => Some(Self::Saxi(Saxi::default())),
            _ => None,
        }
    }

    /// Checks every number: a one-line message naming the key.
    pub fn check(&self) -> Result<(), Error> {
        match self {
            Self::AxiDraw(a) => a.check(),
            Self::Saxi(s) => s.check(),
        }
        .map_err(Error::Setting)
    }

    /// Sets the top pen-down speed, mm/s (`--plot-speed`).
    pub fn set_pen_down_speed(&mut self, mm_s: f64) {
        match self {
            Self::AxiDraw(a) => a.set_pen_down_mm_s(mm_s),
            Self::Saxi(s) => s.pen_down.max_velocity = mm_s,
        }
    }

    /// Sets the top pen-up speed, mm/s (`--travel-speed`).
    pub fn set_pen_up_speed(&mut self, mm_s: f64) {
        match self {
            Self::AxiDraw(a) => a.set_pen_up_mm_s(mm_s),
            Self::Saxi(s) => s.pen_up.max_velocity = mm_s,
        }
    }

    /// Sets the seconds to drop and to lift the pen, both together, half
    /// each (`--pen-delay`).
    pub fn set_pen_delay(&mut self, seconds: f64) {
        let half = seconds / 2.0;
        match self {
            Self::AxiDraw(a) => a.pen_times_s = Some((half, half)),
            Self::Saxi(s) => (s.pen_drop_s, s.pen_lift_s) = (half, half),
        }
    }

    /// Seconds to drop the pen and to lift it.
    #[must_use]
    pub fn pen_s(&self) -> (f64, f64) {
        match self {
            Self::AxiDraw(a) => a.pen_s(),
            Self::Saxi(s) => (s.pen_drop_s, s.pen_lift_s),
        }
    }

    /// One sentence on how the profile times a plot, its figures in mm
    /// and s.
    #[must_use]
    pub fn describe(&self) -> String {
        let (drop, lift) = self.pen_s();
        match self {
            Self::AxiDraw(a) => {
                let (down, up) = a.accel_mm_s2();
                format!(
                    "How long an AxiDraw takes, as its own software plans it: drawing at {down:.0} \
                     mm/s² up to {:.0} mm/s, slowing for corners; travel at {up:.0} mm/s² up to \
                     {:.0} mm/s; {drop} s to drop and {lift} s to lift the pen",
                    a.pen_down_mm_s(),
                    a.pen_up_mm_s()
                )
            }
            Self::Saxi(s) => format!(
                "How long an AxiDraw takes, as saxi plans it: drawing at {} mm/s² up to {} mm/s, \
                 slowing for corners; travel at {} mm/s² up to {} mm/s; {drop} s to drop and \
                 {lift} s to lift the pen",
                s.pen_down.acceleration,
                s.pen_down.max_velocity,
                s.pen_up.acceleration,
                s.pen_up.max_velocity
            ),
        }
    }

    /// A profile file's text (TOML): AxiDraw's option names
    /// ([`AXIDRAW_KEYS`]) over AxiDraw's defaults, or saxi's
    /// ([`PROFILE_KEYS`], mm and s) over saxi's; an empty file is
    /// AxiDraw's. Errors name the key, and an unknown key lists the known.
    pub fn from_toml(text: &str) -> Result<Self, Error> {
        let file: ProfileFile = toml::from_str(text).map_err(|e| {
            let message = e.message();
            let line = e.span().and_then(|s| {
                let start = text[..s.start.min(text.len())]
                    .rfind('\n')
                    .map_or(0, |i| i + 1);
                text[start..].lines().next().map(str::trim)
            });
            Error::Setting(match (line, crate::text::expected(message)) {
                (Some(line), Some(expected)) if line.contains('=') => {
                    format!("{line}: expected {expected}")
                }
                _ => format!(
                    "{}; the keys are AxiDraw's {} or saxi's {}",
                    crate::text::single_line(message),
                    AXIDRAW_KEYS.join(", "),
                    PROFILE_KEYS.join(", ")
                ),
            })
        })?;
        let saxi_keys = [
            file.pen_down_acceleration,
            file.pen_down_max_velocity,
            file.pen_down_cornering_factor,
            file.pen_up_acceleration,
            file.pen_up_max_velocity,
            file.pen_drop_duration,
            file.pen_lift_duration,
        ];
        let axidraw_keys = [
            file.speed_pendown,
            file.speed_penup,
            file.accel,
            file.pen_pos_up,
            file.pen_pos_down,
            file.pen_rate_lower,
            file.pen_rate_raise,
            file.pen_delay_down,
            file.pen_delay_up,
        ];
        let saxi = saxi_keys.iter().any(Option::is_some);
        let axidraw = axidraw_keys.iter().any(Option::is_some)
            || file.const_speed.is_some()
            || file.model.is_some()
            || file.resolution.is_some();
        if saxi && axidraw {
            return Err(Error::Setting(
                "a plotter profile takes AxiDraw's option names (speed_pendown, accel, …) or \
                 saxi's (pen_down_max_velocity, …), not both"
                    .into(),
            ));
        }
        let p = if saxi {
            let d = Saxi::default();
            Self::Saxi(Saxi {
                pen_down: Motion {
                    acceleration: file
                        .pen_down_acceleration
                        .unwrap_or(d.pen_down.acceleration),
                    max_velocity: file
                        .pen_down_max_velocity
                        .unwrap_or(d.pen_down.max_velocity),
                    cornering: file
                        .pen_down_cornering_factor
                        .unwrap_or(d.pen_down.cornering),
                },
                pen_up: Motion {
                    acceleration: file.pen_up_acceleration.unwrap_or(d.pen_up.acceleration),
                    max_velocity: file.pen_up_max_velocity.unwrap_or(d.pen_up.max_velocity),
                    cornering: d.pen_up.cornering,
                },
                pen_drop_s: file.pen_drop_duration.unwrap_or(d.pen_drop_s),
                pen_lift_s: file.pen_lift_duration.unwrap_or(d.pen_lift_s),
            })
        } else {
            let d = AxiDraw::default();
            Self::AxiDraw(AxiDraw {
                speed_pendown: file.speed_pendown.unwrap_or(d.speed_pendown),
                speed_penup: file.speed_penup.unwrap_or(d.speed_penup),
                accel: file.accel.unwrap_or(d.accel),
                pen_pos_up: file.pen_pos_up.unwrap_or(d.pen_pos_up),
                pen_pos_down: file.pen_pos_down.unwrap_or(d.pen_pos_down),
                pen_rate_lower: file.pen_rate_lower.unwrap_or(d.pen_rate_lower),
                pen_rate_raise: file.pen_rate_raise.unwrap_or(d.pen_rate_raise),
                pen_delay_down: file.pen_delay_down.unwrap_or(d.pen_delay_down),
                pen_delay_up: file.pen_delay_up.unwrap_or(d.pen_delay_up),
                const_speed: file.const_speed.unwrap_or(d.const_speed),
                model: file.model.unwrap_or(d.model),
                resolution: file.resolution.unwrap_or(d.resolution),
                pen_times_s: None,
            })
        };
        p.check()?;
        Ok(p)
    }

    /// `--plotter`'s value: a built-in profile's name ([`Self::NAMES`]) or
    /// a profile file (see [`Self::from_toml`]); errors name the file.
    pub fn from_name_or_file(value: &std::path::Path) -> Result<Self, Error> {
        if let Some(p) = value.to_str().and_then(Self::named) {
            return Ok(p);
        }
        Self::from_file(value)
    }

    /// [`Self::from_toml`] of a file; errors name the file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            Error::Setting(format!(
                "cannot read plotter profile '{}' (not {} either): {e}",
                path.display(),
                Self::NAMES.join(" or ")
            ))
        })?;
        Self::from_toml(&text).map_err(|e| Error::Setting(format!("{}: {e}", path.display())))
    }

    /// Where the plot starts and ends, mm on a sheet of `sheet_mm`: the
    /// sheet's top-left corner, or for AxiDraw's software a portrait
    /// sheet's top-right (it turns the sheet onto the machine).
    fn home(&self, sheet_mm: Option<(f64, f64)>) -> (f64, f64) {
        match (self, sheet_mm) {
            (Self::AxiDraw(_), Some((w, h))) if h > w => (w, 0.0),
            _ => (0.0, 0.0),
        }
    }

    /// Seconds of a pen-up move from `a` to `b` (mm).
    fn travel_s(&self, a: (f64, f64), b: (f64, f64), sheet_mm: Option<(f64, f64)>) -> f64 {
        match self {
            Self::AxiDraw(x) => x.travel_s(x.steps_at(a, sheet_mm), x.steps_at(b, sheet_mm)),
            Self::Saxi(s) => s.pen_up.straight_s((a.0 - b.0).hypot(a.1 - b.1)),
        }
    }

    /// Seconds to draw `path` (mm) with the pen down.
    fn stroke_s(
        &self,
        path: &[(f64, f64)],
        sheet_mm: Option<(f64, f64)>,
        scratch: &mut (Scratch, axidraw::Scratch),
    ) -> f64 {
        match self {
            Self::AxiDraw(x) => x.stroke_s(path, sheet_mm, &mut scratch.1),
            Self::Saxi(s) => s.pen_down.path_s(path, &mut scratch.0),
        }
    }
}

/// One pen's plot.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PenPlot {
    /// The pen's name (`ink` for a one-ink drawing).
    pub pen: String,
    /// Dots.
    pub dots: usize,
    /// Pen lifts: one per path.
    pub lifts: usize,
    /// Distance drawn with the pen down, mm.
    pub pen_down_mm: f64,
    /// Distance travelled with the pen up, home to home, mm.
    pub pen_up_mm: f64,
    /// Seconds with the pen down, drawing.
    pub pen_down_s: f64,
    /// Seconds travelling with the pen up, home to home.
    pub pen_up_s: f64,
    /// Estimated time, s: drawing, travel, and each path's drop and lift.
    pub seconds: f64,
}

/// Fills a buffer with path `i`'s points (mm).
pub type PathOf<'a> = dyn Fn(usize, &mut Vec<(f64, f64)>) + Sync + 'a;

/// Paths made and timed at once by one thread.
const CHUNK: usize = 4096;

/// The plot of `count` paths, `path(i, buffer)` filling path `i` (a
/// polyline in mm, in drawing order), from home and back, on a sheet of
/// `sheet_mm` (where home is: AxiDraw's software turns a portrait sheet,
/// and starts at its top-right corner; `None`: at (0, 0)). Paths are made
/// and timed in parallel, a chunk at a time, and added in order: the same
/// figures whatever the number of threads.
#[must_use]
pub fn plot_paths_of(
    pen: &str,
    dots: usize,
    count: usize,
    path: &PathOf<'_>,
    plotter: &Plotter,
    sheet_mm: Option<(f64, f64)>,
) -> PenPlot {
    use rayon::prelude::*;
    let dist = |a: (f64, f64), b: (f64, f64)| ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt();
    // Per chunk: its first and last points, drawn mm and s, travel inside
    // it, lifts.
    #[derive(Clone, Copy, Default)]
    struct Part {
        first: Option<(f64, f64)>,
        last: (f64, f64),
        down_mm: f64,
        down_s: f64,
        up_mm: f64,
        up_s: f64,
        lifts: usize,
    }
    let parts: Vec<Part> = (0..count.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let (mut buf, mut scratch) = (Vec::new(), Default::default());
            let mut part = Part::default();
            for i in c * CHUNK..count.min((c + 1) * CHUNK) {
                buf.clear();
                path(i, &mut buf);
                let (Some(&first), Some(&last)) = (buf.first(), buf.last()) else {
                    continue;
                };
                if part.first.is_none() {
                    part.first = Some(first);
                } else {
                    part.up_mm += dist(part.last, first);
                    part.up_s += plotter.travel_s(part.last, first, sheet_mm);
                }
                part.down_mm += buf.windows(2).map(|w| dist(w[0], w[1])).sum::<f64>();
                part.down_s += plotter.stroke_s(&buf, sheet_mm, &mut scratch);
                part.last = last;
                part.lifts += 1;
            }
            part
        })
        .collect();
    let mut plot = PenPlot {
        pen: pen.to_owned(),
        dots,
        lifts: 0,
        pen_down_mm: 0.0,
        pen_up_mm: 0.0,
        pen_down_s: 0.0,
        pen_up_s: 0.0,
        seconds: 0.0,
    };
    let home = plotter.home(sheet_mm);
    let mut at = home;
    for part in &parts {
        let Some(first) = part.first else { continue };
        plot.pen_up_mm += dist(at, first) + part.up_mm;
        plot.pen_up_s += plotter.travel_s(at, first, sheet_mm) + part.up_s;
        plot.pen_down_mm += part.down_mm;
        plot.pen_down_s += part.down_s;
        plot.lifts += part.lifts;
        at = part.last;
    }
    plot.pen_up_mm += dist(at, home);
    plot.pen_up_s += plotter.travel_s(at, home, sheet_mm);
    let (drop, lift) = plotter.pen_s();
    plot.seconds = plot.pen_down_s + plot.pen_up_s + plot.lifts as f64 * (drop + lift);
    plot
}

/// [`plot_paths_of`] for paths in memory, home at (0, 0).
#[must_use]
pub fn plot_paths(pen: &str, dots: usize, paths: &[Vec<(f64, f64)>], plotter: &Plotter) -> PenPlot {
    plot_paths_of(
        pen,
        dots,
        paths.len(),
        &|i, buf| buf.extend_from_slice(&paths[i]),
        plotter,
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slow() -> Motion {
        Motion {
            acceleration: 100.0,
            max_velocity: 10.0,
            cornering: 0.0,
        }
    }

    /// Two one-touch dots and a square path, by hand.
    #[test]
    fn the_estimate_adds_up_by_hand() {
        let plotter = Plotter::Saxi(Saxi {
            pen_down: slow(),
            pen_up: Motion {
                acceleration: 1000.0,
                max_velocity: 100.0,
                cornering: 0.0,
            },
            pen_drop_s: 0.2,
            pen_lift_s: 0.3,
        });
        let paths = vec![
            vec![(3.0, 4.0), (3.01, 4.0)],
            vec![(3.01, 8.0), (3.02, 8.0)],
            vec![(10.0, 8.0), (12.0, 8.0), (12.0, 10.0)],
        ];
        let p = plot_paths("k", 3, &paths, &plotter);
        let down = 0.01 + 0.01 + 4.0;
        // Home → (3, 4): 5; (3.01, 4) → (3.01, 8): 4; (3.02, 8) → (10, 8):
        // 6.98; (12, 10) → home: √(144 + 100).
        let ups = [5.0, 4.0, 6.98, (244.0f64).sqrt()];
        assert_eq!(p.lifts, 3);
        assert!((p.pen_down_mm - down).abs() < 1e-9, "{p:?}");
        assert!(
            (p.pen_up_mm - ups.iter().sum::<f64>()).abs() < 1e-9,
            "{p:?}"
        );
        // Rest to rest over d at a up to v: 2√(d/a) while d ≤ v²/a, else
        // d/v + v/a. Pen up: v²/a = 10 mm, so 2√(d/1000) for each but the
        // last (15.6 mm: 15.6/100 + 0.1).
        let up_s = 2.0 * (5.0f64 / 1000.0).sqrt()
            + 2.0 * (4.0f64 / 1000.0).sqrt()
            + 2.0 * (6.98f64 / 1000.0).sqrt()
            + (244.0f64).sqrt() / 100.0
            + 0.1;
        assert!((p.pen_up_s - up_s).abs() < 1e-9, "{p:?} {up_s}");
        // Pen down: the touches 2√(0.01/100) each; the square's corner is a
        // stop (cornering 0): two strokes of 2 mm, each v²/a = 1 mm ≤ 2:
        // 2/10 + 0.1.
        let down_s = 2.0 * 2.0 * (0.01f64 / 100.0).sqrt() + 2.0 * (0.2 + 0.1);
        assert!((p.pen_down_s - down_s).abs() < 1e-9, "{p:?} {down_s}");
        let t = up_s + down_s + 3.0 * 0.5;
        assert!((p.seconds - t).abs() < 1e-9, "{p:?}");
        // Nothing to draw: home to home, no time.
        let none = plot_paths("k", 0, &[], &plotter);
        assert_eq!((none.lifts, none.pen_up_mm, none.seconds), (0, 0.0, 0.0));
    }

    #[test]
    fn corners_slow_the_pen_as_the_cornering_factor_says() {
        let mut m = slow();
        let mut speeds = Scratch::default();
        // Straight on through a vertex: no corner at all.
        let straight = m.path_s(&[(0.0, 0.0), (1.0, 0.0), (4.0, 0.0)], &mut speeds);
        assert!((straight - m.straight_s(4.0)).abs() < 1e-12);
        // A right angle with no cornering: two stops.
        let square = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0)];
        assert!((m.path_s(&square, &mut speeds) - 2.0 * m.straight_s(2.0)).abs() < 1e-12);
        // With a cornering factor the corner is faster, and never faster
        // than going straight; more factor, less time.
        let mut last = 2.0 * m.straight_s(2.0);
        for c in [0.001, 0.01, 0.1] {
            m.cornering = c;
            let t = m.path_s(&square, &mut speeds);
            assert!(t < last && t > m.straight_s(4.0), "{c}: {t}");
            last = t;
        }
        // Enough of it and the corner is taken at full speed.
        m.cornering = 100.0;
        assert!((m.path_s(&square, &mut speeds) - m.straight_s(4.0)).abs() < 1e-12);
        // A U-turn always stops; repeated points change nothing.
        let back = [(0.0, 0.0), (2.0, 0.0), (2.0, 0.0), (0.0, 0.0)];
        assert!((m.path_s(&back, &mut speeds) - 2.0 * m.straight_s(2.0)).abs() < 1e-12);
        // By hand, a corner of 90°: s = √½, v = √(a c s / (1 − s)).
        m.cornering = 0.05;
        let s = 0.5f64.sqrt();
        let v: f64 = (100.0 * 0.05 * s / (1.0 - s)).sqrt();
        assert!(v < 10.0);
        // Each leg: from rest to v (or v to rest) over 2 mm.
        let leg = segment_s(2.0, 0.0, v, 100.0, 10.0);
        let want = 2.0 * leg;
        assert!((m.path_s(&square, &mut speeds) - want).abs() < 1e-12);
        // A leg by hand: peak √((2·100·2 + v²)/2) ≥ 10, so capped.
        let up = (100.0 - v * v) / 200.0;
        let hand = 10.0 / 100.0 + (10.0 - v) / 100.0 + (2.0 - 0.5 - up) / 10.0;
        assert!((leg - hand).abs() < 1e-12, "{leg} {hand}");
    }

    #[test]
    fn profiles_read_from_toml_and_errors_name_the_key() {
        let Plotter::Saxi(p) =
            Plotter::from_toml("pen_down_max_velocity = 25\npen_lift_duration = 0.2\n").unwrap()
        else {
            panic!("saxi's names make a saxi profile")
        };
        assert_eq!(p.pen_down.max_velocity, 25.0);
        assert_eq!(p.pen_lift_s, 0.2);
        assert_eq!(p.pen_up, Saxi::default().pen_up);
        // AxiDraw's own option names, over its defaults.
        let Plotter::AxiDraw(a) = Plotter::from_toml(
            "speed_pendown = 50\naccel = 100\npen_rate_lower = 80\npen_delay_up = 20\n\
             const_speed = true\nmodel = 2\n",
        )
        .unwrap() else {
            panic!("AxiDraw's names make an AxiDraw profile")
        };
        assert_eq!(
            (a.speed_pendown, a.accel, a.pen_rate_lower),
            (50.0, 100.0, 80.0)
        );
        assert_eq!((a.pen_delay_up, a.const_speed, a.model), (20.0, true, 2));
        assert_eq!(a.speed_penup, AxiDraw::default().speed_penup);
        // An empty file, and the names, are AxiDraw's defaults.
        assert_eq!(Plotter::from_toml("").unwrap(), Plotter::default());
        assert_eq!(Plotter::named("axidraw"), Some(Plotter::default()));
        assert_eq!(Plotter::named("saxi"), Some(Plotter::Saxi(Saxi::default())));
        assert_eq!(Plotter::named("hp7475a"), None);
        for (text, want) in [
            (
                "pen_down_max_velocity = \"fast\"\n",
                "pen_down_max_velocity = \"fast\": expected",
            ),
            (
                "pen_up_acceleration = -3\n",
                "pen_up_acceleration = -3: expected",
            ),
            (
                "pen_drop_duration = nan\n",
                "pen_drop_duration = NaN: expected",
            ),
            ("accel = 0\n", "accel = 0: expected a number from 1 to 110"),
            ("speed_penup = 300\n", "speed_penup = 300: expected"),
            ("model = 9\n", "model = 9: expected an AxiDraw model"),
            ("const_speed = 1\n", "const_speed = 1: expected"),
            ("accel = 50\npen_up_acceleration = 300\n", "not both"),
        ] {
            let e = Plotter::from_toml(text).unwrap_err().to_string();
            assert!(e.contains(want) && !e.contains('\n'), "{text}: {e}");
        }
        // An unknown name lists every known one, AxiDraw's and saxi's.
        let e = Plotter::from_toml("pen_speed = 3\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("pen_speed") && !e.contains('\n'), "{e}");
        for key in AXIDRAW_KEYS.iter().chain(&PROFILE_KEYS) {
            assert!(e.contains(key), "{key}: {e}");
        }
    }

    #[test]
    fn the_flags_set_either_planners_speeds_and_pen_times() {
        for mut p in [Plotter::default(), Plotter::named("saxi").unwrap()] {
            p.set_pen_down_speed(40.0);
            p.set_pen_up_speed(120.0);
            p.set_pen_delay(0.5);
            assert_eq!(p.pen_s(), (0.25, 0.25));
            let (down, up) = match p {
                Plotter::AxiDraw(a) => (a.pen_down_mm_s(), a.pen_up_mm_s()),
                Plotter::Saxi(s) => (s.pen_down.max_velocity, s.pen_up.max_velocity),
            };
            assert!(
                (down - 40.0).abs() < 1e-9 && (up - 120.0).abs() < 1e-9,
                "{p:?}"
            );
            assert!(p.check().is_ok());
        }
    }

    #[test]
    fn the_sums_do_not_depend_on_the_threads() {
        let paths: Vec<Vec<(f64, f64)>> = (0..10_000)
            .map(|i| {
                let (x, y) = (f64::from(i % 100) * 2.1, f64::from(i / 100) * 1.7);
                (0..9)
                    .map(|k| {
                        let t = f64::from(k) * 0.7;
                        (x + 0.3 * t.cos(), y + 0.3 * t.sin())
                    })
                    .collect()
            })
            .collect();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    Plotter::NAMES.map(|name| {
                        let p = Plotter::named(name).unwrap();
                        plot_paths("k", paths.len(), &paths, &p)
                    })
                })
        };
        assert_eq!(run(1), run(3));
    }
}
