//! The plot time: with a pen width, how long a pen plotter takes to draw
//! the drawing, from `Job::plot_stats` with an AxiDraw's motion profile (as
//! `pixelpie stipple --plot-stats` reports it). It is worked out on a
//! thread of its own when the drawing changes, or once the controls rest
//! after a change of the job, never per frame.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::Instant;

use super::dots::DotInstance;
use super::{DEBOUNCE, PixelPieApp};
use crate::job::{Job, PenCheck};
use crate::stipple::plot::{PenPlot, Plotter};
use crate::text::grouped;

/// An estimate: each pen's plot, or why there is none.
type Estimate = Result<Vec<PenPlot>, String>;

/// The drawing as the pens plot it ([`Job::plotted_radii`]): what the view
/// shows with a pen width, and the pen's warning.
pub(super) struct Plotted {
    /// The drawing's generation it was made for.
    pub of: u64,
    /// Its own generation (the view's caches tell it by this).
    pub generation: u64,
    /// The dots as plotted, one layer per pen (one for a grey drawing).
    pub layers: Layers,
    /// Whether the pens draw the dots larger than the tones ask.
    pub check: Option<PenCheck>,
}

/// Dot layers, one per pen.
type Layers = Vec<Arc<Vec<DotInstance>>>;

/// Generations of [`Plotted`] layers: apart from the drawings' own.
const PLOTTED_GENERATIONS: u64 = 1 << 62;

/// The estimate shown, and the one on its way.
#[derive(Default)]
pub(super) struct PlotTime {
    /// What the estimate is for: the drawing's generation and the job.
    key: Option<(u64, Job)>,
    /// When the job last changed: the estimate starts once it has rested.
    due: Option<Instant>,
    /// The answer of the estimate's thread.
    reply: Option<Receiver<Estimate>>,
    /// The last estimate (stale while a newer one is due or on its way).
    shown: Option<Estimate>,
    /// The drawing as plotted, with the last estimate.
    pub plotted: Option<Plotted>,
    /// Estimates started.
    made: u64,
    /// The answer of the estimate's thread, with the plotted drawing.
    plotted_reply: Option<Receiver<Option<Plotted>>>,
}

impl PixelPieApp {
    /// Starts an estimate when the drawing or the job changed (a new
    /// drawing at once, a changed job once the controls rest) and takes
    /// the answer of the one on its way. Without a pen width, or without a
    /// drawing, there is none.
    pub(super) fn update_plot_time(&mut self, ctx: &egui::Context) {
        let job = self.settings.job();
        let (Some(outcome), Some(_)) = (&self.outcome, job.pen_mm) else {
            self.plot = PlotTime::default();
            return;
        };
        let key = (self.dots_generation, job);
        let scale = outcome.scale;
        let plot = &mut self.plot;
        if plot.key.as_ref() != Some(&key) {
            let now = Instant::now();
            let new_drawing = plot.key.as_ref().map(|k| k.0) != Some(key.0);
            plot.due = Some(if new_drawing {
                now.checked_sub(DEBOUNCE).unwrap_or(now)
            } else {
                now
            });
            plot.key = Some(key);
        }
        if let Some(reply) = &plot.reply {
            match reply.try_recv() {
                Ok(estimate) => {
                    plot.shown = Some(estimate);
                    plot.reply = None;
                }
                Err(TryRecvError::Empty) => {}
                Err(TryRecvError::Disconnected) => {
                    plot.shown = Some(Err("the estimate stopped without an answer".into()));
                    plot.reply = None;
                }
            }
        }
        if let Some(reply) = &plot.plotted_reply {
            match reply.try_recv() {
                Ok(plotted) => {
                    plot.plotted = plotted;
                    plot.plotted_reply = None;
                }
                Err(TryRecvError::Empty) => {}
                Err(TryRecvError::Disconnected) => plot.plotted_reply = None,
            }
        }
        let Some(since) = plot.due else { return };
        let rest = DEBOUNCE.saturating_sub(since.elapsed());
        if !rest.is_zero() {
            ctx.request_repaint_after(rest);
            return;
        }
        plot.due = None;
        let Some((_, job)) = plot.key.clone() else {
            return;
        };
        let drawing = outcome.drawing.clone();
        let (tx, rx) = channel();
        let (plotted_tx, plotted_rx) = channel();
        let repaint = ctx.clone();
        plot.made += 1;
        let (of, generation) = (self.dots_generation, PLOTTED_GENERATIONS + plot.made);
        let spawned = std::thread::Builder::new()
            .name("pixelpie-plot-time".into())
            .spawn(move || {
                let estimate = job
                    .plot_stats(&drawing, &Plotter::default())
                    .map_err(|e| super::words::app_line(&e));
                let _ = tx.send(estimate);
                let plotted = plotted(&job, &drawing, scale).map(|(layers, check)| Plotted {
                    of,
                    generation,
                    layers,
                    check,
                });
                let _ = plotted_tx.send(plotted);
                repaint.request_repaint();
            });
        // A newer estimate replaces the one on its way (its answer is
        // dropped).
        match spawned {
            Ok(_) => {
                plot.reply = Some(rx);
                plot.plotted_reply = Some(plotted_rx);
            }
            Err(e) => plot.shown = Some(Err(format!("cannot estimate the plot time: {e}"))),
        }
    }

    /// Whether a plot-time estimate is due or on its way.
    #[must_use]
    pub fn plot_pending(&self) -> bool {
        self.plot.due.is_some() || self.plot.reply.is_some() || self.plot.plotted_reply.is_some()
    }

    /// The drawing as the pens plot it, when a pen width is set and it is
    /// of the drawing shown.
    pub(super) fn plotted_view(&self) -> Option<&Plotted> {
        self.settings.job.pen_mm?;
        self.plot
            .plotted
            .as_ref()
            .filter(|p| p.of == self.dots_generation)
    }

    /// The pen's warning: the dots narrower than the pen draws them, how
    /// much darker the plot comes out, and the count that draws true.
    #[must_use]
    pub fn pen_warning(&self) -> Option<&PenCheck> {
        self.plotted_view()?.check.as_ref()
    }

    /// The plot-time line ("plot ≈ 1 h 23 min · 4 pens · 20 012 lifts"),
    /// or why there is none; `None` without a pen width.
    #[must_use]
    pub fn plot_line(&self) -> Option<String> {
        Some(match self.plot.shown.as_ref()? {
            Err(e) => format!("no plot time: {e}"),
            Ok(plots) => {
                let seconds: f64 = plots.iter().map(|p| p.seconds).sum();
                let lifts: usize = plots.iter().map(|p| p.lifts).sum();
                let pens = plots.len();
                format!(
                    "plot ≈ {} · {pens} pen{} · {} lifts",
                    duration(seconds),
                    if pens == 1 { "" } else { "s" },
                    grouped(lifts)
                )
            }
        })
    }

    /// The plot time's details: each pen's dots, lifts, distances and
    /// time, and the speeds assumed.
    fn plot_details(&self) -> String {
        let mut text = String::new();
        if let Some(Ok(plots)) = &self.plot.shown {
            for p in plots {
                text += &format!(
                    "{}: {} dots, {} lifts, pen down {:.0} mm, pen up {:.0} mm, {:.1} min\n",
                    p.pen,
                    grouped(p.dots),
                    grouped(p.lifts),
                    p.pen_down_mm,
                    p.pen_up_mm,
                    p.seconds / 60.0
                );
            }
        }
        text += &Plotter::default().describe();
        text += " (the command line's plot statistics give the same).";
        text
    }

    /// The plot-time line in a row of fixed height (empty without a pen
    /// width; greyed while a newer estimate is on its way).
    pub(super) fn plot_time_ui(&self, ui: &mut egui::Ui) {
        let line = self.plot_line();
        super::panel::fixed_row(ui, true, |ui| {
            let Some(line) = line else { return };
            let mut text = egui::RichText::new(&line);
            if self.plot_pending() {
                text = text.weak();
            }
            ui.add(
                egui::Label::new(text)
                    .truncate()
                    .show_tooltip_when_elided(false),
            )
            .on_hover_text(self.plot_details());
        });
    }
}

/// The dots of `drawing` as the pens plot them, one layer per pen, in
/// image px (`scale` domain px each), and the pen's warning; `None`
/// without a pen width and a size in mm.
fn plotted(
    job: &Job,
    drawing: &crate::job::Stipple,
    scale: f32,
) -> Option<(Layers, Option<PenCheck>)> {
    let radii = job.plotted_radii(drawing).ok()??;
    let pens = drawing.pens.as_ref().map_or(1, crate::colour::PenSet::len);
    let mut layers = vec![Vec::new(); pens];
    for (p, r) in drawing.points.iter().zip(radii) {
        if let Some(layer) = layers.get_mut(p.class as usize) {
            layer.push(DotInstance {
                x: p.x / scale,
                y: p.y / scale,
                radius: p.radius / scale,
                drawn: r / scale,
            });
        }
    }
    let check = job.pen_check(drawing).ok().flatten();
    Some((layers.into_iter().map(Arc::new).collect(), check))
}

/// A time as a plot takes it: seconds under a minute, then minutes, then
/// hours and minutes.
fn duration(seconds: f64) -> String {
    let minutes = (seconds / 60.0).round() as u64;
    if seconds < 59.5 {
        format!("{:.0} s", seconds.max(0.0))
    } else if minutes < 60 {
        format!("{minutes} min")
    } else {
        format!("{} h {} min", minutes / 60, minutes % 60)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_and_counts_read_plainly() {
        assert_eq!(duration(12.4), "12 s");
        assert_eq!(duration(59.6), "1 min");
        assert_eq!(duration(23.0 * 60.0 + 20.0), "23 min");
        assert_eq!(duration(83.0 * 60.0), "1 h 23 min");
        assert_eq!(grouped(7), "7");
        assert_eq!(grouped(20_012), "20 012");
        assert_eq!(grouped(1_234_567), "1 234 567");
    }
}
