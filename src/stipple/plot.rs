//! Plot statistics: what a pen plotter does to draw a pen drawing
//! (`--pen-mm`), pen by pen: its dots, its pen lifts, the distance drawn
//! with the pen down and travelled with it up, and an estimated time.
//!
//! Each pen's layer is a plot of its own (a pen change between layers): it
//! starts at the home corner (0, 0), draws its paths in the drawing's order
//! — each path one lower, one stroke and one lift — and returns home. The
//! time is pen-down distance / drawing speed + pen-up distance / travel
//! speed + lifts × the time of a lift and a drop; acceleration is left out,
//! so short moves make it an underestimate.

use super::Error;

/// A plotter's speeds, by default an AxiDraw's (speed_pendown 25% and
/// speed_penup 75% of its 380 mm/s, and about 0.35 s to raise and lower the
/// pen at its default pen rates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotSpeeds {
    /// Pen-down speed, mm/s.
    pub draw_mm_s: f64,
    /// Pen-up (travel) speed, mm/s.
    pub travel_mm_s: f64,
    /// Seconds to lift the pen and lower it again.
    pub lift_s: f64,
}

impl Default for PlotSpeeds {
    fn default() -> Self {
        Self {
            draw_mm_s: 95.0,
            travel_mm_s: 285.0,
            lift_s: 0.35,
        }
    }
}

impl PlotSpeeds {
    /// Checks that the speeds are positive numbers and the delay is not
    /// negative.
    pub fn check(&self) -> Result<(), Error> {
        let ok = self.draw_mm_s.is_finite()
            && self.draw_mm_s > 0.0
            && self.travel_mm_s.is_finite()
            && self.travel_mm_s > 0.0
            && self.lift_s.is_finite()
            && self.lift_s >= 0.0;
        if ok {
            Ok(())
        } else {
            Err(Error::InvalidParameter(format!(
                "plot speeds {} and {} mm/s must be positive and the pen delay {} s at least 0",
                self.draw_mm_s, self.travel_mm_s, self.lift_s
            )))
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
    /// Estimated time, s.
    pub seconds: f64,
}

/// The plot of paths (polylines in mm, in drawing order) from home and
/// back.
#[must_use]
pub fn plot_paths(
    pen: &str,
    dots: usize,
    paths: &[Vec<(f64, f64)>],
    speeds: PlotSpeeds,
) -> PenPlot {
    let dist = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
    let mut at = (0.0, 0.0);
    let (mut down, mut up) = (0.0, 0.0);
    for p in paths {
        let (Some(&first), Some(&last)) = (p.first(), p.last()) else {
            continue;
        };
        up += dist(at, first);
        down += p.windows(2).map(|w| dist(w[0], w[1])).sum::<f64>();
        at = last;
    }
    up += dist(at, (0.0, 0.0));
    let lifts = paths.iter().filter(|p| !p.is_empty()).count();
    PenPlot {
        pen: pen.to_owned(),
        dots,
        lifts,
        pen_down_mm: down,
        pen_up_mm: up,
        seconds: down / speeds.draw_mm_s + up / speeds.travel_mm_s + lifts as f64 * speeds.lift_s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two one-touch dots and a square path, by hand: home (0, 0) → (3, 4)
    /// is 5 mm up, the touch 0.01 mm down; → (3.01, 4) to (6, 8)…
    #[test]
    fn the_estimate_adds_up_by_hand() {
        let speeds = PlotSpeeds {
            draw_mm_s: 10.0,
            travel_mm_s: 100.0,
            lift_s: 0.5,
        };
        let paths = vec![
            vec![(3.0, 4.0), (3.01, 4.0)],
            vec![(3.01, 8.0), (3.02, 8.0)],
            vec![(10.0, 8.0), (12.0, 8.0), (12.0, 10.0)],
        ];
        let p = plot_paths("k", 3, &paths, speeds);
        let down = 0.01 + 0.01 + 4.0;
        // Home → (3, 4): 5; (3.01, 4) → (3.01, 8): 4; (3.02, 8) → (10, 8):
        // 6.98; (12, 10) → home: √(144 + 100).
        let up = 5.0 + 4.0 + 6.98 + (244.0f64).sqrt();
        assert_eq!(p.lifts, 3);
        assert!((p.pen_down_mm - down).abs() < 1e-9, "{p:?}");
        assert!((p.pen_up_mm - up).abs() < 1e-9, "{p:?}");
        let t = down / 10.0 + up / 100.0 + 3.0 * 0.5;
        assert!((p.seconds - t).abs() < 1e-9, "{p:?}");
        // Nothing to draw: home to home, no time.
        let none = plot_paths("k", 0, &[], speeds);
        assert_eq!((none.lifts, none.pen_up_mm, none.seconds), (0, 0.0, 0.0));
        assert!(
            PlotSpeeds {
                draw_mm_s: 0.0,
                ..speeds
            }
            .check()
            .is_err()
        );
    }
}
