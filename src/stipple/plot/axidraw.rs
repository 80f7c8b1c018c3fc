//! AxiDraw's own motion planner, as its software (the Inkscape extension
//! and `axicli`, evil-mad/axidraw) times a plot in preview: the model that
//! `--plotter axidraw` (the default) uses.
//!
//! Everything is in the machine's units: inches, inches per second and
//! motor steps. A portrait sheet is turned a quarter counter-clockwise
//! onto the machine (its home is the sheet's top-right corner).
//!
//! * **Settings.** Speeds are percentages of the machine's top speed
//!   (8.6979 in/s at 16× microstepping, 15 in/s at 8×) divided by 110;
//!   `accel` is a percentage of 40 in/s² with the pen down and 60 in/s²
//!   with it up.
//! * **Pen.** The servo's time to move between the two heights is a
//!   fourth-power blend of its fast-sweep time (45 ms + 2.69 ms per % of
//!   height) and its rate-limited sweep (200 ms × heights / rate), in whole
//!   ms, plus the optional delay.
//! * **Paths.** Vertices within 0.0002 in of the chord around them are
//!   merged; of what is left, steps shorter than one diagonal motor step
//!   are skipped. Each vertex gets the fastest speed that accelerating from
//!   the last allows, capped by the corner (grbl's junction deviation with
//!   a 0.002 in factor), then lowered where braking to the next needs it.
//!   A path of two vertices is one straight move from rest to rest, as is
//!   every pen-up move.
//! * **Moves.** Each straight move, between its planned end speeds, is cut
//!   into 25 ms slices: a trapezoid when it reaches top speed with room to
//!   spare, else a triangle (with a softened acceleration near the
//!   trapezoid's length), else — for fewer than five slices — one linear
//!   ramp that starts at the mean of the entry and peak speeds, or a single
//!   constant speed. Each slice's time is rounded to whole milliseconds,
//!   its travel to whole motor steps; a slice with no step is not sent, and
//!   its time does not count.
//!
//! The estimate is the sum of the slices' times and the pen's. It agrees
//! with `axicli --preview --report_time` within 1% on our stipples
//! (docs/plotter.md has the figures).

/// Steps per inch of each motor at 8× microstepping; twice this at 16×.
const NATIVE_STEPS_PER_INCH: f64 = 1016.0;
/// The motors' fastest step rate, steps per ms.
const MAX_STEP_RATE: f64 = 24.995;
/// Top XY speed in inches per second, at 16× and 8× microstepping.
const TOP_SPEED_FINE: f64 = 8.6979;
const TOP_SPEED_COARSE: f64 = 15.0;
/// Pen-down speed factor in constant-speed mode, at 16× and 8×.
const CONST_SPEED_FINE: f64 = 0.4;
const CONST_SPEED_COARSE: f64 = 0.25;
/// Acceleration at `accel = 100`, pen down and pen up, in/s².
const ACCEL_DOWN: f64 = 40.0;
const ACCEL_UP: f64 = 60.0;
/// The planner's time slice, s.
const SLICE: f64 = 0.025;
/// Junction deviation, inches (the cornering factor 10 over 5000).
const JUNCTION: f64 = 10.0 / 5000.0;
/// Vertices this close to their neighbours' chord are merged, inches.
const MERGE_TOLERANCE: f64 = 0.002 / 10.0;
/// Millimetres per inch.
const MM_PER_INCH: f64 = 25.4;

/// AxiDraw's settings, by its own option names and in its own units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxiDraw {
    /// Top pen-down speed, % (1–110).
    pub speed_pendown: f64,
    /// Top pen-up speed, % (1–200).
    pub speed_penup: f64,
    /// Acceleration, % (1–110).
    pub accel: f64,
    /// Pen heights, % (0–100).
    pub pen_pos_up: f64,
    /// See [`Self::pen_pos_up`].
    pub pen_pos_down: f64,
    /// Servo rates, % (1–200).
    pub pen_rate_raise: f64,
    /// See [`Self::pen_rate_raise`].
    pub pen_rate_lower: f64,
    /// Extra delays after the pen moves, ms (may be negative).
    pub pen_delay_up: f64,
    /// See [`Self::pen_delay_up`].
    pub pen_delay_down: f64,
    /// Draw at one constant speed with the pen down.
    pub const_speed: bool,
    /// The AxiDraw model (1–7): its travel, which the estimate does not clip.
    pub model: u8,
    /// 1: 16× microstepping (fine, the default); 2: 8× (coarse, faster
    /// travel).
    pub resolution: u8,
    /// Seconds to lower and to raise the pen, replacing the servo's (the
    /// command line's `--pen-delay`).
    pub pen_times_s: Option<(f64, f64)>,
}

impl Default for AxiDraw {
    /// The defaults of AxiDraw's software (`axidraw_conf.py`).
    fn default() -> Self {
        Self {
            speed_pendown: 25.0,
            speed_penup: 75.0,
            accel: 75.0,
            pen_pos_up: 60.0,
            pen_pos_down: 30.0,
            pen_rate_raise: 75.0,
            pen_rate_lower: 50.0,
            pen_delay_up: 0.0,
            pen_delay_down: 0.0,
            const_speed: false,
            model: 1,
            resolution: 1,
            pen_times_s: None,
        }
    }
}

/// The motion limits of one pen position, in inches and seconds.
#[derive(Clone, Copy, Debug)]
struct Limits {
    /// Top speed, in/s.
    top: f64,
    /// Acceleration, in/s².
    accel: f64,
    /// The pen-down speed (in/s): constant-speed moves and the slowest
    /// fallback use it, pen up as well.
    pen_down_top: f64,
    /// Pen down in constant-speed mode.
    constant: bool,
    /// Motor steps per inch.
    steps_per_inch: f64,
}

impl AxiDraw {
    fn steps_per_inch(&self) -> f64 {
        if self.resolution == 2 {
            NATIVE_STEPS_PER_INCH
        } else {
            2.0 * NATIVE_STEPS_PER_INCH
        }
    }

    /// Top pen-down speed, mm/s.
    #[must_use]
    pub fn pen_down_mm_s(&self) -> f64 {
        self.limits(true).top * MM_PER_INCH
    }

    /// Top pen-up speed, mm/s.
    #[must_use]
    pub fn pen_up_mm_s(&self) -> f64 {
        self.limits(false).top * MM_PER_INCH
    }

    /// Acceleration with the pen down and up, mm/s².
    #[must_use]
    pub fn accel_mm_s2(&self) -> (f64, f64) {
        (
            self.limits(true).accel * MM_PER_INCH,
            self.limits(false).accel * MM_PER_INCH,
        )
    }

    /// Sets the top pen-down speed from mm/s (as a percentage).
    pub fn set_pen_down_mm_s(&mut self, v: f64) {
        let top = self.limits(true).top / self.speed_pendown;
        self.speed_pendown = v / MM_PER_INCH / top;
    }

    /// Sets the top pen-up speed from mm/s (as a percentage).
    pub fn set_pen_up_mm_s(&mut self, v: f64) {
        let top = self.limits(false).top / self.speed_penup;
        self.speed_penup = v / MM_PER_INCH / top;
    }

    fn limits(&self, pen_down: bool) -> Limits {
        let (top, factor) = if self.resolution == 2 {
            (TOP_SPEED_COARSE, CONST_SPEED_COARSE)
        } else {
            (TOP_SPEED_FINE, CONST_SPEED_FINE)
        };
        let mut down = self.speed_pendown * top / 110.0;
        if self.const_speed {
            down *= factor;
        }
        let (speed, accel) = if pen_down {
            (down, ACCEL_DOWN)
        } else {
            (self.speed_penup * top / 110.0, ACCEL_UP)
        };
        Limits {
            top: speed,
            accel: accel * self.accel / 100.0,
            pen_down_top: down,
            constant: pen_down && self.const_speed,
            steps_per_inch: self.steps_per_inch(),
        }
    }

    /// Seconds to lower and to raise the pen: the servo's travel between
    /// the heights, whole ms, plus the delays.
    #[must_use]
    pub fn pen_s(&self) -> (f64, f64) {
        if let Some(t) = self.pen_times_s {
            return t;
        }
        let height = (self.pen_pos_up - self.pen_pos_down).abs();
        let servo = |rate: f64, delay: f64| {
            let fast = 2.69 * height + 45.0;
            let sweep = 200.0 * height / rate;
            let t = if height < 0.9 {
                0.0
            } else {
                (fast.powi(4) + sweep.powi(4)).powf(0.25).trunc()
            };
            (t + delay.round()).max(0.0) / 1000.0
        };
        (
            servo(self.pen_rate_lower, self.pen_delay_down),
            servo(self.pen_rate_raise, self.pen_delay_up),
        )
    }

    /// Checks each setting against AxiDraw's own range; a message names
    /// the option.
    pub(super) fn check(&self) -> Result<(), String> {
        let ranges = [
            ("speed_pendown", self.speed_pendown, 1.0, 110.0),
            ("speed_penup", self.speed_penup, 1.0, 200.0),
            ("accel", self.accel, 1.0, 110.0),
            ("pen_pos_up", self.pen_pos_up, 0.0, 100.0),
            ("pen_pos_down", self.pen_pos_down, 0.0, 100.0),
            ("pen_rate_raise", self.pen_rate_raise, 1.0, 200.0),
            ("pen_rate_lower", self.pen_rate_lower, 1.0, 200.0),
        ];
        for (key, v, lo, hi) in ranges {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(format!("{key} = {v}: expected a number from {lo} to {hi}"));
            }
        }
        for (key, v) in [
            ("pen_delay_up", self.pen_delay_up),
            ("pen_delay_down", self.pen_delay_down),
        ] {
            if !v.is_finite() {
                return Err(format!("{key} = {v}: expected a number of ms"));
            }
        }
        if !(1..=7).contains(&self.model) {
            return Err(format!(
                "model = {}: expected an AxiDraw model from 1 to 7",
                self.model
            ));
        }
        if !(1..=2).contains(&self.resolution) {
            return Err(format!(
                "resolution = {}: expected 1 (16× microstepping) or 2 (8×)",
                self.resolution
            ));
        }
        if let Some((lower, raise)) = self.pen_times_s
            && !(lower.is_finite() && raise.is_finite() && lower >= 0.0 && raise >= 0.0)
        {
            return Err(format!(
                "pen times {lower} s, {raise} s: expected seconds, at least 0"
            ));
        }
        Ok(())
    }

    /// Where the carriage is after a move to `p` (mm on a sheet of
    /// `sheet_mm`, or on the machine's own axes without one): the nearest
    /// position in whole motor steps, in steps of the two motors.
    pub(super) fn steps_at(&self, p: (f64, f64), sheet_mm: Option<(f64, f64)>) -> (i64, i64) {
        let (x, y) = machine_inches(p, sheet_mm);
        let s = self.steps_per_inch();
        (
            ((x + y) * s).round_ties_even() as i64,
            ((x - y) * s).round_ties_even() as i64,
        )
    }

    /// Seconds of a pen-up move between two step positions.
    pub(super) fn travel_s(&self, from: (i64, i64), to: (i64, i64)) -> f64 {
        move_s(
            &self.limits(false),
            (to.0 - from.0, to.1 - from.1),
            0.0,
            0.0,
        )
    }

    /// Seconds to draw `points` (mm on a sheet of `sheet_mm`) with the pen
    /// down, from the step position of its first point.
    pub(super) fn stroke_s(
        &self,
        points: &[(f64, f64)],
        sheet_mm: Option<(f64, f64)>,
        scratch: &mut Scratch,
    ) -> f64 {
        let lim = self.limits(true);
        let Scratch {
            vertices,
            segs,
            speeds,
        } = scratch;
        vertices.clear();
        vertices.extend(points.iter().map(|&p| machine_inches(p, sheet_mm)));
        merge_near_chords(vertices);
        let Some(&first) = vertices.first() else {
            return 0.0;
        };
        let start = self.steps_at(points[0], sheet_mm);
        // The steps worth planning: (vertex index, length, unit direction).
        let min_step = if self.resolution == 2 {
            0.000_696
        } else {
            0.000_348
        };
        segs.clear();
        let mut at = first;
        for (i, &v) in vertices.iter().enumerate().skip(1) {
            let (dx, dy) = (v.0 - at.0, v.1 - at.1);
            let len = dx.hypot(dy);
            if len >= min_step {
                // The planner keeps lengths and speeds in single precision.
                segs.push((i, f64::from(len as f32), (dx / len, dy / len)));
                at = v;
            }
        }
        let steps_of = |i: usize| {
            let v = vertices[i];
            let s = lim.steps_per_inch;
            (
                ((v.0 + v.1) * s).round_ties_even() as i64,
                ((v.0 - v.1) * s).round_ties_even() as i64,
            )
        };
        if vertices.len() == 2 {
            // A straight stroke, planned as it is.
            let end = steps_of(1);
            return move_s(&lim, (end.0 - start.0, end.1 - start.1), 0.0, 0.0);
        }
        match segs.len() {
            0 => return 0.0,
            1 => {
                let end = steps_of(segs[0].0);
                return move_s(&lim, (end.0 - start.0, end.1 - start.1), 0.0, 0.0);
            }
            _ => {}
        }
        // Speeds at the vertices: forward from rest, each the least of
        // what the last allows, the top speed and the corner's limit.
        let a = lim.accel;
        let full_speed_dist = lim.top * lim.top / (2.0 * a);
        speeds.clear();
        speeds.push(0.0);
        for w in segs.windows(2) {
            let (len, d1, d2) = (w[0].1, w[0].2, w[1].2);
            let last = speeds[speeds.len() - 1];
            let mut v = if len > full_speed_dist {
                lim.top
            } else {
                (last * last + 2.0 * a * len).sqrt().min(lim.top)
            };
            let cosine = -(d1.0 * d2.0 + d1.1 * d2.1);
            let s = ((1.0 - cosine) / 2.0).max(0.0).sqrt();
            let radius = if 1.0 - s > 0.0001 {
                JUNCTION * s / (1.0 - s)
            } else {
                100_000.0
            };
            v = v.min((a * radius).sqrt());
            speeds.push(f64::from(v as f32));
        }
        speeds.push(0.0);
        // Backward: slow enough at each vertex to brake to the next.
        for i in (1..speeds.len()).rev() {
            let len = segs[i - 1].1;
            if speeds[i - 1] > speeds[i] && len > 0.0 {
                let reach = (speeds[i] * speeds[i] + 2.0 * a * len).sqrt();
                if reach < speeds[i - 1] {
                    speeds[i - 1] = f64::from(reach as f32);
                }
            }
        }
        let mut at = start;
        let mut total = 0.0;
        for (k, seg) in segs.iter().enumerate() {
            let to = steps_of(seg.0);
            let steps = (to.0 - at.0, to.1 - at.1);
            if steps != (0, 0) {
                total += move_s(&lim, steps, speeds[k], speeds[k + 1]);
                at = to;
            }
        }
        total
    }
}

/// Working memory of [`AxiDraw::stroke_s`].
#[derive(Debug, Default)]
pub struct Scratch {
    vertices: Vec<(f64, f64)>,
    segs: Vec<(usize, f64, (f64, f64))>,
    speeds: Vec<f64>,
}

/// `p` (mm on a sheet of `sheet_mm`) on the machine's axes, in inches: a
/// portrait sheet turned a quarter counter-clockwise, its top-right corner
/// at home.
fn machine_inches(p: (f64, f64), sheet_mm: Option<(f64, f64)>) -> (f64, f64) {
    let (x, y) = match sheet_mm {
        Some((w, h)) if h > w => (p.1, w - p.0),
        _ => p,
    };
    (x / MM_PER_INCH, y / MM_PER_INCH)
}

/// Merges runs of vertices that lie within [`MERGE_TOLERANCE`] of the
/// chord from the run's first vertex to the vertex after it, greedily
/// from the start.
fn merge_near_chords(v: &mut Vec<(f64, f64)>) {
    if v.len() <= 2 {
        return;
    }
    let near = |run: &[(f64, f64)]| {
        let (a, b) = (run[0], run[run.len() - 1]);
        let (sx, sy) = (b.0 - a.0, b.1 - a.1);
        let len2 = sx * sx + sy * sy;
        let tol2 = MERGE_TOLERANCE * MERGE_TOLERANCE;
        run[1..run.len() - 1].iter().all(|p| {
            let (px, py) = (p.0 - a.0, p.1 - a.1);
            let along = px * sx + py * sy;
            if along <= 0.0 {
                px * px + py * py < tol2
            } else if len2 <= along {
                let (qx, qy) = (p.0 - b.0, p.1 - b.1);
                qx * qx + qy * qy < tol2
            } else {
                len2 != 0.0 && {
                    let cross = px * sy - sx * py;
                    cross * cross < tol2 * len2
                }
            }
        })
    };
    let mut start = 0;
    while start + 2 < v.len() {
        let mut end = start + 2;
        while end < v.len() && near(&v[start..=end]) {
            end += 1;
        }
        if end > start + 2 {
            v.drain(start + 1..end - 1);
        }
        start += 1;
    }
}

/// The 25 ms slices of one straight move: (elapsed s, distance along it).
struct Slices {
    at: Vec<(f64, f64)>,
    t: f64,
    pos: f64,
    v: f64,
}

impl Slices {
    /// `n` slices over `dt` s in all, each changing the speed by `dv`.
    fn ramp(&mut self, n: usize, dt: f64, dv: f64) {
        let each = dt / n as f64;
        for _ in 0..n {
            self.v += dv;
            self.t += each;
            self.pos += self.v * each;
            self.at.push((self.t, f64::from(self.pos as f32)));
        }
    }
}

/// Seconds of a straight move of `steps` motor steps from speed `vi` to
/// `vf` (in/s): its slices, rounded to ms and whole steps, those with a
/// step summed.
fn move_s(lim: &Limits, steps: (i64, i64), vi: f64, vf: f64) -> f64 {
    if steps == (0, 0) {
        return 0.0;
    }
    let s = lim.steps_per_inch;
    let (m1, m2) = (steps.0 as f64 / (2.0 * s), steps.1 as f64 / (2.0 * s));
    let len = (m1 + m2).hypot(m1 - m2);
    let (top, a) = (lim.top, lim.accel);
    let (mut vi, vf) = (vi.min(top), vf.min(top));
    let t_up = (top - vi) / a;
    let t_down = (top - vf) / a;
    let d_up = vi * t_up + 0.5 * a * t_up * t_up;
    let d_down = vf * t_down + 0.5 * a * t_down * t_down;
    let slices = |t: f64| (t / SLICE).floor().max(0.0) as usize;
    let mut sl = Slices {
        at: Vec::new(),
        t: 0.0,
        pos: 0.0,
        v: vi,
    };
    let mut constant = lim.constant;
    if !constant {
        if len > d_up + d_down + SLICE * top && len / top > 4.0 * SLICE {
            // Trapezoid: up to top speed, cruise, down.
            let n = slices(t_up);
            if n > 0 {
                sl.ramp(n, t_up, (top - vi) / (n as f64 + 1.0));
            }
            let cruise = len - (d_up + d_down);
            if cruise > SLICE * top {
                sl.v = top;
                let mut left = cruise / top;
                while left > 20.0 * SLICE {
                    left -= 20.0 * SLICE;
                    sl.ramp(1, 20.0 * SLICE, 0.0);
                }
                sl.ramp(1, left, 0.0);
            }
            let n = slices(t_down);
            if n > 0 {
                sl.ramp(n, t_down, -(top - vf) / (n as f64 + 1.0));
            }
        } else {
            // Triangle: up to a peak and down, softer near the trapezoid.
            let both = d_up + d_down;
            let ta_accel = if len >= 0.9 * both && both != 0.0 {
                0.9 * (both / len) * a
            } else {
                a
            };
            let mut ta = if ta_accel > 0.0 {
                ((2.0 * vi * vi + 2.0 * vf * vf + 4.0 * ta_accel * len).sqrt() - 2.0 * vi)
                    / (2.0 * ta_accel)
            } else {
                0.0
            };
            let peak = vi + ta_accel * ta;
            let n = slices(ta);
            if n == 0 {
                ta = 0.0;
            }
            let td = if ta_accel > 0.0 {
                ta - (vf - vi) / ta_accel
            } else {
                0.0
            };
            let nd = slices(td);
            if n + nd > 4 {
                if n > 0 {
                    sl.ramp(n, ta, (peak - vi) / (n as f64 + 1.0));
                }
                if nd > 0 {
                    sl.ramp(nd, td, -(peak - vf) / (nd as f64 + 1.0));
                }
            } else {
                // Short: one linear ramp from the mean of entry and peak.
                vi = (peak + vi) / 2.0;
                sl.v = vi;
                let ramp_a = ((vf * vf - vi * vi) / (2.0 * len)).clamp(-a, a);
                if ramp_a == 0.0 {
                    constant = true;
                } else {
                    let t = (vf - vi) / ramp_a;
                    let n = slices(t);
                    if n > 1 {
                        sl.ramp(n, t, (vf - vi) / (n as f64 + 1.0));
                    } else {
                        vi = peak;
                        constant = true;
                    }
                }
            }
        }
    }
    if constant {
        let v = if lim.constant {
            lim.pen_down_top
        } else if vf > vi {
            vf
        } else if vi > vf || vi > 0.0 {
            vi
        } else {
            lim.pen_down_top / 10.0
        };
        sl.pos = len;
        sl.at.push((len / v, f64::from(len as f32)));
    }
    // The slices as the motors take them.
    let (mut done1, mut done2, mut last_ms, mut total_ms) = (0i64, 0i64, 0i64, 0i64);
    for &(t, pos) in &sl.at {
        let f = pos / sl.pos;
        let ms = (t * 1000.0).round_ties_even() as i64;
        let mut s1 = (f * steps.0 as f64).round_ties_even() as i64 - done1;
        let mut s2 = (f * steps.1 as f64).round_ties_even() as i64 - done2;
        let mut dt = (ms - last_ms).max(1);
        last_ms = ms;
        // Too slow to be worth a step: left for the next slice.
        if (s1 as f64 / dt as f64).abs() < 0.002 {
            s1 = 0;
        }
        if (s2 as f64 / dt as f64).abs() < 0.002 {
            s2 = 0;
        }
        while (s1 as f64 / dt as f64).abs() >= MAX_STEP_RATE
            || (s2 as f64 / dt as f64).abs() >= MAX_STEP_RATE
        {
            dt += 1;
        }
        done1 += s1;
        done2 += s2;
        if s1 != 0 || s2 != 0 {
            total_ms += dt;
        }
    }
    total_ms as f64 / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_pen_takes_the_servos_time() {
        // Heights 60 and 30: 45 + 2.69·30 = 125.7 ms fast; sweeps of
        // 200·30/50 = 120 ms down and 200·30/75 = 80 ms up.
        let (lower, raise) = AxiDraw::default().pen_s();
        let blend = |a: f64, b: f64| (a.powi(4) + b.powi(4)).powf(0.25).trunc() / 1000.0;
        assert_eq!(lower, blend(125.7, 120.0));
        assert_eq!(raise, blend(125.7, 80.0));
        assert_eq!((lower, raise), (0.146, 0.130));
        let delayed = AxiDraw {
            pen_delay_down: 100.0,
            ..AxiDraw::default()
        };
        assert_eq!(delayed.pen_s().0, 0.246);
    }

    #[test]
    fn speeds_are_percentages_of_the_machines_top_speed() {
        let d = AxiDraw::default();
        // 25% of 8.6979 in/s over 1.1, in mm/s.
        assert!((d.pen_down_mm_s() - 25.0 * 8.6979 / 110.0 * 25.4).abs() < 1e-9);
        assert!((d.pen_up_mm_s() - 75.0 * 8.6979 / 110.0 * 25.4).abs() < 1e-9);
        assert_eq!(d.accel_mm_s2(), (30.0 * 25.4, 45.0 * 25.4));
        let mut e = d;
        e.set_pen_down_mm_s(40.0);
        assert!((e.pen_down_mm_s() - 40.0).abs() < 1e-9);
    }

    #[test]
    fn a_long_move_cruises_at_top_speed() {
        let d = AxiDraw::default();
        let lim = d.limits(false);
        // 10 inches along x: both motors turn 10 · 2032 steps.
        let steps = (20_320, 20_320);
        let t = move_s(&lim, steps, 0.0, 0.0);
        // Ideal trapezoid: 10/top + top/a.
        let ideal = 10.0 / lim.top + lim.top / lim.accel;
        assert!((t - ideal).abs() < 0.01, "{t} {ideal}");
    }

    #[test]
    fn a_short_move_ramps_slower_than_the_ideal_triangle() {
        let lim = AxiDraw::default().limits(false);
        // 2 mm: a triangle of under five slices becomes one linear ramp
        // from half its peak: twice the ideal 2√(L/a).
        let len = 2.0 / MM_PER_INCH;
        let n = (len * 2032.0).round() as i64;
        let t = move_s(&lim, (n, n), 0.0, 0.0);
        let ideal = 2.0 * (len / lim.accel).sqrt();
        assert!((t / ideal - 2.0).abs() < 0.05, "{t} {ideal}");
    }

    #[test]
    fn nearly_straight_vertices_merge() {
        let mut v = vec![(0.0, 0.0), (1.0, 0.0001), (2.0, 0.0), (2.0, 1.0)];
        merge_near_chords(&mut v);
        assert_eq!(v, vec![(0.0, 0.0), (2.0, 0.0), (2.0, 1.0)]);
        let mut w = vec![(0.0, 0.0), (1.0, 0.001), (2.0, 0.0)];
        merge_near_chords(&mut w);
        assert_eq!(w.len(), 3);
    }

    #[test]
    fn a_portrait_sheet_turns_onto_the_machine() {
        // Its top-right corner is home; its left edge the far side.
        assert_eq!(
            machine_inches((210.0, 0.0), Some((210.0, 297.0))),
            (0.0, 0.0)
        );
        let (x, y) = machine_inches((0.0, 254.0), Some((210.0, 297.0)));
        assert!((x - 10.0).abs() < 1e-12 && (y - 210.0 / 25.4).abs() < 1e-12);
        // A landscape one lies as it is.
        assert_eq!(
            machine_inches((25.4, 50.8), Some((297.0, 210.0))),
            (1.0, 2.0)
        );
    }
}
