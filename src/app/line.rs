//! A line drawing (`Style::Line`) in the view, as wide on the screen as
//! the pen on the page.
//!
//! The strokes' paths (smooth ones flattened within a quarter of a screen
//! pixel) are kept in image px and made anew only when the drawing, its
//! smoothing or the zoom's power of two changes. Each frame maps them to
//! the screen, drops the vertices closer than half a pixel to the last one
//! kept and the segments out of sight. What is left, when it is short
//! enough ([`PixelPieApp::line_live_vertices`]), goes to egui's tessellator
//! as anti-aliased paths, sharp at every zoom. A longer line would cost a
//! software rasterizer (lavapipe) half a second a frame at 100K vertices:
//! it is drawn instead from a raster of the screen region, made on a
//! thread of its own by the PNG's own renderer
//! ([`crate::stipple::line::render_polyline`]) once the view rests, and
//! moved and scaled with the view until the next one, as the dots' cache
//! is ([`super::dots`]).
//!
//! A colour drawing's lines, one per pen, are painted over each other in
//! the pens' order (the exports multiply their inks; where two pens' lines
//! cross, the view shows the later one's).

use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::time::Instant;

use egui::{Color32, Pos2, Rect, Vec2};

use super::PixelPieApp;
use super::dots::Placement;
use crate::job::Stipple;

/// Vertices in sight that egui draws as paths on a software rasterizer;
/// past them the line is drawn from its raster.
pub const LIVE_VERTICES_SOFTWARE: usize = 10_000;
/// The same on a GPU, which draws a million vertices' triangles in a few
/// milliseconds.
pub const LIVE_VERTICES_GPU: usize = 1_000_000;

/// The coarsest flattening of a smooth stroke, in domain px.
const MAX_TOLERANCE: f64 = 2.0;
/// The finest, in domain px.
const MIN_TOLERANCE: f64 = 1.0 / 64.0;

/// A stroke's path in image px and its width in image px.
struct Path {
    points: Vec<Pos2>,
    width: f32,
}

/// What a raster holds: the paths, the strokes in their colours, the
/// copies, where the image lay on the screen and the region drawn.
#[derive(Clone, Debug, PartialEq)]
struct RasterSpec {
    /// The paths' key ([`LineCache::key`]).
    paths: (usize, bool, i32),
    /// Each stroke's index and colour, in painting order.
    strokes: Vec<(usize, Color32)>,
    /// The copies' offsets, image px.
    tiles: Vec<[f32; 2]>,
    /// The image's placement on the screen (physical px).
    at: Placement,
    /// The region, physical screen px: left, top, width, height.
    region: [i32; 4],
}

impl RasterSpec {
    /// Whether this raster serves `wanted` as it is: the same line and
    /// scale, moved by whole pixels, covering the part in sight.
    fn covers(&self, wanted: &Self, visible: Rect) -> bool {
        if self.paths != wanted.paths
            || self.strokes != wanted.strokes
            || self.tiles != wanted.tiles
            || self.at.scale != wanted.at.scale
        {
            return false;
        }
        let dx = wanted.at.offset[0] - self.at.offset[0];
        let dy = wanted.at.offset[1] - self.at.offset[1];
        if (dx - dx.round()).abs() > 1e-3 || (dy - dy.round()).abs() > 1e-3 {
            return false;
        }
        let [x, y, w, h] = self.region;
        Rect::from_min_size(
            egui::pos2(x as f32 + dx.round(), y as f32 + dy.round()),
            egui::vec2(w as f32, h as f32),
        )
        .expand(0.5)
        .contains_rect(visible)
    }
}

/// A raster of the line and what it holds.
struct Raster {
    spec: RasterSpec,
    texture: egui::TextureHandle,
}

/// The strokes' paths and raster, as last made, and what they were made for.
pub struct LineCache {
    /// The drawing (its address), its smoothing and the tolerance's level.
    key: Option<(usize, bool, i32)>,
    paths: Arc<Vec<Path>>,
    /// The raster shown.
    raster: Option<Raster>,
    /// A raster on its way from its thread.
    pending: Option<(RasterSpec, Receiver<egui::ColorImage>)>,
    /// The placement at the last frame, and when it last changed.
    last: (Placement, Instant),
    /// Vertices handed to egui at the last frame (all copies; none when
    /// the raster was drawn).
    pub painted: usize,
    /// Rasters made so far.
    pub rasters: u64,
}

impl Default for LineCache {
    fn default() -> Self {
        Self {
            key: None,
            paths: Arc::default(),
            raster: None,
            pending: None,
            last: (Placement::default(), Instant::now()),
            painted: 0,
            rasters: 0,
        }
    }
}

/// Where the view shows the drawing this frame.
pub struct LineView<'a> {
    /// The canvas, points.
    pub canvas: Rect,
    /// The image origin (its first copy) on the screen, points.
    pub origin: Pos2,
    /// The copies' offsets, image px.
    pub tiles: &'a [Vec2],
    /// The image's size, px.
    pub size: Vec2,
    /// Points per image px.
    pub zoom: f32,
    /// Vertices egui draws as paths; past them, the raster.
    pub live: usize,
}

impl LineCache {
    /// The paths of `drawing`'s strokes (`scale` domain px per image px),
    /// smooth strokes flattened within `tolerance` domain px (rounded down
    /// to a power of two).
    fn paths(&mut self, drawing: &Arc<Stipple>, scale: f32, tolerance: f64) -> Arc<Vec<Path>> {
        let tolerance = tolerance.clamp(MIN_TOLERANCE, MAX_TOLERANCE);
        let smooth = drawing.strokes.iter().any(|s| s.smooth);
        let level = if smooth {
            tolerance.log2().floor() as i32
        } else {
            0
        };
        let key = (Arc::as_ptr(drawing) as usize, smooth, level);
        if self.key != Some(key) {
            let tolerance = 2f64.powi(level);
            let k = f64::from(scale.max(f32::MIN_POSITIVE));
            self.paths = Arc::new(
                drawing
                    .strokes
                    .iter()
                    .map(|s| Path {
                        points: s
                            .path(tolerance)
                            .iter()
                            .map(|p| Pos2::new((p[0] / k) as f32, (p[1] / k) as f32))
                            .collect(),
                        width: s.width / scale,
                    })
                    .collect(),
            );
            self.key = Some(key);
        }
        self.paths.clone()
    }

    /// Takes a raster that came back from its thread.
    fn poll(&mut self, ctx: &egui::Context) {
        let Some((_, rx)) = &self.pending else { return };
        match rx.try_recv() {
            Ok(image) => {
                if let Some((spec, _)) = self.pending.take() {
                    let texture = ctx.load_texture("line", image, egui::TextureOptions::LINEAR);
                    self.raster = Some(Raster { spec, texture });
                    self.rasters += 1;
                }
            }
            Err(TryRecvError::Empty) => {}
            Err(TryRecvError::Disconnected) => self.pending = None,
        }
    }
}

/// Paints `drawing`'s strokes `strokes` (each its index and colour, in
/// the order they are painted) with `painter` where `view` shows them.
pub fn paint(
    cache: &mut LineCache,
    painter: &egui::Painter,
    (drawing, scale): (&Arc<Stipple>, f32),
    view: &LineView<'_>,
    strokes: &[(usize, Color32)],
) {
    let ctx = painter.ctx();
    let ppp = ctx.pixels_per_point();
    cache.poll(ctx);
    // A quarter of a screen pixel, in domain px.
    let tolerance = 0.25 * f64::from(scale) / f64::from(view.zoom * ppp);
    let paths = cache.paths(drawing, scale, tolerance);
    let mut runs = Vec::new();
    for &(k, colour) in strokes {
        let Some(path) = paths.get(k) else { continue };
        let width = path.width * view.zoom;
        let clip = view.canvas.expand(width + 1.0);
        for t in view.tiles {
            let origin = view.origin + *t * view.zoom;
            for run in runs_in_sight(&path.points, origin, view.zoom, clip, ppp) {
                runs.push((run, width, colour));
            }
        }
    }
    let vertices: usize = runs.iter().map(|r| r.0.len()).sum();
    let now = Placement {
        scale: view.zoom * ppp,
        offset: [view.origin.x * ppp, view.origin.y * ppp],
    };
    if now != cache.last.0 {
        cache.last = (now, Instant::now());
    }
    // Paths while they are short enough, or while no raster of the
    // drawing can stand in for the one on its way.
    if vertices > view.live && paint_raster(cache, painter, &paths, view, strokes, now) {
        cache.painted = 0;
        return;
    }
    for (run, width, colour) in runs {
        if run.len() == 1 {
            painter.circle_filled(run[0], width / 2.0, colour);
        } else {
            painter.add(egui::Shape::line(run, egui::Stroke::new(width, colour)));
        }
    }
    cache.painted = vertices;
}

/// Draws the line from its raster: the one held when it serves the view,
/// else the one held moved and scaled while a new one is made (once the
/// view rests). False when none of the drawing is held (nothing drawn).
fn paint_raster(
    cache: &mut LineCache,
    painter: &egui::Painter,
    paths: &Arc<Vec<Path>>,
    view: &LineView<'_>,
    strokes: &[(usize, Color32)],
    now: Placement,
) -> bool {
    let ctx = painter.ctx();
    let ppp = ctx.pixels_per_point();
    let Some(key) = cache.key else { return false };
    // The canvas and the drawing (all its copies) on the screen, px.
    let px = |r: Rect| {
        Rect::from_min_max(
            (r.min.to_vec2() * ppp).to_pos2(),
            (r.max.to_vec2() * ppp).to_pos2(),
        )
    };
    let canvas = px(view.canvas);
    let copies = view.tiles.iter().fold(Rect::NOTHING, |r, t| {
        r.union(Rect::from_min_size(t.to_pos2(), view.size))
    });
    let drawing = Rect::from_min_max(
        egui::pos2(
            copies.min.x * now.scale + now.offset[0],
            copies.min.y * now.scale + now.offset[1],
        ),
        egui::pos2(
            copies.max.x * now.scale + now.offset[0],
            copies.max.y * now.scale + now.offset[1],
        ),
    );
    let visible = canvas.intersect(drawing);
    if !visible.is_positive() {
        return true;
    }
    let mut region = super::view::cache_region(canvas, drawing);
    let most = ctx.input(|i| i.max_texture_side) as i32;
    region[2] = region[2].min(most);
    region[3] = region[3].min(most);
    let wanted = RasterSpec {
        paths: key,
        strokes: strokes.to_vec(),
        tiles: view.tiles.iter().map(|t| [t.x, t.y]).collect(),
        at: now,
        region,
    };
    let serves = cache
        .raster
        .as_ref()
        .is_some_and(|r| r.spec.covers(&wanted, visible));
    // A raster of the drawing stands in while the view moves, or while a
    // new one of it (smoothed, in other colours, at another tolerance) is
    // made.
    let stand_in = cache
        .raster
        .as_ref()
        .is_some_and(|r| r.spec.paths.0 == wanted.paths.0);
    let rested = cache.last.1.elapsed() >= super::SETTLE;
    let asked = cache.pending.as_ref().is_some_and(|(s, _)| *s == wanted);
    let coming = cache
        .pending
        .as_ref()
        .is_some_and(|(s, _)| s.paths.0 == wanted.paths.0);
    // A new drawing at once (one raster at a time while the view moves);
    // the same drawing anew once the view rests.
    if !serves && !asked && (rested || !(stand_in || coming)) {
        let (tx, rx) = channel();
        let (paths, spec, repaint) = (paths.clone(), wanted.clone(), ctx.clone());
        let spawned = std::thread::Builder::new()
            .name("pixelpie-line-raster".into())
            .spawn(move || {
                let _ = tx.send(rasterize(&paths, &spec));
                repaint.request_repaint();
            });
        if spawned.is_ok() {
            cache.pending = Some((wanted.clone(), rx));
        }
    } else if !serves && !rested {
        ctx.request_repaint_after(super::SETTLE.saturating_sub(cache.last.1.elapsed()));
    }
    let Some(r) = cache.raster.as_ref().filter(|_| stand_in) else {
        return false;
    };
    // The raster held, moved and scaled to the view now.
    let [x, y, w, h] = r.spec.region;
    let min = now.map_from(&r.spec.at, [x as f32, y as f32]);
    let max = now.map_from(&r.spec.at, [(x + w) as f32, (y + h) as f32]);
    let on_screen = Rect::from_min_max(
        egui::pos2(min[0] / ppp, min[1] / ppp),
        egui::pos2(max[0] / ppp, max[1] / ppp),
    );
    let uv = Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
    painter.image(r.texture.id(), on_screen, uv, Color32::WHITE);
    true
}

/// The line as `spec` asks: each stroke's ink rendered as the PNG renders
/// it, in its colour over the strokes before it, on a clear ground
/// (premultiplied).
fn rasterize(paths: &[Path], spec: &RasterSpec) -> egui::ColorImage {
    let [x, y, w, h] = spec.region;
    let (w, h) = (w.max(1) as u32, h.max(1) as u32);
    let mut out = vec![[0.0f32; 4]; w as usize * h as usize];
    let s = spec.at.scale;
    for &(k, colour) in &spec.strokes {
        let Some(path) = paths.get(k) else { continue };
        let mut ink = vec![255u8; out.len()];
        for t in &spec.tiles {
            let ox = f64::from((t[0] * s + spec.at.offset[0]) - x as f32);
            let oy = f64::from((t[1] * s + spec.at.offset[1]) - y as f32);
            let points: Vec<[f64; 2]> = path
                .points
                .iter()
                .map(|p| [f64::from(p.x * s) + ox, f64::from(p.y * s) + oy])
                .collect();
            let one = crate::stipple::line::render_polyline(
                &points,
                f64::from(path.width * s),
                (w, h),
                1.0,
            );
            for (a, &b) in ink.iter_mut().zip(one.as_raw()) {
                *a = (*a).min(b);
            }
        }
        let rgb = [colour.r(), colour.g(), colour.b()].map(|c| f32::from(c) / 255.0);
        for (o, &g) in out.iter_mut().zip(&ink) {
            let c = 1.0 - f32::from(g) / 255.0;
            for i in 0..3 {
                o[i] = rgb[i] * c + o[i] * (1.0 - c);
            }
            o[3] = c + o[3] * (1.0 - c);
        }
    }
    let byte = |v: f32| (v * 255.0).round().clamp(0.0, 255.0) as u8;
    let pixels = out
        .iter()
        .map(|o| Color32::from_rgba_premultiplied(byte(o[0]), byte(o[1]), byte(o[2]), byte(o[3])))
        .collect();
    egui::ColorImage::new([w as usize, h as usize], pixels)
}

/// The parts of `path` (image px) in sight of `clip` (points) once mapped
/// to the screen (`origin + p × zoom`), each a run of screen points, no two
/// in a row closer than half a pixel (`ppp` pixels per point) but the
/// path's last point.
fn runs_in_sight(path: &[Pos2], origin: Pos2, zoom: f32, clip: Rect, ppp: f32) -> Vec<Vec<Pos2>> {
    let close = (0.5 / ppp).powi(2);
    let on_screen = |p: Pos2| origin + p.to_vec2() * zoom;
    let mut runs = Vec::new();
    let Some(&first) = path.first() else {
        return runs;
    };
    let mut run: Vec<Pos2> = Vec::new();
    let mut kept = on_screen(first);
    if path.len() == 1 {
        if clip.contains(kept) {
            runs.push(vec![kept]);
        }
        return runs;
    }
    let last = path.len() - 1;
    for (i, &p) in path.iter().enumerate().skip(1) {
        let s = on_screen(p);
        if (s - kept).length_sq() < close && i != last {
            continue;
        }
        if clip.intersects(Rect::from_two_pos(kept, s)) {
            if run.is_empty() {
                run.push(kept);
            }
            run.push(s);
        } else if !run.is_empty() {
            runs.push(std::mem::take(&mut run));
        }
        kept = s;
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

impl PixelPieApp {
    /// Vertices in sight up to which the view draws a line as egui's paths
    /// (sharp while it moves); past them, from a raster made once the view
    /// rests. Fewer on a software rasterizer, whose triangles are dear.
    #[must_use]
    pub fn line_live_vertices(&self) -> usize {
        if self.worker.software() || !self.gpu_dots {
            LIVE_VERTICES_SOFTWARE
        } else {
            LIVE_VERTICES_GPU
        }
    }

    /// Rasters of a line drawing made so far (for lines past
    /// [`Self::line_live_vertices`]).
    #[must_use]
    pub fn line_rasters_made(&self) -> u64 {
        self.view.line.rasters
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_keep_what_is_in_sight_and_drop_sub_pixel_steps() {
        let path: Vec<Pos2> = (0..100).map(|i| Pos2::new(i as f32, 0.0)).collect();
        let clip = Rect::from_min_max(Pos2::new(10.0, -5.0), Pos2::new(20.0, 5.0));
        // One point per image px, one screen point each: the part in sight
        // and the segments that reach into it.
        let runs = runs_in_sight(&path, Pos2::ZERO, 1.0, clip, 1.0);
        assert_eq!(runs.len(), 1);
        assert_eq!(runs[0].first(), Some(&Pos2::new(9.0, 0.0)));
        assert_eq!(runs[0].last(), Some(&Pos2::new(21.0, 0.0)));
        // Zoomed out 10×: steps of a tenth of a pixel merge, and the path
        // still ends at its last point.
        let all = Rect::from_min_max(Pos2::new(-1.0, -1.0), Pos2::new(20.0, 1.0));
        let runs = runs_in_sight(&path, Pos2::ZERO, 0.1, all, 1.0);
        assert_eq!(runs.len(), 1);
        assert!(runs[0].len() <= 21, "{} points", runs[0].len());
        let end = runs[0].last().copied().unwrap_or_default();
        assert!((end.x - 9.9).abs() < 1e-4, "ends at {end:?}");
        // Out of sight, nothing; a path that leaves and comes back, two runs.
        let away = Rect::from_min_max(Pos2::new(500.0, 500.0), Pos2::new(600.0, 600.0));
        assert!(runs_in_sight(&path, Pos2::ZERO, 1.0, away, 1.0).is_empty());
        let near = Rect::from_min_max(Pos2::new(-1.0, -1.0), Pos2::new(1.0, 1.0));
        let there_and_back: Vec<Pos2> = (0..50)
            .chain((0..=50).rev())
            .map(|x| Pos2::new(x as f32, 0.0))
            .collect();
        assert_eq!(
            runs_in_sight(&there_and_back, Pos2::ZERO, 1.0, near, 1.0).len(),
            2
        );
    }

    #[test]
    fn the_raster_is_the_ink_in_its_colour_on_a_clear_ground() {
        let paths = [Path {
            points: vec![Pos2::new(2.0, 8.0), Pos2::new(14.0, 8.0)],
            width: 1.0,
        }];
        let spec = RasterSpec {
            paths: (0, false, 0),
            strokes: vec![(0, Color32::from_rgb(200, 0, 0))],
            tiles: vec![[0.0, 0.0]],
            // 2 screen px per image px, the image 4 px right of the region.
            at: Placement {
                scale: 2.0,
                offset: [4.0, 0.0],
            },
            region: [0, 0, 40, 20],
        };
        let img = rasterize(&paths, &spec);
        assert_eq!(img.size, [40, 20]);
        // On the line (x 8 to 32, y 16 ± 1): the ink, opaque.
        let on = img.pixels[15 * 40 + 20];
        assert_eq!((on.r(), on.g(), on.a()), (200, 0, 255));
        // Away from it: clear.
        assert_eq!(img.pixels[5 * 40 + 20], Color32::TRANSPARENT);
        assert_eq!(img.pixels[15 * 40 + 38], Color32::TRANSPARENT);
    }
}
