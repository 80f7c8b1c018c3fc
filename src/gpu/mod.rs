//! The wgpu backend: the paper's pipeline (Figure 3) as compute passes and an
//! instanced depth-only draw, bit-identical to `sampler::cpu`.
//!
//! | paper | here | shader |
//! |---|---|---|
//! | S1 dart throwing (geometry + fragment shader) | [`throw`]: compute darts, vertex-pulled instanced quads, depth = key | `throw.wgsl`, `raster.wgsl` |
//! | S2 conflict removal (transform feedback) | [`cull`]: depth read at each dart, scan, gather | `cull.wgsl` |
//! | S2 coverage map | [`cover`]: compute rasterization into a coverage bitmap | `cover.wgsl` |
//! | PP Thrust compaction | [`compact`]: prefix-sum scans | `compact.wgsl` |
//! | exact mode (S1, S2 and the refinement, in 1/2^F px) | [`exact`], the finest level on the CPU | `exact.wgsl`, `cover.wgsl` |
//!
//! The sampler borrows the caller's `Device` and `Queue` (the app shares
//! egui's), and keeps its pipelines and buffers across runs.

pub(crate) mod compact;
pub(crate) mod cover;
pub(crate) mod cull;
mod error;
pub(crate) mod exact;
mod resources;
pub(crate) mod throw;
pub mod util;

pub use error::GpuError;
pub use resources::S1Path;
pub(crate) use resources::{Resources, Shape, Stages};

use crate::sampler::fixed::iteration_key;
use crate::sampler::run::{self, StageTimes, Step, Stepper};
use crate::sampler::{BackendKind, Control, Params, Plan, Result, SampleSet, Stats};

/// The run's configuration. Mirrors `struct Config` in `shaders/common.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Config {
    width: u32,
    height: u32,
    period_x: u32,
    period_y: u32,
    policy: u32,
    subpixel_bits: u32,
    index_bits: u32,
    radius_bits: u32,
    min_radius: u32,
    max_radius: u32,
    uniform_radius: u32,
    iteration_key: u32,
    empty: u32,
    darts: u32,
    first: u32,
    words: u32,
    splat: u32,
    /// The first row of the key buffer's strip (compute S1 path).
    strip_y0: u32,
    /// Rows of the strip: the (stacked) domain's height unless the key
    /// buffer is chunked.
    strip_rows: u32,
    /// Classes (1 without): the empty list, coverage and keys stack one
    /// layer per class.
    classes: u32,
}

impl Config {
    fn new(plan: &Plan) -> Self {
        let (period_x, period_y) = plan.periods();
        Self {
            width: plan.width,
            height: plan.height,
            period_x,
            period_y,
            policy: plan.policy.index(),
            subpixel_bits: plan.subpixel_bits,
            index_bits: plan.layout.index_bits,
            radius_bits: plan.layout.radius_bits,
            min_radius: plan.radius_range.0,
            max_radius: plan.radius_range.1,
            uniform_radius: if plan.map.is_some() {
                0
            } else {
                plan.radius_range.0
            },
            iteration_key: 0,
            empty: plan.slots(),
            darts: 0,
            first: 1,
            words: plan.slots().div_ceil(32),
            splat: 0,
            strip_y0: 0,
            strip_rows: plan.slot_rows(),
            classes: plan.classes(),
        }
    }
}

/// A headless device: an adapter, its device and queue.
pub struct GpuContext {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter's description.
    pub info: wgpu::AdapterInfo,
}

impl GpuContext {
    /// Opens the first high-performance adapter (Vulkan, Metal or DX12 unless
    /// `WGPU_BACKEND` says otherwise) with its own limits, not the defaults.
    pub fn new() -> Result<Self> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if std::env::var_os("WGPU_BACKEND").is_none() {
            desc.backends = wgpu::Backends::PRIMARY;
        }
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| error::failed("no GPU adapter", e))?;
        check_adapter(&adapter)?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("pixelpie"),
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| error::failed("cannot open the GPU device", e))?;
        Ok(Self {
            device,
            queue,
            info: adapter.get_info(),
        })
    }
}

/// Refuses adapters that cannot run the pipeline (GL without vertex storage).
pub fn check_adapter(adapter: &wgpu::Adapter) -> Result<()> {
    let caps = adapter.get_downlevel_capabilities();
    let need = wgpu::DownlevelFlags::COMPUTE_SHADERS | wgpu::DownlevelFlags::VERTEX_STORAGE;
    if !caps.flags.contains(need) {
        return Err(error::unusable(format!(
            "adapter '{}' lacks compute shaders or vertex storage",
            adapter.get_info().name
        )));
    }
    Ok(())
}

/// The GPU sampler: pipelines built once, buffers kept between runs.
pub struct GpuSampler {
    throw: throw::ThrowStage,
    cull: cull::CullStage,
    cover: cover::CoverStage,
    compact: compact::CompactStage,
    resources: Option<Resources>,
    /// Exact mode's kernels (compiled on its first run) and memory.
    exact: Option<(exact::ExactStage, Option<exact::ExactResources>)>,
    adapter: String,
    /// The S1 path chosen by the caller, or `None` to pick by measurement.
    path: Option<S1Path>,
    /// The path that measured faster on this device.
    measured: Option<S1Path>,
    /// A cap on the rows per strip of the compute path's key buffer.
    strip_cap: Option<u32>,
}

impl GpuSampler {
    /// Compiles the pipelines on `device`; `adapter` names it in the stats.
    pub fn new(device: &wgpu::Device, adapter: impl Into<String>) -> Result<Self> {
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
        let s = Self {
            throw: throw::ThrowStage::new(device),
            cull: cull::CullStage::new(device),
            cover: cover::CoverStage::new(device),
            compact: compact::CompactStage::new(device),
            resources: None,
            exact: None,
            adapter: adapter.into(),
            path: None,
            measured: None,
            strip_cap: None,
        };
        let errors = [
            pollster::block_on(internal.pop()),
            pollster::block_on(scope.pop()),
        ];
        if let Some(err) = errors.into_iter().flatten().next() {
            return Err(error::failed("cannot build the pipelines", err));
        }
        Ok(s)
    }

    /// The adapter's name.
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    /// Forces an S1 path, or with `None` lets the sampler measure both on
    /// this device and keep the faster.
    pub fn set_path(&mut self, path: Option<S1Path>) {
        self.path = path;
    }

    /// Caps the rows per strip of the compute path's key buffer, which is
    /// otherwise chunked only beyond the adapter's largest storage binding:
    /// for tests of the chunking on small domains. `None` lifts the cap.
    pub fn set_strip_cap(&mut self, rows: Option<u32>) {
        self.strip_cap = rows.map(|r| r.max(1));
    }

    /// The S1 path a run takes on `device`: the caller's choice, or the
    /// faster one measured (once) on a 512² calibration run.
    fn path_for(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<S1Path> {
        if let Some(p) = self.path {
            return Ok(p);
        }
        if let Some(p) = self.measured {
            return Ok(p);
        }
        let side = 512.min(device.limits().max_texture_dimension_2d);
        let probe = Params::new(side, side).with_radius(8.5).with_seed(1);
        let mut best = (f64::INFINITY, S1Path::Raster);
        for path in S1Path::ALL {
            self.path = Some(path);
            // The first run compiles and allocates; time the second.
            let _ = self.run(device, queue, &probe, Control::default())?;
            let t = self
                .run(device, queue, &probe, Control::default())?
                .stats
                .seconds;
            if t < best.0 {
                best = (t, path);
            }
        }
        self.path = None;
        self.resources = None;
        self.measured = Some(best.1);
        Ok(best.1)
    }

    /// Runs the sampler on `device`.
    pub fn sample(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        params: &Params,
        ctl: Control<'_>,
    ) -> Result<SampleSet> {
        let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let result = self.run(device, queue, params, ctl);
        let errors = [
            pollster::block_on(scope.pop()),
            pollster::block_on(oom.pop()),
        ];
        if let Some(err) = errors.into_iter().flatten().next() {
            self.resources = None;
            self.exact = None;
            return Err(error::failed("a GPU command failed", err));
        }
        result
    }

    fn run(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        params: &Params,
        ctl: Control<'_>,
    ) -> Result<SampleSet> {
        let plan = params.plan()?;
        let limits = device.limits();
        let max = limits.max_texture_dimension_2d;
        if plan.width > max || plan.height > max {
            return Err(error::unusable(format!(
                "the {}x{} domain exceeds the adapter's largest texture, {max}x{max}",
                plan.width, plan.height
            )));
        }
        if util::disk_rows(plan.radius_range.1) > 65535 {
            return Err(error::unusable(
                "radii above 32766 px exceed the GPU's row dispatch",
            ));
        }
        if plan.exact {
            return self.run_exact(device, queue, &plan, ctl);
        }
        // Classes rasterize a key layer per class: a compute path's.
        let path = match self.path_for(device, queue)? {
            S1Path::Raster if plan.classes() > 1 => S1Path::Compute,
            p => p,
        };
        let map_rows = plan.slot_rows() + if plan.classes() > 1 { plan.height } else { 0 };
        if map_rows > max {
            return Err(error::unusable(format!(
                "{} classes of {} rows exceed the adapter's largest texture, {max} rows",
                plan.classes(),
                plan.height
            )));
        }
        let cap = plan.batch.min(plan.slots()).min(plan.layout.max_batch());
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let shape = Shape {
            capacity: cap,
            timestamps,
            path,
            strip_cap: self.strip_cap,
        };
        let stages = Stages {
            throw: &self.throw,
            cull: &self.cull,
            cover: &self.cover,
            compact: &self.compact,
        };
        let fits = self
            .resources
            .as_ref()
            .is_some_and(|r| r.fits(device, &plan, shape));
        if !fits {
            self.resources = None;
            self.resources = Some(Resources::new(device, queue, stages, &plan, shape)?);
        }
        let Some(res) = self.resources.as_ref() else {
            return Err(error::unusable("no resources"));
        };
        res.radius.upload(queue, &plan);
        res.radius.upload_near(queue, &plan);
        let mut config = Config::new(&plan);
        config.splat = u32::from(path.splats());
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&res.coverage, 0, None);
        queue.submit([encoder.finish()]);
        if plan.holes {
            // Slots of a class with no radius start covered: the first
            // iteration reads a scanned list, not every slot.
            config.empty = res.cover_holes(device, queue, stages, &plan)?;
            config.first = 0;
        }

        let stats = Stats {
            backend: match path {
                S1Path::Raster => BackendKind::GpuRaster,
                S1Path::Compute => BackendKind::GpuCompute,
                S1Path::Coalesced => BackendKind::GpuCoalesced,
            },
            device: self.adapter.clone(),
            gpu_timestamps: timestamps,
            ..Stats::default()
        };
        let mut stepper = GpuStepper {
            device,
            queue,
            stages,
            res,
            plan: &plan,
            config,
            held: 0,
        };
        run::run(&plan, &mut stepper, stats, ctl)
    }
}

impl GpuSampler {
    /// Runs exact mode: down to the finest level here, then on the CPU.
    fn run_exact(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        plan: &Plan,
        ctl: Control<'_>,
    ) -> Result<SampleSet> {
        if plan.radius_range.1 > exact::MAX_RADIUS_PX * crate::sampler::fixed::RADIUS_ONE {
            return Err(error::unusable(format!(
                "exact mode on the GPU takes radii up to {} px",
                exact::MAX_RADIUS_PX
            )));
        }
        let storage = device.limits().max_storage_buffers_per_shader_stage;
        if storage < exact::STORAGE_BUFFERS {
            return Err(error::unusable(format!(
                "exact mode on the GPU binds {} storage buffers per shader stage; this device \
                 allows {storage}",
                exact::STORAGE_BUFFERS
            )));
        }
        // Below the pixel a batch may outnumber the pixels (cells are finer).
        let cap = plan.batch.min(crate::sampler::fixed::MAX_BATCH);
        let (stage, slot) = self
            .exact
            .get_or_insert_with(|| (exact::ExactStage::new(device), None));
        if !slot.as_ref().is_some_and(|r| r.fits(plan, cap)) {
            *slot = None;
            *slot = Some(exact::ExactResources::new(
                device,
                queue,
                exact::Kernels {
                    exact: stage,
                    cover: &self.cover,
                    compact: &self.compact,
                },
                plan,
                cap,
            )?);
        }
        let Some(res) = slot.as_mut() else {
            return Err(error::unusable("no resources"));
        };
        let stats = Stats {
            backend: BackendKind::GpuExact,
            device: self.adapter.clone(),
            ..Stats::default()
        };
        let kernels = exact::Kernels {
            exact: stage,
            cover: &self.cover,
            compact: &self.compact,
        };
        let mut stepper = exact::ExactGpuStepper::new(device, queue, kernels, res, plan);
        run::run(plan, &mut stepper, stats, ctl)
    }
}

/// One GPU run between iterations: the device, the stages, the buffers,
/// the configuration that the next iteration uploads and the accepted
/// samples the GPU holds, read back when the run ends or their room would
/// not take another batch (one read-back per run, not one per iteration).
struct GpuStepper<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    stages: Stages<'a>,
    res: &'a Resources,
    plan: &'a Plan,
    config: Config,
    held: u32,
}

impl GpuStepper<'_> {
    /// Reads back the held samples.
    fn take_held(&mut self) -> Result<Vec<crate::sampler::Point>> {
        let points = self
            .res
            .take_held(self.device, self.queue, self.plan, self.held)?;
        self.held = 0;
        Ok(points)
    }
}

impl Stepper for GpuStepper<'_> {
    fn empty(&self) -> u64 {
        u64::from(self.config.empty)
    }

    fn step(&mut self, iteration: u32, darts: u32) -> Result<Step> {
        self.config.iteration_key = iteration_key(self.plan.seed_key, iteration);
        self.config.darts = darts;
        self.res.dart_scan.set_len(self.queue, darts + 1, 0);
        let mut accepted = Vec::new();
        if self.held + darts > self.res.held_capacity() {
            accepted = self.take_held()?;
        }
        let it = self.res.iterate(
            self.device,
            self.queue,
            self.stages,
            self.plan,
            self.config,
            self.held,
        )?;
        self.held += it.accepted;
        let last = it.empty == 0 || iteration + 1 >= self.plan.max_iterations;
        if last || self.held + self.res.capacity() > self.res.held_capacity() {
            accepted.extend(self.take_held()?);
        }
        self.config.empty = it.empty;
        self.config.first = 0;
        let mut stages = StageTimes::default();
        for (name, s) in resources::STAGES.iter().zip(it.seconds) {
            stages.add(name, s);
        }
        Ok(Step {
            empty: u64::from(it.empty),
            accepted,
            stages,
            finished: false,
            removed: Vec::new(),
            held: self.held as usize,
        })
    }

    fn bytes(&self) -> usize {
        usize::try_from(self.res.bytes()).unwrap_or(usize::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::util::{COMMON, rust_layout, wgsl_layout};

    #[test]
    fn the_config_mirrors_the_layout_naga_reads_from_common_wgsl() {
        let rust = rust_layout!(super::Config;
            width, height, period_x, period_y, policy, subpixel_bits, index_bits,
            radius_bits, min_radius, max_radius, uniform_radius, iteration_key, empty,
            darts, first, words, splat, strip_y0, strip_rows, classes);
        assert_eq!(rust, wgsl_layout(COMMON, "Config"));
    }

    #[test]
    fn the_dart_mirrors_the_layout_naga_reads_from_common_wgsl() {
        let rust = rust_layout!(crate::sampler::Dart; x, y, pixel, radius);
        assert_eq!(rust, wgsl_layout(COMMON, "Dart"));
    }
}
