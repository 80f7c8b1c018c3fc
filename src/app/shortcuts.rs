//! Keyboard shortcuts, the help panel that lists them, and undo of
//! settings changes.

use std::time::{Duration, Instant};

use egui::{Key, KeyboardShortcut, Modifiers};

use super::PixelPieApp;
use super::settings::Settings;

/// The shortcuts, as the help panel lists them.
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("Ctrl+O", "Open an image (file dialog)"),
    ("Ctrl+S", "Export the drawing (file dialog)"),
    ("F", "Fit the picture in the view"),
    ("+ / −", "Zoom in / out"),
    ("R", "Re-roll the seed (another drawing)"),
    ("Ctrl+Z", "Undo the last settings change"),
    ("F1", "Show or hide this help"),
];

/// Changes closer together than this are one step of undo (a slider drag).
pub const UNDO_GROUP: Duration = Duration::from_millis(400);
/// Undo steps kept.
pub const UNDO_DEPTH: usize = 100;

/// Settings changes, for undo.
#[derive(Default)]
pub struct History {
    steps: Vec<Settings>,
    seen: Option<Settings>,
    last_change: Option<Instant>,
}

impl History {
    /// Records `now` as the current settings; a change starts an undo step
    /// unless it follows the last one within [`UNDO_GROUP`].
    pub fn observe(&mut self, now: &Settings) {
        let Some(seen) = &self.seen else {
            self.seen = Some(now.clone());
            return;
        };
        if seen == now {
            return;
        }
        let grouped = self.last_change.is_some_and(|t| t.elapsed() < UNDO_GROUP);
        if !grouped {
            self.steps.push(seen.clone());
            if self.steps.len() > UNDO_DEPTH {
                self.steps.remove(0);
            }
        }
        self.last_change = Some(Instant::now());
        self.seen = Some(now.clone());
    }

    /// Makes the next change a step of its own (a button, a key).
    pub fn barrier(&mut self) {
        self.last_change = None;
    }

    /// The settings before the last change, if any.
    pub fn undo(&mut self) -> Option<Settings> {
        let back = self.steps.pop()?;
        self.seen = Some(back.clone());
        self.last_change = None;
        Some(back)
    }
}

impl PixelPieApp {
    /// Handles the shortcuts of this frame. Single keys act only when no
    /// text field has the keyboard.
    pub(super) fn handle_shortcuts(&mut self, ctx: &egui::Context) {
        let cmd = |k| KeyboardShortcut::new(Modifiers::COMMAND, k);
        let pressed = |s: KeyboardShortcut| ctx.input_mut(|i| i.consume_shortcut(&s));
        if pressed(cmd(Key::O)) {
            self.open_dialog(ctx);
        }
        if pressed(cmd(Key::S)) {
            self.export_dialog();
        }
        if pressed(cmd(Key::Z)) {
            self.undo();
        }
        if pressed(KeyboardShortcut::new(Modifiers::NONE, Key::F1)) {
            self.show_help = !self.show_help;
        }
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        // + and − zoom the picture, with or without Ctrl (egui's own Ctrl+±
        // UI scaling is off).
        let zoom_key = |k| ctx.input(|i| i.key_pressed(k) && !i.modifiers.alt);
        if zoom_key(Key::Plus) || zoom_key(Key::Equals) {
            self.zoom_by(1.25);
        }
        if zoom_key(Key::Minus) {
            self.zoom_by(0.8);
        }
        let key = |k| ctx.input(|i| i.key_pressed(k) && !i.modifiers.command && !i.modifiers.alt);
        if key(Key::F) {
            self.view.fit_next = true;
        }
        if key(Key::R) {
            self.reroll();
        }
    }

    /// Goes back to the settings before the last change.
    pub fn undo(&mut self) {
        if let Some(back) = self.history.undo() {
            let image = self.settings.image.clone();
            self.settings = Settings { image, ..back };
        }
    }

    /// Puts every control back to its default (the picture stays); undo
    /// brings them back.
    pub fn reset_settings(&mut self) {
        self.history.barrier();
        let keep = (self.settings.image.clone(), self.settings.last_dir.clone());
        self.settings = Settings {
            image: keep.0,
            last_dir: keep.1,
            ..Settings::default()
        };
    }

    /// Another seed: another drawing of the same picture.
    pub fn reroll(&mut self) {
        self.history.barrier();
        let seed = &mut self.settings.job.sampler.seed;
        *seed = crate::sampler::fixed::mix(*seed as u32 ^ 0x5bd1_e995).into();
    }

    /// The help window with the shortcuts.
    pub(super) fn help_ui(&mut self, ctx: &egui::Context) {
        let mut open = self.show_help;
        egui::Window::new("Keyboard shortcuts")
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .show(ctx, |ui| {
                egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                    for (keys, what) in SHORTCUTS {
                        ui.strong(*keys);
                        ui.label(*what);
                        ui.end_row();
                    }
                });
                ui.separator();
                ui.label("Drop an image on the window to open it. Scroll to zoom, drag to pan.");
            });
        self.show_help = open;
    }
}
