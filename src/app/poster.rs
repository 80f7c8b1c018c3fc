//! A poster in the app (`pixelpie stipple --poster WxH`): the Poster row
//! of the Paper section, the sheet grid over the view, and the export of
//! the folder of sheets, each through the job's own poster functions.

use egui::{Color32, Pos2, Rect, Stroke, Vec2};

use super::PixelPieApp;
use crate::job::{Job, Picture, SheetGrid};
use crate::stipple::Paper;
use crate::stipple::plot::Plotter;

/// The poster's size when one is turned on: two sheets by two.
fn first_size(paper: Option<&Paper>, landscape: bool) -> (f64, f64) {
    let (w, h) = paper.map_or((210.0, 297.0), |p| p.oriented(landscape));
    (2.0 * w, 2.0 * h)
}

/// The sheets' edges over the view.
const SHEET_EDGE: Color32 = Color32::from_rgb(40, 90, 220);
/// The seams (where one sheet's dots end and the next one's begin).
const SEAM: Color32 = Color32::from_rgb(220, 40, 40);

impl PixelPieApp {
    /// The Poster row: on (with a paper, the sheet), its width × height in
    /// mm, and how many sheets it takes.
    pub(super) fn poster_ui(&mut self, ui: &mut egui::Ui) {
        self.refresh_poster_grid();
        let sheets = self.poster_grid().map(|g| (g.rows, g.cols));
        let job = &mut self.settings.job;
        let on_paper = job.paper.is_some();
        if !on_paper {
            job.poster = None;
        }
        ui.horizontal(|ui| {
            let mut on = job.poster.is_some();
            let r = ui
                .add_enabled(on_paper, egui::Checkbox::new(&mut on, "Poster"))
                .on_hover_text(
                    "Draw the picture at a poster's size and plot it sheet by sheet: \
                     the paper is the sheet, the sheets overlap, registration crosses \
                     on the seams; export writes a folder of one SVG a sheet",
                )
                .on_disabled_hover_text("Choose a paper first: it is the poster's sheet");
            if r.changed() {
                job.poster = if on {
                    let (w, h) = first_size(job.paper.as_ref(), job.landscape);
                    format!("{w}x{h}mm").parse().ok()
                } else {
                    None
                };
            }
            let (mut w, mut h) = job.poster.as_ref().map_or_else(
                || first_size(job.paper.as_ref(), job.landscape),
                |p| (p.width_mm, p.height_mm),
            );
            let (w0, h0) = (w, h);
            fn side(v: &mut f64) -> egui::DragValue<'_> {
                egui::DragValue::new(v)
                    .update_while_editing(false)
                    .range(20.0..=20_000.0)
                    .speed(5.0)
                    .max_decimals(0)
            }
            let on = job.poster.is_some();
            ui.add_enabled(on, side(&mut w))
                .on_hover_text("The poster's width in mm");
            ui.label("×");
            ui.add_enabled(on, side(&mut h))
                .on_hover_text("The poster's height in mm");
            ui.label("mm");
            if on
                && (w, h) != (w0, h0)
                && let Ok(p) = format!("{w}x{h}mm").parse::<Paper>()
            {
                job.poster = Some(p);
            }
            if let (true, Some((rows, cols))) = (on, sheets) {
                ui.label(format!("{} sheets ({rows} × {cols})", rows * cols))
                    .on_hover_text("Rows × columns of the paper, as the export cuts them");
            }
        });
    }

    /// The grid the drawing on screen is cut along for the poster, when
    /// there is one, as the last frame made it ([`Self::refresh_poster_grid`]).
    #[must_use]
    pub fn poster_grid(&self) -> Option<SheetGrid> {
        self.poster_view.as_ref().and_then(|(_, g)| g.clone())
    }

    /// Makes the poster's grid again when the drawing or the job changed
    /// (it reads every dot: not once a frame).
    pub(super) fn refresh_poster_grid(&mut self) {
        let key = (self.dots_generation, self.settings.job());
        if self.poster_view.as_ref().map(|(k, _)| k) != Some(&key) {
            let grid = self.poster_cut().map(|(_, _, g)| g);
            self.poster_view = Some((key, grid));
        }
    }

    /// The framed job (the drawing's), the job that draws the poster whole,
    /// and the grid the drawing on screen is cut along; `None` without a
    /// poster or a drawing, or when the sheets cannot hold its dots.
    pub(super) fn poster_cut(&self) -> Option<(Job, Job, SheetGrid)> {
        let (o, src) = (self.outcome.as_ref()?, self.source.as_ref()?);
        let run = self.settings.framed().job();
        run.poster.as_ref()?;
        let whole = run
            .poster_whole(Picture::Both(&src.map, &src.colour))
            .ok()??;
        let grid = run.poster_grid(&whole, &o.drawing).ok()?;
        Some((run, whole, grid))
    }

    /// The sheets' edges (blue) and the seams (red) over the view, the
    /// drawing being `(0, 0)`–`size` picture pixels at the poster's frame.
    pub(super) fn paint_poster(&mut self, painter: &egui::Painter, rect: Rect, size: Vec2) {
        self.refresh_poster_grid();
        let Some(g) = self.poster_grid() else {
            return;
        };
        let [fx, fy, fw, fh] = g.frame_mm;
        let k = Vec2::new(size.x / fw as f32, size.y / fh as f32);
        let at = |x: f64, y: f64| Pos2::new(((x - fx) as f32) * k.x, ((y - fy) as f32) * k.y);
        for row in 0..g.rows {
            for col in 0..g.cols {
                let [x, y] = g.sheet_origin(row, col);
                let sheet = Rect::from_min_max(at(x, y), at(x + g.sheet_mm[0], y + g.sheet_mm[1]));
                painter.rect_stroke(
                    self.on_screen(rect, sheet),
                    0.0,
                    Stroke::new(1.0, SHEET_EDGE),
                    egui::StrokeKind::Middle,
                );
            }
        }
        // The seams: the middle of each overlap, across the grid.
        let [.., x1, y1] = g.printable_mm(g.rows - 1, g.cols - 1);
        let [x0, y0, ..] = g.printable_mm(0, 0);
        let screen = |p: Pos2| rect.min + self.view.pan + p.to_vec2() * self.view.zoom;
        for c in 0..g.cols.saturating_sub(1) {
            let x = g.printable_mm(0, c)[2] - g.overlap_mm / 2.0;
            painter.line_segment(
                [screen(at(x, y0)), screen(at(x, y1))],
                Stroke::new(1.0, SEAM),
            );
        }
        for r in 0..g.rows.saturating_sub(1) {
            let y = g.printable_mm(r, 0)[3] - g.overlap_mm / 2.0;
            painter.line_segment(
                [screen(at(x0, y)), screen(at(x1, y))],
                Stroke::new(1.0, SEAM),
            );
        }
    }

    /// Exports the poster to the folder the export path names (its
    /// extension dropped): one SVG a sheet and poster.json, as `pixelpie
    /// stipple --poster -o DIR/` writes them.
    pub fn export_poster(&mut self) {
        let typed = self.export_path.trim();
        if typed.is_empty() {
            self.export_error = Some("no folder given: type one or use Browse".into());
            return;
        }
        let dir = super::typed_path(typed).with_extension("");
        let Some((run, whole, _)) = self.poster_cut() else {
            self.export_error = Some("no poster to export: turn Poster on and draw".into());
            return;
        };
        let Some(o) = &self.outcome else { return };
        let plotter = Plotter::default();
        let written = run.poster(&whole, &o.drawing, &mut || false).and_then(|p| {
            p.write(&run, &dir, run.pen_mm.is_some().then_some(&plotter))
                .map(|()| p)
        });
        match written {
            Ok(p) => {
                let full = std::fs::canonicalize(&dir).unwrap_or(dir);
                self.settings.last_dir = full.parent().map(std::path::Path::to_path_buf);
                self.exported_note = Some(format!("{} sheets and poster.json", p.sheets.len()));
                self.export_path = full.display().to_string();
                self.exported = Some(full);
                self.export_error = None;
            }
            Err(e) => {
                self.exported = None;
                self.export_error = Some(super::words::app_line(&e));
            }
        }
    }
}
