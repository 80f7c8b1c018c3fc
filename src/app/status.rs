//! The panel's bottom: progress while a job runs (with Cancel) and the
//! last drawing's statistics, in places of fixed height.

use egui::Color32;

use super::PixelPieApp;
use super::panel::fixed_row;

impl PixelPieApp {
    /// Progress and statistics, in a place of fixed height.
    pub(super) fn stats_ui(&mut self, ui: &mut egui::Ui) {
        let mut cancel = false;
        fixed_row(ui, false, |ui| {
            if !self.busy() {
                ui.label(match (self.cancelled, self.outcome.is_some()) {
                    (true, _) => "cancelled",
                    (false, true) => "ready",
                    (false, false) => "",
                });
                return;
            }
            // Cancel first: the progress line beside it changes width at
            // every reply, and a button after it would move under the
            // pointer.
            if ui
                .button("Cancel")
                .on_hover_text("Stop this sampling or relaxation; keep the last drawing.")
                .clicked()
            {
                cancel = true;
            }
            self.busy_spinner(ui);
            ui.label(self.progress_shown().unwrap_or_default());
        });
        if cancel {
            self.cancel_job();
        }
        let (a, b, c) = match &self.outcome {
            Some(o) => {
                let d = &o.drawing;
                let st = &d.set.stats;
                let (t_sample, t_relax) = (
                    d.seconds(crate::job::Stage::Sample),
                    d.seconds(crate::job::Stage::Relax),
                );
                // The plan's line: what was decided (and why, on hover).
                (
                    format!(
                        "{} · took {:.2} s",
                        super::words::app_text(&d.plan.line()),
                        o.seconds
                    ),
                    format!(
                        "sampler {t_sample:.2} s, relaxation {t_relax:.2} s; last run: S1 \
                         {:.1} ms, S2 {:.1} ms, PP {:.1} ms",
                        st.stages.get("throw") * 1e3,
                        st.stages.get("cull") * 1e3,
                        st.stages.get("compact") * 1e3,
                    ),
                    format!("{} on {}", st.backend, st.device),
                )
            }
            None => (String::new(), String::new(), String::new()),
        };
        // One line each (the panel's height goes to the controls); the
        // whole text on hover.
        let hover = self.outcome.as_ref().map_or_else(String::new, |o| {
            let d = &o.drawing;
            // A line's width and why its count is what it is.
            let what = d.plan.line.as_ref().map_or_else(
                || format!("{} dots", d.points.len()),
                |l| {
                    let mm = l
                        .width_mm
                        .map_or_else(String::new, |mm| format!(" ({mm:.2} mm)"));
                    format!(
                        "One line {:.2} px wide{mm} through {} points: {}",
                        l.width_px,
                        d.points.len(),
                        super::words::app_text(&l.why)
                    )
                },
            );
            format!(
                "The last drawing's plan: {} ({}; {}×{} px domain; the command line's plan \
                 prints it whole). {what}; {} sampler iterations, {} run(s).",
                super::words::app_text(&d.plan.line()),
                super::words::app_text(&d.plan.why),
                d.plan.domain.0,
                d.plan.domain.1,
                d.set.stats.iterations,
                d.runs
            )
        });
        ui.add(
            egui::Label::new(a)
                .truncate()
                .show_tooltip_when_elided(false),
        )
        .on_hover_text(hover);
        ui.add(
            egui::Label::new(&b)
                .truncate()
                .show_tooltip_when_elided(false),
        )
        .on_hover_text(format!(
            "{b}. The paper's stages: S1 throws darts, S2 culls the conflicting ones, PP \
             compacts the still-empty pixels"
        ));
        let r = ui.add(
            egui::Label::new(&c)
                .truncate()
                .show_tooltip_when_elided(false),
        );
        if !c.is_empty() {
            r.on_hover_text(&c);
        }
        let note = match (&self.error, self.status.is_empty()) {
            (Some(e), _) => (Color32::from_rgb(200, 40, 40), format!("Error: {e}")),
            (None, false) => (ui.visuals().text_color(), self.status.clone()),
            (None, true) => (ui.visuals().text_color(), String::new()),
        };
        super::panel::message_row(
            ui,
            (!note.1.is_empty()).then_some(note.1.as_str()),
            Some(note.0),
        );
    }

    /// A spinner that turns at a few frames a second: egui's asks for a
    /// frame at once, again and again, and on a software rasterizer every
    /// frame is CPU time taken from the sampler. The progress line and
    /// the elapsed time come along with its frames.
    pub(super) fn busy_spinner(&self, ui: &mut egui::Ui) {
        let size = ui.spacing().interact_size.y;
        let (rect, _) = ui.allocate_exact_size(egui::vec2(size, size), egui::Sense::hover());
        let time = ui.input(|i| i.time);
        let radius = rect.height() / 2.0 - 2.0;
        let start = time * std::f64::consts::TAU;
        let end = start + 240f64.to_radians() * time.sin();
        let points: Vec<egui::Pos2> = (0..=20)
            .map(|i| {
                let a = start + (end - start) * f64::from(i) / 20.0;
                rect.center() + radius * egui::vec2(a.cos() as f32, a.sin() as f32)
            })
            .collect();
        ui.painter().add(egui::Shape::line(
            points,
            egui::Stroke::new(3.0, ui.visuals().strong_text_color()),
        ));
        ui.ctx().request_repaint_after(self.busy_frame());
    }

    /// How often the window redraws while a job runs or a picture decodes:
    /// twice a second on a software adapter (whose frames cost CPU), ten
    /// times on a GPU.
    #[must_use]
    pub fn busy_frame(&self) -> std::time::Duration {
        std::time::Duration::from_millis(if self.worker.software() { 500 } else { 100 })
    }

    /// The progress line while a job is queued or runs: what it does and
    /// for how long; `None` when idle.
    #[must_use]
    pub fn progress_shown(&self) -> Option<String> {
        if !self.busy() {
            return None;
        }
        if self.done_job == self.next_job {
            // Queued: the last job's progress is not this one's.
            return Some("waiting for the controls to rest".into());
        }
        let elapsed = self.job_started.map_or(String::new(), |t| {
            format!(", {:.1} s", t.elapsed().as_secs_f64())
        });
        // After sampling, the stage says what the job is doing.
        use crate::job::Stage;
        let later = self
            .stage
            .filter(|s| !matches!(s, Stage::Prepare | Stage::Sample | Stage::Relax));
        if let Some(stage) = later {
            let what = match stage {
                Stage::Order => "ordering the dots".to_owned(),
                Stage::Size => "sizing the dots".to_owned(),
                s => format!(
                    "sizing the dots ({})",
                    s.to_string().trim_start_matches("size: ")
                ),
            };
            return Some(format!("{what}{elapsed}"));
        }
        Some(match (&self.progress, self.relaxed) {
            (_, Some((done, of))) => format!("relaxing: {done} of {of} steps{elapsed}"),
            (Some(p), None) => format!(
                "iteration {}, {:.0}% covered{elapsed}",
                p.iteration,
                100.0 - 100.0 * p.empty_pixels as f64 / p.pixels.max(1) as f64
            ),
            (None, None) => format!("sampling{elapsed}"),
        })
    }
}
