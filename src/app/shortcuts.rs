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
    ("Ctrl+Shift+Z, Ctrl+Y", "Redo the change undone"),
    ("F1", "Show or hide this help"),
];

/// Changes closer together than this are one step of undo (a slider drag).
pub const UNDO_GROUP: Duration = Duration::from_millis(400);
/// Undo steps kept.
pub const UNDO_DEPTH: usize = 100;

/// Settings changes, for undo and redo. The picture and the last folder
/// are not settings changes: undo keeps them as they are.
#[derive(Default)]
pub struct History {
    steps: Vec<Settings>,
    undone: Vec<Settings>,
    seen: Option<Settings>,
    last_change: Option<Instant>,
    /// When the history was last cleared ("when g.png opened"), if it held
    /// anything then.
    cleared: Option<String>,
}

/// `s` without what undo leaves alone (the picture, the last folder).
fn undoable(s: &Settings) -> Settings {
    Settings {
        image: None,
        last_dir: None,
        ..s.clone()
    }
}

impl History {
    /// Records `now` as the current settings; a change starts an undo step
    /// unless it follows the last one within [`UNDO_GROUP`], and leaves
    /// nothing to redo.
    pub fn observe(&mut self, now: &Settings) {
        let now = undoable(now);
        let Some(seen) = &self.seen else {
            self.seen = Some(now);
            return;
        };
        if *seen == now {
            return;
        }
        let grouped = self.last_change.is_some_and(|t| t.elapsed() < UNDO_GROUP);
        if !grouped {
            self.steps.push(seen.clone());
            if self.steps.len() > UNDO_DEPTH {
                self.steps.remove(0);
            }
        }
        self.undone.clear();
        self.last_change = Some(Instant::now());
        self.seen = Some(now);
    }

    /// Makes the next change a step of its own (a button, a key).
    pub fn barrier(&mut self) {
        self.last_change = None;
    }

    /// The settings before the last change, if any (`now` can be redone).
    pub fn undo(&mut self, now: &Settings) -> Option<Settings> {
        let back = self.steps.pop()?;
        self.undone.push(undoable(now));
        self.seen = Some(back.clone());
        self.last_change = None;
        Some(back)
    }

    /// The settings the last undo left, if no change came since.
    pub fn redo(&mut self, now: &Settings) -> Option<Settings> {
        let next = self.undone.pop()?;
        self.steps.push(undoable(now));
        self.seen = Some(next.clone());
        self.last_change = None;
        Some(next)
    }

    /// Whether there is a change to undo.
    #[must_use]
    pub fn can_undo(&self) -> bool {
        !self.steps.is_empty()
    }

    /// Whether there is an undone change to redo.
    #[must_use]
    pub fn can_redo(&self) -> bool {
        !self.undone.is_empty()
    }

    /// Forgets every step, saying `why` ("when g.png opened") if there
    /// were any.
    pub fn clear(&mut self, why: String) {
        if self.can_undo() || self.can_redo() {
            self.cleared = Some(why);
        }
        self.steps.clear();
        self.undone.clear();
        self.seen = None;
        self.last_change = None;
    }

    /// When the history was last cleared, if it held anything then.
    #[must_use]
    pub fn cleared(&self) -> Option<&str> {
        self.cleared.as_deref()
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
        // Ctrl+Shift+Z first: Ctrl+Z matches it too.
        if pressed(KeyboardShortcut::new(
            Modifiers::COMMAND | Modifiers::SHIFT,
            Key::Z,
        )) || pressed(cmd(Key::Y))
        {
            self.redo();
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

    /// Goes back to the settings before the last change (the picture and
    /// the last folder stay).
    pub fn undo(&mut self) {
        if let Some(back) = self.history.undo(&self.settings) {
            self.restore(back);
        }
    }

    /// Makes the last undone change again.
    pub fn redo(&mut self) {
        if let Some(next) = self.history.redo(&self.settings) {
            self.restore(next);
        }
    }

    /// Takes `s` (from the history) as the settings, keeping the picture
    /// and the last folder.
    fn restore(&mut self, s: Settings) {
        let image = self.settings.image.clone();
        let last_dir = self.settings.last_dir.clone();
        self.typed_points = s.job.points.unwrap_or(self.typed_points);
        self.settings = Settings {
            image,
            last_dir,
            ..s
        };
        self.keep_line_pen();
    }

    /// Whether Undo and Redo have anything to do, and when the history was
    /// last cleared.
    #[must_use]
    pub fn history_state(&self) -> (bool, bool, Option<&str>) {
        (
            self.history.can_undo(),
            self.history.can_redo(),
            self.history.cleared(),
        )
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
