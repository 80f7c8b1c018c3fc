//! The side panel's controls, the zoomable canvas and the exports.

use std::path::PathBuf;

use egui::{Color32, Rect, Sense, Vec2};

use super::PixelPieApp;
use super::dots::{DotLayer, ViewUniform};
use super::settings::{Background, DotMode};
use crate::backend::BackendChoice;
use crate::importance::Tones;
use crate::sampler::Policy;
use crate::stipple::{DotSize, raster, svg};

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
}

impl Default for ViewState {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            pan: Vec2::ZERO,
            fit_next: true,
            canvas: Vec2::ZERO,
            tiles: 1,
        }
    }
}

impl PixelPieApp {
    pub(super) fn controls(&mut self, ui: &mut egui::Ui) {
        ui.set_width(270.0);
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
            });
        });
        ui.label("Drop an image or EXR on the window, or open one:");
        ui.horizontal(|ui| {
            let edit = ui
                .add(egui::TextEdit::singleline(&mut self.open_path).desired_width(130.0))
                .on_hover_text("The path of an image (PNG, JPEG, TIFF, BMP, WebP) or OpenEXR");
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui
                .button("Open")
                .on_hover_text("Open the image at the typed path")
                .clicked()
                || enter
            {
                let path = PathBuf::from(self.open_path.trim());
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
        if let Some(src) = &self.source {
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
        ui.separator();
        let s = &mut self.settings;
        ui.horizontal(|ui| {
            ui.radio_value(&mut s.use_count, true, "Point count")
                .on_hover_text("Aim for a number of dots; the radii scale to fit it");
            ui.radio_value(&mut s.use_count, false, "Radius range")
                .on_hover_text("Use the radius range as it is, in image pixels");
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
        ui.horizontal(|ui| {
            let l = ui.label("Radius");
            ui.add(
                egui::DragValue::new(&mut s.r_min)
                    .range(1.0..=500.0)
                    .speed(0.05)
                    .prefix("min "),
            )
            .labelled_by(l.id)
            .on_hover_text("Disk radius in black areas: the closest dots");
            ui.add(
                egui::DragValue::new(&mut s.r_max)
                    .range(1.0..=500.0)
                    .speed(0.05)
                    .prefix("max "),
            )
            .on_hover_text("Disk radius in white areas: the sparsest dots");
        });
        s.r_max = s.r_max.max(s.r_min);
        egui::ComboBox::from_label("Mapping")
            .selected_text(if s.tone { "Tone" } else { "Linear" })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.tone, true, "Tone")
                    .on_hover_text("Calibrated: the drawing's ink equals the picture's darkness.");
                ui.selectable_value(&mut s.tone, false, "Linear")
                    .on_hover_text("The paper's ramp r_min + (r_max − r_min)·v.");
            })
            .response
            .on_hover_text("How a pixel's grey becomes its disk radius");
        egui::ComboBox::from_label("Tones")
            .selected_text(match s.tones {
                Tones::Display => "Display grey",
                Tones::Linear => "Linear light",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.tones, Tones::Display, "Display grey")
                    .on_hover_text("Reproduce the grey a viewer sees (sRGB values).");
                ui.selectable_value(&mut s.tones, Tones::Linear, "Linear light")
                    .on_hover_text("Reproduce luminance: mid tones come out darker.");
            })
            .response
            .on_hover_text("Which grey the ink reproduces");
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("Policy")
                .selected_text(format!("{:?}", s.policy))
                .show_ui(ui, |ui| {
                    for p in Policy::ALL {
                        ui.selectable_value(&mut s.policy, p, format!("{p:?}"))
                            .on_hover_text(policy_help(p));
                    }
                })
                .response
                .on_hover_text(
                    "The disk policy (paper §3.4): how far apart two dots of different \
                     sizes must be. Smaller keeps dark areas crisp; Bigger keeps light \
                     areas open.",
                );
            ui.checkbox(&mut s.exact, "Exact spacing").on_hover_text(
                "No two dot centres closer than the policy allows, not even by a \
                 fraction of a pixel, and no gap left that a dot would fit in (exact \
                 mode; about half the speed)",
            );
        });
        ui.add(
            egui::Slider::new(&mut s.gamma, 0.2..=5.0)
                .logarithmic(true)
                .text("Gamma"),
        )
        .on_hover_text("Above 1 darkens the mid tones, below 1 lightens them");
        ui.add(egui::Slider::new(&mut s.black, 0.0..=0.95).text("Black level"))
            .on_hover_text("Greys at or below this count as black");
        ui.add(egui::Slider::new(&mut s.white, 0.05..=1.0).text("White level"))
            .on_hover_text("Greys at or above this count as white");
        s.white = s.white.max(s.black + 0.01);
        ui.checkbox(&mut s.invert, "Invert")
            .on_hover_text("Light parts get the dots (white ink on black paper)");
        ui.add(egui::Slider::new(&mut s.cutoff, 0.0..=1.0).text("White cutoff"))
            .on_hover_text("No dots where the picture is lighter than this (1 = off)");
        ui.add_enabled(
            !s.exact,
            egui::Slider::new(&mut s.subpixel_bits, 0..=7).text("Sub-pixel bits"),
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
            ui.add(egui::DragValue::new(&mut s.seed))
                .labelled_by(l.id)
                .on_hover_text("The dart hash's seed: the same seed gives the same dots");
        });
        if reroll {
            self.reroll();
        }
        let s = &mut self.settings;
        ui.checkbox(&mut s.periodic, "Periodic (tileable)")
            .on_hover_text(
                "Wrap the domain around: copies of the drawing tile without seams or crowding",
            );
        ui.add_enabled(
            s.periodic,
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
        ui.separator();
        let s = &mut self.settings;
        egui::ComboBox::from_label("Dots")
            .selected_text(format!("{:?}", s.dot_mode))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.dot_mode, DotMode::Fixed, "Fixed")
                    .on_hover_text("All dots alike; their density follows the tones.");
                ui.selectable_value(&mut s.dot_mode, DotMode::Sized, "Sized")
                    .on_hover_text("Small dots in light areas, larger in dark ones.");
                ui.selectable_value(&mut s.dot_mode, DotMode::Proportional, "Proportional")
                    .on_hover_text("A fraction of each sample's disk: a texture, not tones.");
            })
            .response
            .on_hover_text("How big each dot is drawn");
        match s.dot_mode {
            DotMode::Fixed | DotMode::Sized => {
                ui.add(
                    egui::Slider::new(&mut s.dot_factor, 0.3..=2.0).text("Dot size (× calibrated)"),
                )
                .on_hover_text("1 reproduces the picture's tones; more darkens, less lightens.");
            }
            DotMode::Proportional => {
                ui.add(egui::Slider::new(&mut s.dot_scale, 0.05..=1.0).text("Dot size (× disk)"))
                    .on_hover_text("The dot's radius as a fraction of its disk's");
            }
        }
        if s.dot_mode == DotMode::Sized {
            ui.add(egui::Slider::new(&mut s.dot_ratio, 0.1..=1.0).text("Lightest / darkest dot"))
                .on_hover_text("The lightest dots' radius as a fraction of the darkest dots'");
        }
        ui.add(egui::Slider::new(&mut s.relax, 0..=30).text("Relax (Lloyd steps)"))
            .on_hover_text("Weighted Voronoi relaxation after sampling: more even spacing.");
        ink_ui(ui, &mut s.dot_color);
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
        ui.horizontal(|ui| {
            if ui
                .button("Fit view")
                .on_hover_text("Fit the picture in the view (F); + and − zoom")
                .clicked()
            {
                self.view.fit_next = true;
            }
            if ui
                .button("Undo")
                .on_hover_text("Undo the last settings change (Ctrl+Z)")
                .clicked()
            {
                self.undo();
            }
            if ui
                .button("Reset")
                .on_hover_text("Every control back to its default (Undo brings them back)")
                .clicked()
            {
                self.reset_settings();
            }
        });
    }

    /// Progress and statistics, in a place of fixed height.
    pub(super) fn stats_ui(&mut self, ui: &mut egui::Ui) {
        let mut cancel = false;
        let row = egui::vec2(ui.available_width(), ui.spacing().interact_size.y);
        ui.allocate_ui_with_layout(
            row,
            egui::Layout::left_to_right(egui::Align::Center),
            |ui| {
                ui.set_min_size(row);
                if !self.busy() {
                    ui.label(if self.outcome.is_some() { "ready" } else { "" });
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
            },
        );
        if cancel {
            self.cancel_job();
        }
        let (a, b, c) = match &self.outcome {
            Some(o) => {
                let st = &o.set.stats;
                (
                    format!(
                        "{} dots, {} iterations, {} run(s) in {:.2} s",
                        o.set.points.len(),
                        st.iterations,
                        o.runs,
                        o.seconds
                    ),
                    format!(
                        "last run: S1 {:.1} ms, S2 {:.1} ms, PP {:.1} ms, total {:.1} ms",
                        st.stages.get("throw") * 1e3,
                        st.stages.get("cull") * 1e3,
                        st.stages.get("compact") * 1e3,
                        st.seconds * 1e3
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
                format!("relaxing: {done} of {} steps{elapsed}", self.settings.relax)
            }
            (Some(p), None) => format!(
                "iteration {}, {:.0}% covered{elapsed}",
                p.iteration,
                100.0 - 100.0 * p.empty_pixels as f64 / p.pixels.max(1) as f64
            ),
            (None, None) => format!("sampling{elapsed}"),
        })
    }

    /// Under the Export row: the file written, or why not.
    fn export_result_ui(&self, ui: &mut egui::Ui) {
        if let Some(e) = &self.export_error {
            ui.colored_label(Color32::from_rgb(200, 40, 40), e);
        } else if let Some(p) = &self.exported {
            ui.label(format!("wrote {}", p.display()));
        } else {
            ui.label("");
        }
    }

    pub(super) fn export_ui(&mut self, ui: &mut egui::Ui) {
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
                egui::DragValue::new(&mut self.settings.png_scale)
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
        if self.settings.periodic && self.settings.tile {
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
        let path = PathBuf::from(typed).with_extension(ext);
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
                self.export_error = Some(format!("{e:#}"));
            }
        }
    }

    /// How big the dots are drawn and exported.
    pub fn dot_size(&self) -> DotSize {
        let s = &self.settings;
        s.dot_mode.size(match s.dot_mode {
            DotMode::Proportional => s.dot_scale,
            DotMode::Fixed | DotMode::Sized => s.dot_factor,
        })
    }

    /// The dots as drawn: the view's and the exports'.
    pub fn drawn_dots(&self) -> Vec<crate::stipple::Dot> {
        let Some(o) = &self.outcome else {
            return Vec::new();
        };
        let size = self.dot_size();
        o.set
            .points
            .iter()
            .zip(&o.calibrated)
            .map(|(p, &c)| size.dots(std::slice::from_ref(p), |_| c)[0])
            .collect()
    }

    /// Writes the current stipple with the CLI's writers, picked by extension.
    pub fn export(&self, path: &std::path::Path) -> anyhow::Result<()> {
        let Some(o) = &self.outcome else {
            anyhow::bail!("nothing to export yet");
        };
        let dots = self.drawn_dots();
        let domain = (o.set.width, o.set.height);
        match path.extension().and_then(|e| e.to_str()) {
            Some("svg") => {
                let opts = svg::SvgOptions::new(domain).with_ink(self.settings.dot_color);
                crate::io::write_atomic(path, |w| {
                    svg::write(w, &dots, &opts)?;
                    Ok(())
                })?;
            }
            Some("png") => {
                let img = raster::render(&dots, domain, self.settings.png_scale)?;
                crate::io::write_atomic(path, |w| {
                    raster::write_png_ink(w, &img, self.settings.dot_color, dots.len())?;
                    Ok(())
                })?;
            }
            _ => crate::io::write_points(path, &o.set, &self.settings)?,
        }
        Ok(())
    }

    pub(super) fn canvas(&mut self, ui: &mut egui::Ui) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        self.view.canvas = rect.size();
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
        // A periodic drawing can show 2×2 copies: the seams should vanish.
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
        }
        // Zoom about the pointer, pan by dragging.
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                let factor = (scroll / 200.0).exp();
                let pointer =
                    ui.input(|i| i.pointer.hover_pos()).unwrap_or(rect.center()) - rect.min;
                self.view.pan = pointer - (pointer - self.view.pan) * factor;
                self.view.zoom *= factor;
            }
        }
        self.view.pan += response.drag_delta();
        let offsets: Vec<Vec2> = (0..tiles * tiles)
            .map(|t| Vec2::new((t % tiles) as f32 * size.x, (t / tiles) as f32 * size.y))
            .collect();
        let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        for off in &offsets {
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
        let s = &self.settings;
        let [r, g, b] = s.dot_color;
        let base = ViewUniform {
            rect: [rect.width(), rect.height()],
            scale: self.view.zoom,
            pixels_per_point: ui.ctx().pixels_per_point(),
            offset: [self.view.pan.x, self.view.pan.y],
            radius_scale: match self.dot_size() {
                DotSize::Proportional(f) => f,
                DotSize::Fixed(_) | DotSize::Calibrated(_) => 0.0,
            },
            drawn_scale: match self.dot_size() {
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
        for layer in layers {
            if self.gpu_dots {
                painter.add(egui_wgpu::Callback::new_paint_callback(rect, layer));
            } else {
                // No wgpu renderer (e.g. a glow build): egui's own shapes.
                let color = Color32::from_rgba_unmultiplied(
                    (layer.view.color[0] * 255.0) as u8,
                    (layer.view.color[1] * 255.0) as u8,
                    (layer.view.color[2] * 255.0) as u8,
                    (layer.view.color[3] * 255.0) as u8,
                );
                let pan = Vec2::new(layer.view.offset[0], layer.view.offset[1]);
                for d in layer.dots.iter() {
                    let radius =
                        d.radius * layer.view.radius_scale + d.drawn * layer.view.drawn_scale;
                    let c = rect.min + pan + Vec2::new(d.x, d.y) * self.view.zoom;
                    painter.circle_filled(c, (radius * self.view.zoom).max(0.5), color);
                }
            }
        }
    }
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
    ("Black", [20, 20, 20]),
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
