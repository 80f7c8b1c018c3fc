//! Backend selection: the GPU backend when an adapter exists (or is asked
//! for), the CPU reference otherwise. Both give the same points.

#[cfg(feature = "gpu")]
use std::sync::{Mutex, OnceLock};

#[cfg(feature = "gpu")]
use crate::gpu::{GpuContext, GpuSampler, S1Path};
use crate::sampler::{self, Control, Error, Params, SampleSet};

/// Which backend to run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum BackendChoice {
    /// The GPU when an adapter exists, else the CPU.
    #[default]
    Auto,
    /// The CPU reference backend.
    Cpu,
    /// The wgpu backend; an error when no adapter exists.
    Gpu,
}

/// The facade over the backends: [`Params::generate`] lives here, above the
/// contract, so that `sampler` knows no backend.
impl Params {
    /// Samples the set: the common case, as fast_poisson's `generate()`.
    /// Runs on the GPU when the `gpu` feature finds a hardware adapter, on
    /// the CPU otherwise; the points are the same either way.
    ///
    /// ```
    /// use pixelpie::sampler::Params;
    /// let set = Params::new(256, 256).with_radius(6.0).with_seed(3).generate().unwrap();
    /// assert!(set.maximal() && set.points.len() > 400);
    /// ```
    pub fn generate(&self) -> sampler::Result<SampleSet> {
        self.generate_with(Control::default())
    }

    /// [`Self::generate`] with progress reporting and cancellation.
    pub fn generate_with(&self, ctl: Control<'_>) -> sampler::Result<SampleSet> {
        sample(self, BackendChoice::Auto, ctl, &mut |_| {})
    }
}

/// The process's GPU being opened on a thread of its own while the caller
/// goes on (decoding the picture, preparing its maps): made by
/// [`open_early`]. Dropping it waits for the thread, so that no driver is
/// left starting while the process exits.
#[must_use = "dropping it at once waits for the GPU"]
pub struct Opening(Option<std::thread::JoinHandle<()>>);

impl Drop for Opening {
    fn drop(&mut self) {
        if let Some(thread) = self.0.take() {
            // A panic in the driver's start is the run's to report: the
            // run opens the GPU again and hears why.
            let _ = thread.join();
        }
    }
}

/// Starts opening the process's GPU (`SharedGpu::get`) when `choice` may
/// use it, so that the first run finds it open (or known absent) instead of
/// waiting for the driver: probing takes 30–100 ms where Mesa's drivers are
/// installed, as long as sampling 10K dots.
pub fn open_early(choice: BackendChoice) -> Opening {
    #[cfg(feature = "gpu")]
    if choice != BackendChoice::Cpu {
        return Opening(
            std::thread::Builder::new()
                .name("pixelpie-gpu-open".into())
                .spawn(|| {
                    let _ = SharedGpu::get();
                })
                .ok(),
        );
    }
    let _ = choice;
    Opening(None)
}

/// A process-wide headless GPU: opened on first use, kept for later runs so
/// that pipelines and buffers are reused.
#[cfg(feature = "gpu")]
pub struct SharedGpu {
    ctx: GpuContext,
    /// Built on the first run, so that probing the adapter stays cheap.
    sampler: Mutex<Option<GpuSampler>>,
    preferred: Mutex<Option<S1Path>>,
}

#[cfg(feature = "gpu")]
impl SharedGpu {
    /// The process's GPU, or why there is none.
    pub fn get() -> Result<&'static Self, NoGpu> {
        static GPU: OnceLock<Result<SharedGpu, NoGpu>> = OnceLock::new();
        GPU.get_or_init(|| {
            let ctx = GpuContext::new().map_err(|e| {
                let why = crate::text::one_line(&e);
                NoGpu(why.trim_start_matches("GPU: ").to_owned())
            })?;
            Ok(Self {
                ctx,
                sampler: Mutex::new(None),
                preferred: Mutex::new(None),
            })
        })
        .as_ref()
        .map_err(Clone::clone)
    }

    /// The adapter's name.
    pub fn adapter(&self) -> &str {
        &self.ctx.info.name
    }

    /// Whether the adapter is a software rasterizer (such as lavapipe).
    pub fn is_software(&self) -> bool {
        self.ctx.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Sets the S1 path of later [`Self::sample`] calls (`None`: the faster
    /// one, measured on this adapter).
    pub fn set_preferred_path(&self, path: Option<S1Path>) {
        if let Ok(mut p) = self.preferred.lock() {
            *p = path;
        }
    }

    /// Runs the sampler on this GPU, on the preferred S1 path.
    pub fn sample(&self, params: &Params, ctl: Control<'_>) -> sampler::Result<SampleSet> {
        let path = self.preferred.lock().ok().and_then(|p| *p);
        self.sample_on(params, path, ctl)
    }

    /// Runs the sampler on this GPU on the given S1 path (`None`: the faster).
    pub fn sample_on(
        &self,
        params: &Params,
        path: Option<S1Path>,
        ctl: Control<'_>,
    ) -> sampler::Result<SampleSet> {
        let mut guard = self.sampler.lock().map_err(|_| {
            crate::gpu::GpuError::Unusable(
                "the GPU sampler was poisoned by an earlier failure".into(),
            )
        })?;
        if guard.is_none() {
            *guard = Some(GpuSampler::new(
                &self.ctx.device,
                self.ctx.info.name.clone(),
            )?);
        }
        let Some(s) = guard.as_mut() else {
            return Err(crate::gpu::GpuError::Unusable("no GPU sampler".into()).into());
        };
        s.set_path(path);
        s.sample(&self.ctx.device, &self.ctx.queue, params, ctl)
    }
}

/// The GPU backend cannot be used here: no adapter, or a build without the
/// `gpu` feature.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("GPU: {0}")]
pub struct NoGpu(pub String);

/// A one-line message about the backend a run uses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Notice {
    /// The GPU adapter that runs the sampler (for `--verbose`).
    Adapter(String),
    /// `auto` found no usable GPU, or only a software rasterizer, and falls
    /// back to the CPU (always shown).
    Fallback(String),
}

impl std::fmt::Display for Notice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Adapter(name) => write!(f, "GPU backend on '{name}'"),
            Self::Fallback(why) => write!(f, "no usable GPU ({why}); using the CPU backend"),
        }
    }
}

#[doc(hidden)]
/// A GPU as the fallback policy sees it: the CLI's [`SharedGpu`], or the
/// app's sampler on egui's device.
pub trait GpuRun {
    /// The adapter's name.
    fn adapter(&self) -> String;
    /// Whether the adapter is a software rasterizer (such as lavapipe).
    fn is_software(&self) -> bool;
    /// Runs the sampler on this GPU.
    fn sample(&mut self, params: &Params, ctl: Control<'_>) -> sampler::Result<SampleSet>;
}

#[cfg(feature = "gpu")]
impl GpuRun for &SharedGpu {
    fn adapter(&self) -> String {
        SharedGpu::adapter(self).to_owned()
    }

    fn is_software(&self) -> bool {
        SharedGpu::is_software(self)
    }

    fn sample(&mut self, params: &Params, ctl: Control<'_>) -> sampler::Result<SampleSet> {
        SharedGpu::sample(self, params, ctl)
    }
}

/// Runs `params` on the chosen backend; `notice` hears which one. The GPU is
/// opened only when the choice may use it.
pub fn sample(
    params: &Params,
    choice: BackendChoice,
    ctl: Control<'_>,
    notice: &mut dyn FnMut(Notice),
) -> sampler::Result<SampleSet> {
    #[cfg(feature = "gpu")]
    {
        let wants_gpu = choice != BackendChoice::Cpu;
        let mut gpu = if wants_gpu {
            SharedGpu::get()
        } else {
            Err(NoGpu("not asked for".into()))
        };
        let runner = gpu
            .as_mut()
            .map(|g| g as &mut dyn GpuRun)
            .map_err(|e| e.0.clone());
        sample_with(params, choice, runner, ctl, notice)
    }
    #[cfg(not(feature = "gpu"))]
    sample_with(
        params,
        choice,
        Err("built without the `gpu` feature".into()),
        ctl,
        notice,
    )
}

#[doc(hidden)]
/// The fallback policy, the same for the CLI and the app:
///
/// * `cpu` runs the CPU backend;
/// * `gpu` runs the GPU and reports its errors (in exact mode the CPU runs
///   the finest level; radii above `gpu::exact::MAX_RADIUS_PX` (100 px) are
///   refused there);
/// * `auto` runs the GPU when there is a hardware adapter, and the CPU when
///   there is none, when the adapter is a software rasterizer (slower than
///   the CPU backend itself), or when the GPU fails during the run; `notice`
///   hears why.
pub fn sample_with(
    params: &Params,
    choice: BackendChoice,
    gpu: Result<&mut dyn GpuRun, String>,
    ctl: Control<'_>,
    notice: &mut dyn FnMut(Notice),
) -> sampler::Result<SampleSet> {
    match choice {
        BackendChoice::Cpu => sampler::cpu::sample(params, ctl),
        BackendChoice::Gpu => {
            let gpu = gpu.map_err(|why| Error::backend(NoGpu(why)))?;
            notice(Notice::Adapter(gpu.adapter()));
            gpu.sample(params, ctl)
        }
        BackendChoice::Auto => match gpu {
            Ok(gpu) if gpu.is_software() => {
                notice(Notice::Fallback(format!(
                    "'{}' is a software rasterizer",
                    gpu.adapter()
                )));
                sampler::cpu::sample(params, ctl)
            }
            Ok(gpu) => {
                notice(Notice::Adapter(gpu.adapter()));
                match gpu.sample(params, ctl) {
                    Err(e) if e.is_backend() => {
                        let why = crate::text::one_line(&e);
                        notice(Notice::Fallback(format!("the GPU failed: {why}")));
                        sampler::cpu::sample(params, ctl)
                    }
                    other => other,
                }
            }
            Err(e) => {
                notice(Notice::Fallback(e));
                sampler::cpu::sample(params, ctl)
            }
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CPU backend opens nothing; `auto` and `gpu` open the GPU on a
    /// thread that the guard waits for, after which the process's GPU is
    /// settled: opened, or known absent.
    #[test]
    fn the_gpu_opens_early_only_when_it_may_be_used() {
        assert!(open_early(BackendChoice::Cpu).0.is_none());
        #[cfg(feature = "gpu")]
        for choice in [BackendChoice::Auto, BackendChoice::Gpu] {
            let opening = open_early(choice);
            assert!(opening.0.is_some());
            drop(opening);
            let first = SharedGpu::get().map(std::ptr::from_ref);
            assert_eq!(first, SharedGpu::get().map(std::ptr::from_ref));
        }
    }
}
