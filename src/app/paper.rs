//! The Paper section of the panel: a sheet (none, a named size, or a custom
//! width × height in mm), its orientation and its margin, the job's
//! `paper`, `landscape` and `margin` (`pixelpie stipple --paper --landscape
//! --margin`); and where the sheet lies around the drawing in the view.

use egui::{Rect, Vec2};

use super::PixelPieApp;
use crate::job::{Job, PaperColour};
use crate::stipple::{Paper, Placement};

/// The sheets offered, as shown and as the job names them.
const SHEETS: [(&str, &str); 6] = [
    ("A5", "a5"),
    ("A4", "a4"),
    ("A3", "a3"),
    ("Letter", "letter"),
    ("Legal", "legal"),
    ("Tabloid", "tabloid"),
];

/// A custom sheet's size when none is set yet, mm.
const CUSTOM_MM: (f64, f64) = (300.0, 200.0);

/// The paper picked in the combo box.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Choice {
    /// No paper: the SVG in px, or `--width-mm`.
    None,
    /// A named sheet (its name in the job).
    Named(&'static str),
    /// Width × height in mm.
    Custom,
}

/// The choice that `paper` stands for, and how the combo box shows it.
fn choice(paper: Option<&Paper>) -> (Choice, String) {
    match paper {
        None => (Choice::None, "None".into()),
        Some(p) => match SHEETS.iter().find(|(_, n)| *n == p.name) {
            Some(&(label, name)) => (Choice::Named(name), label.into()),
            // Sheets the combo box does not list (a2, a6…, from the saved
            // settings) show under their own name, as named sheets.
            None if !p.name.ends_with("mm") => (Choice::Custom, p.name.to_uppercase()),
            None => (Choice::Custom, "Custom".into()),
        },
    }
}

/// The largest margin the sheet leaves room for (the job refuses margins
/// of half its shorter side or more), mm.
fn max_margin(paper: &Paper) -> f64 {
    (paper.width_mm.min(paper.height_mm) / 2.0 - 1.0).max(0.0)
}

/// A custom sheet of `w` × `h` mm, turned as given: landscape when wider
/// than tall.
fn set_custom(job: &mut Job, (w, h): (f64, f64)) {
    if let Ok(p) = format!("{w}x{h}mm").parse::<Paper>() {
        job.paper = Some(p);
        job.landscape = w > h;
    }
}

impl PixelPieApp {
    /// The sheet, its orientation, its margin and (custom) its size. The
    /// paper and the export's width in mm exclude each other: choosing a
    /// sheet turns the width off. Without paper, the margin and the
    /// orientation grey out (the job has neither).
    pub(super) fn paper_ui(&mut self, ui: &mut egui::Ui) {
        let job = &mut self.settings.job;
        let (current, shown) = choice(job.paper.as_ref());
        let mut picked = current;
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("Paper")
                .selected_text(shown)
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut picked, Choice::None, "None")
                        .on_hover_text("No sheet: the SVG in pixels, or the export's width in mm");
                    for (label, name) in SHEETS {
                        ui.selectable_value(&mut picked, Choice::Named(name), label);
                    }
                    ui.selectable_value(&mut picked, Choice::Custom, "Custom")
                        .on_hover_text("A sheet of any width × height in mm");
                })
                .response
                .on_hover_text(
                    "The sheet the drawing is plotted on: the drawing fits inside \
                     the margins, centred, keeping its aspect, and the SVG is the whole sheet \
                     in mm",
                );
            ui.add_enabled(
                job.paper.is_some(),
                egui::Checkbox::new(&mut job.landscape, "Landscape"),
            )
            .on_hover_text("Turn the sheet wider than tall")
            .on_disabled_hover_text("Choose a paper first");
        });
        if picked != current {
            match picked {
                Choice::None => {
                    job.paper = None;
                    job.margin = None;
                    job.landscape = false;
                    // A pen needs a page in mm: without paper or a width
                    // there is none.
                    if job.width_mm.is_none() {
                        job.pen_mm = None;
                        job.dot_path = crate::stipple::svg::DotPath::Spiral;
                    }
                }
                Choice::Named(name) => {
                    job.paper = name.parse().ok();
                    job.width_mm = None;
                }
                Choice::Custom => {
                    let size = job
                        .paper
                        .as_ref()
                        .map_or(CUSTOM_MM, |p| p.oriented(job.landscape));
                    set_custom(job, size);
                    job.width_mm = None;
                }
            }
        }
        let on = job.paper.is_some();
        ui.horizontal(|ui| {
            let l = ui.label("Margin");
            let mut margin = job.margin();
            let top = job.paper.as_ref().map_or(100.0, max_margin);
            let r = ui
                .add_enabled(
                    on,
                    egui::DragValue::new(&mut margin)
                        .update_while_editing(false)
                        .range(0.0..=top)
                        .speed(0.5)
                        .max_decimals(1)
                        .suffix(" mm"),
                )
                .labelled_by(l.id)
                .on_hover_text("Blank paper around the drawing on every side")
                .on_disabled_hover_text("Choose a paper first");
            if r.changed() {
                job.margin = Some(margin);
            }
            ui.add_space(8.0);
            let custom = current == Choice::Custom && picked == Choice::Custom;
            let (mut w, mut h) = job
                .paper
                .as_ref()
                .map_or(CUSTOM_MM, |p| p.oriented(job.landscape));
            let (w0, h0) = (w, h);
            fn side(v: &mut f64) -> egui::DragValue<'_> {
                egui::DragValue::new(v)
                    .update_while_editing(false)
                    .range(10.0..=10_000.0)
                    .speed(1.0)
                    .max_decimals(1)
            }
            ui.add_enabled(custom, side(&mut w))
                .on_hover_text("The sheet's width in mm (Custom paper)")
                .on_disabled_hover_text("The sheet's width in mm; choose Custom to type one");
            ui.label("×");
            ui.add_enabled(custom, side(&mut h))
                .on_hover_text("The sheet's height in mm (Custom paper)")
                .on_disabled_hover_text("The sheet's height in mm; choose Custom to type one");
            ui.label("mm");
            if custom && (w, h) != (w0, h0) {
                set_custom(job, (w, h));
            }
        });
        self.poster_ui(ui);
        let job = &mut self.settings.job;
        ui.horizontal(|ui| {
            let l = ui.label("Paper colour");
            let now = job.paper_colour.unwrap_or(PaperColour::WHITE);
            let name = |c: PaperColour| c.to_string();
            egui::ComboBox::from_id_salt("paper colour")
                .selected_text(name(now))
                .show_ui(ui, |ui| {
                    for (n, c) in PaperColour::NAMES {
                        let c = PaperColour(c);
                        if ui.selectable_label(now == c, n).clicked() {
                            job.paper_colour = (c != PaperColour::WHITE).then_some(c);
                        }
                    }
                })
                .response
                .labelled_by(l.id)
                .on_hover_text(
                    "The paper's colour: the inks lie on it; an ink \
                     lighter than the paper covers it (a white gel pen on black)",
                );
        });
        // A smaller sheet can leave no room for the margin: keep it inside.
        if let Some(p) = &job.paper
            && job.margin() > max_margin(p)
        {
            job.margin = Some(max_margin(p));
        }
    }

    /// Where the drawing lies on the job's paper, for the drawing on screen
    /// (or, before the first, for the picture); `None` without paper.
    #[must_use]
    pub fn placement(&self) -> Option<Placement> {
        let domain = match (&self.outcome, &self.source) {
            (Some(o), _) => o.drawing.domain,
            (None, Some(src)) => (src.map.width(), src.map.height()),
            (None, None) => return None,
        };
        self.settings.job().placement(domain).ok().flatten()
    }

    /// The sheet and its printable area (inside the margins) in picture
    /// pixels, the drawing being `(0, 0)`–`size`: the placement's mm mapped
    /// onto the picture's pixels. `None` without paper, or when the view
    /// shows tiles.
    pub(super) fn sheet(&self, size: Vec2) -> Option<(Rect, Rect)> {
        if self.tiles() > 1 {
            return None;
        }
        let p = self.placement()?;
        let k = Vec2::new(size.x / p.size_mm.0 as f32, size.y / p.size_mm.1 as f32);
        let origin = Vec2::new(p.origin_mm.0 as f32, p.origin_mm.1 as f32) * k;
        let sheet_size = Vec2::new(p.sheet_mm.0 as f32, p.sheet_mm.1 as f32) * k;
        let sheet = Rect::from_min_size((-origin).to_pos2(), sheet_size);
        let margin = Vec2::splat(p.margin_mm as f32) * k;
        Some((sheet, sheet.shrink2(margin)))
    }
}
