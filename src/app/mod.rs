//! The interactive stippling app: an eframe/egui front end over the library.
//!
//! The importance map is loaded into textures, sampling runs on a worker
//! thread (debounced, the latest request wins) on egui's own wgpu device, and
//! the dots are drawn on the GPU by an `egui_wgpu` paint callback (a line
//! drawing's strokes by egui's own tessellator).

pub mod dialogs;
mod dots;
mod export;
mod line;
mod panel;
mod paper;
mod pens;
mod plot;
mod poster;
mod settings;
pub mod shortcuts;
mod status;
mod view;
pub mod words;
mod worker;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use egui_wgpu::wgpu;

pub use dots::SHADER as DOTS_SHADER;
pub use settings::{Background, Settings};
pub use view::SETTLE;
use worker::{Outcome, Reply, Request, Worker};

use crate::importance::{ColourMap, ImportanceMap};
use crate::sampler::Progress;

/// How long the controls must rest before a re-sample starts.
pub const DEBOUNCE: Duration = Duration::from_millis(150);
/// The key under which the settings persist.
const STORAGE_KEY: &str = "pixelpie-settings";
/// The photo shown at first start, built into the binary (assets/default.png).
pub const DEFAULT_IMAGE: &[u8] = include_bytes!("../../assets/default.png");
/// The built-in photo's name in the panel and in error messages.
pub const DEFAULT_IMAGE_NAME: &str = "default.png (built in)";

/// A loaded picture: the importance map and its display textures.
pub struct Source {
    /// Where it came from: a file, or `None` for the built-in photo.
    pub path: Option<PathBuf>,
    /// The importance map.
    pub map: Arc<ImportanceMap>,
    /// The picture in colour (grey for a grey picture), for pens.
    pub colour: Arc<ColourMap>,
    importance: egui::TextureHandle,
    photo: egui::TextureHandle,
    /// Why the picture may not be whole (a file cut short), shown with it.
    pub warning: Option<String>,
    /// The picture as decoded, before the job's crop and turn.
    original: Arc<Original>,
    /// The crop and turn `map`, `colour` and the textures have.
    framing: (Option<crate::importance::Crop>, u16),
}

/// A decoded picture before framing: the maps and the display images.
struct Original {
    map: Arc<ImportanceMap>,
    colour: Arc<ColourMap>,
    importance: egui::ColorImage,
    photo: egui::ColorImage,
}

/// The app.
pub struct PixelPieApp {
    /// The controls.
    pub settings: Settings,
    /// The loaded picture.
    pub source: Option<Source>,
    /// The latest finished sampling.
    pub outcome: Option<Outcome>,
    /// The last sampling error, shown with the statistics.
    pub error: Option<String>,
    /// Why the last image could not be opened, shown under the Open row
    /// until an image opens.
    pub open_error: Option<String>,
    /// Why the last export failed, shown under the Export row until an
    /// export succeeds.
    pub export_error: Option<String>,
    /// The sampler's note (fallbacks, a count that did not fit).
    pub status: String,
    /// The last file exported, in full.
    pub exported: Option<PathBuf>,
    /// What the last export wrote, when not the present settings' drawing.
    pub exported_note: Option<String>,
    /// Why the job's crop cannot frame the picture.
    pub framing_error: Option<String>,
    /// The preset (job file) path typed.
    pub preset_path: String,
    /// What the last preset save or load did, or why it failed.
    pub preset_note: Option<String>,
    /// Where exports go (the extension is set by the button).
    pub export_path: String,
    worker: Worker,
    next_job: u64,
    done_job: u64,
    pending: Option<Instant>,
    last_key: Option<settings::SamplingKey>,
    progress: Option<Progress>,
    relaxed: Option<(u32, u32)>,
    /// The stage the running job is in, as its run last reported it.
    stage: Option<crate::job::Stage>,
    dots_generation: u64,
    /// The poster's sheet grid over the view, and the drawing and job it
    /// was made for ([`Self::refresh_poster_grid`]).
    poster_view: Option<((u64, crate::job::Job), Option<crate::job::SheetGrid>)>,
    dot_instances: Arc<Vec<dots::DotInstance>>,
    /// Why the last pen edit was refused (duplicate colours).
    pens_error: Option<String>,
    /// The pen box loaded (its file's name and pens), to choose pens from.
    pub pen_box: Option<(String, crate::colour::PenSet)>,
    /// How many pens "Choose" picks from the pen box.
    pub choose_count: usize,
    /// What the last choice said (the pens, the predicted error), or why
    /// there is none.
    pub choice_note: Option<Result<String, String>>,
    /// The pens the last choice set: its note shows while the job has them.
    choice_pens: Option<crate::colour::PenSet>,
    /// The pen box's path typed (a pen file).
    pub pen_box_path: String,
    /// What ticking Pen mm changed besides (the dots' mode), shown in the
    /// Export section's message row until the next export or job.
    pub pen_note: Option<String>,
    /// A colour drawing's dots, pen by pen, with the pen's colour.
    pen_layers: Vec<([u8; 3], Arc<Vec<dots::DotInstance>>)>,
    view: view::ViewState,
    gpu_dots: bool,
    /// The path typed in the Open field.
    pub open_path: String,
    /// The file dialogs (the desktop's; tests answer them).
    pub dialogs: Box<dyn dialogs::FileDialogs>,
    /// Whether the shortcut help shows.
    pub show_help: bool,
    history: shortcuts::History,
    /// When the job in flight started (for its elapsed time).
    job_started: Option<Instant>,
    /// The last job was cancelled (the top line says so, not "ready").
    cancelled: bool,
    /// A picture being decoded on its own thread.
    loading: Option<Loading>,
    /// The plot-time estimate (with a pen width).
    plot: plot::PlotTime,
    /// A job file's crop, loaded for the next photo: kept when it opens
    /// (another photo's crop is dropped).
    crop_for_next: bool,
    /// The Points field's count, kept while the radius range or the dots'
    /// size in mm sets the radii (the job then has no count).
    pub typed_points: usize,
    /// The heights of the panel's parts, as last drawn.
    heights: Heights,
    /// The style and whether a pen was set, as the last frame left them
    /// (a line's count follows its pen: see [`Self::line_rules`]).
    line_pen: (crate::job::Style, bool),
}

/// A picture decoding off the UI thread.
struct Loading {
    /// The file, or `None` for the built-in photo.
    path: Option<PathBuf>,
    /// The decoder's answer.
    reply: std::sync::mpsc::Receiver<Result<Decoded, String>>,
}

/// A decoded picture: the importance map and its two display images.
struct Decoded {
    warning: Option<String>,
    map: ImportanceMap,
    colour: ColourMap,
    importance: egui::ColorImage,
    photo: egui::ColorImage,
}

/// The control panel's width, in points.
pub const PANEL_WIDTH: f32 = 340.0;

/// The least height, in points, left to the scrolling controls with the
/// Export section fixed at the panel's bottom; a shorter window scrolls it
/// with the controls.
pub const MIN_CONTROLS_HEIGHT: f32 = 330.0;

/// The heights of the panel's parts, as last drawn (points).
struct Heights {
    /// Progress and statistics.
    stats: f32,
    /// The Export section.
    export: f32,
}

impl Default for Heights {
    /// Before the first frame: about what they take.
    fn default() -> Self {
        Self {
            stats: 120.0,
            export: 330.0,
        }
    }
}

impl Source {
    /// The picture's size before the crop and turn.
    #[must_use]
    pub fn original_size(&self) -> (u32, u32) {
        (self.original.map.width(), self.original.map.height())
    }
}

impl PixelPieApp {
    /// Builds the app on eframe's context; `image` overrides the stored one.
    pub fn new(cc: &eframe::CreationContext<'_>, image: Option<PathBuf>) -> Self {
        let mut settings: Settings = cc
            .storage
            .and_then(|s| eframe::get_value(s, STORAGE_KEY))
            .unwrap_or_default();
        // Settings stored by earlier versions kept the count beside the job:
        // a job with nothing to set its radii counts the default.
        let j = &mut settings.job;
        if j.points.is_none()
            && j.dot_mm.is_none()
            && j.dot_radius.is_none()
            && j.importance.min_radius.is_none()
        {
            j.points = Some(crate::job::DEFAULT_POINTS);
        }
        let mut gpu = None;
        let mut gpu_dots = false;
        if let Some(rs) = &cc.wgpu_render_state {
            let renderer = dots::DotRenderer::new(&rs.device, rs.target_format);
            rs.renderer.write().callback_resources.insert(renderer);
            gpu_dots = true;
            gpu = Some((rs.device.clone(), rs.queue.clone(), rs.adapter.get_info()));
        }
        let worker = Worker::new(gpu, cc.egui_ctx.clone());
        let mut app = Self {
            settings: settings.clone(),
            source: None,
            outcome: None,
            error: None,
            open_error: None,
            export_error: None,
            status: String::new(),
            exported: None,
            exported_note: None,
            framing_error: None,
            preset_path: "job.toml".into(),
            preset_note: None,
            export_path: "stipple.svg".into(),
            worker,
            next_job: 0,
            done_job: 0,
            pending: None,
            last_key: None,
            progress: None,
            relaxed: None,
            stage: None,
            dots_generation: 0,
            poster_view: None,
            dot_instances: Arc::new(Vec::new()),
            pen_layers: Vec::new(),
            pens_error: None,
            pen_box: None,
            choose_count: 5,
            choice_note: None,
            choice_pens: None,
            pen_box_path: String::new(),
            pen_note: None,
            view: view::ViewState::default(),
            gpu_dots,
            open_path: String::new(),
            dialogs: Box::new(dialogs::NativeDialogs),
            show_help: false,
            history: shortcuts::History::default(),
            job_started: None,
            cancelled: false,
            loading: None,
            plot: plot::PlotTime::default(),
            crop_for_next: false,
            typed_points: settings.job.points.unwrap_or(crate::job::DEFAULT_POINTS),
            heights: Heights::default(),
            line_pen: (settings.job.style, settings.job.pen_mm.is_some()),
        };
        // Ctrl+plus and Ctrl+minus zoom the picture, not the whole UI.
        cc.egui_ctx.options_mut(|o| o.zoom_with_keyboard = false);
        match image.or_else(|| settings.image.take()) {
            Some(path) => app.open(&cc.egui_ctx, &path),
            None => app.open_builtin(&cc.egui_ctx),
        }
        app
    }

    /// Starts decoding an image or EXR as the importance map, on its own
    /// thread: the window stays responsive, a spinner shows, and the
    /// picture replaces the current one when it is decoded (errors go to
    /// the panel).
    pub fn open(&mut self, ctx: &egui::Context, path: &Path) {
        if path.as_os_str().is_empty() {
            self.open_error = Some("no file given: type a path, drop a file or use Browse".into());
            return;
        }
        self.decode(ctx, Some(path.to_path_buf()));
    }

    /// Decodes `path` (`None`: the built-in photo) on a thread of its own.
    fn decode(&mut self, ctx: &egui::Context, path: Option<PathBuf>) {
        let (tx, reply) = std::sync::mpsc::channel();
        let (file, repaint) = (path.clone(), ctx.clone());
        let spawned = std::thread::Builder::new()
            .name("pixelpie-decode".into())
            .spawn(move || {
                let _ = tx.send(decode(file.as_deref()));
                repaint.request_repaint();
            });
        match spawned {
            Ok(_) => self.loading = Some(Loading { path, reply }),
            Err(e) => self.open_error = Some(format!("cannot start decoding: {e}")),
        }
    }

    /// The name of the picture being decoded, if any.
    #[must_use]
    pub fn loading_name(&self) -> Option<String> {
        self.loading.as_ref().map(|l| {
            l.path.as_ref().map_or_else(
                || DEFAULT_IMAGE_NAME.to_owned(),
                |p| p.display().to_string(),
            )
        })
    }

    /// Takes a finished decode: the picture is shown, or the error. A
    /// failed first picture still leaves the built-in photo to work on.
    fn poll_loading(&mut self, ctx: &egui::Context) {
        let Some(loading) = &self.loading else { return };
        let result = match loading.reply.try_recv() {
            Ok(r) => r,
            Err(std::sync::mpsc::TryRecvError::Empty) => return,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                Err("the decoder stopped without an answer".into())
            }
        };
        let Some(loading) = self.loading.take() else {
            return;
        };
        match result {
            Ok(decoded) => {
                // A new photo drops the last one's crop, unless a job file
                // loaded since brought it for this photo.
                if self.settings.image != loading.path && !self.crop_for_next {
                    self.settings.job.crop = None;
                }
                // Another photo starts a new undo history, and says so.
                if self.source.is_some() && self.settings.image != loading.path {
                    let name = loading.path.as_ref().map_or_else(
                        || DEFAULT_IMAGE_NAME.to_owned(),
                        |p| {
                            p.file_name().map_or_else(
                                || p.display().to_string(),
                                |n| n.to_string_lossy().into_owned(),
                            )
                        },
                    );
                    self.history.clear(format!("cleared when {name} opened"));
                }
                self.crop_for_next = false;
                let original = Arc::new(Original {
                    map: Arc::new(decoded.map),
                    colour: Arc::new(decoded.colour),
                    importance: decoded.importance,
                    photo: decoded.photo,
                });
                let source = Source {
                    path: loading.path.clone(),
                    map: original.map.clone(),
                    colour: original.colour.clone(),
                    importance: ctx.load_texture(
                        "importance",
                        original.importance.clone(),
                        egui::TextureOptions::LINEAR,
                    ),
                    photo: ctx.load_texture(
                        "photo",
                        original.photo.clone(),
                        egui::TextureOptions::LINEAR,
                    ),
                    warning: decoded.warning,
                    original,
                    framing: (None, 0),
                };
                match &loading.path {
                    Some(path) => {
                        self.settings.image = Some(path.clone());
                        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                            self.settings.last_dir = Some(dir.to_path_buf());
                        }
                        self.open_path = path.display().to_string();
                    }
                    None => {
                        self.settings.image = None;
                        self.open_path.clear();
                    }
                }
                self.show(source);
            }
            Err(e) => {
                self.open_error = Some(e);
                // The path field names the picture shown, not the one that
                // failed (the error names that).
                self.open_path = self
                    .source
                    .as_ref()
                    .and_then(|s| s.path.as_ref())
                    .map_or_else(String::new, |p| p.display().to_string());
                if self.source.is_none() && loading.path.is_some() {
                    // Keep the error, but show something to work on.
                    let error = self.open_error.take();
                    self.open_builtin(ctx);
                    self.open_error = error;
                }
            }
        }
    }

    /// Asks for an image with the file dialog, from the last folder; a
    /// desktop without a working dialog gets a message, not silence.
    pub fn open_dialog(&mut self, ctx: &egui::Context) {
        match self.dialogs.pick_image(self.settings.last_dir.as_deref()) {
            Ok(Some(path)) => self.open(ctx, &path),
            Ok(None) => {}
            Err(why) => self.open_error = Some(why),
        }
    }

    /// Asks where to export with the file dialog, from the last folder, and
    /// exports there (the extension picks the format; SVG without one).
    pub fn export_dialog(&mut self) {
        let name = Path::new(self.export_path.trim()).file_name().map_or_else(
            || "stipple.svg".into(),
            |n| n.to_string_lossy().into_owned(),
        );
        let path = match self
            .dialogs
            .save_drawing(self.settings.last_dir.as_deref(), &name)
        {
            Ok(Some(path)) => path,
            Ok(None) => return,
            Err(why) => {
                self.exported = None;
                self.export_error = Some(why);
                return;
            }
        };
        let ext = match crate::job::Format::from_path(&path) {
            Ok(_) => path
                .extension()
                .map_or_else(String::new, |e| e.to_string_lossy().into_owned()),
            Err(_) => "svg".to_owned(),
        };
        self.export_path = path.display().to_string();
        self.export_as(&ext);
    }

    /// Loads the built-in photo.
    pub fn open_builtin(&mut self, ctx: &egui::Context) {
        self.decode(ctx, None);
    }

    /// Makes `source` the picture, drops the old drawing (its dots belong to
    /// another domain) and samples anew.
    fn show(&mut self, source: Source) {
        // A job in flight samples the old picture: its reply is stale.
        self.worker.cancel();
        self.next_job += 1;
        self.done_job = self.next_job;
        self.progress = None;
        self.relaxed = None;
        self.stage = None;
        self.source = Some(source);
        self.open_error = None;
        self.outcome = None;
        self.dot_instances = Arc::new(Vec::new());
        self.pen_layers.clear();
        self.dots_generation += 1;
        self.error = None;
        self.last_key = None;
        self.view.fit_next = true;
        self.request_sample();
    }

    /// Frames the picture as the job's crop and turn ask, when they
    /// changed: the maps the jobs sample and the images the view shows.
    fn reframe(&mut self, ctx: &egui::Context) {
        let want = (
            self.settings.job.crop,
            self.settings.job.rotate.unwrap_or(0),
        );
        let Some(src) = &mut self.source else { return };
        if src.framing == want {
            return;
        }
        let o = src.original.clone();
        let framed = (|| -> Result<_, String> {
            let text = |e: crate::importance::Error| words::app_line(&e);
            let map = o.map.framed(want.0, want.1).map_err(text)?;
            let colour = o.colour.framed(want.0, want.1).map_err(text)?;
            let image = |img: &egui::ColorImage| {
                let size = (img.size[0] as u32, img.size[1] as u32);
                crate::importance::frame(size, &img.pixels, want.0, want.1)
                    .map(|((w, h), px)| egui::ColorImage::new([w as usize, h as usize], px))
                    .map_err(text)
            };
            Ok((map, colour, image(&o.importance)?, image(&o.photo)?))
        })();
        src.framing = want;
        match framed {
            Ok((map, colour, importance, photo)) => {
                src.map = Arc::new(map);
                src.colour = Arc::new(colour);
                src.importance =
                    ctx.load_texture("importance", importance, egui::TextureOptions::LINEAR);
                src.photo = ctx.load_texture("photo", photo, egui::TextureOptions::LINEAR);
                self.framing_error = None;
            }
            Err(e) => self.framing_error = Some(e),
        }
        self.drop_drawing();
        self.view.fit_next = true;
        self.request_sample();
    }

    /// Saves the job to the preset path (a job file, as `--save-job`).
    pub fn save_preset(&mut self) {
        let path = typed_path(&self.preset_path);
        let image = self.source.as_ref().and_then(|s| s.path.clone());
        let result = self
            .settings
            .job()
            .to_toml(image.as_deref())
            .and_then(|text| {
                Ok(crate::io::write_atomic(&path, |w| {
                    Ok(w.write_all(text.as_bytes())?)
                })?)
            });
        self.preset_note = Some(match result {
            Ok(()) => format!("saved {}", path.display()),
            Err(e) => format!("not saved: {}", words::app_line(&e)),
        });
    }

    /// Loads the job from the preset path (a job file, as `--job`): every
    /// setting, the count in the Points field.
    pub fn load_preset(&mut self) {
        let path = typed_path(&self.preset_path);
        self.preset_note = Some(match crate::job::Job::open(&path) {
            Ok((job, warning)) => {
                // Messages about the old job's pens go with it.
                self.choice_note = None;
                self.pens_error = None;
                self.pen_note = None;
                self.typed_points = job.points.unwrap_or(self.typed_points);
                self.crop_for_next = job.crop.is_some();
                self.settings.job = job;
                self.keep_line_pen();
                match warning {
                    Some(w) => format!(
                        "loaded {} (warning: {})",
                        path.display(),
                        words::app_text(&w)
                    ),
                    None => format!("loaded {}", path.display()),
                }
            }
            Err(e) => format!("not loaded: {}", words::app_line(&e)),
        });
    }

    /// Drops the drawing: nothing is shown or exported until the next one.
    fn drop_drawing(&mut self) {
        self.outcome = None;
        self.dot_instances = Arc::new(Vec::new());
        self.pen_layers.clear();
        self.dots_generation += 1;
    }

    /// The GPU adapter that samples and draws, if any.
    pub fn adapter(&self) -> Option<&str> {
        self.worker.adapter()
    }

    /// The plan of the drawing shown, in one line (the status shows it).
    #[must_use]
    pub fn plan_line(&self) -> Option<String> {
        self.outcome
            .as_ref()
            .map(|o| words::app_text(&o.drawing.plan.line()))
    }

    /// The number of dots on screen (none in a line drawing).
    pub fn dots_drawn(&self) -> usize {
        if self.is_line() {
            0
        } else {
            self.dot_instances.len()
        }
    }

    /// Keeps a line's settings whole after the controls changed them:
    /// the smoothing is a line's alone; a line with a pen takes its count
    /// from the pen (the pen's width and the picture's ink set it, as
    /// `pixelpie stipple --style line` does without `--points`), without
    /// one from the Points field, and dots get the Points field's count
    /// back. Only a change of the style or of the pen moves the count, so
    /// that a job file's own count stays.
    fn line_rules(&mut self) {
        use crate::job::Style;
        let job = &mut self.settings.job;
        if job.style != Style::Line {
            job.line_smooth = false;
        }
        let now = (job.style, job.pen_mm.is_some());
        if now == self.line_pen {
            return;
        }
        self.line_pen = now;
        match now {
            (Style::Line, true) => {
                job.points = None;
                job.dot_mm = None;
                job.dot_radius = None;
                job.importance.min_radius = None;
            }
            // Dots, or a line without a pen: the count typed, unless a
            // radius range or the dots' size in mm sets the radii.
            (style, _) => {
                let sized = job.dot_mm.is_some()
                    || job.dot_radius.is_some()
                    || job.importance.min_radius.is_some();
                if job.points.is_none() && (style == Style::Line || !sized) {
                    job.points = Some(self.typed_points);
                    job.dot_mm = None;
                    job.dot_radius = None;
                    job.importance.min_radius = None;
                }
            }
        }
    }

    /// Takes the style and the pen as they are now, without moving the
    /// count: settings restored whole (undo, a job file, Cancel) keep theirs.
    fn keep_line_pen(&mut self) {
        let job = &self.settings.job;
        self.line_pen = (job.style, job.pen_mm.is_some());
    }

    /// A line drawing's strokes as the job draws them: smooth or straight
    /// (the smoothing samples nothing anew, so the drawing shown and
    /// exported takes it from the controls).
    fn restyle_line(&mut self) {
        let smooth = self.settings.job.line_smooth;
        let Some(o) = &mut self.outcome else { return };
        if o.drawing.strokes.iter().all(|s| s.smooth == smooth) {
            return;
        }
        let mut drawing = (*o.drawing).clone();
        for s in &mut drawing.strokes {
            s.smooth = smooth;
        }
        o.drawing = Arc::new(drawing);
        o.settings.job.line_smooth = smooth;
    }

    /// Whether a picture is decoding or a sampling job is queued or running.
    pub fn busy(&self) -> bool {
        self.loading.is_some() || self.pending.is_some() || self.done_job < self.next_job
    }

    /// Stops the queued or running job (sampling or relaxation) and keeps
    /// the last finished drawing. The controls go back to the settings that
    /// drawing was made with, so that what they show is what is drawn; the
    /// next change samples again.
    pub fn cancel_job(&mut self) {
        self.worker.cancel();
        self.pending = None;
        self.done_job = self.next_job;
        self.progress = None;
        self.relaxed = None;
        self.stage = None;
        if let Some(o) = &self.outcome {
            // Every setting of the drawing: its job (the crop and the turn
            // too) and its backend.
            let drawn = &o.settings;
            let s = &mut self.settings;
            s.job = drawn.job.clone();
            s.backend = drawn.backend;
            self.typed_points = s.job.points.unwrap_or(self.typed_points);
            self.history.barrier();
            self.keep_line_pen();
        }
        self.last_key = Some(self.settings.sampling_key());
        self.cancelled = true;
        self.status = "cancelled: the controls show the last drawing's settings".into();
    }

    fn request_sample(&mut self) {
        self.pending = Some(Instant::now());
    }

    fn start_job(&mut self) {
        if let Some(why) = self
            .settings
            .refused_count()
            .or_else(|| self.framing_error.clone())
        {
            // Refused in words; the old drawing goes, as it is not this one.
            self.error = Some(why);
            self.drop_drawing();
            return;
        }
        let Some(src) = &self.source else { return };
        self.next_job += 1;
        self.progress = None;
        self.relaxed = None;
        self.stage = None;
        self.job_started = Some(Instant::now());
        self.worker.submit(Request {
            id: self.next_job,
            map: src.map.clone(),
            colour: src.colour.clone(),
            // The source is framed already; the worker runs the job
            // without the crop and turn, and keeps them for Cancel.
            settings: self.settings.clone(),
        });
    }

    fn poll_worker(&mut self) {
        for reply in self.worker.poll() {
            match reply {
                Reply::Progress(id, p) if id == self.next_job => self.progress = Some(p),
                Reply::Progress(..) => {}
                Reply::Relaxed(id, done, of) if id == self.next_job => {
                    self.relaxed = Some((done, of));
                }
                Reply::Relaxed(..) => {}
                Reply::Stage(id, name) if id == self.next_job => self.stage = Some(name),
                Reply::Stage(..) => {}
                Reply::Done(id, result) => {
                    self.done_job = self.done_job.max(id);
                    if id != self.next_job {
                        continue;
                    }
                    match *result {
                        Ok(outcome) => {
                            self.status = outcome.note.clone().unwrap_or_default();
                            self.cancelled = false;
                            self.dot_instances = outcome.dots.clone();
                            self.pen_layers = outcome.pen_dots.clone();
                            self.dots_generation += 1;
                            self.outcome = Some(outcome);
                            self.error = None;
                            // Messages about the last drawing go with it.
                            self.exported = None;
                            self.export_error = None;
                            self.exported_note = None;
                        }
                        Err(e) => {
                            // The drawing shown and exported would not be
                            // this job's: it goes.
                            self.error = Some(e);
                            self.drop_drawing();
                        }
                    }
                }
            }
        }
    }
}

/// The path typed in a path field: `~/` is the home folder and a
/// `file://` address its path.
#[must_use]
pub fn typed_path(typed: &str) -> PathBuf {
    let t = typed.trim();
    let t = t.strip_prefix("file://").unwrap_or(t);
    match (t.strip_prefix("~/"), std::env::var_os("HOME")) {
        (Some(rest), Some(home)) => Path::new(&home).join(rest),
        _ => PathBuf::from(t),
    }
}

/// Decodes `path` (`None`: the built-in photo) into an importance map and
/// two display images (run off the UI thread).
fn decode(path: Option<&Path>) -> Result<Decoded, String> {
    let map = match path {
        Some(p) => ImportanceMap::open(p, None),
        None => ImportanceMap::from_encoded(DEFAULT_IMAGE, Path::new(DEFAULT_IMAGE_NAME), None),
    }
    .map_err(|e| words::app_line(&e))?;
    let (w, h) = (map.width() as usize, map.height() as usize);
    let gray: Vec<egui::Color32> = map
        .values()
        .iter()
        .map(|&v| {
            let g =
                (crate::stipple::raster::linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0).round() as u8;
            egui::Color32::from_gray(g)
        })
        .collect();
    let importance = egui::ColorImage::new([w, h], gray.clone());
    // The photo in colour where `image` can decode it; EXR shows its luminance.
    let decoded = match path {
        // Upright, as the drawing is.
        Some(p) => crate::importance::decode_file(p).ok(),
        None => image::load_from_memory(DEFAULT_IMAGE).ok(),
    };
    let photo = decoded
        .map(|img| img.to_rgba8())
        .filter(|img| img.dimensions() == (map.width(), map.height()))
        .map_or_else(
            || egui::ColorImage::new([w, h], gray),
            |img| egui::ColorImage::from_rgba_unmultiplied([w, h], img.as_raw()),
        );
    // The colours the pens separate: the file's own, or the luminance's
    // grey (the built-in photo is grey).
    let colour = match path {
        Some(p) => ColourMap::open(p, None).unwrap_or_else(|_| map_grey(&map)),
        None => map_grey(&map),
    };
    Ok(Decoded {
        warning: path
            .and_then(crate::importance::cut_short)
            .map(|w| words::app_text(&w)),
        map,
        colour,
        importance,
        photo,
    })
}

impl eframe::App for PixelPieApp {
    /// The panels' colour: they are drawn unfilled, on the clear.
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, STORAGE_KEY, &self.settings);
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.poll_loading(&ctx);
        self.reframe(&ctx);
        self.poll_worker();
        self.update_plot_time(&ctx);
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        if let Some(path) = dropped.into_iter().next() {
            self.open(&ctx, &path);
        }
        self.handle_shortcuts(&ctx);
        // The panels are not filled: the window's clear colour is theirs
        // (`clear_color`), and a software rasterizer is spared egui's
        // shader over the whole window at every frame.
        let panel = egui::Frame::side_top_panel(ui.style()).fill(egui::Color32::TRANSPARENT);
        // One width, whatever the state (long labels truncate).
        egui::Panel::left("controls")
            .exact_size(PANEL_WIDTH)
            .resizable(false)
            .frame(panel)
            .show(ui, |ui| {
                // Progress and statistics keep fixed places at the bottom,
                // the export rows too where the window leaves the controls
                // room enough above them; else the Export section scrolls
                // with the controls, so that every control can be reached.
                let bottom = self.heights.stats + self.heights.export;
                let tall = ui.available_height() - bottom >= MIN_CONTROLS_HEIGHT;
                egui::Panel::bottom("actions")
                    .resizable(false)
                    .frame(panel)
                    .show(ui, |ui| {
                        self.heights.stats =
                            ui.scope(|ui| self.stats_ui(ui)).response.rect.height();
                        if tall {
                            ui.separator();
                            self.export_measured(ui);
                        }
                    });
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.controls(ui);
                    if !tall {
                        egui::CollapsingHeader::new("Export")
                            .default_open(true)
                            .show(ui, |ui| self.export_measured(ui));
                    }
                });
            });
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.canvas(ui));
        self.help_ui(&ctx);
        // The dots' size in mm needs the page's: without a width in mm or
        // a paper the count sets the radii again.
        let job = &mut self.settings.job;
        if job.dot_mm.is_some() && job.width_mm.is_none() && job.paper.is_none() {
            job.dot_mm = None;
            job.points = Some(self.typed_points);
        }
        // A choice's note describes the pens it chose, while they are the
        // job's.
        if matches!(self.choice_note, Some(Ok(_))) && self.settings.job.pens != self.choice_pens {
            self.choice_note = None;
        }
        self.line_rules();
        self.restyle_line();
        self.history.observe(&self.settings);
        let key = self.settings.sampling_key();
        if self.last_key.as_ref() != Some(&key) {
            self.last_key = Some(key);
            self.request_sample();
        }
        if let Some(t) = self.pending {
            let rest = DEBOUNCE.saturating_sub(t.elapsed());
            if rest.is_zero() {
                self.pending = None;
                self.start_job();
            } else {
                ctx.request_repaint_after(rest);
            }
        }
    }
}

/// Opens the app's window (`image`, or the last or bundled one).
pub fn run(image: Option<PathBuf>) -> anyhow::Result<()> {
    let mut options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("PixelPie stippling")
            .with_inner_size([1200.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    options.wgpu_options.wgpu_setup = wgpu_setup();
    eframe::run_native(
        "PixelPie",
        options,
        Box::new(move |cc| Ok(Box::new(PixelPieApp::new(cc, image)))),
    )
    .map_err(|e| anyhow::anyhow!("cannot open the window: {e}"))
}

/// egui's wgpu setup, asking for the adapter's own limits (the sampler needs
/// more than egui's defaults) and its timestamp queries.
pub fn wgpu_setup() -> egui_wgpu::WgpuSetup {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.device_descriptor = Arc::new(|adapter: &wgpu::Adapter| wgpu::DeviceDescriptor {
        label: Some("pixelpie"),
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        required_limits: adapter.limits(),
        ..Default::default()
    });
    egui_wgpu::WgpuSetup::CreateNew(setup)
}

/// A grey picture's colours.
fn map_grey(map: &ImportanceMap) -> ColourMap {
    map.colours()
}
