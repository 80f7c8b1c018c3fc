//! The drawing job off the UI thread: the latest job wins, an older one in
//! flight is cancelled, and the GPU sampler shares egui's device. The job
//! is the library's ([`crate::job::Job`]), the same that `pixelpie
//! stipple` runs, so the app draws what the CLI draws.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};

use egui_wgpu::wgpu;

use super::dots::DotInstance;
use super::settings::Settings;
use crate::backend::BackendChoice;
use crate::gpu::GpuSampler;
use crate::importance::{ColourMap, ImportanceMap};
use crate::job::{Step, Stipple};
use crate::sampler::{self, Control, Params, Progress, SampleSet};

/// A sampling request.
pub struct Request {
    /// Increases with every job; replies carry it.
    pub id: u64,
    /// The importance map.
    pub map: Arc<ImportanceMap>,
    /// The picture in colour, for drawings with pens.
    pub colour: Arc<ColourMap>,
    /// The settings, the crop and the turn included (the map and the
    /// colours are framed already: the job runs without them).
    pub settings: Settings,
}

/// A finished job.
pub struct Outcome {
    /// The drawing (in domain pixels), as `pixelpie stipple` makes it
    /// (shared with the plot-time estimate's thread).
    pub drawing: Arc<Stipple>,
    /// The settings it was made with, every one, the crop and the turn
    /// included (Cancel goes back to them).
    pub settings: Settings,
    /// Domain pixels per image pixel: the sampling domain is the image
    /// scaled as `pixelpie stipple` scales it.
    pub scale: f32,
    /// A note for the status line, such as a fallback to the CPU.
    pub note: Option<String>,
    /// Seconds the whole job took: every sampler run, relaxation and dot
    /// sizes (the statistics' `seconds` is the last run's sampler alone).
    pub seconds: f64,
    /// The dots as the view draws them (image px), built on the worker.
    pub dots: Arc<Vec<DotInstance>>,
    /// A colour drawing's dots, pen by pen, with the pen's colour.
    pub pen_dots: Vec<([u8; 3], Arc<Vec<DotInstance>>)>,
    /// The sizes of the dots, for the view.
    pub sizes: DotSizes,
}

/// What the view needs to know of a drawing's dot sizes, in domain px.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DotSizes {
    /// The median sample radius.
    pub sample_radius: f32,
}

impl DotSizes {
    /// The sizes of `dots` (image px) in domain px (`scale` domain px per
    /// image px).
    #[must_use]
    pub fn of(dots: &[DotInstance], scale: f32) -> Self {
        let mut radii: Vec<f32> = dots.iter().map(|d| d.radius).collect();
        Self {
            sample_radius: median(&mut radii) * scale,
        }
    }
}

/// The median of `v` (0 when empty); reorders `v`.
fn median(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// A message from the worker.
pub enum Reply {
    /// An iteration finished.
    Progress(u64, Progress),
    /// This many relaxation steps are done, of how many.
    Relaxed(u64, u32, u32),
    /// A stage of the drawing begins (after sampling: relax, order, size
    /// and its parts).
    Stage(u64, crate::job::Stage),
    /// A job ended.
    Done(u64, Box<Result<Outcome, String>>),
}

struct GpuState {
    device: wgpu::Device,
    queue: wgpu::Queue,
    sampler: GpuSampler,
    /// A software rasterizer (lavapipe): `Auto` samples on the CPU, faster.
    software: bool,
}

/// The background sampler.
pub struct Worker {
    jobs: Option<Sender<Request>>,
    thread: Option<std::thread::JoinHandle<()>>,
    replies: Receiver<Reply>,
    cancel: Arc<AtomicBool>,
    adapter: Option<String>,
    software: bool,
}

impl Worker {
    /// Starts the worker. With `gpu`, it samples on that device (egui's).
    pub fn new(
        gpu: Option<(wgpu::Device, wgpu::Queue, wgpu::AdapterInfo)>,
        repaint: egui::Context,
    ) -> Self {
        let (jobs, job_rx) = channel::<Request>();
        let (reply_tx, replies) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let mut adapter = None;
        let mut software = false;
        let gpu_state = gpu.and_then(|(device, queue, info)| {
            match GpuSampler::new(&device, info.name.clone()) {
                Ok(sampler) => {
                    adapter = Some(info.name);
                    software = info.device_type == wgpu::DeviceType::Cpu;
                    Some(GpuState {
                        device,
                        queue,
                        sampler,
                        software: info.device_type == wgpu::DeviceType::Cpu,
                    })
                }
                Err(_) => None,
            }
        });
        let flag = cancel.clone();
        let thread = std::thread::Builder::new()
            .name("pixelpie-sampler".into())
            .spawn(move || run(job_rx, reply_tx, flag, gpu_state, repaint))
            .ok();
        Self {
            jobs: Some(jobs),
            thread,
            replies,
            cancel,
            adapter,
            software,
        }
    }

    /// Whether the window's adapter is a software rasterizer (lavapipe):
    /// its frames cost CPU time that the sampler needs.
    pub fn software(&self) -> bool {
        self.software
    }

    /// The GPU adapter the worker samples on, if any.
    pub fn adapter(&self) -> Option<&str> {
        self.adapter.as_deref()
    }

    /// Queues a job and cancels the one in flight.
    pub fn submit(&self, job: Request) {
        self.cancel.store(true, Ordering::Relaxed);
        if let Some(jobs) = &self.jobs {
            let _ = jobs.send(job);
        }
    }

    /// Cancels the job in flight (it sends no reply).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Replies received so far.
    pub fn poll(&self) -> Vec<Reply> {
        self.replies.try_iter().collect()
    }
}

impl Drop for Worker {
    /// Cancels the job in flight and waits for the thread, so that the GPU
    /// sampler is released before the device.
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
        self.jobs = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn run(
    jobs: Receiver<Request>,
    replies: Sender<Reply>,
    cancel: Arc<AtomicBool>,
    gpu: Option<GpuState>,
    repaint: egui::Context,
) {
    let gpu = Mutex::new(gpu);
    while let Ok(mut job) = jobs.recv() {
        while let Ok(newer) = jobs.try_recv() {
            job = newer;
        }
        cancel.store(false, Ordering::Relaxed);
        let id = job.id;
        // Progress asks for no frame: the window redraws at its own pace
        // while a job runs (`busy_frame`), so that its frames do not take
        // the CPU from the sampler on a software rasterizer.
        let progress = |p: Progress| {
            let _ = replies.send(Reply::Progress(id, p));
        };
        let ctl = Control::new().with_progress(&progress).with_cancel(&cancel);
        let step = |step: Step| {
            let reply = match step {
                Step::Relaxed(done, of) => Reply::Relaxed(id, done, of),
                Step::Stage(name) => Reply::Stage(id, name),
                // Heard for its answer only (the cancel flag).
                _ => return,
            };
            let _ = replies.send(reply);
        };
        let start = std::time::Instant::now();
        let result = match compute(&job, &gpu, ctl, &step) {
            Err(crate::Error::Sampler(sampler::Error::Cancelled)) => continue,
            _ if cancel.load(Ordering::Relaxed) => continue,
            Ok(mut o) => {
                o.seconds = start.elapsed().as_secs_f64();
                Ok(o)
            }
            Err(e) => Err(super::words::app_line(&e)),
        };
        let _ = replies.send(Reply::Done(id, Box::new(result)));
        repaint.request_repaint();
    }
}

/// Runs a job's drawing on the chosen backend.
fn compute(
    job: &Request,
    gpu: &Mutex<Option<GpuState>>,
    ctl: Control<'_>,
    step: &dyn Fn(Step),
) -> crate::Result<Outcome> {
    let s = &job.settings;
    let mut note = None;
    // The map is framed already: the job without its crop and turn.
    let run = s.framed().job();
    let drawing = run.draw(
        crate::job::Picture::Both(&job.map, &job.colour),
        |params| Ok(sample(params, s.backend, gpu, ctl, &mut note)?),
        |s| {
            step(s);
            ctl.check().is_ok()
        },
    )?;
    ctl.check()?;
    if let Some(n) = drawing.short_of {
        note = Some(super::words::app_text(&crate::job::short_of(
            n,
            drawing.points.len(),
        )));
    }
    let scale = (f64::from(drawing.domain.0) / f64::from(job.map.width())) as f32;
    let dots: Vec<DotInstance> = drawing
        .points
        .iter()
        .zip(&drawing.calibrated)
        .map(|(p, &c)| DotInstance {
            x: p.x / scale,
            y: p.y / scale,
            radius: p.radius / scale,
            drawn: c / scale,
        })
        .collect();
    let pen_dots = match &drawing.pens {
        Some(pens) => pens
            .pens()
            .iter()
            .enumerate()
            .map(|(k, pen)| {
                let mine = drawing
                    .points
                    .iter()
                    .zip(&dots)
                    .filter(|(p, _)| p.class == k as u32)
                    .map(|(_, d)| *d)
                    .collect();
                (pen.colour, Arc::new(mine))
            })
            .collect(),
        None => Vec::new(),
    };
    Ok(Outcome {
        scale,
        sizes: DotSizes::of(&dots, scale),
        dots: Arc::new(dots),
        pen_dots,
        drawing: Arc::new(drawing),
        settings: s.clone(),
        note,
        seconds: 0.0,
    })
}

impl crate::backend::GpuRun for GpuState {
    fn adapter(&self) -> String {
        self.sampler.adapter().to_owned()
    }

    fn is_software(&self) -> bool {
        self.software
    }

    fn sample(&mut self, params: &Params, ctl: Control<'_>) -> sampler::Result<SampleSet> {
        self.sampler.sample(&self.device, &self.queue, params, ctl)
    }
}

/// Samples under the CLI's fallback policy ([`crate::backend::sample_with`]),
/// on the window's device; a fallback becomes the status line's note.
fn sample(
    params: &Params,
    choice: BackendChoice,
    gpu: &Mutex<Option<GpuState>>,
    ctl: Control<'_>,
    note: &mut Option<String>,
) -> sampler::Result<SampleSet> {
    let mut guard = gpu
        .lock()
        .map_err(|_| crate::gpu::GpuError::Unusable("the GPU state was poisoned".into()))?;
    let runner = match guard.as_mut() {
        Some(g) => Ok(g as &mut dyn crate::backend::GpuRun),
        None => Err("no GPU device in this window".to_owned()),
    };
    crate::backend::sample_with(params, choice, runner, ctl, &mut |n| {
        if let crate::backend::Notice::Fallback(_) = n {
            *note = Some(super::words::app_text(&n.to_string()));
        }
    })
}
