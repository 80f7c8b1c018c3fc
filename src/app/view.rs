//! The side panel's controls, the zoomable canvas and the exports.

use egui::{Color32, Rect, Sense, Vec2};

use super::PixelPieApp;
use super::dots::{DotLayer, ViewUniform};
use super::settings::Background;
use crate::backend::BackendChoice;
use crate::importance::{MappingKind, Tones};
use crate::sampler::Policy;
use crate::stipple::{DotMode, DotSize, Order};

/// Zoom and pan of the canvas.
pub struct ViewState {
    /// Points per image pixel.
    pub zoom: f32,
    /// Screen offset of the image origin from the canvas corner, in points.
    pub pan: Vec2,
    /// Fit the image at the next frame.
    pub fit_next: bool,
    /// The canvas's size in points, as last drawn.
    pub canvas: Vec2,
    /// Copies per side last drawn (a change fits the view).
    pub tiles: usize,
    /// The view is fitted (no zoom or pan since): a resized canvas fits it
    /// again.
    pub fitted: bool,
}

impl Default for ViewState {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            pan: Vec2::ZERO,
            fit_next: true,
            canvas: Vec2::ZERO,
            tiles: 1,
            fitted: false,
        }
    }
}

impl PixelPieApp {
    /// The side panel's controls, one function per section.
    pub(super) fn controls(&mut self, ui: &mut egui::Ui) {
        ui.set_width(270.0);
        self.header_ui(ui);
        self.open_ui(ui);
        ui.separator();
        self.spacing_ui(ui);
        self.levels_ui(ui);
        self.darts_ui(ui);
        ui.separator();
        self.dots_ui(ui);
        self.view_ui(ui);
    }

    /// The title, Undo and Reset (always in reach, however long the
    /// panel), and the help button.
    fn header_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.heading("PixelPie");
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if ui
                    .button("?")
                    .on_hover_text("Keyboard shortcuts (F1)")
                    .clicked()
                {
                    self.show_help = !self.show_help;
                }
                if ui
                    .button("Reset")
                    .on_hover_text("Every control back to its default (Undo brings them back)")
                    .clicked()
                {
                    self.reset_settings();
                }
                if ui
                    .button("Undo")
                    .on_hover_text("Undo the last settings change (Ctrl+Z)")
                    .clicked()
                {
                    self.undo();
                }
            });
        });
    }

    /// The Open row, its error and the picture's name.
    fn open_ui(&mut self, ui: &mut egui::Ui) {
        ui.label("Drop an image or EXR on the window, or open one:");
        ui.horizontal(|ui| {
            let edit = ui
                .add(egui::TextEdit::singleline(&mut self.open_path).desired_width(130.0))
                .on_hover_text(
                    "The path of an image (PNG, JPEG, TIFF, BMP, WebP) or OpenEXR; ~/ and \
                     file:// work",
                );
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui
                .button("Open")
                .on_hover_text("Open the image at the typed path")
                .clicked()
                || enter
            {
                let path = super::typed_path(&self.open_path);
                let ctx = ui.ctx().clone();
                self.open(&ctx, &path);
            }
            if ui
                .button("Browse…")
                .on_hover_text("Choose an image with a file dialog (Ctrl+O)")
                .clicked()
            {
                let ctx = ui.ctx().clone();
                self.open_dialog(&ctx);
            }
        });
        if let Some(e) = &self.open_error {
            ui.colored_label(Color32::from_rgb(200, 40, 40), e);
        }
        if let Some(name) = self.loading_name() {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(format!("decoding {name}…"));
            });
        } else if let Some(src) = &self.source {
            ui.label(format!(
                "{} ({}×{})",
                src.path.as_ref().map_or_else(
                    || super::DEFAULT_IMAGE_NAME.to_owned(),
                    |p| p
                        .file_name()
                        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
                ),
                src.map.width(),
                src.map.height()
            ));
        }
    }

    /// Count or radius range, mapping, tones, policy and exact spacing.
    fn spacing_ui(&mut self, ui: &mut egui::Ui) {
        let s = &mut self.settings;
        ui.horizontal(|ui| {
            ui.radio_value(&mut s.use_count, true, "Point count")
                .on_hover_text("Aim for a number of dots; the radii scale to fit it");
            ui.radio_value(&mut s.use_count, false, "Radius range")
                .on_hover_text(
                    "Use the radius range as it is, in domain pixels (the picture scaled \
                     as pixelpie stipple scales it: longer side 1024 px or more)",
                );
        });
        ui.add_enabled_ui(s.use_count, |ui| {
            ui.horizontal(|ui| {
                let l = ui.label("Points");
                ui.add(
                    egui::DragValue::new(&mut s.points)
                        .range(10..=2_000_000)
                        .speed(50),
                )
                .labelled_by(l.id)
                .on_hover_text("How many dots the drawing has (within 3%)");
            });
        });
        let imp = &mut s.job.importance;
        let mut lo = imp.min_radius.unwrap_or(1.0);
        let mut hi = imp
            .max_radius
            .unwrap_or(lo * crate::importance::DEFAULT_RADIUS_RATIO);
        let (lo0, hi0) = (lo, hi);
        ui.horizontal(|ui| {
            let l = ui.label("Radius");
            ui.add(
                egui::DragValue::new(&mut lo)
                    .range(1.0..=500.0)
                    .speed(0.05)
                    .prefix("min "),
            )
            .labelled_by(l.id)
            .on_hover_text("Disk radius in black areas: the closest dots");
            ui.add(
                egui::DragValue::new(&mut hi)
                    .range(1.0..=500.0)
                    .speed(0.05)
                    .prefix("max "),
            )
            .on_hover_text("Disk radius in white areas: the sparsest dots");
        });
        if lo != lo0 || hi != hi0 {
            imp.min_radius = Some(lo);
            imp.max_radius = Some(hi.max(lo));
        }
        let mut tone = imp.mapping != Some(MappingKind::Linear);
        egui::ComboBox::from_label("Mapping")
            .selected_text(if tone { "Tone" } else { "Linear" })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut tone, true, "Tone")
                    .on_hover_text("Calibrated: the drawing's ink equals the picture's darkness.");
                ui.selectable_value(&mut tone, false, "Linear")
                    .on_hover_text("The paper's ramp r_min + (r_max − r_min)·v.");
            })
            .response
            .on_hover_text("How a pixel's grey becomes its disk radius");
        imp.mapping = (!tone).then_some(MappingKind::Linear);
        egui::ComboBox::from_label("Tones")
            .selected_text(match imp.tones {
                Tones::Display => "Display grey",
                Tones::Linear => "Linear light",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut imp.tones, Tones::Display, "Display grey")
                    .on_hover_text("Reproduce the grey a viewer sees (sRGB values).");
                ui.selectable_value(&mut imp.tones, Tones::Linear, "Linear light")
                    .on_hover_text("Reproduce luminance: mid tones come out darker.");
            })
            .response
            .on_hover_text("Which grey the ink reproduces");
        let job = &mut s.job;
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("Policy")
                .selected_text(format!("{:?}", job.policy))
                .show_ui(ui, |ui| {
                    for p in Policy::ALL {
                        ui.selectable_value(&mut job.policy, p, format!("{p:?}"))
                            .on_hover_text(policy_help(p));
                    }
                })
                .response
                .on_hover_text(
                    "The disk policy (paper §3.4): how far apart two dots of different \
                     sizes must be. Smaller keeps dark areas crisp; Bigger keeps light \
                     areas open.",
                );
            ui.checkbox(&mut job.sampler.exact, "Exact spacing")
                .on_hover_text(
                    "No two dot centres closer than the policy allows, not even by a \
                     fraction of a pixel, and no gap left that a dot would fit in (exact \
                     mode; about half the speed)",
                );
        });
    }

    /// Levels, gamma, invert and the white cutoff.
    fn levels_ui(&mut self, ui: &mut egui::Ui) {
        let imp = &mut self.settings.job.importance;
        ui.add(
            egui::Slider::new(&mut imp.gamma, 0.2..=5.0)
                .logarithmic(true)
                .text("Gamma"),
        )
        .on_hover_text("Above 1 darkens the mid tones, below 1 lightens them");
        ui.add(egui::Slider::new(&mut imp.black_level, 0.0..=0.95).text("Black level"))
            .on_hover_text("Greys at or below this count as black");
        ui.add(egui::Slider::new(&mut imp.white_level, 0.05..=1.0).text("White level"))
            .on_hover_text("Greys at or above this count as white");
        imp.white_level = imp.white_level.max(imp.black_level + 0.01);
        ui.checkbox(&mut imp.invert, "Invert")
            .on_hover_text("Light parts get the dots (white ink on black paper)");
        let mut cutoff = imp.white_cutoff.unwrap_or(1.0);
        ui.add(egui::Slider::new(&mut cutoff, 0.0..=1.0).text("White cutoff"))
            .on_hover_text("No dots where the picture is lighter than this (1 = off)");
        imp.white_cutoff = (cutoff < 1.0).then_some(cutoff);
    }

    /// Sub-pixel bits, seed, periodic domain and backend.
    fn darts_ui(&mut self, ui: &mut egui::Ui) {
        let sampler = &mut self.settings.job.sampler;
        ui.add_enabled(
            !sampler.exact,
            egui::Slider::new(&mut sampler.subpixel_bits, 0..=7).text("Sub-pixel bits"),
        )
        .on_hover_text(
            "Dart positions inside a pixel: 0 puts every dot on a pixel centre (the \
             paper's darts, a faint grid); each bit halves the grid's spacing",
        )
        .on_disabled_hover_text("Exact spacing places darts anywhere, to 1/2^F px");
        let mut reroll = false;
        ui.horizontal(|ui| {
            let l = ui.label("Seed");
            // Re-roll comes first, so that it stays put as the seed grows.
            if ui
                .button("Re-roll")
                .on_hover_text("Another seed: another drawing of the same picture (R)")
                .clicked()
            {
                reroll = true;
            }
            ui.add(egui::DragValue::new(&mut sampler.seed))
                .labelled_by(l.id)
                .on_hover_text("The dart hash's seed: the same seed gives the same dots");
        });
        if reroll {
            self.reroll();
        }
        let s = &mut self.settings;
        ui.checkbox(&mut s.job.sampler.periodic, "Periodic (tileable)")
            .on_hover_text(
                "Wrap the domain around: copies of the drawing tile without seams or crowding",
            );
        ui.add_enabled(
            s.job.sampler.periodic,
            egui::Checkbox::new(&mut s.tile, "Show 2×2 tiles"),
        )
        .on_hover_text("Preview four copies side by side: the seams should vanish");
        egui::ComboBox::from_label("Backend")
            .selected_text(format!("{:?}", s.backend))
            .show_ui(ui, |ui| {
                for b in [BackendChoice::Auto, BackendChoice::Gpu, BackendChoice::Cpu] {
                    ui.selectable_value(&mut s.backend, b, format!("{b:?}"));
                }
            })
            .response
            .on_hover_text(
                "Where the sampler runs: the GPU (wgpu) or the CPU; Auto picks the CPU on \
                 software adapters. Both give the same dots.",
            );
        ui.label(format!(
            "Adapter: {}",
            self.worker.adapter().unwrap_or("none (CPU only)")
        ));
    }

    /// Dot mode, size, ratio, relaxation and ink. Every row stays in place
    /// whatever the mode: rows that do not apply are greyed out.
    fn dots_ui(&mut self, ui: &mut egui::Ui) {
        let job = &mut self.settings.job;
        let mut mode = job.dot_mode();
        egui::ComboBox::from_label("Dots")
            .selected_text(format!("{mode:?}"))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut mode, DotMode::Fixed, "Fixed")
                    .on_hover_text("All dots alike; their density follows the tones.");
                ui.selectable_value(&mut mode, DotMode::Sized, "Sized")
                    .on_hover_text("Small dots in light areas, larger in dark ones.");
                ui.selectable_value(&mut mode, DotMode::Proportional, "Proportional")
                    .on_hover_text("A fraction of each sample's disk: a texture, not tones.");
            })
            .response
            .on_hover_text("How big each dot is drawn");
        if mode != job.dot_mode() {
            job.dot = Some(mode);
            // Each mode has its own default factor.
            job.dot_factor = None;
        }
        let mut factor = job.dot_factor.unwrap_or(mode.default_factor());
        let (range, text, help) = match mode {
            DotMode::Fixed | DotMode::Sized => (
                0.3..=2.0,
                "Dot size (× calibrated)",
                "1 reproduces the picture's tones; more darkens, less lightens.",
            ),
            DotMode::Proportional => (
                0.05..=1.0,
                "Dot size (× disk)",
                "The dot's radius as a fraction of its disk's",
            ),
        };
        if ui
            .add(egui::Slider::new(&mut factor, range).text(text))
            .on_hover_text(help)
            .changed()
        {
            job.dot_factor = Some(factor);
        }
        ui.add_enabled(
            mode == DotMode::Sized,
            egui::Slider::new(&mut job.dot_ratio, 0.1..=1.0).text("Lightest / darkest dot"),
        )
        .on_hover_text("The lightest dots' radius as a fraction of the darkest dots'")
        .on_disabled_hover_text("Sized dots only");
        ui.add(egui::Slider::new(&mut job.relax, 0..=30).text("Relax (Lloyd steps)"))
            .on_hover_text("Weighted Voronoi relaxation after sampling: more even spacing.");
        ink_ui(ui, &mut job.ink.0);
    }

    /// What is behind the dots, the coverage disks and the view's buttons.
    fn view_ui(&mut self, ui: &mut egui::Ui) {
        let s = &mut self.settings;
        ui.horizontal(|ui| {
            ui.label("Behind");
            ui.selectable_value(&mut s.background, Background::Paper, "Paper")
                .on_hover_text("White paper behind the dots");
            ui.selectable_value(&mut s.background, Background::Importance, "Map")
                .on_hover_text("The grey the dots reproduce, after levels and gamma");
            ui.selectable_value(&mut s.background, Background::Photo, "Photo")
                .on_hover_text("The original picture, faded");
        });
        ui.checkbox(&mut s.show_coverage, "Coverage disks (Figure 4)")
            .on_hover_text(
                "Each sample's disk in blue (the paper's Figure 4): where the disks overlap \
                 and how the set covers the picture",
            );
        if ui
            .button("Fit view")
            .on_hover_text("Fit the picture in the view (F); + and − zoom")
            .clicked()
        {
            self.view.fit_next = true;
        }
    }

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
            ui.spinner();
            ui.label(self.progress_shown().unwrap_or_default());
            if ui
                .button("Cancel")
                .on_hover_text("Stop this sampling or relaxation; keep the last drawing.")
                .clicked()
            {
                cancel = true;
            }
        });
        if cancel {
            self.cancel_job();
        }
        let (a, b, c) = match &self.outcome {
            Some(o) => {
                let d = &o.drawing;
                let st = &d.set.stats;
                let (_, t_sample, t_relax) = d.seconds;
                (
                    format!(
                        "{} dots, {} iterations, {} run(s) in {:.2} s",
                        d.points.len(),
                        st.iterations,
                        d.runs,
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
        ui.label(a)
            .on_hover_text("The last drawing: dots, sampler iterations and runs");
        ui.label(b).on_hover_text(
            "The paper's stages: S1 throws darts, S2 culls the conflicting ones, PP \
             compacts the still-empty pixels",
        );
        ui.label(c);
        let note = match (&self.error, self.status.is_empty()) {
            (Some(e), _) => (Color32::from_rgb(200, 40, 40), format!("Error: {e}")),
            (None, false) => (ui.visuals().text_color(), self.status.clone()),
            (None, true) => (ui.visuals().text_color(), String::new()),
        };
        ui.colored_label(note.0, note.1);
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
        Some(match (&self.progress, self.relaxed) {
            (_, Some(done)) => {
                format!(
                    "relaxing: {done} of {} steps{elapsed}",
                    self.settings.job.relax
                )
            }
            (Some(p), None) => format!(
                "iteration {}, {:.0}% covered{elapsed}",
                p.iteration,
                100.0 - 100.0 * p.empty_pixels as f64 / p.pixels.max(1) as f64
            ),
            (None, None) => format!("sampling{elapsed}"),
        })
    }

    /// Under the Export row: the file written, or why not, on one line of
    /// fixed height (the whole text on hover), so that nothing above moves.
    fn export_result_ui(&self, ui: &mut egui::Ui) {
        let (text, color) = match (&self.export_error, &self.exported) {
            (Some(e), _) => (e.clone(), Color32::from_rgb(200, 40, 40)),
            (None, Some(p)) => (format!("wrote {}", p.display()), ui.visuals().text_color()),
            (None, None) => (String::new(), ui.visuals().text_color()),
        };
        fixed_row(ui, true, |ui| {
            let label = egui::Label::new(egui::RichText::new(&text).color(color)).truncate();
            let r = ui.add(label);
            if !text.is_empty() {
                r.on_hover_text(&text);
            }
        });
    }

    /// The Export section: plotter options, the path, the format buttons
    /// and the outcome. The job's `write` writes every format, as the CLI's.
    pub(super) fn export_ui(&mut self, ui: &mut egui::Ui) {
        let job = &mut self.settings.job;
        ui.horizontal(|ui| {
            ui.label("Order");
            ui.selectable_value(&mut job.order, Order::None, "As sampled")
                .on_hover_text("The sampler's order");
            ui.selectable_value(&mut job.order, Order::Tsp, "Plotter (TSP)")
                .on_hover_text("A short pen path (nearest neighbour and 2-opt), as --order tsp");
        });
        ui.horizontal(|ui| {
            let mut mm = job.width_mm.is_some();
            ui.checkbox(&mut mm, "Width mm")
                .on_hover_text("Size the SVG in millimetres (--width-mm); off: pixels");
            let mut width = job.width_mm.unwrap_or(200.0);
            ui.add_enabled(
                mm,
                egui::DragValue::new(&mut width)
                    .range(1.0..=5000.0)
                    .speed(1.0),
            );
            job.width_mm = mm.then_some(width);
            let mut pen = job.pen_mm.is_some();
            ui.add_enabled(mm, egui::Checkbox::new(&mut pen, "Pen mm"))
                .on_hover_text("Draw each dot as a pen of this width draws it (--pen-mm)")
                .on_disabled_hover_text("Needs a width in mm");
            let mut pen_mm = job.pen_mm.unwrap_or(0.3);
            ui.add_enabled(
                mm && pen,
                egui::DragValue::new(&mut pen_mm)
                    .range(0.05..=5.0)
                    .speed(0.01),
            );
            job.pen_mm = (mm && pen).then_some(pen_mm);
        });
        ui.horizontal(|ui| {
            ui.label("Export to");
            if ui
                .button("Browse…")
                .on_hover_text("Choose where to export with a file dialog (Ctrl+S)")
                .clicked()
            {
                self.export_dialog();
            }
        });
        ui.add(egui::TextEdit::singleline(&mut self.export_path).desired_width(250.0))
            .on_hover_text("The file to write; the button picks the format");
        ui.horizontal(|ui| {
            for (ext, what) in [
                ("svg", "The drawing as SVG (browsers, Inkscape, plotters)"),
                ("png", "The drawing as PNG, at the scale set here"),
                ("csv", "The dots' centres and radii as CSV"),
                ("json", "The dots and the settings as JSON"),
            ] {
                if ui.button(ext.to_uppercase()).on_hover_text(what).clicked() {
                    self.export_as(ext);
                }
            }
            ui.add(
                egui::DragValue::new(&mut self.settings.job.scale)
                    .range(0.1..=8.0)
                    .speed(0.05)
                    .prefix("PNG ×"),
            )
            .on_hover_text("PNG pixels per sampled pixel");
        });
        self.export_result_ui(ui);
    }

    /// Copies of the drawing per side in the view: 2 for a periodic drawing
    /// shown tiled, else 1.
    #[must_use]
    pub fn tiles(&self) -> usize {
        if self.settings.periodic() && self.settings.tile {
            2
        } else {
            1
        }
    }

    /// Zooms the view by `factor` about the canvas's centre.
    pub fn zoom_by(&mut self, factor: f32) {
        let c = self.view.canvas / 2.0;
        self.view.pan = c - (c - self.view.pan) * factor;
        self.view.zoom *= factor;
        self.view.fitted = false;
    }

    /// Points per image pixel in the view.
    #[must_use]
    pub fn zoom(&self) -> f32 {
        self.view.zoom
    }

    /// Exports to the export path with extension `ext`; the outcome shows
    /// under the Export row.
    pub fn export_as(&mut self, ext: &str) {
        let typed = self.export_path.trim();
        if typed.is_empty() {
            self.export_error = Some("no file name given: type one or use Browse".into());
            return;
        }
        let path = super::typed_path(typed).with_extension(ext);
        match self.export(&path) {
            Ok(()) => {
                let full = std::fs::canonicalize(&path).unwrap_or(path);
                if let Some(dir) = full.parent() {
                    self.settings.last_dir = Some(dir.to_path_buf());
                }
                self.export_path = full.display().to_string();
                self.exported = Some(full);
                self.export_error = None;
            }
            Err(e) => {
                self.exported = None;
                self.export_error = Some(crate::text::one_line(&e));
            }
        }
    }

    /// How big the dots are drawn and exported.
    pub fn dot_size(&self) -> DotSize {
        self.settings.job().dot_size()
    }

    /// The dots as drawn: the view's and the exports'.
    pub fn drawn_dots(&self) -> Vec<crate::stipple::Dot> {
        self.outcome
            .as_ref()
            .map_or_else(Vec::new, |o| self.settings.job().dots(&o.drawing))
    }

    /// Writes the current drawing with the job's writer, the CLI's, picked
    /// by extension (any case).
    pub fn export(&self, path: &std::path::Path) -> crate::Result<()> {
        let Some(o) = &self.outcome else {
            return Err(
                crate::stipple::Error::InvalidParameter("nothing to export yet".into()).into(),
            );
        };
        self.settings.job().write(&o.drawing, path)
    }

    /// The zoomable canvas: the paper (or the picture) and the dots.
    pub(super) fn canvas(&mut self, ui: &mut egui::Ui) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, Color32::from_gray(90));
        let Some(src) = &self.source else {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "Drop an image here",
                egui::FontId::proportional(20.0),
                Color32::WHITE,
            );
            return;
        };
        let size = Vec2::new(src.map.width() as f32, src.map.height() as f32);
        self.navigate(ui, rect, &response, size);
        // A periodic drawing can show 2×2 copies: the seams should vanish.
        let tiles = self.tiles();
        let offsets: Vec<Vec2> = (0..tiles * tiles)
            .map(|t| Vec2::new((t % tiles) as f32 * size.x, (t / tiles) as f32 * size.y))
            .collect();
        self.paint_backgrounds(&painter, rect, &offsets, size);
        let layers = self.dot_layers(ui, rect, &offsets);
        self.paint_dots(&painter, rect, layers);
    }

    /// Fits the view when asked (or when a fitted view's canvas or tiling
    /// changes), zooms about the pointer and pans by dragging.
    fn navigate(&mut self, ui: &egui::Ui, rect: Rect, response: &egui::Response, size: Vec2) {
        if self.view.fitted && self.view.canvas != rect.size() {
            self.view.fit_next = true;
        }
        self.view.canvas = rect.size();
        let tiles = self.tiles();
        if self.view.tiles != tiles {
            self.view.tiles = tiles;
            self.view.fit_next = true;
        }
        if self.view.fit_next {
            let all = size * tiles as f32;
            self.view.zoom = (rect.width() / all.x).min(rect.height() / all.y) * 0.98;
            self.view.pan = (rect.size() - all * self.view.zoom) / 2.0;
            self.view.fit_next = false;
            self.view.fitted = true;
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                let factor = (scroll / 200.0).exp();
                let pointer =
                    ui.input(|i| i.pointer.hover_pos()).unwrap_or(rect.center()) - rect.min;
                self.view.pan = pointer - (pointer - self.view.pan) * factor;
                self.view.zoom *= factor;
                self.view.fitted = false;
            }
        }
        if response.drag_delta() != Vec2::ZERO {
            self.view.pan += response.drag_delta();
            self.view.fitted = false;
        }
    }

    /// The paper under each copy, and the map or the photo when asked.
    fn paint_backgrounds(&self, painter: &egui::Painter, rect: Rect, offsets: &[Vec2], size: Vec2) {
        let Some(src) = &self.source else { return };
        let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        for off in offsets {
            let image_rect = Rect::from_min_size(
                rect.min + self.view.pan + *off * self.view.zoom,
                size * self.view.zoom,
            );
            painter.rect_filled(image_rect, 0.0, Color32::WHITE);
            match self.settings.background {
                Background::Paper => {}
                Background::Importance => {
                    painter.image(src.importance.id(), image_rect, uv, Color32::WHITE);
                }
                Background::Photo => {
                    painter.image(
                        src.photo.id(),
                        image_rect,
                        uv,
                        Color32::from_white_alpha(150),
                    );
                }
            }
        }
    }

    /// The dot layers of each copy: the coverage disks when asked, then
    /// the dots in the ink, sized as the job draws them.
    fn dot_layers(&self, ui: &egui::Ui, rect: Rect, offsets: &[Vec2]) -> Vec<DotLayer> {
        let s = &self.settings;
        let [r, g, b] = s.job.ink.0;
        let size = self.dot_size();
        let base = ViewUniform {
            rect: [rect.width(), rect.height()],
            scale: self.view.zoom,
            pixels_per_point: ui.ctx().pixels_per_point(),
            offset: [self.view.pan.x, self.view.pan.y],
            radius_scale: match size {
                DotSize::Proportional(f) => f,
                DotSize::Fixed(_) | DotSize::Calibrated(_) => 0.0,
            },
            drawn_scale: match size {
                DotSize::Calibrated(f) => f,
                DotSize::Fixed(_) | DotSize::Proportional(_) => 0.0,
            },
            color: [
                f32::from(r) / 255.0,
                f32::from(g) / 255.0,
                f32::from(b) / 255.0,
                1.0,
            ],
        };
        let mut layers = Vec::new();
        for (t, off) in offsets.iter().enumerate() {
            let pan = self.view.pan + *off * self.view.zoom;
            let base = ViewUniform {
                offset: [pan.x, pan.y],
                ..base
            };
            if s.show_coverage {
                layers.push(DotLayer {
                    dots: self.dot_instances.clone(),
                    generation: self.dots_generation,
                    view: ViewUniform {
                        radius_scale: 1.0,
                        drawn_scale: 0.0,
                        color: [0.2, 0.45, 0.9, 0.18],
                        ..base
                    },
                    slot: 2 * t,
                });
            }
            layers.push(DotLayer {
                dots: self.dot_instances.clone(),
                generation: self.dots_generation,
                view: base,
                slot: 2 * t + 1,
            });
        }
        layers
    }

    /// Draws the layers on the GPU (egui_wgpu callbacks), or with egui's
    /// own shapes where there is no wgpu renderer (a glow build).
    fn paint_dots(&self, painter: &egui::Painter, rect: Rect, layers: Vec<DotLayer>) {
        for layer in layers {
            if self.gpu_dots {
                painter.add(egui_wgpu::Callback::new_paint_callback(rect, layer));
                continue;
            }
            let color = Color32::from_rgba_unmultiplied(
                (layer.view.color[0] * 255.0) as u8,
                (layer.view.color[1] * 255.0) as u8,
                (layer.view.color[2] * 255.0) as u8,
                (layer.view.color[3] * 255.0) as u8,
            );
            let pan = Vec2::new(layer.view.offset[0], layer.view.offset[1]);
            for d in layer.dots.iter() {
                let radius = d.radius * layer.view.radius_scale + d.drawn * layer.view.drawn_scale;
                let c = rect.min + pan + Vec2::new(d.x, d.y) * self.view.zoom;
                painter.circle_filled(c, (radius * self.view.zoom).max(0.5), color);
            }
        }
    }
}

/// A row at least one control high and the panel's width (at most, with
/// `clip`), whatever `add` puts in it, so that the rows around it stay put.
fn fixed_row(ui: &mut egui::Ui, clip: bool, add: impl FnOnce(&mut egui::Ui)) {
    let row = egui::vec2(ui.available_width(), ui.spacing().interact_size.y);
    ui.allocate_ui_with_layout(
        row,
        egui::Layout::left_to_right(egui::Align::Center),
        |ui| {
            ui.set_min_size(row);
            if clip {
                ui.set_max_size(row);
            }
            add(ui);
        },
    );
}

/// What a disk policy does to a drawing, in plain words.
fn policy_help(p: Policy) -> &'static str {
    match p {
        Policy::Prior => {
            "Prior: the earlier dot's disk decides. Dots placed first keep their space;              edges between light and dark areas blur a little."
        }
        Policy::Current => {
            "Current: the new dot's disk decides. Small dots may crowd up to larger ones."
        }
        Policy::Bigger => {
            "Bigger: the larger disk decides. Light areas stay open; dark areas near them              thin out."
        }
        Policy::Smaller => {
            "Smaller: the smaller disk decides. Dark areas stay dense up to their edges (the              paper's choice for stippling)."
        }
    }
}

/// Ink colours offered as swatches.
const INKS: &[(&str, [u8; 3])] = &[
    ("Black", [0, 0, 0]),
    ("Graphite", [70, 70, 75]),
    ("Sepia", [112, 66, 20]),
    ("Indigo", [40, 40, 110]),
    ("Red", [190, 30, 30]),
];

/// The dot colour: swatches and R, G, B values (drawn with the bundled
/// fonts' glyphs only).
fn ink_ui(ui: &mut egui::Ui, ink: &mut [u8; 3]) {
    ui.horizontal(|ui| {
        ui.label("Dot colour")
            .on_hover_text("The ink, on screen and in the exports");
        for (name, rgb) in INKS {
            let (rect, resp) = ui.allocate_exact_size(egui::vec2(16.0, 16.0), Sense::click());
            let [r, g, b] = *rgb;
            let stroke = if ink == rgb {
                egui::Stroke::new(2.0, ui.visuals().strong_text_color())
            } else {
                egui::Stroke::new(1.0, Color32::GRAY)
            };
            ui.painter()
                .rect_filled(rect, 2.0, Color32::from_rgb(r, g, b));
            ui.painter()
                .rect_stroke(rect, 2.0, stroke, egui::StrokeKind::Inside);
            resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Button, true, *name));
            if resp.on_hover_text(*name).clicked() {
                *ink = *rgb;
            }
        }
    });
    ui.horizontal(|ui| {
        for (i, c) in ["R ", "G ", "B "].into_iter().enumerate() {
            ui.add(egui::DragValue::new(&mut ink[i]).prefix(c))
                .on_hover_text("The ink's red, green and blue (0 to 255)");
        }
    });
}
