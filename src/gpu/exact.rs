//! Exact mode on wgpu: the iterations of [`crate::sampler::exact`] as
//! compute passes, bit-identical to the CPU's, down to the finest level,
//! where the CPU takes over. Shader: `shaders/exact.wgsl` (and `cover_exact`
//! in `shaders/cover.wgsl`).
//!
//! | exact mode's semantics | here |
//! |---|---|
//! | darts, F − L-bit offsets in the active pixels or cells | `exact_throw` |
//! | acceptance against the accepted samples | `exact_throw`, over the sample grid |
//! | acceptance in dart order within the batch | `exact_resolve` rounds over the dart grid, `exact_flags` |
//! | the accepted darts, in order, join the set | the scan of `compact.wgsl`, `exact_gather` |
//! | level 0: coverage of pixels by the corner rule | `cover_exact`, then the empty-pixel scan |
//! | levels 1 and on: the active cells no new sample holds stay | `exact_keep`, the scan, `exact_pack` |
//! | refinement: four children each, those one sample holds dropped | `exact_split`, the scan, `exact_emit` |
//! | the finest level (union of disks, in `f64`), repair | on the CPU |
//!
//! The handover: when a refinement reaches the finest level F, the samples
//! (read back in order every iteration), the coverage bitmap and the active
//! cells go to [`ExactStepper::resume`], which sets aside the cells whose one
//! position is covered (a test in `f64`, which WGSL lacks), repairs voids,
//! and runs every later iteration. By then nearly every sample is placed
//! and the cells left are few.

use std::time::Instant;

use super::compact::{CompactStage, ScanChain};
use super::cover::CoverStage;
use super::resources::RadiusTexture;
use super::{Config, util};
use crate::sampler::exact::rules::{self, Handover, Placed};
use crate::sampler::exact::{ExactStepper, frac_bits};
use crate::sampler::fixed::{RADIUS_ONE, iteration_key};
use crate::sampler::run::{StageTimes, Step, Stepper};
use crate::sampler::{Dart, Plan, Point, Result};

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
    level: u32,
    live: u32,
    pad0: u32,
    pad1: u32,
}

impl ExactConfig {
    fn new(plan: &Plan, cap: u32) -> Self {
        let frac = frac_bits(plan.width, plan.height);
        let g = plan.radius_range.1.div_ceil(RADIUS_ONE) + 1;
        let cols = plan.width.div_ceil(g);
        let (period_x, period_y) = rules::periods(plan, frac);
        Self {
            frac,
            g,
            cols,
            cells: cols * plan.height.div_ceil(g),
            cap,
            base: 0,
            period_x,
            period_y,
            level: 0,
            live: 0,
            pad0: 0,
            pad1: 0,
        }
    }

    /// Words of the grid buffer: two heads per cell, a state and a link per
    /// dart, the undecided count.
    fn grid_words(&self) -> u64 {
        2 * u64::from(self.cells) + 2 * u64::from(self.cap) + 1
    }
}

/// Storage buffers that the kernels of `exact.wgsl` bind: above wgpu's
/// default limit (8), within every desktop adapter's own; [`super::GpuContext`]
/// and the app open their devices with the adapter's limits.
pub const STORAGE_BUFFERS: u32 = 10;

/// The kernels of `exact.wgsl`.
pub struct ExactStage {
    layout: wgpu::BindGroupLayout,
    throw: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    flags: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
    keep: wgpu::ComputePipeline,
    pack: wgpu::ComputePipeline,
    split: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
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
                util::storage(10, c, true),
                util::storage(11, c, false),
                util::storage(12, c, false),
            ],
        );
        let pl = util::pipeline_layout(device, &layout);
        let module = util::module(device, "exact.wgsl", util::SHADERS[6].1);
        Self {
            throw: util::compute(device, &pl, &module, "exact_throw"),
            resolve: util::compute(device, &pl, &module, "exact_resolve"),
            flags: util::compute(device, &pl, &module, "exact_flags"),
            gather: util::compute(device, &pl, &module, "exact_gather"),
            keep: util::compute(device, &pl, &module, "exact_keep"),
            pack: util::compute(device, &pl, &module, "exact_pack"),
            split: util::compute(device, &pl, &module, "exact_split"),
            emit: util::compute(device, &pl, &module, "exact_emit"),
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
    /// The cells below the pixel, read from one and written to the other.
    cells: [wgpu::Buffer; 2],
    /// Cells each of `cells` holds.
    cell_caps: [u32; 2],
    /// The cells' flags and their scan.
    cell_scan: ScanChain,
    staging: wgpu::Buffer,
    /// Bind group `i` reads the cells from `cells[i]`.
    groups: Vec<wgpu::BindGroup>,
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
            return Err(super::error::unusable(format!(
                "the batch of {cap} darts exceeds the adapter's storage binding size"
            )));
        }
        if 4 * ex.grid_words() > max {
            return Err(super::error::unusable(format!(
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
        let cells = [Self::cell_buffer(device, 2), Self::cell_buffer(device, 2)];
        let cell_scan = ScanChain::new(device, compact, "cell scan", 3, None);
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
            cells,
            cell_caps: [2; 2],
            cell_scan,
            staging,
            groups: Vec::new(),
            cover_group,
        }
        .rebound(device, stage))
    }

    fn cell_buffer(device: &wgpu::Device, cap: u32) -> wgpu::Buffer {
        use wgpu::BufferUsages as B;
        util::buffer_of(
            device,
            "exact cells",
            8 * u64::from(cap),
            B::STORAGE | B::COPY_SRC | B::COPY_DST,
        )
    }

    /// These resources with their bind groups built anew.
    fn rebound(mut self, device: &wgpu::Device, stage: &ExactStage) -> Self {
        self.rebind(device, stage);
        self
    }

    /// Builds the two bind groups from the current buffers.
    fn rebind(&mut self, device: &wgpu::Device, stage: &ExactStage) {
        let group = |i: usize| {
            util::bind_group(
                device,
                &stage.layout,
                &[
                    self.config.as_entire_binding(),
                    self.darts.as_entire_binding(),
                    self.coverage.as_entire_binding(),
                    self.word_scan.levels[0].as_entire_binding(),
                    wgpu::BindingResource::TextureView(&self.radius.view),
                    self.ex_buffer.as_entire_binding(),
                    self.samples.as_entire_binding(),
                    self.grid.as_entire_binding(),
                    self.dart_scan.levels[0].as_entire_binding(),
                    self.survivors.as_entire_binding(),
                    self.cells[i].as_entire_binding(),
                    self.cells[1 - i].as_entire_binding(),
                    self.cell_scan.levels[0].as_entire_binding(),
                ],
            )
        };
        self.groups = vec![group(0), group(1)];
    }

    /// Makes `cells[out]`, the buffer a pass writes, hold `n` cells, and the
    /// cell scan `scan` flags. Neither keeps its contents: the cells a pass
    /// reads are in the other buffer, and the scan is filled anew.
    fn reserve_cells(
        &mut self,
        device: &wgpu::Device,
        kernels: Kernels<'_>,
        (out, n, scan): (usize, u32, u32),
    ) -> Result<()> {
        let max = device.limits().max_storage_buffer_binding_size / 8;
        if u64::from(n.max(scan)) > max {
            return Err(super::error::unusable(format!(
                "{} cells exceed the adapter's storage binding size",
                n.max(scan)
            )));
        }
        let mut changed = false;
        if n > self.cell_caps[out] {
            let cap = (u64::from(n).max(2 * u64::from(self.cell_caps[out]))).min(max) as u32;
            self.cells[out] = Self::cell_buffer(device, cap);
            self.cell_caps[out] = cap;
            changed = true;
        }
        if scan > self.cell_scan.capacity() {
            let cap = (u64::from(scan).max(2 * u64::from(self.cell_scan.capacity()))).min(max);
            self.cell_scan = ScanChain::new(device, kernels.compact, "cell scan", cap as u32, None);
            changed = true;
        }
        if changed {
            self.rebind(device, kernels.exact);
        }
        Ok(())
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
            &self.cells[0],
            &self.cells[1],
        ]
        .iter()
        .map(|b| b.size())
        .sum::<u64>()
            + self.word_scan.bytes()
            + self.dart_scan.bytes()
            + self.cell_scan.bytes()
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
            return Err(super::error::unusable(format!(
                "{n} samples exceed the adapter's storage binding size"
            )));
        }
        let cap = (u64::from(n).max(2 * u64::from(self.sample_cap))).min(max) as u32;
        let samples = Self::sample_buffer(device, cap);
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.samples, 0, &samples, 0, u64::from(kept) * DART_BYTES);
        queue.submit([encoder.finish()]);
        self.samples = samples;
        self.sample_cap = cap;
        self.rebind(device, stage);
        Ok(())
    }
}

/// An exact run between iterations: the GPU's state (the level, its pixels
/// or cells, the samples), and the CPU's run once the finest level is
/// reached.
pub struct ExactGpuStepper<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    kernels: Kernels<'a>,
    res: &'a mut ExactResources,
    plan: &'a Plan,
    config: Config,
    /// The level, its active cells and the samples before this iteration.
    ex: ExactConfig,
    /// Which of `res.cells` holds the active cells.
    cells_in: usize,
    /// The accepted samples in order.
    samples: Vec<Placed>,
    /// The CPU's run, from the finest level on.
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
        let ex = res.ex;
        Self {
            device,
            queue,
            kernels,
            res,
            plan,
            config: Config::new(plan),
            ex,
            cells_in: 0,
            samples: Vec::new(),
            cpu: None,
        }
    }

    /// The bind group that reads the active cells.
    fn group(&self) -> &wgpu::BindGroup {
        &self.res.groups[self.cells_in]
    }

    /// Uploads the configurations.
    fn upload(&self) {
        self.queue
            .write_buffer(&self.res.config, 0, bytemuck::bytes_of(&self.config));
        self.queue
            .write_buffer(&self.res.ex_buffer, 0, bytemuck::bytes_of(&self.ex));
    }

    /// Active pixels (level 0) or cells.
    fn active(&self) -> u32 {
        if self.ex.level == 0 {
            self.config.empty
        } else {
            self.ex.live
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
                    stage.dispatch(&mut pass, self.group(), &stage.resolve, darts);
                }
                stage.dispatch(&mut pass, self.group(), &stage.flags, darts + 1);
            }
            encoder.copy_buffer_to_buffer(&res.grid, count_at, &res.staging, 0, 4);
            let left = self.finish(encoder, 4)?;
            if bytemuck::pod_read_unaligned::<u32>(&left[..4]) == 0 {
                return Ok(());
            }
            encoder = self.device.create_command_encoder(&Default::default());
        }
        Err(super::error::unusable(
            "the batch's acceptance order did not settle on the GPU",
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
        let mut map = crate::sampler::coverage::new_map(self.plan.pixels());
        for (i, word) in map.iter_mut().enumerate() {
            let lo = u64::from(gpu.get(2 * i).copied().unwrap_or(0));
            let hi = u64::from(gpu.get(2 * i + 1).copied().unwrap_or(0));
            *word |= lo | (hi << 32);
        }
        Ok(map)
    }

    /// Refines the active cells (the empty pixels at level 0) on the GPU:
    /// the level goes one down.
    fn refine(&mut self) -> Result<()> {
        let parents = self.active();
        self.res.reserve_cells(
            self.device,
            self.kernels,
            (1 - self.cells_in, parents.saturating_mul(4), parents + 1),
        )?;
        self.ex.live = parents;
        self.upload();
        let (res, stage) = (&*self.res, self.kernels.exact);
        res.cell_scan.set_len(self.queue, parents + 1, 0);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            stage.dispatch(&mut pass, self.group(), &stage.split, parents + 1);
            res.cell_scan
                .encode_scan(&mut pass, self.kernels.compact, parents + 1);
            stage.dispatch(&mut pass, self.group(), &stage.emit, parents);
        }
        encoder.copy_buffer_to_buffer(
            &res.cell_scan.levels[0],
            4 * u64::from(parents),
            &res.staging,
            0,
            4,
        );
        let count = self.finish(encoder, 4)?;
        self.ex.live = bytemuck::pod_read_unaligned(&count[..4]);
        self.ex.level += 1;
        self.cells_in = 1 - self.cells_in;
        Ok(())
    }

    /// Throws the iteration's darts and settles the batch's order;
    /// returns the pixels or cells active before it.
    fn throw(&mut self, iteration: u32, darts: u32) -> Result<u32> {
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
        self.ex.base = base;
        self.upload();
        let level = self.ex.level;
        let active = self.active();
        if level > 0 {
            // The cells that stay go to the other buffer.
            self.res.reserve_cells(
                self.device,
                self.kernels,
                (1 - self.cells_in, active, active + 1),
            )?;
        }
        let (res, stage) = (&*self.res, self.kernels.exact);
        res.dart_scan.set_len(self.queue, darts + 1, 0);
        // Throw, then settle the batch's order.
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let cells = u64::from(self.ex.cells);
        encoder.clear_buffer(&res.grid, 4 * cells, Some(4 * cells));
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            stage.dispatch(&mut pass, self.group(), &stage.throw, darts);
        }
        self.resolve(encoder, darts)?;
        Ok(active)
    }

    /// Gathers the accepted darts, covers the pixels or keeps the cells
    /// that no new sample holds, and counts what is left: returns that
    /// count, the accepted count and the accepted points.
    fn gather(&mut self, darts: u32, active: u32) -> Result<(u32, u32, Vec<Point>)> {
        let level = self.ex.level;
        let (res, stage, compact) = (&*self.res, self.kernels.exact, self.kernels.compact);
        if level > 0 {
            res.cell_scan.set_len(self.queue, active + 1, 0);
        }
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            res.dart_scan.encode_scan(&mut pass, compact, darts + 1);
            stage.dispatch(&mut pass, self.group(), &stage.gather, darts);
            if level == 0 {
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
            } else {
                stage.dispatch(&mut pass, self.group(), &stage.keep, active + 1);
                res.cell_scan.encode_scan(&mut pass, compact, active + 1);
                stage.dispatch(&mut pass, self.group(), &stage.pack, active);
            }
        }
        if level == 0 {
            encoder.copy_buffer_to_buffer(res.word_scan.total(), 0, &res.staging, 0, 4);
        } else {
            encoder.copy_buffer_to_buffer(
                &res.cell_scan.levels[0],
                4 * u64::from(active),
                &res.staging,
                0,
                4,
            );
        }
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
        let (left, count) = (head[0], head[1].min(darts));
        let survivors: Vec<Dart> =
            bytemuck::pod_collect_to_vec(&view[16..16 + count as usize * DART_BYTES as usize]);
        let placed = survivors.iter().map(|d| Placed {
            x: d.x,
            y: d.y,
            pixel: d.pixel,
        });
        let from = self.samples.len();
        self.samples.extend(placed);
        let accepted: Vec<Point> = self.samples[from..]
            .iter()
            .map(|p| p.point(self.plan, self.ex.frac))
            .collect();
        if level == 0 {
            self.config.empty = left;
            self.config.first = 0;
        } else {
            self.ex.live = left;
            self.cells_in = 1 - self.cells_in;
        }
        Ok((left, count, accepted))
    }

    /// The finest level is reached: the CPU's run takes over from the
    /// GPU's state, and finishes the iteration (`step`).
    fn hand_over(&mut self, step: &mut Step) -> Result<()> {
        let handover = Handover {
            coverage: self.coverage()?,
            cells: self.cells()?,
            samples: std::mem::take(&mut self.samples),
            level: self.ex.level,
        };
        let (cpu, removed) = ExactStepper::resume(self.plan, handover);
        step.empty = cpu.left();
        step.finished = cpu.empty() == 0;
        step.removed = removed;
        self.cpu = Some(cpu);
        Ok(())
    }

    /// The active cells, read back.
    fn cells(&self) -> Result<Vec<[u32; 2]>> {
        let n = u64::from(self.ex.live);
        if n == 0 {
            return Ok(Vec::new());
        }
        let staging = util::buffer_of(
            self.device,
            "cells read-back",
            8 * n,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.res.cells[self.cells_in], 0, &staging, 0, 8 * n);
        self.queue.submit([encoder.finish()]);
        let bytes = util::read_back(self.device, &staging, 8 * n)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

impl Stepper for ExactGpuStepper<'_> {
    fn empty(&self) -> u64 {
        match &self.cpu {
            Some(cpu) => cpu.empty(),
            None => u64::from(self.active()),
        }
    }

    fn darts_for(&self, plan: &Plan, empty: u64) -> u32 {
        rules::darts_for(plan, empty)
    }

    fn step(&mut self, iteration: u32, darts: u32) -> Result<Step> {
        if let Some(cpu) = &mut self.cpu {
            return cpu.step(iteration, darts);
        }
        let t0 = Instant::now();
        let active = self.throw(iteration, darts)?;
        let t1 = Instant::now();
        let (left, count, accepted) = self.gather(darts, active)?;
        let t2 = Instant::now();
        let mut step = Step {
            empty: u64::from(left),
            accepted,
            stages: StageTimes::default(),
            finished: false,
            removed: Vec::new(),
            held: 0,
        };
        if rules::refines(self.ex.level, self.ex.frac, count as usize, darts as usize) {
            self.refine()?;
            step.empty = u64::from(self.ex.live);
            if self.ex.level == self.ex.frac {
                self.hand_over(&mut step)?;
            }
        }
        let t3 = Instant::now();
        step.stages.add("cull", (t1 - t0).as_secs_f64());
        step.stages.add("compact", (t2 - t1).as_secs_f64());
        step.stages.add("refine", (t3 - t2).as_secs_f64());
        Ok(step)
    }

    fn bytes(&self) -> usize {
        let gpu = usize::try_from(self.res.bytes()).unwrap_or(usize::MAX);
        gpu + self.cpu.as_ref().map_or(0, Stepper::bytes)
    }
}

#[cfg(test)]
mod tests {
    use crate::gpu::util::{COMMON, rust_layout, wgsl_layout};

    #[test]
    fn the_configuration_mirrors_the_layout_naga_reads_from_the_wgsl() {
        let rust = rust_layout!(super::ExactConfig;
            frac, g, cols, cells, cap, base, period_x, period_y, level, live, pad0, pad1);
        assert_eq!(rust, wgsl_layout(COMMON, "Exact"));
    }
}
