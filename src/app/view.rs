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
}

impl Default for ViewState {
    fn default() -> Self {
        Self {
            zoom: 1.0,
            pan: Vec2::ZERO,
            fit_next: true,
        }
    }
}

impl PixelPieApp {
    pub(super) fn controls(&mut self, ui: &mut egui::Ui) {
        ui.set_width(260.0);
        ui.heading("PixelPie");
        ui.label("Drop an image or EXR on the window, or type a path:");
        ui.horizontal(|ui| {
            let edit = ui.add(egui::TextEdit::singleline(&mut self.open_path).desired_width(170.0));
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui.button("Open").clicked() || enter {
                let path = PathBuf::from(self.open_path.trim());
                let ctx = ui.ctx().clone();
                self.open(&ctx, &path);
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
            ui.radio_value(&mut s.use_count, true, "Point count");
            ui.radio_value(&mut s.use_count, false, "Radius range");
        });
        ui.add_enabled_ui(s.use_count, |ui| {
            ui.horizontal(|ui| {
                let l = ui.label("Points");
                ui.add(
                    egui::DragValue::new(&mut s.points)
                        .range(10..=2_000_000)
                        .speed(50),
                )
                .labelled_by(l.id);
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
            .labelled_by(l.id);
            ui.add(
                egui::DragValue::new(&mut s.r_max)
                    .range(1.0..=500.0)
                    .speed(0.05)
                    .prefix("max "),
            );
        });
        s.r_max = s.r_max.max(s.r_min);
        egui::ComboBox::from_label("Mapping")
            .selected_text(if s.tone { "Tone" } else { "Linear" })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.tone, true, "Tone")
                    .on_hover_text("Calibrated: the drawing's ink equals the picture's darkness.");
                ui.selectable_value(&mut s.tone, false, "Linear")
                    .on_hover_text("The paper's ramp r_min + (r_max − r_min)·v.");
            });
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
            });
        egui::ComboBox::from_label("Policy")
            .selected_text(format!("{:?}", s.policy))
            .show_ui(ui, |ui| {
                for p in Policy::ALL {
                    ui.selectable_value(&mut s.policy, p, format!("{p:?}"));
                }
            });
        ui.add(
            egui::Slider::new(&mut s.gamma, 0.2..=5.0)
                .logarithmic(true)
                .text("Gamma"),
        );
        ui.add(egui::Slider::new(&mut s.black, 0.0..=0.95).text("Black level"));
        ui.add(egui::Slider::new(&mut s.white, 0.05..=1.0).text("White level"));
        s.white = s.white.max(s.black + 0.01);
        ui.checkbox(&mut s.invert, "Invert");
        ui.add(egui::Slider::new(&mut s.cutoff, 0.0..=1.0).text("White cutoff"));
        ui.add(egui::Slider::new(&mut s.subpixel_bits, 0..=7).text("Sub-pixel bits"));
        ui.horizontal(|ui| {
            let l = ui.label("Seed");
            ui.add(egui::DragValue::new(&mut s.seed)).labelled_by(l.id);
            if ui.button("Re-roll").clicked() {
                s.seed = crate::sampler::fixed::mix(s.seed as u32 ^ 0x5bd1_e995).into();
            }
        });
        ui.checkbox(&mut s.periodic, "Periodic (tileable)");
        egui::ComboBox::from_label("Backend")
            .selected_text(format!("{:?}", s.backend))
            .show_ui(ui, |ui| {
                for b in [BackendChoice::Auto, BackendChoice::Gpu, BackendChoice::Cpu] {
                    ui.selectable_value(&mut s.backend, b, format!("{b:?}"));
                }
            });
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
            });
        match s.dot_mode {
            DotMode::Fixed | DotMode::Sized => {
                ui.add(
                    egui::Slider::new(&mut s.dot_factor, 0.3..=2.0).text("Dot size (× calibrated)"),
                )
                .on_hover_text("1 reproduces the picture's tones; more darkens, less lightens.");
            }
            DotMode::Proportional => {
                ui.add(egui::Slider::new(&mut s.dot_scale, 0.05..=1.0).text("Dot size (× disk)"));
            }
        }
        if s.dot_mode == DotMode::Sized {
            ui.add(egui::Slider::new(&mut s.dot_ratio, 0.1..=1.0).text("Lightest / darkest dot"));
        }
        ui.add(egui::Slider::new(&mut s.relax, 0..=30).text("Relax (Lloyd steps)"))
            .on_hover_text("Weighted Voronoi relaxation after sampling: more even spacing.");
        ui.horizontal(|ui| {
            ui.label("Dot colour");
            ui.color_edit_button_srgb(&mut s.dot_color);
        });
        ui.horizontal(|ui| {
            ui.label("Behind");
            ui.selectable_value(&mut s.background, Background::Paper, "Paper");
            ui.selectable_value(&mut s.background, Background::Importance, "Map");
            ui.selectable_value(&mut s.background, Background::Photo, "Photo");
        });
        ui.checkbox(&mut s.show_coverage, "Coverage disks (Figure 4)");
        if ui.button("Fit view").clicked() {
            self.view.fit_next = true;
        }
        ui.separator();
        self.stats_ui(ui);
        ui.separator();
        self.export_ui(ui);
    }

    fn stats_ui(&mut self, ui: &mut egui::Ui) {
        let mut cancel = false;
        if self.busy() {
            ui.horizontal(|ui| {
                ui.spinner();
                match (&self.progress, self.relaxed) {
                    (_, Some(done)) => {
                        ui.label(format!("relaxing: {done} of {} steps", self.settings.relax))
                    }
                    (Some(p), None) => ui.label(format!(
                        "iteration {}, {:.0}% covered",
                        p.iteration,
                        100.0 - 100.0 * p.empty_pixels as f64 / p.pixels.max(1) as f64
                    )),
                    (None, None) => ui.label("sampling…"),
                };
                if ui
                    .button("Cancel")
                    .on_hover_text("Stop this sampling or relaxation; keep the last drawing.")
                    .clicked()
                {
                    cancel = true;
                }
            });
        }
        if cancel {
            self.cancel_job();
        }
        if let Some(o) = &self.outcome {
            let st = &o.set.stats;
            ui.label(format!(
                "{} dots, {} iterations, {} run(s)",
                o.set.points.len(),
                st.iterations,
                o.runs
            ));
            ui.label(format!(
                "S1 {:.1} ms, S2 {:.1} ms, PP {:.1} ms, total {:.1} ms",
                st.stages.get("throw") * 1e3,
                st.stages.get("cull") * 1e3,
                st.stages.get("compact") * 1e3,
                st.seconds * 1e3
            ));
            ui.label(format!("{} on {}", st.backend, st.device));
        }
        if let Some(e) = &self.error {
            ui.colored_label(Color32::from_rgb(200, 40, 40), format!("Error: {e}"));
        }
        if !self.status.is_empty() {
            ui.label(&self.status);
        }
    }

    /// Under the Export row: the file written, or why not.
    fn export_result_ui(&self, ui: &mut egui::Ui) {
        if let Some(e) = &self.export_error {
            ui.colored_label(Color32::from_rgb(200, 40, 40), e);
        } else if let Some(p) = &self.exported {
            ui.label(format!("wrote {}", p.display()));
        }
    }

    fn export_ui(&mut self, ui: &mut egui::Ui) {
        ui.label("Export to");
        ui.add(egui::TextEdit::singleline(&mut self.export_path).desired_width(240.0));
        ui.horizontal(|ui| {
            for ext in ["svg", "png", "csv", "json"] {
                if ui.button(ext.to_uppercase()).clicked() {
                    self.export_as(ext);
                }
            }
        });
        self.export_result_ui(ui);
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
        match s.dot_mode {
            DotMode::Fixed | DotMode::Sized => DotSize::Calibrated(s.dot_factor),
            DotMode::Proportional => DotSize::Proportional(s.dot_scale),
        }
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
        if self.view.fit_next {
            self.view.zoom = (rect.width() / size.x).min(rect.height() / size.y) * 0.98;
            self.view.pan = (rect.size() - size * self.view.zoom) / 2.0;
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
        let image_rect = Rect::from_min_size(rect.min + self.view.pan, size * self.view.zoom);
        painter.rect_filled(image_rect, 0.0, Color32::WHITE);
        let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
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
                slot: 0,
            });
        }
        layers.push(DotLayer {
            dots: self.dot_instances.clone(),
            generation: self.dots_generation,
            view: base,
            slot: 1,
        });
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
                for d in layer.dots.iter() {
                    let radius =
                        d.radius * layer.view.radius_scale + d.drawn * layer.view.drawn_scale;
                    let c = rect.min + self.view.pan + Vec2::new(d.x, d.y) * self.view.zoom;
                    painter.circle_filled(c, (radius * self.view.zoom).max(0.5), color);
                }
            }
        }
    }
}
