//! The drawing job off the UI thread: the latest job wins, an older one in
//! flight is cancelled, and the GPU sampler shares egui's device. The job
//! is the library's ([`crate::stipple::Job`]), the same that `pixelpie
//! stipple` runs, so the app draws what the CLI draws.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};

use egui_wgpu::wgpu;

use super::settings::Settings;
use crate::backend::BackendChoice;
use crate::gpu::GpuSampler;
use crate::importance::{ColourMap, ImportanceMap};
use crate::sampler::{self, Control, Params, Progress, SampleSet};
use crate::stipple::Stipple;

/// A sampling request.
pub struct Job {
    /// Increases with every job; replies carry it.
    pub id: u64,
    /// The importance map.
    pub map: Arc<ImportanceMap>,
    /// The picture in colour, for drawings with pens.
    pub colour: Arc<ColourMap>,
    /// The settings.
    pub settings: Settings,
}

/// A finished job.
pub struct Outcome {
    /// The drawing (in domain pixels), as `pixelpie stipple` makes it
    /// (shared with the plot-time estimate's thread).
    pub drawing: Arc<Stipple>,
    /// The settings it was made with (Cancel goes back to them).
    pub settings: Settings,
    /// Domain pixels per image pixel: the sampling domain is the image
    /// scaled as `pixelpie stipple` scales it.
    pub scale: f32,
    /// A note for the status line, such as a fallback to the CPU.
    pub note: Option<String>,
    /// Seconds the whole job took: every sampler run, relaxation and dot
    /// sizes (the statistics' `seconds` is the last run's sampler alone).
    pub seconds: f64,
}

/// A message from the worker.
pub enum Reply {
    /// An iteration finished.
    Progress(u64, Progress),
    /// This many relaxation steps are done.
    Relaxed(u64, u32),
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
    jobs: Option<Sender<Job>>,
    thread: Option<std::thread::JoinHandle<()>>,
    replies: Receiver<Reply>,
    cancel: Arc<AtomicBool>,
    adapter: Option<String>,
}

impl Worker {
    /// Starts the worker. With `gpu`, it samples on that device (egui's).
    pub fn new(
        gpu: Option<(wgpu::Device, wgpu::Queue, wgpu::AdapterInfo)>,
        repaint: egui::Context,
    ) -> Self {
        let (jobs, job_rx) = channel::<Job>();
        let (reply_tx, replies) = channel();
        let cancel = Arc::new(AtomicBool::new(false));
        let mut adapter = None;
        let gpu_state = gpu.and_then(|(device, queue, info)| {
            match GpuSampler::new(&device, info.name.clone()) {
                Ok(sampler) => {
                    adapter = Some(info.name);
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
        }
    }

    /// The GPU adapter the worker samples on, if any.
    pub fn adapter(&self) -> Option<&str> {
        self.adapter.as_deref()
    }

    /// Queues a job and cancels the one in flight.
    pub fn submit(&self, job: Job) {
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
    jobs: Receiver<Job>,
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
        let progress = |p: Progress| {
            let _ = replies.send(Reply::Progress(id, p));
            repaint.request_repaint();
        };
        let ctl = Control::new().with_progress(&progress).with_cancel(&cancel);
        let relaxed = |done: u32| {
            let _ = replies.send(Reply::Relaxed(id, done));
            repaint.request_repaint();
        };
        let start = std::time::Instant::now();
        let result = match compute(&job, &gpu, ctl, &relaxed) {
            Err(crate::Error::Sampler(sampler::Error::Cancelled)) => continue,
            _ if cancel.load(Ordering::Relaxed) => continue,
            Ok(mut o) => {
                o.seconds = start.elapsed().as_secs_f64();
                Ok(o)
            }
            Err(e) => Err(crate::text::one_line(&e)),
        };
        let _ = replies.send(Reply::Done(id, Box::new(result)));
        repaint.request_repaint();
    }
}

/// Runs a job's drawing on the chosen backend.
fn compute(
    job: &Job,
    gpu: &Mutex<Option<GpuState>>,
    ctl: Control<'_>,
    relaxed: &dyn Fn(u32),
) -> crate::Result<Outcome> {
    let s = &job.settings;
    let mut note = None;
    let run = s.job();
    let drawing = if run.colour() {
        run.run_colour(&job.colour, |params| {
            Ok(sample(params, s.backend, gpu, ctl, &mut note)?)
        })?
    } else {
        run.run_map(
            &job.map,
            |params| Ok(sample(params, s.backend, gpu, ctl, &mut note)?),
            |done| {
                relaxed(done);
                ctl.check().is_ok()
            },
        )?
    };
    ctl.check()?;
    if let Some(n) = drawing.short_of {
        note = Some(format!(
            "{n} points asked, {} fit at radii of at least 1 px",
            drawing.points.len()
        ));
    }
    Ok(Outcome {
        scale: (f64::from(drawing.domain.0) / f64::from(job.map.width())) as f32,
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
            *note = Some(format!("{n}"));
        }
    })
}
