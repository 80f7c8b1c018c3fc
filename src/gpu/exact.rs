//! Exact mode on wgpu: the pixel pass (level 0 of [`crate::sampler::exact`])
//! as compute passes, bit-identical to the CPU's, then the refinement below
//! the pixel on the CPU. Shader: `shaders/exact.wgsl`.
//!
//! | exact mode's semantics | here |
//! |---|---|
//! | darts, F-bit offsets in empty pixels | `exact_throw` |
//! | acceptance against the accepted samples | `exact_throw`, over the sample grid |
//! | acceptance in dart order within the batch | `exact_resolve` rounds over the dart grid, `exact_flags` |
//! | the accepted darts, in order, join the set | the scan of `compact.wgsl`, `exact_gather` |
//! | coverage of pixels by the corner rule | `cover_exact` (`cover.wgsl`), then the empty-pixel scan |
//! | refinement, finest level, repair | on the CPU, from the iteration that first refines |
//!
//! The handover: when an iteration accepts fewer than 1/[`REFINE_BELOW`] of
//! its darts, the semantics refine the cells; the samples (already read back
//! in order) and the coverage bitmap go to [`ExactStepper::resume`], which
//! refines, and the CPU runs every later iteration. The pixel pass holds
//! most of the samples (at 4096²: 94% at r = 8.5 px, 75% at r = 2 px) and
//! most of the CPU's time at the larger radii (80% at r = 8.5 px, 36% at
//! r = 2 px); below the pixel the cells are few and scattered.

use std::time::Instant;

use super::compact::{CompactStage, ScanChain};
use super::cover::CoverStage;
use super::resources::RadiusTexture;
use super::{Config, util};
use crate::sampler::exact::{ExactStepper, REFINE_BELOW, frac_bits};
use crate::sampler::fixed::{self, MAX_BATCH, RADIUS_ONE, iteration_key};
use crate::sampler::run::{StageTimes, Step, Stepper};
use crate::sampler::{Dart, Error, Plan, Point, Result};

/// Rounds of `exact_resolve` per submission; more run while a dart is
/// undecided (random darts settle in a few).
const ROUNDS: u32 = 8;

/// The largest radius, in pixels, that the GPU's pixel pass takes. One
/// thread walks the lists of nine grid cells of g = r_max + 1 px: a cell
/// holds at most (g / r_min + 1)² samples and, on average, one dart per
/// pixel, about 10⁴ of each at 100 px; llvmpipe stops a loop after 65535
/// iterations, and a longer walk gains nothing on a GPU over the CPU.
pub const MAX_RADIUS_PX: u32 = 100;

/// Bytes of one dart or sample.
const DART_BYTES: u64 = std::mem::size_of::<Dart>() as u64;

/// Mirrors `struct Exact` in `shaders/exact.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct ExactConfig {
    frac: u32,
    g: u32,
    cols: u32,
    cells: u32,
    cap: u32,
    base: u32,
    period_x: u32,
    period_y: u32,
}

impl ExactConfig {
    fn new(plan: &Plan, cap: u32) -> Self {
        let frac = frac_bits(plan.width, plan.height);
        let g = plan.radius_range.1.div_ceil(RADIUS_ONE) + 1;
        let cols = plan.width.div_ceil(g);
        let (period_x, period_y) = if plan.periodic {
            (plan.width << frac, plan.height << frac)
        } else {
            (0, 0)
        };
        Self {
            frac,
            g,
            cols,
            cells: cols * plan.height.div_ceil(g),
            cap,
            base: 0,
            period_x,
            period_y,
        }
    }

    /// Words of the grid buffer: two heads per cell, a state and a link per
    /// dart, the undecided count.
    fn grid_words(&self) -> u64 {
        2 * u64::from(self.cells) + 2 * u64::from(self.cap) + 1
    }
}

/// The kernels of `exact.wgsl`.
pub struct ExactStage {
    layout: wgpu::BindGroupLayout,
    throw: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    flags: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
}

/// The kernels an exact run uses.
#[derive(Clone, Copy)]
pub struct Kernels<'a> {
    /// `exact.wgsl`'s.
    pub exact: &'a ExactStage,
    /// Coverage, for `cover_exact`.
    pub cover: &'a CoverStage,
    /// The scans.
    pub compact: &'a CompactStage,
}

impl ExactStage {
    /// Compiles the kernels.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = util::layout(
            device,
            "exact",
            &[
                util::uniform(0, c),
                util::storage(1, c, false),
                util::storage(2, c, true),
                util::storage(3, c, true),
                util::texture(4, wgpu::TextureSampleType::Uint),
                util::uniform(5, c),
                util::storage(6, c, false),
                util::storage(7, c, false),
                util::storage(8, c, false),
                util::storage(9, c, false),
            ],
        );
        let pl = util::pipeline_layout(device, &layout);
        let module = util::module(device, "exact.wgsl", util::SHADERS[6].1);
        Self {
            throw: util::compute(device, &pl, &module, "exact_throw"),
            resolve: util::compute(device, &pl, &module, "exact_resolve"),
            flags: util::compute(device, &pl, &module, "exact_flags"),
            gather: util::compute(device, &pl, &module, "exact_gather"),
            layout,
        }
    }

    fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        pipeline: &wgpu::ComputePipeline,
        threads: u32,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        util::dispatch(pass, threads.div_ceil(256));
    }
}

/// The GPU memory of an exact run: kept between runs of one domain shape.
pub struct ExactResources {
    width: u32,
    height: u32,
    ex: ExactConfig,
    config: wgpu::Buffer,
    ex_buffer: wgpu::Buffer,
    darts: wgpu::Buffer,
    coverage: wgpu::Buffer,
    word_scan: ScanChain,
    dart_scan: ScanChain,
    radius: RadiusTexture,
    grid: wgpu::Buffer,
    samples: wgpu::Buffer,
    /// Samples the sample buffer holds.
    sample_cap: u32,
    survivors: wgpu::Buffer,
    staging: wgpu::Buffer,
    group: wgpu::BindGroup,
    cover_group: wgpu::BindGroup,
}

impl ExactResources {
    /// Allocates what `plan` needs with batches of up to `cap` darts.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernels: Kernels<'_>,
        plan: &Plan,
        cap: u32,
    ) -> Result<Self> {
        let (stage, compact) = (kernels.exact, kernels.compact);
        use wgpu::BufferUsages as B;
        let ex = ExactConfig::new(plan, cap);
        let words = plan.pixels().div_ceil(32);
        let dart_bytes = u64::from(cap) * DART_BYTES;
        let max = device.limits().max_storage_buffer_binding_size;
        if dart_bytes > max {
            return Err(Error::Gpu(format!(
                "the batch of {cap} darts exceeds the adapter's storage binding size"
            )));
        }
        if 4 * ex.grid_words() > max {
            return Err(Error::Gpu(format!(
                "the sample grid of {} cells exceeds the adapter's storage binding size",
                ex.cells
            )));
        }
        let uniform = |label, size| util::buffer_of(device, label, size, B::UNIFORM | B::COPY_DST);
        let config = uniform("config", std::mem::size_of::<Config>() as u64);
        let ex_buffer = uniform("exact config", std::mem::size_of::<ExactConfig>() as u64);
        let darts = util::buffer_of(device, "exact darts", dart_bytes, B::STORAGE);
        let coverage = util::buffer_of(
            device,
            "coverage",
            4 * u64::from(words),
            B::STORAGE | B::COPY_DST | B::COPY_SRC,
        );
        let word_scan = ScanChain::new(device, compact, "word scan", words, Some(&coverage));
        word_scan.set_len(queue, words, plan.pixels());
        let dart_scan = ScanChain::new(device, compact, "dart scan", cap + 1, None);
        let grid = util::buffer_of(
            device,
            "exact grid",
            4 * ex.grid_words(),
            B::STORAGE | B::COPY_DST | B::COPY_SRC,
        );
        // Room for the expected count and a margin, grown when a batch could
        // overflow it ([`Self::reserve`]).
        let most = (max / DART_BYTES).min(u64::from(u32::MAX)) as f64;
        let sample_cap = (plan.expected_points * 1.25)
            .max(1024.0)
            .max(f64::from(cap))
            .min(most) as u32;
        let samples = Self::sample_buffer(device, sample_cap);
        let survivors = util::buffer_of(device, "survivors", dart_bytes, B::STORAGE | B::COPY_SRC);
        let staging = util::buffer_of(
            device,
            "read-back",
            16 + dart_bytes,
            B::MAP_READ | B::COPY_DST,
        );
        let radius = RadiusTexture::new(device, plan);
        let group = Self::bind(
            device,
            stage,
            [
                &config,
                &darts,
                &coverage,
                &word_scan.levels[0],
                &ex_buffer,
                &samples,
                &grid,
                &dart_scan.levels[0],
                &survivors,
            ],
            &radius.view,
        );
        let cover_group = kernels.cover.bind_exact(
            device,
            [
                &config,
                &survivors,
                dart_scan.total(),
                &coverage,
                &ex_buffer,
            ],
            &radius.view,
        );
        Ok(Self {
            width: plan.width,
            height: plan.height,
            ex,
            config,
            ex_buffer,
            darts,
            coverage,
            word_scan,
            dart_scan,
            radius,
            grid,
            samples,
            sample_cap,
            survivors,
            staging,
            group,
            cover_group,
        })
    }

    fn sample_buffer(device: &wgpu::Device, cap: u32) -> wgpu::Buffer {
        use wgpu::BufferUsages as B;
        util::buffer_of(
            device,
            "exact samples",
            u64::from(cap) * DART_BYTES,
            B::STORAGE | B::COPY_SRC | B::COPY_DST,
        )
    }

    /// The bind group: buffers in binding order, the radius map at 4.
    fn bind(
        device: &wgpu::Device,
        stage: &ExactStage,
        b: [&wgpu::Buffer; 9],
        radius: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        util::bind_group(
            device,
            &stage.layout,
            &[
                b[0].as_entire_binding(),
                b[1].as_entire_binding(),
                b[2].as_entire_binding(),
                b[3].as_entire_binding(),
                wgpu::BindingResource::TextureView(radius),
                b[4].as_entire_binding(),
                b[5].as_entire_binding(),
                b[6].as_entire_binding(),
                b[7].as_entire_binding(),
                b[8].as_entire_binding(),
            ],
        )
    }

    /// Whether these resources serve `plan` with batches of `cap` darts.
    pub fn fits(&self, plan: &Plan, cap: u32) -> bool {
        // The grid and the periods come from the plan, the state arrays'
        // size from the largest batch.
        let ex = ExactConfig {
            cap: self.ex.cap,
            ..ExactConfig::new(plan, cap)
        };
        bytemuck::bytes_of(&ex) == bytemuck::bytes_of(&self.ex)
            && (self.width, self.height) == (plan.width, plan.height)
            && self.radius.fits(plan)
            && cap <= self.ex.cap
    }

    /// Device memory held, in bytes.
    fn bytes(&self) -> u64 {
        [
            &self.darts,
            &self.coverage,
            &self.grid,
            &self.samples,
            &self.survivors,
        ]
        .iter()
        .map(|b| b.size())
        .sum::<u64>()
            + self.word_scan.bytes()
            + self.dart_scan.bytes()
    }

    /// Grows the sample buffer to hold `n` samples, keeping the first `kept`.
    fn reserve(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stage: &ExactStage,
        n: u32,
        kept: u32,
    ) -> Result<()> {
        if n <= self.sample_cap {
            return Ok(());
        }
        let max = device.limits().max_storage_buffer_binding_size / DART_BYTES;
        if u64::from(n) > max {
            return Err(Error::Gpu(format!(
                "{n} samples exceed the adapter's storage binding size"
            )));
        }
        let cap = (u64::from(n).max(2 * u64::from(self.sample_cap))).min(max) as u32;
        let samples = Self::sample_buffer(device, cap);
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.samples, 0, &samples, 0, u64::from(kept) * DART_BYTES);
        queue.submit([encoder.finish()]);
        self.group = Self::bind(
            device,
            stage,
            [
                &self.config,
                &self.darts,
                &self.coverage,
                &self.word_scan.levels[0],
                &self.ex_buffer,
                &samples,
                &self.grid,
                &self.dart_scan.levels[0],
                &self.survivors,
            ],
            &self.radius.view,
        );
        self.samples = samples;
        self.sample_cap = cap;
        Ok(())
    }
}

/// The exact pixel pass between iterations, and the CPU's run once the
/// cells are refined.
pub struct ExactGpuStepper<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    kernels: Kernels<'a>,
    res: &'a mut ExactResources,
    plan: &'a Plan,
    config: Config,
    /// The accepted samples in order: x, y (1/2^F px) and pixel.
    samples: Vec<(u32, u32, u32)>,
    /// The CPU's run, from the first refinement on.
    cpu: Option<ExactStepper<'a>>,
}

impl<'a> ExactGpuStepper<'a> {
    /// A run of `plan` on `res` with every pixel empty.
    pub fn new(
        device: &'a wgpu::Device,
        queue: &'a wgpu::Queue,
        kernels: Kernels<'a>,
        res: &'a mut ExactResources,
        plan: &'a Plan,
    ) -> Self {
        res.radius.upload(queue, plan);
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&res.coverage, 0, None);
        encoder.clear_buffer(&res.grid, 0, None);
        queue.submit([encoder.finish()]);
        Self {
            device,
            queue,
            kernels,
            res,
            plan,
            config: Config::new(plan),
            samples: Vec::new(),
            cpu: None,
        }
    }

    /// Submits `encoder` and reads back the first `len` bytes of the staging
    /// buffer.
    fn finish(&self, encoder: wgpu::CommandEncoder, len: u64) -> Result<Vec<u8>> {
        self.queue.submit([encoder.finish()]);
        util::read_back(self.device, &self.res.staging, len)
    }

    /// Runs resolve rounds until no dart is undecided. Each round decides
    /// at least the first undecided dart, so `darts` rounds always suffice;
    /// more mean a broken device.
    fn resolve(&self, mut encoder: wgpu::CommandEncoder, darts: u32) -> Result<()> {
        let (res, stage) = (&*self.res, self.kernels.exact);
        let count_at = 4 * (res.ex.grid_words() - 1);
        for _ in 0..=darts.div_ceil(ROUNDS) {
            encoder.clear_buffer(&res.grid, count_at, Some(4));
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                for _ in 0..ROUNDS {
                    stage.dispatch(&mut pass, &res.group, &stage.resolve, darts);
                }
                stage.dispatch(&mut pass, &res.group, &stage.flags, darts + 1);
            }
            encoder.copy_buffer_to_buffer(&res.grid, count_at, &res.staging, 0, 4);
            let left = self.finish(encoder, 4)?;
            if bytemuck::pod_read_unaligned::<u32>(&left[..4]) == 0 {
                return Ok(());
            }
            encoder = self.device.create_command_encoder(&Default::default());
        }
        Err(Error::Gpu(
            "the batch's acceptance order did not settle on the GPU".into(),
        ))
    }

    /// The coverage bitmap in the CPU's layout.
    fn coverage(&self) -> Result<Vec<u64>> {
        let words = self.config.words;
        let staging = util::buffer_of(
            self.device,
            "coverage read-back",
            4 * u64::from(words),
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.res.coverage, 0, &staging, 0, 4 * u64::from(words));
        self.queue.submit([encoder.finish()]);
        let bytes = util::read_back(self.device, &staging, 4 * u64::from(words))?;
        let gpu: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let mut map = crate::sampler::cpu::cover::new_map(self.plan.pixels());
        for (i, word) in map.iter_mut().enumerate() {
            let lo = u64::from(gpu.get(2 * i).copied().unwrap_or(0));
            let hi = u64::from(gpu.get(2 * i + 1).copied().unwrap_or(0));
            *word |= lo | (hi << 32);
        }
        Ok(map)
    }
}

impl Stepper for ExactGpuStepper<'_> {
    fn empty(&self) -> u64 {
        match &self.cpu {
            Some(cpu) => cpu.empty(),
            None => u64::from(self.config.empty),
        }
    }

    fn darts_for(&self, plan: &Plan, empty: u64) -> u32 {
        u64::from(plan.batch).min(empty).min(u64::from(MAX_BATCH)) as u32
    }

    fn step(&mut self, iteration: u32, darts: u32) -> Result<Step> {
        if let Some(cpu) = &mut self.cpu {
            return cpu.step(iteration, darts);
        }
        let t0 = Instant::now();
        let base = self.samples.len() as u32;
        self.res.reserve(
            self.device,
            self.queue,
            self.kernels.exact,
            base.saturating_add(darts),
            base,
        )?;
        self.config.iteration_key = iteration_key(self.plan.seed_key, iteration);
        self.config.darts = darts;
        let mut ex = self.res.ex;
        ex.base = base;
        let (res, stage, compact) = (&*self.res, self.kernels.exact, self.kernels.compact);
        self.queue
            .write_buffer(&res.config, 0, bytemuck::bytes_of(&self.config));
        self.queue
            .write_buffer(&res.ex_buffer, 0, bytemuck::bytes_of(&ex));
        res.dart_scan.set_len(self.queue, darts + 1, 0);
        // Throw, then settle the batch's order.
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(
            &res.grid,
            4 * u64::from(ex.cells),
            Some(4 * u64::from(ex.cells)),
        );
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            stage.dispatch(&mut pass, &res.group, &stage.throw, darts);
        }
        self.resolve(encoder, darts)?;
        let t1 = Instant::now();
        // Gather the accepted darts, cover, count the empty pixels.
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            res.dart_scan.encode_scan(&mut pass, compact, darts + 1);
            stage.dispatch(&mut pass, &res.group, &stage.gather, darts);
            self.kernels.cover.encode_exact(
                &mut pass,
                &res.cover_group,
                darts,
                self.plan.radius_range.1,
            );
            res.word_scan
                .encode_count(&mut pass, compact, self.config.words);
            res.word_scan
                .encode_scan(&mut pass, compact, self.config.words);
        }
        encoder.copy_buffer_to_buffer(res.word_scan.total(), 0, &res.staging, 0, 4);
        encoder.copy_buffer_to_buffer(
            &res.dart_scan.levels[0],
            4 * u64::from(darts),
            &res.staging,
            4,
            4,
        );
        encoder.copy_buffer_to_buffer(
            &res.survivors,
            0,
            &res.staging,
            16,
            u64::from(darts) * DART_BYTES,
        );
        let view = self.finish(encoder, 16 + u64::from(darts) * DART_BYTES)?;
        let head: Vec<u32> = bytemuck::pod_collect_to_vec(&view[..8]);
        let (empty, count) = (head[0], head[1].min(darts));
        let survivors: Vec<Dart> =
            bytemuck::pod_collect_to_vec(&view[16..16 + count as usize * DART_BYTES as usize]);
        let one = (1u32 << ex.frac) as f32;
        let accepted: Vec<Point> = survivors
            .iter()
            .map(|d| Point {
                x: d.x as f32 / one,
                y: d.y as f32 / one,
                radius: fixed::fx_to_radius(self.plan.radius_at(d.pixel)),
            })
            .collect();
        self.samples
            .extend(survivors.iter().map(|d| (d.x, d.y, d.pixel)));
        self.config.empty = empty;
        self.config.first = 0;
        let t2 = Instant::now();
        let mut stages = StageTimes::default();
        stages.add("cull", (t1 - t0).as_secs_f64());
        stages.add("compact", (t2 - t1).as_secs_f64());
        let mut left = u64::from(empty);
        let mut finished = false;
        if (count as usize) * REFINE_BELOW < darts as usize {
            let coverage = self.coverage()?;
            let samples = std::mem::take(&mut self.samples);
            let cpu = ExactStepper::resume(self.plan, &samples, coverage, true);
            left = cpu.empty();
            finished = left == 0;
            self.cpu = Some(cpu);
            stages.add("refine", t2.elapsed().as_secs_f64());
        }
        Ok(Step {
            empty: left,
            accepted,
            stages,
            finished,
            removed: Vec::new(),
        })
    }

    fn bytes(&self) -> usize {
        let gpu = usize::try_from(self.res.bytes()).unwrap_or(usize::MAX);
        gpu + self.cpu.as_ref().map_or(0, Stepper::bytes)
    }
}
