//! Plot statistics: what a pen plotter does to draw a pen drawing
//! (`--pen-mm`), pen by pen: its dots, its pen lifts, the distance drawn
//! with the pen down and travelled with it up, and the time a motion
//! planner of an AxiDraw's kind takes.
//!
//! Each pen's layer is a plot of its own (a pen change between layers): it
//! starts at the home corner (0, 0), draws its paths in the drawing's order
//! — each path one travel, one drop, one stroke and one lift — and returns
//! home.
//!
//! # The motion model
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
//! The default profile is an AxiDraw's as its motion planners drive it
//! (saxi's defaults): pen down 200 mm/s² up to 50 mm/s with cornering
//! factor 0.127 mm, pen up 400 mm/s² up to 200 mm/s, 0.12 s to drop and to
//! lift. `docs/plotter.md` compares the estimate with saxi's own plan.

use super::Error;

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

/// A plotter's motion profile, by default an AxiDraw's as saxi plans it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plotter {
    /// Drawing, with the pen down.
    pub pen_down: Motion,
    /// Travel, with the pen up.
    pub pen_up: Motion,
    /// Seconds to drop the pen onto the paper.
    pub pen_drop_s: f64,
    /// Seconds to lift it.
    pub pen_lift_s: f64,
}

impl Default for Plotter {
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

/// A plotter profile file's keys (saxi's option names, with underscores),
/// all optional: the default profile fills in the rest.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileFile {
    pen_down_acceleration: Option<f64>,
    pen_down_max_velocity: Option<f64>,
    pen_down_cornering_factor: Option<f64>,
    pen_up_acceleration: Option<f64>,
    pen_up_max_velocity: Option<f64>,
    pen_drop_duration: Option<f64>,
    pen_lift_duration: Option<f64>,
}

/// A profile file's keys, for its errors.
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
    /// Checks every number: a one-line message naming the key.
    pub fn check(&self) -> Result<(), Error> {
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
            .map_err(Error::Setting)
    }

    /// A profile file's text (TOML): any of [`PROFILE_KEYS`], in mm and
    /// seconds, over the default profile. Errors name the key.
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
                    "{}; the keys are {}",
                    crate::text::single_line(message),
                    PROFILE_KEYS.join(", ")
                ),
            })
        })?;
        let d = Self::default();
        let p = Self {
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
        };
        p.check()?;
        Ok(p)
    }

    /// [`Self::from_toml`] of a file; errors name the file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            Error::Setting(format!(
                "cannot read plotter profile '{}': {e}",
                path.display()
            ))
        })?;
        Self::from_toml(&text).map_err(|e| Error::Setting(format!("{}: {e}", path.display())))
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
/// polyline in mm, in drawing order), from home and back. Paths are made
/// and timed in parallel, a chunk at a time, and added in order: the same
/// figures whatever the number of threads.
#[must_use]
pub fn plot_paths_of(
    pen: &str,
    dots: usize,
    count: usize,
    path: &PathOf<'_>,
    plotter: &Plotter,
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
            let (mut buf, mut scratch) = (Vec::new(), Scratch::default());
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
                    let d = dist(part.last, first);
                    part.up_mm += d;
                    part.up_s += plotter.pen_up.straight_s(d);
                }
                part.down_mm += buf.windows(2).map(|w| dist(w[0], w[1])).sum::<f64>();
                part.down_s += plotter.pen_down.path_s(&buf, &mut scratch);
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
    let mut at = (0.0, 0.0);
    for part in &parts {
        let Some(first) = part.first else { continue };
        let d = dist(at, first);
        plot.pen_up_mm += d + part.up_mm;
        plot.pen_up_s += plotter.pen_up.straight_s(d) + part.up_s;
        plot.pen_down_mm += part.down_mm;
        plot.pen_down_s += part.down_s;
        plot.lifts += part.lifts;
        at = part.last;
    }
    let home = dist(at, (0.0, 0.0));
    plot.pen_up_mm += home;
    plot.pen_up_s += plotter.pen_up.straight_s(home);
    plot.seconds = plot.pen_down_s
        + plot.pen_up_s
        + plot.lifts as f64 * (plotter.pen_drop_s + plotter.pen_lift_s);
    plot
}

/// [`plot_paths_of`] for paths in memory.
#[must_use]
pub fn plot_paths(pen: &str, dots: usize, paths: &[Vec<(f64, f64)>], plotter: &Plotter) -> PenPlot {
    plot_paths_of(
        pen,
        dots,
        paths.len(),
        &|i, buf| buf.extend_from_slice(&paths[i]),
        plotter,
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
        let plotter = Plotter {
            pen_down: slow(),
            pen_up: Motion {
                acceleration: 1000.0,
                max_velocity: 100.0,
                cornering: 0.0,
            },
            pen_drop_s: 0.2,
            pen_lift_s: 0.3,
        };
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
        let p =
            Plotter::from_toml("pen_down_max_velocity = 25\npen_lift_duration = 0.2\n").unwrap();
        assert_eq!(p.pen_down.max_velocity, 25.0);
        assert_eq!(p.pen_lift_s, 0.2);
        assert_eq!(p.pen_up, Plotter::default().pen_up);
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
            ("pen_speed = 3\n", "pen_down_acceleration"),
        ] {
            let e = Plotter::from_toml(text).unwrap_err().to_string();
            assert!(e.contains(want) && !e.contains('\n'), "{text}: {e}");
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
                .install(|| plot_paths("k", paths.len(), &paths, &Plotter::default()))
        };
        assert_eq!(run(1), run(3));
    }
}
