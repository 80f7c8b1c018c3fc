//! The side panel's controls, one function per section (header, open,
//! spacing, levels, darts, dots, pens (`pens.rs`), paper (`paper.rs`),
//! view), and the helpers they share.

use egui::{Color32, Sense};

use super::PixelPieApp;
use super::settings::Background;
use crate::backend::BackendChoice;
use crate::importance::{MappingKind, Tones};
use crate::job::{DotMode, Style};
use crate::sampler::Policy;

impl PixelPieApp {
    /// The side panel's controls, one function per section.
    pub(super) fn controls(&mut self, ui: &mut egui::Ui) {
        self.header_ui(ui);
        self.open_ui(ui);
        self.frame_ui(ui);
        self.preset_ui(ui);
        self.count_ui(ui);
        // Collapsible sections, so that each is in reach on a small screen;
        // the pens and the paper (short) first, for the plot.
        let section = |name: &str, open: bool| {
            egui::CollapsingHeader::new(name.to_owned()).default_open(open)
        };
        section("Pens", true).show(ui, |ui| self.pens_ui(ui));
        section("Paper", true).show(ui, |ui| self.paper_ui(ui));
        section("Dot size", true).show(ui, |ui| self.dots_ui(ui));
        section("Sampling", true).show(ui, |ui| {
            self.spacing_ui(ui);
            self.levels_ui(ui);
            self.darts_ui(ui);
        });
        section("View", true).show(ui, |ui| self.view_ui(ui));
    }

    /// The photo's crop and quarter turn (the job's `crop` and `rotate`,
    /// as the CLI's `--crop` and `--rotate`), and why a crop does not fit.
    fn frame_ui(&mut self, ui: &mut egui::Ui) {
        // Without a picture yet (a job loaded before its photo) the crop is
        // kept as it is: the photo's size bounds only what is typed, and a
        // crop past the photo is refused in words (`framing_error`).
        let size = self.source.as_ref().map(super::Source::original_size);
        let (w, h) = size.unwrap_or((u32::MAX, u32::MAX));
        let job = &mut self.settings.job;
        ui.horizontal(|ui| {
            let turn = job.rotate.unwrap_or(0);
            if ui
                .button(format!("Turn 90° ({turn}°)"))
                .on_hover_text("Turn the photo a quarter clockwise")
                .clicked()
            {
                job.rotate = match (turn + 90) % 360 {
                    0 => None,
                    t => Some(t),
                };
            }
            let mut cropped = job.crop.is_some();
            if ui
                .checkbox(&mut cropped, "Crop")
                .on_hover_text("Draw a part of the photo: x, y, width, height in its pixels")
                .changed()
            {
                let (width, height) = size.unwrap_or((1, 1));
                job.crop = cropped.then_some(crate::importance::Crop {
                    x: 0,
                    y: 0,
                    width,
                    height,
                });
            }
        });
        if let Some(c) = &mut job.crop {
            ui.horizontal(|ui| {
                for (name, v, most) in [
                    ("x", &mut c.x, w - 1),
                    ("y", &mut c.y, h - 1),
                    ("w", &mut c.width, w),
                    ("h", &mut c.height, h),
                ] {
                    ui.add(
                        egui::DragValue::new(v)
                            .update_while_editing(false)
                            .range(0..=most)
                            .clamp_existing_to_range(false)
                            .prefix(format!("{name} ")),
                    )
                    .on_hover_text("In the photo's pixels, upright");
                }
            });
        }
        // While cropping, a row of its own for why the crop does not fit.
        if job.crop.is_some() || self.framing_error.is_some() {
            message_row(
                ui,
                self.framing_error.as_deref(),
                Some(Color32::from_rgb(200, 40, 40)),
            );
        }
    }

    /// Presets: the job's every setting saved to, or loaded from, a job
    /// file (`pixelpie stipple --save-job` / `--job`).
    fn preset_ui(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label("Preset");
            ui.add(egui::TextEdit::singleline(&mut self.preset_path).desired_width(110.0))
                .on_hover_text(
                    "A job file: every setting of the drawing; the command line's \
                     pixelpie stipple saves and replays the same files",
                );
            if ui
                .button("Save")
                .on_hover_text("Save every setting to the job file")
                .clicked()
            {
                self.save_preset();
            }
            if ui
                .button("Load")
                .on_hover_text("Load every setting from the job file")
                .clicked()
            {
                self.load_preset();
            }
        });
        message_row(ui, self.preset_note.as_deref(), None);
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
                let (undo, redo, cleared) = self.history_state();
                let since = cleared.map_or_else(String::new, |c| format!(" (the history was {c})"));
                if ui
                    .add_enabled(redo, egui::Button::new("Redo"))
                    .on_hover_text("Make the change undone again (Ctrl+Shift+Z)")
                    .on_disabled_hover_text("Nothing undone to redo")
                    .clicked()
                {
                    self.redo();
                }
                if ui
                    .add_enabled(undo, egui::Button::new("Undo"))
                    .on_hover_text(format!("Undo the last settings change (Ctrl+Z){since}"))
                    .on_disabled_hover_text(format!("Nothing to undo{since}"))
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
        // One row of fixed height: the picture decoding, why it could not
        // open, or its name and size (and why it may not be whole).
        if let Some(name) = self.loading_name() {
            fixed_row(ui, true, |ui| {
                self.busy_spinner(ui);
                ui.label(format!("decoding {name}…"));
            });
        } else if let Some(e) = &self.open_error {
            message_row(ui, Some(e), Some(Color32::from_rgb(200, 40, 40)));
        } else if let Some(src) = &self.source {
            let name = format!(
                "{} ({}×{})",
                src.path.as_ref().map_or_else(
                    || super::DEFAULT_IMAGE_NAME.to_owned(),
                    |p| p
                        .file_name()
                        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
                ),
                src.map.width(),
                src.map.height()
            );
            match &src.warning {
                Some(w) => message_row(
                    ui,
                    Some(&format!("{name} — warning: {w}")),
                    Some(Color32::from_rgb(210, 120, 20)),
                ),
                None => message_row(ui, Some(&name), None),
            }
        } else {
            message_row(ui, None, None);
        }
    }

    /// The dot count (or the radius range): always in sight, above the
    /// sections.
    fn count_ui(&mut self, ui: &mut egui::Ui) {
        let job = &mut self.settings.job;
        // The radii follow from the count (or the dots' size in mm), or are
        // the radius range as it is.
        // A line has a count: the Points field's, or its pen's.
        let line = job.style == Style::Line;
        let pen_line = line && job.pen_mm.is_some();
        let was_counted = job.points.is_some() || job.dot_mm.is_some() || line;
        let mut counted = was_counted;
        ui.add_enabled_ui(!line, |ui| {
            ui.horizontal(|ui| {
                ui.radio_value(&mut counted, true, "Point count")
                    .on_hover_text("Aim for a number of dots; the radii scale to fit it")
                    .on_disabled_hover_text(LINE_COUNT);
                ui.radio_value(&mut counted, false, "Radius range")
                    .on_hover_text(
                        "Use the radius range as it is, in domain pixels (the picture scaled \
                         as pixelpie stipple scales it: longer side 1024 px or more)",
                    )
                    .on_disabled_hover_text(LINE_COUNT);
            });
        });
        if counted != was_counted {
            job.dot_mm = None;
            job.dot_radius = None;
            if counted {
                job.points = Some(self.typed_points);
            } else {
                job.points = None;
                let imp = &mut job.importance;
                imp.min_radius = Some(imp.min_radius.unwrap_or(1.0));
            }
        }
        let typed = &mut self.typed_points;
        ui.add_enabled_ui(job.points.is_some(), |ui| {
            ui.horizontal(|ui| {
                let l = ui.label("Points");
                let mut n = job.points.unwrap_or(*typed);
                // Not clamped: a count out of range is refused in words.
                let r = ui
                    .add(
                        egui::DragValue::new(&mut n)
                            .update_while_editing(false)
                            .range(0..=usize::MAX)
                            .speed(50),
                    )
                    .labelled_by(l.id)
                    .on_hover_text(if line {
                        "How many points the line passes through (within 3%): more points, a \
                         thinner line"
                            .to_owned()
                    } else {
                        format!(
                            "How many dots the drawing has (within 3%): 1 to {} (a photo on \
                             the largest domain, 4096×4096 px, holds about 6 million dots of 1 \
                             px)",
                            super::settings::MAX_POINTS
                        )
                    })
                    .on_disabled_hover_text(if pen_line {
                        "A line with a pen: the pen's width and the picture's ink set the \
                         count (untick Pen mm to give one)"
                    } else {
                        "Point count sets it (the radius range or Dot mm sets the radii now)"
                    });
                if r.changed() && job.points.is_some() {
                    job.points = Some(n);
                    *typed = n;
                }
            });
        });
    }

    /// The radius range, mapping, tones, policy and exact spacing.
    fn spacing_ui(&mut self, ui: &mut egui::Ui) {
        let s = &mut self.settings;
        let imp = &mut s.job.importance;
        let mut lo = imp.min_radius.unwrap_or(1.0);
        let mut hi = imp
            .max_radius
            .unwrap_or(lo * crate::importance::DEFAULT_RADIUS_RATIO);
        let (lo0, hi0) = (lo, hi);
        let line = s.job.style == Style::Line;
        ui.add_enabled_ui(!line, |ui| {
            ui.horizontal(|ui| {
                let l = ui.label("Radius");
                ui.add(
                    egui::DragValue::new(&mut lo)
                        .update_while_editing(false)
                        .range(1.0..=500.0)
                        .speed(0.05)
                        .prefix("min "),
                )
                .labelled_by(l.id)
                .on_hover_text("Disk radius in black areas: the closest dots")
                .on_disabled_hover_text(NOT_A_LINE_MAP);
                ui.add(
                    egui::DragValue::new(&mut hi)
                        .update_while_editing(false)
                        .range(1.0..=500.0)
                        .speed(0.05)
                        .prefix("max "),
                )
                .on_hover_text("Disk radius in white areas: the sparsest dots")
                .on_disabled_hover_text(NOT_A_LINE_MAP);
            });
        });
        if lo != lo0 || hi != hi0 {
            imp.min_radius = Some(lo);
            imp.max_radius = Some(hi.max(lo));
        }
        let mut tone = imp.mapping != Some(MappingKind::Linear);
        ui.add_enabled_ui(!line, |ui| {
            egui::ComboBox::from_label("Mapping")
                .selected_text(if tone { "Tone" } else { "Linear" })
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut tone, true, "Tone").on_hover_text(
                        "Calibrated: the drawing's ink equals the picture's darkness.",
                    );
                    ui.selectable_value(&mut tone, false, "Linear")
                        .on_hover_text("The paper's ramp r_min + (r_max − r_min)·v.");
                })
                .response
                .on_hover_text("How a pixel's grey becomes its disk radius")
                .on_disabled_hover_text(NOT_A_LINE_MAP);
        });
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
                .update_while_editing(false)
                .logarithmic(true)
                .text("Gamma"),
        )
        .on_hover_text("Above 1 darkens the mid tones, below 1 lightens them");
        ui.add(
            egui::Slider::new(&mut imp.black_level, 0.0..=0.95)
                .update_while_editing(false)
                .text("Black level"),
        )
        .on_hover_text("Greys at or below this count as black");
        ui.add(
            egui::Slider::new(&mut imp.white_level, 0.05..=1.0)
                .update_while_editing(false)
                .text("White level"),
        )
        .on_hover_text("Greys at or above this count as white");
        imp.white_level = imp.white_level.max(imp.black_level + 0.01);
        ui.checkbox(&mut imp.invert, "Invert")
            .on_hover_text("Light parts get the dots (white ink on black paper)");
        let mut cutoff = imp.white_cutoff.unwrap_or(1.0);
        ui.add(
            egui::Slider::new(&mut cutoff, 0.0..=1.0)
                .update_while_editing(false)
                .text("White cutoff"),
        )
        .on_hover_text("No dots where the picture is lighter than this (1 = off)");
        imp.white_cutoff = (cutoff < 1.0).then_some(cutoff);
    }

    /// Sub-pixel bits, seed, periodic domain and backend.
    fn darts_ui(&mut self, ui: &mut egui::Ui) {
        let sampler = &mut self.settings.job.sampler;
        ui.add_enabled(
            !sampler.exact,
            egui::Slider::new(&mut sampler.subpixel_bits, 0..=7)
                .update_while_editing(false)
                .text("Sub-pixel bits"),
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
            ui.add(egui::DragValue::new(&mut sampler.seed).update_while_editing(false))
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
        // The steps the last drawing's plan took, the job's own when set.
        let planned = self.outcome.as_ref().map(|o| o.drawing.plan.relax);
        let typed = self.typed_points;
        let job = &mut self.settings.job;
        style_ui(ui, job);
        let line = job.style == Style::Line;
        let mut mode = job.dot_mode();
        ui.add_enabled_ui(!line, |ui| {
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
                .on_hover_text(
                    "How the dots are sized. Fixed: all alike, the tones made by their spacing (a \
                 pen's own width). Sized: larger where it is dark, as StippleGen. Both are \
                 calibrated, so that the drawing's grey is the picture's. Proportional: a \
                 fraction of each sample's disk, a texture that does not keep the tones.",
                )
                .on_disabled_hover_text(NOT_A_LINE);
        });
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
            .add_enabled(
                !line,
                egui::Slider::new(&mut factor, range)
                    .update_while_editing(false)
                    .text(text),
            )
            .on_hover_text(help)
            .on_disabled_hover_text(NOT_A_LINE)
            .changed()
        {
            job.dot_factor = Some(factor);
        }
        // The darkest dots' diameter on the page, when it has a size in mm
        //: then it, not the count, sets the radii.
        let on_page = job.width_mm.is_some() || job.paper.is_some();
        ui.add_enabled_ui(on_page && !line, |ui| {
            ui.horizontal(|ui| {
                let mut sized = job.dot_mm.is_some();
                if ui
                    .checkbox(&mut sized, "Dot mm")
                    .on_hover_text(
                        "Give the darkest dots' diameter on the page in mm instead \
                         of a count: the count follows",
                    )
                    .on_disabled_hover_text(if line {
                        NOT_A_LINE
                    } else {
                        "Needs a width in mm or paper (Paper section)"
                    })
                    .changed()
                {
                    job.dot_mm = sized.then_some(1.0);
                    job.points = (!sized).then_some(typed);
                    job.dot_radius = None;
                    job.importance.min_radius = None;
                }
                if let Some(d) = &mut job.dot_mm {
                    ui.add(
                        egui::DragValue::new(d)
                            .update_while_editing(false)
                            .range(0.05..=20.0)
                            .speed(0.01)
                            .suffix(" mm"),
                    );
                }
            });
        });
        let job = &mut self.settings.job;
        ui.add_enabled(
            mode == DotMode::Sized && !line,
            egui::Slider::new(&mut job.dot_ratio, 0.1..=1.0)
                .update_while_editing(false)
                .text("Lightest / darkest dot"),
        )
        .on_hover_text("The lightest dots' radius as a fraction of the darkest dots'")
        .on_disabled_hover_text(if line { NOT_A_LINE } else { "Sized dots only" });
        let mut local = job.spacing == crate::job::Spacing::Local;
        if ui
            .add_enabled(
                job.spacing_applies() && !line,
                egui::Checkbox::new(&mut local, "Size for local spacing"),
            )
            .on_hover_text(
                "Size each dot for the spacing the dots have around it: \
                 where an edge or the policy thins them out, bigger, so the tones hold. Off: \
                 for its sample radius alone, as earlier versions drew.",
            )
            .on_disabled_hover_text(if line {
                NOT_A_LINE
            } else {
                "Sized dots of a grey drawing on a tone mapping only (one ink or one pen)"
            })
            .changed()
        {
            job.spacing = if local {
                crate::job::Spacing::Local
            } else {
                crate::job::Spacing::Radius
            };
        }
        let mut correct = job.correction == crate::job::Correction::On;
        if ui
            .add_enabled(
                mode == DotMode::Sized || line,
                egui::Checkbox::new(&mut correct, "Correct tones by rendering"),
            )
            .on_hover_text(if line {
                "Render the line, blur it, compare it with the picture and move its points \
                 toward the ink each part lacks (up to 100 000 points; up to 30 000 are first \
                 spread again for it). Off: the calibration alone."
            } else {
                "Render the drawing, blur it by the dot spacing, compare it with the picture and \
                 resize each dot for the ink its neighbourhood lacks. Off: the \
                 calibration's curves alone, as earlier versions drew."
            })
            .on_disabled_hover_text("Sized dots or a line only")
            .changed()
        {
            job.correction = if correct {
                crate::job::Correction::On
            } else {
                crate::job::Correction::Off
            };
        }
        // Relaxation: by default two over-relaxed steps up to 200K dots,
        // none past.
        let mut auto = job.relax.is_none();
        if ui
            .checkbox(&mut auto, "Auto relax")
            .on_hover_text(format!(
                "{} Lloyd steps (over-relaxed) up to {}K dots where dots are corrected \
                 (sized, tones corrected by rendering), else none (a step costs about as much \
                 as sampling at 1M dots); in colour, each pen's dots on their own",
                crate::job::AUTO_RELAX_STEPS,
                crate::job::AUTO_RELAX_DOTS / 1000
            ))
            .changed()
        {
            job.relax = (!auto).then(|| planned.unwrap_or(crate::job::AUTO_RELAX_STEPS));
        }
        let mut steps = job
            .relax
            .or(planned)
            .unwrap_or(crate::job::AUTO_RELAX_STEPS);
        if ui
            .add_enabled(
                !auto,
                egui::Slider::new(&mut steps, 0..=30)
                    .update_while_editing(false)
                    .text("Relax (Lloyd steps)"),
            )
            .on_hover_text("Weighted Voronoi relaxation after sampling: more even spacing.")
            .on_disabled_hover_text("Untick Auto relax to choose the steps")
            .changed()
        {
            job.relax = Some(steps);
        }
        // One ink's colour; with pens each pen has its own.
        ui.add_enabled_ui(job.pens.is_none(), |ui| ink_ui(ui, &mut job.ink.0));
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
        let line = s.job.style == Style::Line;
        ui.add_enabled(!line, egui::Checkbox::new(&mut s.show_travel, "Pen travel"))
            .on_disabled_hover_text("A line is drawn pen down: it is its own travel")
            .on_hover_text(format!(
                "The pen's moves from dot to dot in drawing order (pen up), each pen's in its \
             colour: the plotter's path (Order: Plotter shortens it); the first {} moves",
                super::view::MAX_TRAVEL_MOVES
            ));
        if ui
            .button("Fit view")
            .on_hover_text("Fit the picture in the view (F); + and − zoom")
            .clicked()
        {
            self.view.fit_next = true;
        }
    }
}

/// Why the radii's controls are greyed out for a line.
const NOT_A_LINE_MAP: &str = "Dots only: a line spreads its points for the darkness squared, \
                              its own radii";

/// Why the count's mode is greyed out for a line.
const LINE_COUNT: &str = "A line's count is Points (or its pen's, with Pen mm): the line's \
                          width follows";

/// Why a control of the dots is greyed out for a line.
pub(super) const NOT_A_LINE: &str = "Dots only: a line drawing has no dots (Style)";

/// The style (dots or one line) and the line's smoothing.
fn style_ui(ui: &mut egui::Ui, job: &mut crate::job::Job) {
    ui.horizontal(|ui| {
        ui.label("Style").on_hover_text(
            "What the pen draws: dots, or one continuous line through the points (TSP art)",
        );
        ui.selectable_value(&mut job.style, Style::Dots, "Dots")
            .on_hover_text("Stipples: a dot for every point");
        ui.selectable_value(&mut job.style, Style::Line, "Line")
            .on_hover_text(
                "One continuous pen line through the points, whose ink reproduces the tones. \
                 With Pen mm the pen's width sets the count; without, Points sets the \
                 line's width. With several pens, one line for each.",
            );
        ui.add_enabled(
            job.style == Style::Line,
            egui::Checkbox::new(&mut job.line_smooth, "Smooth line"),
        )
        .on_hover_text("Smooth curves through the points instead of straight segments")
        .on_disabled_hover_text("A line only (Style: Line)");
    });
}

/// A row at least one control high and the panel's width (at most, with
/// `clip`), whatever `add` puts in it, so that the rows around it stay put.
pub(super) fn fixed_row(ui: &mut egui::Ui, clip: bool, add: impl FnOnce(&mut egui::Ui)) {
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

/// A message's row: always one control high, present or not, so that a
/// message never moves the controls below it; a message wider than the
/// panel is cut with "…" and shown whole on hover.
pub(super) fn message_row(ui: &mut egui::Ui, message: Option<&str>, colour: Option<Color32>) {
    fixed_row(ui, true, |ui| {
        if let Some(text) = message {
            let mut rich = egui::RichText::new(text);
            if let Some(c) = colour {
                rich = rich.color(c);
            }
            ui.add(
                egui::Label::new(rich)
                    .truncate()
                    .show_tooltip_when_elided(false),
            )
            .on_hover_text(text);
        }
    });
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
            ui.add(
                egui::DragValue::new(&mut ink[i])
                    .update_while_editing(false)
                    .prefix(c),
            )
            .on_hover_text("The ink's red, green and blue (0 to 255)");
        }
    });
}
