//! The zoomable canvas: the paper or the picture under the dots, fitted,
//! zoomed about the pointer and panned by dragging; with a sheet of paper
//! (the Paper section), the sheet and its margins around the drawing.

use std::sync::Arc;
use std::time::{Duration, Instant};

use egui::{Color32, Rect, Sense, Vec2};

use super::PixelPieApp;
use super::dots::{Blend, CacheSpec, DotFrame, DotLayer, FillFrame, MAX_CACHE_PX, Placement};
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
    /// The canvas's top left corner on the screen, as last drawn.
    pub origin: egui::Pos2,
    /// The dots' cache.
    pub cache: DotCache,
    /// A line drawing's paths.
    pub line: super::line::LineCache,
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
            origin: egui::Pos2::ZERO,
            cache: DotCache::default(),
            line: super::line::LineCache::default(),
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

    /// Pans the view by `delta` points, as a drag does.
    pub fn pan_by(&mut self, delta: Vec2) {
        self.view.pan += delta;
        self.view.fitted = false;
    }

    /// Points per image pixel in the view.
    #[must_use]
    pub fn zoom(&self) -> f32 {
        self.view.zoom
    }

    /// Where the canvas is on the screen, in points, as last drawn.
    #[must_use]
    pub fn canvas_on_screen(&self) -> Rect {
        Rect::from_min_size(self.view.origin, self.view.canvas)
    }

    /// Where the drawing (its first copy) is on the screen, in points, as
    /// last drawn.
    #[must_use]
    pub fn drawing_on_screen(&self) -> Option<Rect> {
        let src = self.source.as_ref()?;
        let size = Vec2::new(src.map.width() as f32, src.map.height() as f32);
        Some(Rect::from_min_size(
            self.view.origin + self.view.pan,
            size * self.view.zoom,
        ))
    }

    /// The zoomable canvas: the paper (or the picture) and the dots.
    pub(super) fn canvas(&mut self, ui: &mut egui::Ui) {
        let (rect, response) = ui.allocate_exact_size(ui.available_size(), Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        let Some(src) = &self.source else {
            painter.rect_filled(rect, 0.0, BACKDROP);
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
        self.paint_fills(&painter, rect, sheet, &offsets, size);
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
        self.paint_dots(ui, &painter, rect, &offsets, size);
        self.paint_line(&painter, rect, &offsets, size);
        self.paint_poster(&painter, rect, size);
        if self.settings.show_travel && !self.is_line() {
            self.paint_travel(&painter, rect);
        }
    }

    /// A line drawing's strokes at their pens' widths ([`super::line`]):
    /// the one ink's, or each pen's in its colour and the pens' order
    /// (hidden pens left out).
    fn paint_line(&mut self, painter: &egui::Painter, rect: Rect, offsets: &[Vec2], size: Vec2) {
        let Some(o) = &self.outcome else { return };
        if o.drawing.strokes.is_empty() {
            self.view.line.painted = 0;
            return;
        }
        let s = &self.settings;
        let rgb = |[r, g, b]: [u8; 3]| Color32::from_rgb(r, g, b);
        let strokes: Vec<(usize, Color32)> = match &o.drawing.pens {
            Some(pens) => {
                let inks: Vec<[u8; 3]> = pens.pens().iter().map(|p| p.colour).collect();
                s.job
                    .plot_order(&inks)
                    .into_iter()
                    .filter(|&k| !s.hidden_pens.get(k).copied().unwrap_or(false))
                    .map(|k| (k, rgb(inks[k])))
                    .collect()
            }
            None => (0..o.drawing.strokes.len())
                .map(|k| (k, rgb(s.job.ink_rgb())))
                .collect(),
        };
        let view = super::line::LineView {
            canvas: rect,
            origin: rect.min + self.view.pan,
            tiles: offsets,
            size,
            zoom: self.view.zoom,
            live: self.line_live_vertices(),
        };
        super::line::paint(
            &mut self.view.line,
            painter,
            (&o.drawing, o.scale),
            &view,
            &strokes,
        );
    }

    /// Whether the drawing shown is a line (its strokes, no dots).
    #[must_use]
    pub fn is_line(&self) -> bool {
        self.outcome
            .as_ref()
            .is_some_and(|o| !o.drawing.strokes.is_empty())
    }

    /// Vertices of a line drawing's strokes painted at the last frame
    /// (all copies; 0 for dots).
    #[must_use]
    pub fn line_vertices_painted(&self) -> usize {
        self.view.line.painted
    }

    /// The pen's travel over the drawing: each layer's dots joined in
    /// drawing order (its first [`MAX_TRAVEL_MOVES`] moves in all), in the
    /// layer's ink, faded.
    fn paint_travel(&self, painter: &egui::Painter, rect: Rect) {
        let layers: Vec<([u8; 3], &[super::dots::DotInstance])> = if self.pen_layers.is_empty() {
            vec![(self.settings.job.ink.0, self.dot_instances.as_slice())]
        } else {
            self.pen_layers
                .iter()
                .map(|(c, d)| (*c, d.as_slice()))
                .collect()
        };
        let origin = rect.min + self.view.pan;
        let mut left = MAX_TRAVEL_MOVES + layers.len();
        for (colour, dots) in layers {
            let n = dots.len().min(left);
            left -= n;
            if n < 2 {
                continue;
            }
            let points: Vec<egui::Pos2> = dots[..n]
                .iter()
                .map(|d| origin + Vec2::new(d.x, d.y) * self.view.zoom)
                .collect();
            // Red for black ink, so that the path shows over the dots.
            let [r, g, b] = if colour == [0, 0, 0] {
                [220, 40, 40]
            } else {
                colour
            };
            painter.add(egui::Shape::line(
                points,
                egui::Stroke::new(1.0, Color32::from_rgba_unmultiplied(r, g, b, 160)),
            ));
        }
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
        self.view.origin = rect.min;
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
    pub(super) fn on_screen(&self, rect: Rect, r: Rect) -> Rect {
        Rect::from_min_max(
            rect.min + self.view.pan + r.min.to_vec2() * self.view.zoom,
            rect.min + self.view.pan + r.max.to_vec2() * self.view.zoom,
        )
    }

    /// The flat areas under the drawing: the canvas's backdrop, the sheet of
    /// paper (in picture pixels) with a faint shadow, and the paper under
    /// each copy. On the GPU they are one paint callback (egui's shader costs
    /// a software rasterizer several times more per pixel).
    fn paint_fills(
        &self,
        painter: &egui::Painter,
        rect: Rect,
        sheet: Option<(Rect, Rect)>,
        offsets: &[Vec2],
        size: Vec2,
    ) {
        let mut fills = vec![(rect, BACKDROP)];
        let [pr, pg, pb] = self.settings.job.paper_rgb();
        let paper = Color32::from_rgb(pr, pg, pb);
        if let Some((sheet, _)) = sheet {
            let on_screen = self.on_screen(rect, sheet);
            fills.push((
                on_screen.translate(Vec2::splat(3.0)),
                Color32::from_black_alpha(60),
            ));
            fills.push((on_screen, paper));
        }
        for off in offsets {
            let image_rect = Rect::from_min_size(
                rect.min + self.view.pan + *off * self.view.zoom,
                size * self.view.zoom,
            );
            fills.push((image_rect, paper));
        }
        // Within the canvas (its clip rectangle clips egui's shapes, the
        // scissor the callback's).
        for (r, _) in &mut fills {
            *r = r.intersect(rect);
        }
        fills.retain(|(r, _)| r.is_positive());
        if self.gpu_dots {
            painter.add(egui_wgpu::Callback::new_paint_callback(
                rect,
                FillFrame { rects: fills },
            ));
        } else {
            for (r, c) in fills {
                painter.rect_filled(r, 0.0, c);
            }
        }
    }

    /// The map or the photo under each copy, when asked.
    fn paint_backgrounds(&self, painter: &egui::Painter, rect: Rect, offsets: &[Vec2], size: Vec2) {
        let Some(src) = &self.source else { return };
        let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        for off in offsets {
            let image_rect = Rect::from_min_size(
                rect.min + self.view.pan + *off * self.view.zoom,
                size * self.view.zoom,
            );
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

    /// The dot layers: the coverage disks when asked, then the dots in the
    /// ink (or each pen's, multiplied in), sized as the job draws them.
    fn dot_layers(&self) -> Vec<DotLayer> {
        let s = &self.settings;
        let [r, g, b] = s.job.ink_rgb().map(|c| f32::from(c) / 255.0);
        let (radius_scale, drawn_scale) = match self.dot_size() {
            DotSize::Proportional(f) => (f, 0.0),
            DotSize::Calibrated(f) => (0.0, f),
        };
        let ink = DotLayer {
            dots: self.dot_instances.clone(),
            generation: self.dots_generation,
            radius_scale,
            drawn_scale,
            color: [r, g, b, 1.0],
            slot: 1,
            blend: Blend::Ink,
        };
        let mut layers = Vec::new();
        if s.show_coverage {
            layers.push(DotLayer {
                radius_scale: 1.0,
                drawn_scale: 0.0,
                color: [0.2, 0.45, 0.9, 0.18],
                slot: 0,
                blend: Blend::Disks,
                ..ink.clone()
            });
        }
        // With a pen width, the dots as the pens plot them (their radii on
        // paper, as `stipple --preview` draws them).
        // A line's points are drawn as its strokes ([`Self::paint_line`]):
        // their disks alone, when asked.
        if self.is_line() {
            return layers;
        }
        let plotted = self.plotted_view();
        let as_plotted = |k: usize, layer: DotLayer| match plotted {
            Some(p) => DotLayer {
                dots: p.layers.get(k).cloned().unwrap_or_default(),
                generation: p.generation,
                radius_scale: 0.0,
                drawn_scale: 1.0,
                ..layer
            },
            None => layer,
        };
        if self.pen_layers.is_empty() {
            layers.push(as_plotted(0, ink.clone()));
        }
        // A colour drawing: each pen's layer in its ink, multiplied in (or
        // over what is below, for an opaque ink).
        let paper = s.job.paper_rgb();
        let opaque = |k: usize| {
            s.job
                .pens
                .as_ref()
                .and_then(|p| p.pens().get(k))
                .is_some_and(|p| p.opacity_on(paper) >= 0.5)
        };
        let inks: Vec<[u8; 3]> = self.pen_layers.iter().map(|(c, _)| *c).collect();
        for k in s.job.plot_order(&inks) {
            let (colour, dots) = &self.pen_layers[k];
            if s.hidden_pens.get(k).copied().unwrap_or(false) {
                continue;
            }
            let [r, g, b] = colour.map(|c| f32::from(c) / 255.0);
            layers.push(as_plotted(
                k,
                DotLayer {
                    dots: dots.clone(),
                    color: [r, g, b, 1.0],
                    slot: 1 + k,
                    blend: if opaque(k) {
                        Blend::Ink
                    } else {
                        Blend::Multiply
                    },
                    ..ink.clone()
                },
            ));
        }
        layers
    }

    /// Draws the layers: on the GPU through their cache ([`super::dots`]),
    /// or with egui's own shapes where there is no wgpu renderer (a glow
    /// build).
    fn paint_dots(
        &mut self,
        ui: &egui::Ui,
        painter: &egui::Painter,
        rect: Rect,
        offsets: &[Vec2],
        size: Vec2,
    ) {
        let layers = self.dot_layers();
        if self.gpu_dots {
            if let Some(frame) = self.dot_frame(ui, rect, offsets, size, layers) {
                painter.add(egui_wgpu::Callback::new_paint_callback(rect, frame));
            }
            return;
        }
        for layer in layers {
            let [r, g, b, a] = layer.color.map(|c| (c * 255.0) as u8);
            let color = Color32::from_rgba_unmultiplied(r, g, b, a);
            for off in offsets {
                let pan = self.view.pan + *off * self.view.zoom;
                for d in layer.dots.iter() {
                    let radius = d.radius * layer.radius_scale + d.drawn * layer.drawn_scale;
                    let c = rect.min + pan + Vec2::new(d.x, d.y) * self.view.zoom;
                    painter.circle_filled(c, (radius * self.view.zoom).max(0.5), color);
                }
            }
        }
    }

    /// The frame's dots: the cache to show (the one held while the view
    /// moves, a new one when the drawing changed or the view rests) and
    /// where the image is now. `None` when no drawing is in sight.
    fn dot_frame(
        &mut self,
        ui: &egui::Ui,
        rect: Rect,
        offsets: &[Vec2],
        size: Vec2,
        mut layers: Vec<DotLayer>,
    ) -> Option<DotFrame> {
        let ppp = ui.ctx().pixels_per_point();
        let now = Placement {
            scale: self.view.zoom * ppp,
            offset: [
                (rect.min.x + self.view.pan.x) * ppp,
                (rect.min.y + self.view.pan.y) * ppp,
            ],
        };
        let style: Vec<LayerKey> = layers.iter().map(LayerKey::of).collect();
        let cache = &mut self.view.cache;
        if now != cache.last {
            cache.last = now;
            cache.moved = Instant::now();
        }
        if cache.style.as_ref() != Some(&style) {
            cache.style = Some(style.clone());
            cache.restyled = Instant::now();
        }
        // The canvas and the drawing (all its copies) on the screen, px.
        let canvas = Rect::from_min_max(
            (rect.min.to_vec2() * ppp).to_pos2(),
            (rect.max.to_vec2() * ppp).to_pos2(),
        );
        let tiles_px = offsets.iter().fold(Rect::NOTHING, |r, o| {
            r.union(Rect::from_min_size(o.to_pos2(), size))
        });
        let drawing = Rect::from_min_max(
            egui::pos2(
                tiles_px.min.x * now.scale + now.offset[0],
                tiles_px.min.y * now.scale + now.offset[1],
            ),
            egui::pos2(
                tiles_px.max.x * now.scale + now.offset[0],
                tiles_px.max.y * now.scale + now.offset[1],
            ),
        );
        let visible = canvas.intersect(drawing);
        if !visible.is_positive() || layers.is_empty() {
            return None;
        }
        // Screen px per exported PNG px (the view shows the PNG's ink).
        let domain_px = self.outcome.as_ref().map_or(1.0, |o| o.scale);
        let export_px = (now.scale / (self.settings.job.scale * domain_px)).min(1.0);
        let wanted = CacheSpec {
            at: now,
            region: cache_region(canvas, drawing),
            tiles: offsets.iter().map(|o| [o.x, o.y]).collect(),
            export_px,
            sample_radius: self.outcome.as_ref().map_or(1.0, |o| o.sizes.sample_radius),
        };
        let dots: usize = layers.iter().map(|l| l.dots.len()).sum::<usize>() * offsets.len();
        let keys = |held: &[LayerKey]| -> Option<Vec<LayerKey>> {
            // The same layers of the same dots, perhaps sized otherwise.
            (held.len() == style.len() && held.iter().zip(&style).all(|(a, b)| a.same_dots(b)))
                .then(|| held.to_vec())
        };
        let held = cache.held.as_ref().and_then(|(spec, held)| {
            let same = keys(held)?;
            Some((spec.clone(), same))
        });
        let still = cache.moved.elapsed() >= SETTLE;
        let resting = still && cache.restyled.elapsed() >= SETTLE;
        let (spec, sizes) = match held {
            // The drawing or its layers changed: a new cache at once.
            None => (wanted, style.clone()),
            Some((spec, held)) => {
                let restyled = held != style;
                if !restyled && covers(&spec, &wanted, visible) {
                    (spec, held)
                } else if resting || (restyled && dots <= LIVE_DOTS && still) {
                    (wanted, style.clone())
                } else {
                    let since = cache.moved.elapsed().min(cache.restyled.elapsed());
                    ui.ctx().request_repaint_after(SETTLE.saturating_sub(since));
                    (spec, held)
                }
            }
        };
        if cache
            .held
            .as_ref()
            .is_none_or(|(s, k)| *s != spec || *k != sizes)
        {
            cache.made += 1;
            cache.held = Some((spec.clone(), sizes.clone()));
        }
        // The layers as the cache holds them (their sizes, while it waits).
        for (layer, key) in layers.iter_mut().zip(&sizes) {
            layer.radius_scale = f32::from_bits(key.radius_scale);
            layer.drawn_scale = f32::from_bits(key.drawn_scale);
        }
        Some(DotFrame {
            layers,
            cache: spec,
            now,
        })
    }

    /// Caches of the dots asked for so far: one per drawing, and one each
    /// time the view comes to rest after it moved.
    #[must_use]
    pub fn dot_caches_made(&self) -> u64 {
        self.view.cache.made
    }
}

/// How long the view must rest before the dots are splatted anew at its
/// zoom; until then the cache is drawn moved and scaled.
pub const SETTLE: Duration = Duration::from_millis(150);

/// Drawings of up to this many dots (all copies) follow a change of the
/// dot size at once; larger ones once the control rests.
const LIVE_DOTS: usize = 200_000;

/// A layer as its cache holds it.
#[derive(Clone, Debug, PartialEq)]
struct LayerKey {
    slot: usize,
    generation: u64,
    dots: usize,
    radius_scale: u32,
    drawn_scale: u32,
}

impl LayerKey {
    fn of(l: &DotLayer) -> Self {
        Self {
            slot: l.slot,
            generation: l.generation,
            dots: Arc::as_ptr(&l.dots) as usize,
            radius_scale: l.radius_scale.to_bits(),
            drawn_scale: l.drawn_scale.to_bits(),
        }
    }

    fn same_dots(&self, other: &Self) -> bool {
        (self.slot, self.generation, self.dots) == (other.slot, other.generation, other.dots)
    }
}

/// The most pen moves the travel overlay draws (its lines are drawn every
/// frame).
pub const MAX_TRAVEL_MOVES: usize = 200_000;

/// The cache of the dots the view holds, and when the view last moved.
pub struct DotCache {
    /// The cache asked for and the layers it holds.
    held: Option<(CacheSpec, Vec<LayerKey>)>,
    /// The image's placement at the last frame.
    last: Placement,
    /// The layers' sizes at the last frame.
    style: Option<Vec<LayerKey>>,
    /// When the placement last changed.
    moved: Instant,
    /// When the sizes last changed.
    restyled: Instant,
    /// Caches asked for.
    made: u64,
}

impl Default for DotCache {
    fn default() -> Self {
        Self {
            held: None,
            last: Placement::default(),
            style: None,
            moved: Instant::now(),
            restyled: Instant::now(),
            made: 0,
        }
    }
}

/// The screen region to cache, physical px: the canvas and a fifth of it
/// around (for panning), within the drawing; the canvas alone where that
/// is too large.
pub(super) fn cache_region(canvas: Rect, drawing: Rect) -> [i32; 4] {
    let round = |r: Rect| {
        let (x0, y0) = (r.min.x.floor() as i32, r.min.y.floor() as i32);
        let (x1, y1) = (r.max.x.ceil() as i32, r.max.y.ceil() as i32);
        [x0, y0, (x1 - x0).max(0), (y1 - y0).max(0)]
    };
    let wide = round(canvas.expand2(canvas.size() * 0.2).intersect(drawing));
    if i64::from(wide[2]) * i64::from(wide[3]) <= MAX_CACHE_PX {
        return wide;
    }
    let [x, y, w, h] = round(canvas.intersect(drawing));
    // A canvas larger than any cache: its top left part, sharp.
    let side = (MAX_CACHE_PX as f64).sqrt() as i32;
    [x, y, w.min(side), h.min(side)]
}

/// Whether the cache `held` still serves the view `wanted` at rest: the
/// same scale and style, moved by whole pixels, and covering the part of
/// the drawing in sight.
fn covers(held: &CacheSpec, wanted: &CacheSpec, visible: Rect) -> bool {
    if held.at.scale != wanted.at.scale
        || held.tiles != wanted.tiles
        || held.export_px != wanted.export_px
    {
        return false;
    }
    let dx = wanted.at.offset[0] - held.at.offset[0];
    let dy = wanted.at.offset[1] - held.at.offset[1];
    if (dx - dx.round()).abs() > 1e-3 || (dy - dy.round()).abs() > 1e-3 {
        return false;
    }
    let [x, y, w, h] = held.region;
    let shown = Rect::from_min_size(
        egui::pos2(x as f32 + dx.round(), y as f32 + dy.round()),
        egui::vec2(w as f32, h as f32),
    );
    shown.expand(0.5).contains_rect(visible)
}
