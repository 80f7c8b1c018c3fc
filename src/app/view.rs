//! The zoomable canvas: the paper or the picture under the dots, fitted,
//! zoomed about the pointer and panned by dragging; with a sheet of paper
//! (the Paper section), the sheet and its margins around the drawing.

use egui::{Color32, Rect, Sense, Vec2};

use super::PixelPieApp;
use super::dots::{DotLayer, ViewUniform};
use super::settings::Background;
use crate::stipple::DotSize;

/// The canvas around the picture (and its sheet).
const BACKDROP: Color32 = Color32::from_gray(90);
/// The line of the margins on the sheet.
const MARGIN_LINE: Color32 = Color32::from_rgb(150, 180, 225);

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
    /// What a fit shows, in picture pixels, as last drawn: the drawing (or
    /// its tiles) or its sheet of paper (a change refits a fitted view).
    pub frame: Rect,
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
            frame: Rect::NOTHING,
        }
    }
}

impl PixelPieApp {
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

    /// The zoomable canvas: the paper (or the picture) and the dots.
    pub(super) fn canvas(&mut self, ui: &mut egui::Ui) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, BACKDROP);
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
        let sheet = self.sheet(size);
        self.navigate(ui, rect, &response, size, sheet.map(|(s, _)| s));
        // A periodic drawing can show 2×2 copies: the seams should vanish.
        let tiles = self.tiles();
        let offsets: Vec<Vec2> = (0..tiles * tiles)
            .map(|t| Vec2::new((t % tiles) as f32 * size.x, (t / tiles) as f32 * size.y))
            .collect();
        if let Some(sheet) = sheet {
            self.paint_sheet(&painter, rect, sheet);
        }
        self.paint_backgrounds(&painter, rect, &offsets, size);
        if let Some((_, printable)) = sheet {
            // The margins: a thin line around the printable area, over the
            // picture behind the dots but under the dots.
            painter.rect_stroke(
                self.on_screen(rect, printable),
                0.0,
                egui::Stroke::new(1.0, MARGIN_LINE),
                egui::StrokeKind::Middle,
            );
        }
        let layers = self.dot_layers(ui, rect, &offsets);
        self.paint_dots(&painter, rect, layers);
    }

    /// Fits the view when asked (or when a fitted view's canvas, tiling or
    /// sheet changes), zooms about the pointer and pans by dragging. A fit
    /// shows the whole sheet when there is one, else the drawing (tiled).
    fn navigate(
        &mut self,
        ui: &egui::Ui,
        rect: Rect,
        response: &egui::Response,
        size: Vec2,
        sheet: Option<Rect>,
    ) {
        if self.view.fitted && self.view.canvas != rect.size() {
            self.view.fit_next = true;
        }
        self.view.canvas = rect.size();
        let tiles = self.tiles();
        if self.view.tiles != tiles {
            self.view.tiles = tiles;
            self.view.fit_next = true;
        }
        let frame =
            sheet.unwrap_or_else(|| Rect::from_min_size(egui::Pos2::ZERO, size * tiles as f32));
        if self.view.frame != frame {
            self.view.frame = frame;
            self.view.fit_next |= self.view.fitted;
        }
        if self.view.fit_next {
            let all = frame.size();
            self.view.zoom = (rect.width() / all.x).min(rect.height() / all.y) * 0.98;
            self.view.pan =
                (rect.size() - all * self.view.zoom) / 2.0 - frame.min.to_vec2() * self.view.zoom;
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

    /// A rectangle in picture pixels on the screen, as the view shows it.
    fn on_screen(&self, rect: Rect, r: Rect) -> Rect {
        Rect::from_min_max(
            rect.min + self.view.pan + r.min.to_vec2() * self.view.zoom,
            rect.min + self.view.pan + r.max.to_vec2() * self.view.zoom,
        )
    }

    /// The sheet of paper (in picture pixels) under the drawing, with a
    /// faint shadow.
    fn paint_sheet(&self, painter: &egui::Painter, rect: Rect, (sheet, _): (Rect, Rect)) {
        let on_screen = self.on_screen(rect, sheet);
        painter.rect_filled(
            on_screen.translate(Vec2::splat(3.0)),
            0.0,
            Color32::from_black_alpha(60),
        );
        painter.rect_filled(on_screen, 0.0, Color32::WHITE);
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
            let slot = super::dots::LAYERS * t;
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
                    slot,
                    multiply: false,
                });
            }
            if self.pen_layers.is_empty() {
                layers.push(DotLayer {
                    dots: self.dot_instances.clone(),
                    generation: self.dots_generation,
                    view: base,
                    slot: slot + 1,
                    multiply: false,
                });
            }
            // A colour drawing: each pen's layer in its ink, multiplied in.
            for (k, (colour, dots)) in self.pen_layers.iter().enumerate() {
                if s.hidden_pens.get(k).copied().unwrap_or(false) {
                    continue;
                }
                let [r, g, b] = colour.map(|c| f32::from(c) / 255.0);
                layers.push(DotLayer {
                    dots: dots.clone(),
                    generation: self.dots_generation,
                    view: ViewUniform {
                        color: [r, g, b, 1.0],
                        ..base
                    },
                    slot: slot + 1 + k,
                    multiply: true,
                });
            }
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
