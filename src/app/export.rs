//! The Export section: the plotter options, the path and the format
//! buttons, and the exports themselves, all through the job's `write`.

use egui::Color32;

use super::PixelPieApp;
use super::panel::fixed_row;
use crate::job::{Order, Style};
use crate::stipple::DotSize;
use crate::stipple::svg::DotPath;

/// Dots narrower than this, in mm, do not print (a pen or a printer's
/// dot is wider).
pub const MIN_PRINT_MM: f64 = 0.1;

impl PixelPieApp {
    /// Under the Export row: the file written, or why not, on one line of
    /// fixed height (the whole text on hover), so that nothing above moves.
    fn export_result_ui(&self, ui: &mut egui::Ui) {
        let (text, color) = match (&self.export_error, &self.exported) {
            (Some(e), _) => (e.clone(), Color32::from_rgb(200, 40, 40)),
            (None, Some(p)) => (
                match &self.exported_note {
                    Some(note) => format!("wrote {}: {note}", p.display()),
                    None => format!("wrote {}", p.display()),
                },
                ui.visuals().text_color(),
            ),
            (None, None) => (
                self.pen_note.clone().unwrap_or_default(),
                ui.visuals().text_color(),
            ),
        };
        fixed_row(ui, true, |ui| {
            let label = egui::Label::new(egui::RichText::new(&text).color(color))
                .truncate()
                .show_tooltip_when_elided(false);
            let r = ui.add(label);
            if !text.is_empty() {
                r.on_hover_text(&text);
            }
        });
    }

    /// The Export section ([`Self::export_ui`]), its height measured for
    /// the panel's layout.
    pub(super) fn export_measured(&mut self, ui: &mut egui::Ui) {
        self.heights.export = ui.scope(|ui| self.export_ui(ui)).response.rect.height();
    }

    /// The Export section: plotter options (order, width, pen, dot path and
    /// the plot time), the path, the format buttons and the outcome. The
    /// job's `write` writes every format, as the CLI's.
    fn export_ui(&mut self, ui: &mut egui::Ui) {
        let placement = self.placement();
        let mut pen_note = None;
        let job = &mut self.settings.job;
        let line = job.style == Style::Line;
        ui.horizontal(|ui| {
            ui.label("Order");
            // A line is a tour whatever the order: shown as one, greyed.
            let tour = job.order == Order::Tsp || line;
            for (order, name, help) in [
                (
                    Order::None,
                    "Along a curve",
                    "A Hilbert curve through the dots, unplanned",
                ),
                (
                    Order::Tsp,
                    "Plotter (TSP)",
                    "A short pen path (a Hilbert curve and 2-opt)",
                ),
            ] {
                if ui
                    .add_enabled(
                        !line,
                        egui::Button::selectable(tour == (order == Order::Tsp), name),
                    )
                    .on_hover_text(help)
                    .on_disabled_hover_text(
                        "A line is always a tour: a short path through its points, without \
                         crossings",
                    )
                    .clicked()
                {
                    job.order = order;
                }
            }
        });
        ui.horizontal(|ui| {
            // The paper and a width exclude each other: with paper, the
            // width is the drawing's on the sheet, greyed out.
            let paper = job.paper.is_some();
            let why = placement.map_or_else(String::new, |p| {
                format!(
                    "The paper sizes the drawing: {:.0} × {:.0} mm on the sheet (Paper \
                     section; set Paper to None to give a width)",
                    p.size_mm.0, p.size_mm.1
                )
            });
            let mut mm = job.width_mm.is_some() || paper;
            ui.add_enabled(!paper, egui::Checkbox::new(&mut mm, "Width mm"))
                .on_hover_text("Size the SVG in millimetres; off: pixels")
                .on_disabled_hover_text(&why);
            let mut width = match (paper, placement) {
                (true, Some(p)) => p.size_mm.0,
                _ => job.width_mm.unwrap_or(200.0),
            };
            ui.add_enabled(
                mm && !paper,
                egui::DragValue::new(&mut width)
                    .update_while_editing(false)
                    .range(1.0..=5000.0)
                    .speed(1.0)
                    .max_decimals(1),
            )
            .on_hover_text("The SVG's width in mm")
            .on_disabled_hover_text(if paper {
                why.as_str()
            } else {
                "Tick Width mm to give one"
            });
            if !paper {
                job.width_mm = mm.then_some(width);
            }
            let sized = mm || paper;
            let had = job.pen_mm.is_some();
            let mut pen = had;
            // Dots left to their default are Fixed with a pen, Sized without.
            let moves_dots = job.dot.is_none();
            let ticked = ui
                .add_enabled(sized, egui::Checkbox::new(&mut pen, "Pen mm"))
                .on_hover_text(if moves_dots && !line {
                    "Draw each dot as a pen of this width draws it. With the dots' mode left \
                     to its default (Dot size), this makes them Fixed (all one size, as a pen \
                     draws them); unticked they are Sized again"
                } else {
                    "Draw each dot as a pen of this width draws it"
                })
                .on_disabled_hover_text("Needs a width in mm or a paper");
            // The pens' own widths beat this one: with every pen's own it
            // is not used.
            let (own, pens) = job.pens.as_ref().map_or((0, 0), |set| {
                let own = set.pens().iter().filter(|p| p.width_mm.is_some()).count();
                (own, set.len())
            });
            let all_own = pens > 0 && own == pens;
            let mut pen_mm = job.pen_mm.unwrap_or(0.3);
            ui.add_enabled(
                sized && pen && !all_own,
                egui::DragValue::new(&mut pen_mm)
                    .update_while_editing(false)
                    .range(0.05..=5.0)
                    .speed(0.01),
            )
            .on_hover_text(if own > 0 {
                format!(
                    "The width in mm of the pens without one of their own ({own} of the {pens} \
                     pens carry their own, Pens section)"
                )
            } else {
                "The pen's width in mm".to_owned()
            })
            .on_disabled_hover_text(if all_own {
                "Not used: every pen carries its own width (Pens section), and each draws at it"
            } else if !sized {
                "Needs a width in mm or a paper"
            } else {
                "Tick Pen mm to give one"
            });
            job.pen_mm = (sized && pen).then_some(pen_mm);
            if ticked.changed() && moves_dots && pen != had && !line {
                pen_note = Some(if pen {
                    "Pen mm: the dots are Fixed now, one size as a pen draws them (Dot size's \
                     Dots sets another mode)"
                } else {
                    "No Pen mm: the dots are Sized again (Dot size's Dots sets another mode)"
                });
            }
        });
        if let Some(note) = pen_note {
            self.pen_note = Some(note.to_owned());
        }
        let job = &mut self.settings.job;
        ui.horizontal(|ui| {
            let pen = job.pen_mm.is_some();
            let line = job.style == Style::Line;
            ui.label("Dot path").on_hover_text(
                "How the pen draws a dot wider than itself; a dot no wider than \
                 the pen is one touch",
            );
            for (path, name, help) in [
                (
                    DotPath::Spiral,
                    "Spiral",
                    "A spiral from the centre out and a closing circle: the ink is the dot's disk",
                ),
                (
                    DotPath::Circle,
                    "Circle",
                    "The closing circle alone: a ring, fast to plot, lighter than the disk",
                ),
                (
                    DotPath::Touch,
                    "Touch",
                    "One touch of the pen for every dot, whatever its size",
                ),
            ] {
                if ui
                    .add_enabled(
                        pen && !line,
                        egui::Button::selectable(job.dot_path == path, name),
                    )
                    .on_hover_text(help)
                    .on_disabled_hover_text(if line {
                        super::panel::NOT_A_LINE
                    } else {
                        "Needs a pen width (Pen mm)"
                    })
                    .clicked()
                {
                    job.dot_path = path;
                }
            }
            if !pen {
                job.dot_path = DotPath::Spiral;
            }
        });
        self.plot_time_ui(ui);
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
            if self.settings.job.poster.is_some()
                && ui
                    .button("Poster")
                    .on_hover_text(
                        "The poster as a folder (the path, its extension dropped): \
                         one SVG a sheet and poster.json",
                    )
                    .clicked()
            {
                self.export_poster();
            }
            ui.add(
                egui::DragValue::new(&mut self.settings.job.scale)
                    .update_while_editing(false)
                    .range(0.1..=8.0)
                    .speed(0.05)
                    .prefix("PNG ×"),
            )
            .on_hover_text("PNG pixels per sampled pixel");
        });
        self.dot_warning_ui(ui);
        self.pen_warning_ui(ui);
        self.export_result_ui(ui);
    }

    /// The pen's warning (dots narrower than the pen plots them), with a
    /// button that asks for the count that draws the tones true; a row of
    /// fixed height, empty without a warning.
    fn pen_warning_ui(&mut self, ui: &mut egui::Ui) {
        let warning = self.pen_warning().map(|c| {
            let text = super::words::app_text(&c.message());
            (text, c.true_count, c.plotted, c.asked)
        });
        // Mean greys: the plot's, and the picture's as the tones ask.
        fixed_row(ui, true, |ui| {
            let Some((text, count, plotted, asked)) = warning else {
                return;
            };
            if ui
                .button(format!("Use {count} dots"))
                .on_hover_text("Draw this many dots: the pen then draws the tones true")
                .clicked()
            {
                let job = &mut self.settings.job;
                job.points = Some(count);
                job.dot_mm = None;
                job.dot_radius = None;
            }
            let short = format!("Pen too wide: grey {plotted:.2}, not {asked:.2}");
            let label =
                egui::Label::new(egui::RichText::new(short).color(Color32::from_rgb(210, 120, 20)))
                    .truncate()
                    .show_tooltip_when_elided(false);
            ui.add(label).on_hover_text(text);
        });
    }

    /// The warning that the dots are too small for the export's size, on
    /// one line of fixed height (empty when they are not).
    fn dot_warning_ui(&self, ui: &mut egui::Ui) {
        let warning = self.dot_size_warning();
        fixed_row(ui, true, |ui| {
            let Some(text) = &warning else { return };
            let label =
                egui::Label::new(egui::RichText::new(text).color(Color32::from_rgb(210, 120, 20)))
                    .truncate()
                    .show_tooltip_when_elided(false);
            ui.add(label).on_hover_text(format!(
                "{text}. A printer or plotter cannot draw dots under {MIN_PRINT_MM} mm, and a \
                 PNG turns dots under a pixel into a grey haze. Use fewer dots, a larger width \
                 or paper, or a larger PNG scale."
            ));
        });
    }

    /// Why the dots are too small to print (under [`MIN_PRINT_MM`] across
    /// at the SVG's size in mm) or to see in the PNG (the job's own
    /// warning, [`crate::job::Job::png_check`]), or `None`. The size is
    /// that of the dots that hold half the drawing's ink, as the job
    /// measures it for the PNG.
    #[must_use]
    pub fn dot_size_warning(&self) -> Option<String> {
        let o = self.outcome.as_ref()?;
        let job = self.settings.job();
        let mut why = Vec::new();
        // The job's PNG rule at the scale that makes one PNG pixel
        // MIN_PRINT_MM on the page: its dots under a pixel are dots under
        // MIN_PRINT_MM in the SVG.
        if let Ok(Some(mm)) = job.mm_per_px(o.drawing.domain) {
            let mut print = job.clone();
            print.scale = (mm / MIN_PRINT_MM) as f32;
            if print.png_check(&o.drawing).is_some() {
                why.push(format!(
                    "half the ink in dots under {MIN_PRINT_MM} mm across in the SVG"
                ));
            }
        }
        if let Some(w) = job.png_check(&o.drawing) {
            why.push(super::words::app_text(&w));
        }
        (!why.is_empty()).then(|| format!("Dots too small: {}", why.join("; ")))
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
                // Said when the drawing written is not what the controls ask.
                self.exported_note = self.busy().then(|| {
                    let (n, what) = self.outcome.as_ref().map_or((0, "dots"), |o| {
                        let d = &o.drawing;
                        (
                            d.points.len(),
                            if d.strokes.is_empty() {
                                "dots"
                            } else {
                                "points on a line"
                            },
                        )
                    });
                    format!(
                        "the last finished drawing ({n} {what}); the one for the present \
                         settings is still being made"
                    )
                });
                let full = std::fs::canonicalize(&path).unwrap_or(path);
                if let Some(dir) = full.parent() {
                    self.settings.last_dir = Some(dir.to_path_buf());
                }
                self.export_path = full.display().to_string();
                self.exported = Some(full);
                self.export_error = None;
                self.pen_note = None;
            }
            Err(e) => {
                self.exported = None;
                self.export_error = Some(super::words::app_line(&e));
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
}
