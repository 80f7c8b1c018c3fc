//! The Pens section of the panel: one ink, or several pens sampled
//! together (presets, a list with swatches, add and remove, each pen's
//! width), and which pens the view shows.

use egui::{Color32, Sense};

use super::PixelPieApp;
use crate::colour::pens::{MAX_PENS, Pen, PenSet, name_of};

/// Colours offered, in order, for a pen added to the set.
const NEW_PENS: &[[u8; 3]] = &[
    [0, 0, 0],
    [214, 39, 40],
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [148, 103, 189],
    [140, 86, 75],
    [0, 255, 255],
    [255, 0, 255],
    [255, 255, 0],
];

impl PixelPieApp {
    /// Presets, the list of pens and the pens shown.
    pub(super) fn pens_ui(&mut self, ui: &mut egui::Ui) {
        let job = &mut self.settings.job;
        ui.horizontal(|ui| {
            ui.label("Pens").on_hover_text(
                "Draw with several pens sampled together, so that their dots interleave; \
                 the photo is separated into their inks",
            );
            if ui
                .selectable_label(job.pens.is_none(), "One ink")
                .on_hover_text("One pen in the dot colour below: the grey drawing")
                .clicked()
            {
                job.pens = None;
            }
            if ui
                .selectable_label(job.pens == Some(PenSet::cmyk()), "CMYK")
                .on_hover_text("Cyan, magenta, yellow and black pens")
                .clicked()
            {
                job.pens = Some(PenSet::cmyk());
            }
        });
        self.pen_box_ui(ui);
        let job = &mut self.settings.job;
        let Some(set) = job.pens.clone() else {
            return;
        };
        let mut pens: Vec<Pen> = set.pens().to_vec();
        let pen_mm = job.pen_mm;
        let mut changed = false;
        let mut remove = None;
        self.settings.hidden_pens.resize(pens.len(), false);
        for (k, pen) in pens.iter_mut().enumerate() {
            ui.horizontal(|ui| {
                let shown = &mut self.settings.hidden_pens[k];
                let mut visible = !*shown;
                if ui
                    .checkbox(&mut visible, "")
                    .on_hover_text("Show this pen's dots in the view (exports keep every pen)")
                    .changed()
                {
                    *shown = !visible;
                }
                swatch(ui, pen.colour, &pen.name);
                let mut rgb = pen.colour;
                ui.spacing_mut().item_spacing.x = 3.0;
                for (i, what) in ["red", "green", "blue"].into_iter().enumerate() {
                    if ui
                        .add(egui::DragValue::new(&mut rgb[i]).update_while_editing(false))
                        .on_hover_text(format!("The pen's ink: its {what} (0 to 255)"))
                        .changed()
                    {
                        pen.colour = rgb;
                        if pen.name.starts_with('#') {
                            pen.name = name_of(rgb);
                        }
                        changed = true;
                    }
                }
                // The width the pen draws at: its own, else the export's
                // Pen mm; with neither, it draws no pen paths, which the
                // row says rather than showing 0.
                let mut width = pen.width_mm.or(pen_mm).unwrap_or(0.0);
                let own = pen.width_mm.is_some();
                let hover = match (own, pen_mm) {
                    (true, _) => "This pen's own width in the SVG's pen paths".to_owned(),
                    (false, Some(mm)) => format!(
                        "No width of its own: the export's Pen mm ({mm:.2} mm); drag to give it one"
                    ),
                    (false, None) => "No width: the dots are drawn as circles; set Pen mm \
                        (Export) or drag to give this pen a width"
                        .to_owned(),
                };
                let drag = egui::DragValue::new(&mut width)
                    .update_while_editing(false)
                    .range(0.0..=5.0)
                    .speed(0.01)
                    .max_decimals(2)
                    .custom_parser(|t| {
                        let t = t.trim().trim_end_matches("mm").trim();
                        if t == "no width" {
                            Some(0.0)
                        } else {
                            t.parse().ok()
                        }
                    })
                    .custom_formatter(move |v, _| {
                        if v <= 0.0 {
                            "no width".to_owned()
                        } else {
                            format!("{v:.2}mm")
                        }
                    });
                if ui.add(drag).on_hover_text(hover).changed() {
                    pen.width_mm = (width > 0.0).then_some(width);
                    changed = true;
                }
                if ui
                    .add_enabled(set.len() > 1, egui::Button::new("−"))
                    .on_hover_text("Remove this pen")
                    .clicked()
                {
                    remove = Some(k);
                }
            });
        }
        if let Some(k) = remove {
            pens.remove(k);
            self.settings.hidden_pens.remove(k);
            changed = true;
        }
        if ui
            .add_enabled(
                pens.len() < crate::colour::pens::MAX_PENS,
                egui::Button::new("Add pen"),
            )
            .on_hover_text("Add a pen in a colour the set lacks")
            .clicked()
            && let Some(&c) = NEW_PENS
                .iter()
                .find(|c| pens.iter().all(|p| p.colour != **c))
        {
            pens.push(Pen {
                name: name_of(c),
                colour: c,
                width_mm: None,
                dot_gain: None,
                opacity: None,
            });
            changed = true;
        }
        if changed {
            match PenSet::new(pens) {
                Ok(set) => {
                    self.settings.job.pens = Some(set);
                    self.pens_error = None;
                }
                Err(e) => self.pens_error = Some(super::words::app_line(&e)),
            }
        }
        let colour = ui.visuals().error_fg_color;
        super::panel::message_row(ui, self.pens_error.as_deref(), Some(colour));
    }
}

impl PixelPieApp {
    /// The pen box: load a pen file of up to 64 pens, see its pens, and
    /// choose N of them for the photo (`--pens BOX.toml --choose N`).
    fn pen_box_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let l = ui.label("Pen file");
            let edit = ui
                .add(egui::TextEdit::singleline(&mut self.pen_box_path).desired_width(80.0))
                .labelled_by(l.id)
                .on_hover_text(
                    "The path of a pen file (.toml, up to 64 pens: the pens you own) to choose \
                     the drawing's pens from; ~/ and file:// work",
                );
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui
                .button("Load pens")
                .on_hover_text("Load the pen box at the typed path")
                .clicked()
                || enter
            {
                let path = super::typed_path(&self.pen_box_path);
                self.load_pen_box(&path);
            }
            if ui
                .button("Pen box…")
                .on_hover_text("Choose a pen file with a file dialog")
                .clicked()
            {
                let folder = self.settings.last_dir.clone();
                match self.dialogs.pick_pens(folder.as_deref()) {
                    Ok(Some(path)) => {
                        self.pen_box_path = path.display().to_string();
                        self.load_pen_box(&path);
                    }
                    Ok(None) => {}
                    Err(why) => self.choice_note = Some(Err(why)),
                }
            }
        });
        if let Some((name, set)) = self.pen_box.clone() {
            egui::CollapsingHeader::new(format!("Pen box: {} pens ({name})", set.len()))
                .id_salt("pen box")
                .show(ui, |ui| {
                    ui.horizontal_wrapped(|ui| {
                        for p in set.pens() {
                            swatch(ui, p.colour, &p.name);
                            ui.label(&p.name);
                        }
                    });
                });
            ui.horizontal(|ui| {
                let most = set.len().min(MAX_PENS);
                ui.add(
                    egui::DragValue::new(&mut self.choose_count)
                        .update_while_editing(false)
                        .range(1..=most),
                )
                .on_hover_text("How many pens to choose");
                if ui
                    .button(format!("Choose {} for this photo", self.choose_count))
                    .on_hover_text(
                        "The pens whose drawing the render model predicts closest to the \
                         photo's colours",
                    )
                    .clicked()
                {
                    self.choose_from_box(&set);
                }
            });
        }
        let colour = match &self.choice_note {
            Some(Err(_)) => Some(ui.visuals().error_fg_color),
            _ => None,
        };
        let note = self.choice_note.as_ref().map(|n| match n {
            Ok(s) | Err(s) => s.as_str(),
        });
        super::panel::message_row(ui, note, colour);
    }

    /// Loads the pen box at `path` to choose from, or says why not.
    pub fn load_pen_box(&mut self, path: &std::path::Path) {
        if path.as_os_str().is_empty() {
            self.choice_note = Some(Err(
                "no pen file given: type its path or use Pen box…".into()
            ));
            return;
        }
        match PenSet::from_file(path) {
            Ok(set) => {
                let name = path.file_name().map_or_else(
                    || path.display().to_string(),
                    |n| n.to_string_lossy().into_owned(),
                );
                self.choose_count = self.choose_count.clamp(1, set.len().min(MAX_PENS));
                self.pen_box = Some((name, set));
                self.choice_note = None;
            }
            Err(e) => self.choice_note = Some(Err(super::words::app_line(&e))),
        }
    }

    /// Sets the job's pens to those chosen from `set` for the photo.
    fn choose_from_box(&mut self, set: &PenSet) {
        let Some(src) = &self.source else {
            self.choice_note = Some(Err("open a photo first".into()));
            return;
        };
        let mut job = self.settings.job.clone();
        job.pens = Some(set.clone());
        job.choose = Some(self.choose_count);
        job.ink = crate::job::Ink::BLACK;
        match job.chosen(crate::job::Picture::Colour(&src.colour)) {
            Ok((chosen, Some(c))) => {
                let names: Vec<&str> = c.pens.pens().iter().map(|p| p.name.as_str()).collect();
                self.choice_note = Some(Ok(format!(
                    "chose {}: predicted ΔE00 {:.2}",
                    names.join(", "),
                    c.predicted
                )));
                self.settings.hidden_pens = vec![false; c.pens.len()];
                // The note goes when the pens are no longer these.
                self.choice_pens = chosen.pens.clone();
                self.settings.job.pens = chosen.pens;
            }
            Ok((_, None)) => {}
            Err(e) => self.choice_note = Some(Err(super::words::app_line(&e))),
        }
    }
}

/// A pen's colour swatch, named for screen readers and tests.
fn swatch(ui: &mut egui::Ui, colour: [u8; 3], name: &str) {
    let (rect, resp) = ui.allocate_exact_size(egui::vec2(16.0, 16.0), Sense::hover());
    let [r, g, b] = colour;
    ui.painter()
        .rect_filled(rect, 2.0, Color32::from_rgb(r, g, b));
    ui.painter().rect_stroke(
        rect,
        2.0,
        egui::Stroke::new(1.0, Color32::GRAY),
        egui::StrokeKind::Inside,
    );
    let label = format!("pen {name}");
    resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Image, true, &label));
    resp.on_hover_text(name);
}
