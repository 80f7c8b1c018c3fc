//! The GPU memory of a run, allocated once per domain and reused: darts,
//! survivors, the depth map, the coverage bitmap, the scans, the radius map,
//! the accepted samples held on the GPU and the read-back buffer; and the
//! encoding of one iteration.

use std::time::Instant;

use super::Config;
use super::compact::{CompactStage, ScanChain};
use super::cover::CoverStage;
use super::cull::CullStage;
use super::throw::{ThrowGroups, ThrowStage};
use super::util::{self, Bindings};
use crate::sampler::Dart;
use crate::sampler::{Plan, Point, Policy, Result};

/// Bytes of the read-back header: empty count, survivor count, padding and
/// six timestamps.
const HEADER: u64 = 64;
const DART_BYTES: u64 = std::mem::size_of::<Dart>() as u64;

/// Rows per strip of the key buffer for `path`: every row for the raster
/// path (no key buffer) and wherever the whole buffer fits one storage
/// binding; otherwise as many rows as fit, and never more than `cap`. 0 when
/// not even one row fits.
fn strip_rows(device: &wgpu::Device, plan: &Plan, path: S1Path, cap: Option<u32>) -> u32 {
    if !path.splats() {
        return plan.height;
    }
    let max_binding = device.limits().max_storage_buffer_binding_size;
    (max_binding / (4 * u64::from(plan.width)))
        .min(u64::from(plan.slot_rows()))
        .min(u64::from(cap.unwrap_or(u32::MAX))) as u32
}

/// The names of the stages whose seconds [`Iteration::seconds`] holds.
pub const STAGES: [&str; 3] = ["throw", "cull", "compact"];
/// Timestamp queries: the start and end of each stage's passes.
const QUERIES: u32 = 2 * STAGES.len() as u32;
/// Where the resolved timestamps land in the read-back, after the counts.
const TIMESTAMPS_AT: u64 = 16;
const _: () = assert!(TIMESTAMPS_AT + 8 * QUERIES as u64 <= HEADER);

/// The first timestamp query of stage `name`: its passes write the stage's
/// start there and its end at the next index.
const fn stage_index(name: &str) -> u32 {
    let mut i = 0;
    while i < STAGES.len() {
        if str_eq(STAGES[i], name) {
            return 2 * i as u32;
        }
        i += 1;
    }
    panic!("no such stage")
}

const fn str_eq(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// What one iteration returns. Its survivors stay on the GPU, appended to
/// the held samples ([`Resources::take_held`] reads them back).
pub struct Iteration {
    /// Empty pixels after the iteration.
    pub empty: u32,
    /// Survivors (darts accepted) in this iteration.
    pub accepted: u32,
    /// Seconds of S1, S2 and PP.
    pub seconds: [f64; 3],
}

/// Accepted samples the GPU holds between read-backs: four full batches,
/// and never more than a sixteenth of the slots (64K at least; the held
/// samples and their read-back then take at most 2 bytes a slot), than the
/// slots (one sample per slot at most) or than a buffer of the adapter's
/// (`max_bytes`) holds. Where that is less than two batches, one: each
/// iteration's survivors are read back from where the gather put them, with
/// no buffer of held samples. A run of the paper's batch (N/2) on a disk of
/// a few pixels is read back once, at its end.
fn held_capacity(capacity: u32, slots: u32, max_bytes: u64) -> u32 {
    let fits = u32::try_from(max_bytes.saturating_sub(HEADER) / DART_BYTES).unwrap_or(u32::MAX);
    let room = capacity
        .saturating_mul(4)
        .min((slots / 16).max(1 << 16))
        .min(slots)
        .min(fits);
    if room < capacity.saturating_mul(2) {
        capacity
    } else {
        room
    }
}

/// How dart throwing (S1) rasterizes the disks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum S1Path {
    /// An instanced depth-only draw into a Depth32Float target (the paper's way).
    Raster,
    /// A compute pass with atomicMax into a key buffer (`splat.wgsl`), a
    /// thread per row of a disk.
    Compute,
    /// The compute pass with the lanes of a warp along one disk's rows, so
    /// that neighbouring threads write neighbouring keys.
    Coalesced,
}

impl S1Path {
    /// Every path, in the order `auto` measures them.
    pub const ALL: [Self; 3] = [Self::Raster, Self::Compute, Self::Coalesced];

    /// Whether the path rasterizes into the key buffer (a compute pass).
    #[must_use]
    pub const fn splats(self) -> bool {
        !matches!(self, Self::Raster)
    }
}

/// The pixel pass's four stages, as the resources bind and encode them.
#[derive(Clone, Copy)]
pub struct Stages<'a> {
    /// S1.
    pub throw: &'a ThrowStage,
    /// S2, conflict removal.
    pub cull: &'a CullStage,
    /// S2, coverage.
    pub cover: &'a CoverStage,
    /// PP.
    pub compact: &'a CompactStage,
}

/// What a run's resources are sized for, besides the plan.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// Darts per batch, at most.
    pub capacity: u32,
    /// Whether the stages are timed by timestamp queries.
    pub timestamps: bool,
    /// How S1 rasterizes.
    pub path: S1Path,
    /// A cap on the rows per strip of the compute path's key buffer (tests).
    pub strip_cap: Option<u32>,
}

/// S1's target: the compute path's key buffer (one strip of `strip_rows`
/// rows) or the raster path's depth map, and a stand-in for the other.
fn s1_target(
    device: &wgpu::Device,
    plan: &Plan,
    path: S1Path,
    strip_rows: u32,
) -> (wgpu::Buffer, wgpu::TextureView) {
    let splat = path.splats();
    let keys = util::buffer_of(
        device,
        "splat keys",
        if splat {
            4 * u64::from(plan.width) * u64::from(strip_rows)
        } else {
            16
        },
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    );
    let (w, h) = if splat {
        (1, 1)
    } else {
        (plan.width, plan.height)
    };
    let depth = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("depth"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    (keys, depth.create_view(&Default::default()))
}

/// The stage timestamps' query set and the buffer they resolve into.
fn timestamp_queries(device: &wgpu::Device) -> (wgpu::QuerySet, wgpu::Buffer) {
    let set = device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("stage timestamps"),
        ty: wgpu::QueryType::Timestamp,
        count: QUERIES,
    });
    let resolve = util::buffer_of(
        device,
        "timestamps",
        8 * u64::from(QUERIES),
        wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
    );
    (set, resolve)
}

/// Refuses a run whose key rows, darts or coverage words exceed the
/// adapter's largest storage binding.
fn check_limits(
    device: &wgpu::Device,
    width: u32,
    strip_rows: u32,
    dart_bytes: u64,
    words: u32,
    capacity: u32,
) -> Result<()> {
    let max_binding = device.limits().max_storage_buffer_binding_size;
    if strip_rows == 0 {
        return Err(super::error::unusable(format!(
            "a {width}-pixel row of keys exceeds the adapter's storage binding size"
        )));
    }
    if dart_bytes > max_binding || 4 * u64::from(words) > max_binding {
        return Err(super::error::unusable(format!(
            "the batch of {capacity} darts exceeds the adapter's storage binding size"
        )));
    }
    Ok(())
}

/// Buffers, textures and bind groups of one domain size.
pub struct Resources {
    width: u32,
    /// Rows of the stacked slot domain (the height without classes).
    height: u32,
    classes: u32,
    capacity: u32,
    path: S1Path,
    /// Rows per strip of the key buffer (compute path; the height if whole).
    strip_rows: u32,
    keys: wgpu::Buffer,
    /// The run's configuration (uniform).
    pub config: wgpu::Buffer,
    survivors: wgpu::Buffer,
    /// Accepted samples not yet read back, in acceptance order.
    /// `None` where the room is one batch: the survivors themselves.
    held: Option<wgpu::Buffer>,
    /// Room for held samples.
    held_capacity: u32,
    /// The coverage bitmap, one bit per pixel.
    pub coverage: wgpu::Buffer,
    words: u32,
    word_scan: ScanChain,
    /// The scan of the survivor flags.
    pub dart_scan: ScanChain,
    depth: wgpu::TextureView,
    /// The radius map.
    pub radius: RadiusTexture,
    staging: wgpu::Buffer,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    throw_groups: ThrowGroups,
    cull_group: wgpu::BindGroup,
    cover_group: wgpu::BindGroup,
    bytes: u64,
}

impl Resources {
    /// Allocates everything a `plan` of `shape` needs. The compute path's
    /// key buffer is cut into strips of rows when the whole would exceed the
    /// adapter's largest storage binding, or when `shape.strip_cap` (rows;
    /// for tests) asks for it.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stages: Stages<'_>,
        plan: &Plan,
        shape: Shape,
    ) -> Result<Self> {
        let Shape {
            capacity,
            timestamps,
            path,
            strip_cap,
        } = shape;
        use wgpu::BufferUsages as B;
        let (width, height) = (plan.width, plan.slot_rows());
        let words = plan.slots().div_ceil(32);
        let dart_bytes = u64::from(capacity) * DART_BYTES;
        let strip_rows = strip_rows(device, plan, path, strip_cap);
        check_limits(device, width, strip_rows, dart_bytes, words, capacity)?;
        let config = util::buffer_of(
            device,
            "config",
            std::mem::size_of::<super::Config>() as u64,
            B::UNIFORM | B::COPY_DST,
        );
        let darts = util::buffer_of(device, "darts", dart_bytes, B::STORAGE);
        let survivors = util::buffer_of(device, "survivors", dart_bytes, B::STORAGE | B::COPY_SRC);
        let held_capacity = held_capacity(capacity, plan.slots(), device.limits().max_buffer_size);
        let held_bytes = u64::from(held_capacity) * DART_BYTES;
        let held = (held_capacity > capacity).then(|| {
            util::buffer_of(
                device,
                "held samples",
                held_bytes,
                B::COPY_DST | B::COPY_SRC,
            )
        });
        let coverage = util::buffer_of(
            device,
            "coverage",
            4 * u64::from(words),
            B::STORAGE | B::COPY_DST,
        );
        let word_scan = ScanChain::new(device, stages.compact, "word scan", words, Some(&coverage));
        word_scan.set_len(queue, words, plan.slots());
        // One more flag than darts: the 0 that ends them (see cull.wgsl).
        let dart_scan = ScanChain::new(device, stages.compact, "dart scan", capacity + 1, None);
        let splat = path.splats();
        let (keys, depth) = s1_target(device, plan, path, strip_rows);
        let radius = RadiusTexture::new(device, plan);
        let staging = util::buffer_of(
            device,
            "read-back",
            HEADER + held_bytes,
            B::MAP_READ | B::COPY_DST,
        );
        let queries = timestamps.then(|| timestamp_queries(device));
        let bindings = Bindings {
            config: &config,
            darts: &darts,
            survivors: &survivors,
            coverage: &coverage,
            empty_scan: &word_scan.levels[0],
            dart_flags: &dart_scan.levels[0],
            survivor_count: dart_scan.total(),
            keys: &keys,
            depth: &depth,
            radius: &radius.view,
            near: &radius.near,
        };
        let throw_groups = stages.throw.bind(device, &bindings);
        let cull_group = stages.cull.bind(device, &bindings);
        let cover_group = stages.cover.bind(device, &bindings);
        let s1_bytes = if splat {
            keys.size()
        } else {
            4 * u64::from(width) * u64::from(height)
        };
        let bytes = s1_bytes
            + radius.bytes(plan)
            + radius.near.size()
            + 2 * dart_bytes
            + held.as_ref().map_or(0, wgpu::Buffer::size)
            + HEADER
            + held_bytes
            + coverage.size()
            + word_scan.bytes()
            + dart_scan.bytes();
        Ok(Self {
            width,
            height,
            classes: plan.classes(),
            capacity,
            path,
            strip_rows,
            keys,
            config,
            survivors,
            held,
            held_capacity,
            coverage,
            words,
            word_scan,
            dart_scan,
            depth,
            radius,
            staging,
            queries,
            throw_groups,
            cull_group,
            cover_group,
            bytes,
        })
    }

    /// Whether these resources serve `plan` of `shape`.
    pub fn fits(&self, device: &wgpu::Device, plan: &Plan, shape: Shape) -> bool {
        (self.width, self.height, self.path) == (plan.width, plan.slot_rows(), shape.path)
            && self.classes == plan.classes()
            && self.radius.fits(plan)
            && shape.capacity <= self.capacity
            && self.queries.is_some() == shape.timestamps
            && self.strip_rows == strip_rows(device, plan, shape.path, shape.strip_cap)
    }

    /// Device memory held, in bytes.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Darts per batch, at most.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Room for accepted samples on the GPU between read-backs.
    pub fn held_capacity(&self) -> u32 {
        self.held_capacity
    }

    /// The timestamp writes of a pass that is all of the stage whose first
    /// query is `first` ([`stage_index`]).
    fn pass_writes(&self, first: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.queries
            .as_ref()
            .map(|(set, _)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(first),
                end_of_pass_write_index: Some(first + 1),
            })
    }

    /// Encodes and runs one iteration of `config.darts` darts, appends its
    /// survivors to the `held` samples the GPU already holds, and reads back
    /// its counts and times. Without timestamp queries each stage is
    /// submitted and timed on its own.
    pub fn iterate(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stages: Stages<'_>,
        plan: &Plan,
        config: Config,
        held: u32,
    ) -> Result<Iteration> {
        let darts = config.darts;
        if u64::from(held) + u64::from(darts) > u64::from(self.held_capacity) {
            return Err(super::error::unusable(format!(
                "{held} held samples and {darts} darts exceed the room for {}",
                self.held_capacity
            )));
        }
        let mut laps = Laps::new(device, queue, self.queries.is_none());
        let mut encoder = device.create_command_encoder(&Default::default());
        let strips = self.encode_s1(device, queue, &mut encoder, stages, plan, config);
        laps.lap(&mut encoder, 0);
        // S2: cull by depth, gather the survivors, cover their disks.
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("S2 cull"),
                timestamp_writes: self.pass_writes(const { stage_index("cull") }),
            });
            if strips == 1 {
                stages.cull.encode_cull(&mut pass, &self.cull_group, darts);
            }
            self.dart_scan
                .encode_scan(&mut pass, stages.compact, darts + 1);
            stages
                .cull
                .encode_gather(&mut pass, &self.cull_group, darts);
            stages.cover.encode(
                &mut pass,
                &self.cover_group,
                darts,
                plan.radius_range.1,
                self.classes,
            );
        }
        laps.lap(&mut encoder, 1);
        // PP: count and scan the empty pixels.
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("PP compact"),
                timestamp_writes: self.pass_writes(const { stage_index("compact") }),
            });
            self.word_scan
                .encode_count(&mut pass, stages.compact, self.words);
            self.word_scan
                .encode_scan(&mut pass, stages.compact, self.words);
        }
        laps.lap(&mut encoder, 2);
        let seconds = laps.seconds;
        // The whole batch's room: what lies past this iteration's survivors
        // is overwritten by the next iteration's or never read. Without a
        // buffer of held samples they stay where they are (`held` is 0).
        if let Some(buffer) = &self.held {
            encoder.copy_buffer_to_buffer(
                &self.survivors,
                0,
                buffer,
                u64::from(held) * DART_BYTES,
                u64::from(darts) * DART_BYTES,
            );
        }
        self.read_iteration(device, queue, encoder, darts, seconds)
    }

    /// Reads back the first `count` held samples, as points, in acceptance
    /// order; the GPU's room for them is free again afterwards.
    pub fn take_held(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        plan: &Plan,
        count: u32,
    ) -> Result<Vec<Point>> {
        if count == 0 {
            return Ok(Vec::new());
        }
        let bytes = u64::from(count.min(self.held_capacity)) * DART_BYTES;
        let mut encoder = device.create_command_encoder(&Default::default());
        let from = self.held.as_ref().unwrap_or(&self.survivors);
        encoder.copy_buffer_to_buffer(from, 0, &self.staging, HEADER, bytes);
        queue.submit([encoder.finish()]);
        util::read_back_with(device, &self.staging, HEADER..HEADER + bytes, |view| {
            let points = |darts: &[Dart]| darts.iter().map(|d| plan.point(d)).collect();
            match bytemuck::try_cast_slice::<u8, Dart>(view) {
                Ok(darts) => points(darts),
                Err(_) => points(&bytemuck::pod_collect_to_vec::<u8, Dart>(view)),
            }
        })
    }

    /// Encodes S1: the darts made, then rasterized into the depth map (a
    /// depth-tested draw) or splatted into the key buffer (a compute pass,
    /// one strip of rows per submission when the buffer is chunked, each
    /// strip culled while its keys are there). Returns the strips.
    fn encode_s1(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        stages: Stages<'_>,
        plan: &Plan,
        mut config: Config,
    ) -> u32 {
        let darts = config.darts;
        config.strip_y0 = 0;
        config.strip_rows = self.strip_rows;
        queue.write_buffer(&self.config, 0, bytemuck::bytes_of(&config));
        let strips = self.height.div_ceil(self.strip_rows);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("S1 throw"),
                timestamp_writes: self.queries.as_ref().map(|(set, _)| {
                    wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: None,
                    }
                }),
            });
            stages
                .throw
                .encode_throw(&mut pass, &self.throw_groups.throw, darts);
        }
        match self.path {
            S1Path::Raster => stages.throw.encode_raster(
                encoder,
                &self.throw_groups.raster,
                &self.depth,
                darts,
                plan,
                self.queries
                    .as_ref()
                    .map(|(set, _)| wgpu::RenderPassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: None,
                        end_of_pass_write_index: Some(1),
                    }),
            ),
            S1Path::Compute | S1Path::Coalesced => {
                for strip in 0..strips {
                    if strip > 0 {
                        let done = std::mem::replace(
                            encoder,
                            device.create_command_encoder(&Default::default()),
                        );
                        queue.submit([done.finish()]);
                        config.strip_y0 = strip * self.strip_rows;
                        config.strip_rows = self.strip_rows.min(self.height - config.strip_y0);
                        queue.write_buffer(&self.config, 0, bytemuck::bytes_of(&config));
                    }
                    encoder.clear_buffer(&self.keys, 0, None);
                    let last = strip + 1 == strips;
                    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("S1 splat"),
                        timestamp_writes: self.queries.as_ref().filter(|_| last).map(|(set, _)| {
                            wgpu::ComputePassTimestampWrites {
                                query_set: set,
                                beginning_of_pass_write_index: None,
                                end_of_pass_write_index: Some(1),
                            }
                        }),
                    });
                    stages.throw.encode_splat(
                        &mut pass,
                        &self.throw_groups.splat,
                        darts,
                        plan.radius_range.1,
                        self.classes,
                        self.path == S1Path::Coalesced,
                    );
                    if strips > 1 {
                        stages.cull.encode_cull(&mut pass, &self.cull_group, darts);
                    }
                }
            }
        }
        strips
    }

    /// Marks the slots of classes with no radius at their pixel as covered
    /// and scans the empty list they leave; returns its length.
    pub fn cover_holes(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stages: Stages<'_>,
        plan: &Plan,
    ) -> Result<u32> {
        let Some(map) = &plan.map else {
            return Ok(plan.slots());
        };
        let mut words = vec![0u32; self.words as usize];
        for (s, _) in map.radii_fx().iter().enumerate().filter(|(_, r)| **r == 0) {
            words[s / 32] |= 1 << (s % 32);
        }
        queue.write_buffer(&self.coverage, 0, bytemuck::cast_slice(&words));
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            self.word_scan
                .encode_count(&mut pass, stages.compact, self.words);
            self.word_scan
                .encode_scan(&mut pass, stages.compact, self.words);
        }
        encoder.copy_buffer_to_buffer(self.word_scan.total(), 0, &self.staging, 0, 4);
        queue.submit([encoder.finish()]);
        let view = util::read_back(device, &self.staging, 4)?;
        let empty: Vec<u32> = bytemuck::pod_collect_to_vec(&view[..4]);
        Ok(empty[0])
    }

    /// Copies the counts and the timestamps to the read-back buffer, submits
    /// `encoder` and reads them back; with timestamps, they replace the
    /// wall-clock `seconds`.
    fn read_iteration(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mut encoder: wgpu::CommandEncoder,
        darts: u32,
        mut seconds: [f64; 3],
    ) -> Result<Iteration> {
        encoder.copy_buffer_to_buffer(self.word_scan.total(), 0, &self.staging, 0, 4);
        encoder.copy_buffer_to_buffer(self.dart_scan.total(), 0, &self.staging, 4, 4);
        if let Some((set, resolve)) = &self.queries {
            encoder.resolve_query_set(set, 0..QUERIES, resolve, 0);
            encoder.copy_buffer_to_buffer(
                resolve,
                0,
                &self.staging,
                TIMESTAMPS_AT,
                8 * u64::from(QUERIES),
            );
        }
        queue.submit([encoder.finish()]);

        let view = util::read_back(device, &self.staging, HEADER)?;
        let header: Vec<u32> = bytemuck::pod_collect_to_vec(&view[..HEADER as usize]);
        let (empty, count) = (header[0], header[1].min(darts));
        if self.queries.is_some() {
            // Each stage runs from its first pass's start to the next
            // stage's start (PP: to its end), so no gap goes uncounted.
            let at = TIMESTAMPS_AT as usize;
            let ts: Vec<u64> = bytemuck::pod_collect_to_vec(&view[at..at + 8 * QUERIES as usize]);
            let period = f64::from(queue.get_timestamp_period()) * 1e-9;
            for (i, s) in seconds.iter_mut().enumerate() {
                let (a, b) = (
                    2 * i,
                    if i + 1 < STAGES.len() {
                        2 * i + 2
                    } else {
                        2 * i + 1
                    },
                );
                *s = ts[b].saturating_sub(ts[a]) as f64 * period;
            }
        }
        Ok(Iteration {
            empty,
            accepted: count,
            seconds,
        })
    }
}

/// Wall-clock stage times where there are no timestamp queries: each stage
/// is submitted and waited for on its own.
struct Laps<'d> {
    device: &'d wgpu::Device,
    queue: &'d wgpu::Queue,
    /// Time by submission (no timestamp queries).
    wall_clock: bool,
    clock: Instant,
    seconds: [f64; 3],
}

impl<'d> Laps<'d> {
    fn new(device: &'d wgpu::Device, queue: &'d wgpu::Queue, wall_clock: bool) -> Self {
        Self {
            device,
            queue,
            wall_clock,
            clock: Instant::now(),
            seconds: [0.0; 3],
        }
    }

    /// Ends `stage`: submits what `encoder` holds, waits, and times it.
    fn lap(&mut self, encoder: &mut wgpu::CommandEncoder, stage: usize) {
        if !self.wall_clock {
            return;
        }
        let fresh = self.device.create_command_encoder(&Default::default());
        let done = std::mem::replace(encoder, fresh);
        self.queue.submit([done.finish()]);
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        let now = Instant::now();
        self.seconds[stage] = (now - self.clock).as_secs_f64();
        self.clock = now;
    }
}

/// The radius map as a texture, in 1/64 px: 16-bit radii when they fit
/// (below 1024 px), so that the map costs 2 bytes per pixel; 1×1 without a
/// map. With classes, their maps stacked row-wise, then the cross-class
/// radii's rows.
pub struct RadiusTexture {
    texture: wgpu::Texture,
    /// Its view, for bind groups.
    pub view: wgpu::TextureView,
    /// The largest radius within reach of each 8×8 block of each layer
    /// (`sampler::coverage::Blocks`): what limits cover's reach under Current and
    /// Bigger. One word without a map.
    pub near: wgpu::Buffer,
    has_map: bool,
    narrow: bool,
    rows: u32,
}

impl RadiusTexture {
    /// A texture for `plan`'s map.
    pub fn new(device: &wgpu::Device, plan: &Plan) -> Self {
        let has_map = plan.map.is_some();
        let narrow = Self::narrow(plan);
        let rows = Self::rows(plan);
        let size = if has_map { (plan.width, rows) } else { (1, 1) };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("radius map"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: if narrow {
                wgpu::TextureFormat::R16Uint
            } else {
                wgpu::TextureFormat::R32Uint
            },
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let blocks = if has_map {
            crate::sampler::coverage::Blocks::count(plan)
        } else {
            1
        };
        let near = util::buffer_of(
            device,
            "near radii",
            4 * blocks as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        Self {
            texture,
            view,
            near,
            has_map,
            narrow,
            rows,
        }
    }

    fn narrow(plan: &Plan) -> bool {
        plan.radius_range.1 <= u32::from(u16::MAX)
    }

    /// The texture's rows: the classes' maps and the cross radii, or the map.
    fn rows(plan: &Plan) -> u32 {
        if plan.classes() > 1 {
            plan.slot_rows() + plan.height
        } else {
            plan.height
        }
    }

    /// Whether the texture serves `plan`.
    pub fn fits(&self, plan: &Plan) -> bool {
        (self.has_map, self.narrow, self.rows)
            == (plan.map.is_some(), Self::narrow(plan), Self::rows(plan))
    }

    /// Bytes held for `plan`'s domain.
    pub fn bytes(&self, plan: &Plan) -> u64 {
        if self.has_map {
            (4 - 2 * u64::from(self.narrow)) * u64::from(plan.width) * u64::from(self.rows)
        } else {
            0
        }
    }

    /// Under Current and Bigger with a map, uploads its blocks' reach, which
    /// the pixel pass's cover reads (exact mode's does not).
    pub fn upload_near(&self, queue: &wgpu::Queue, plan: &Plan) {
        if matches!(plan.policy, Policy::Current | Policy::Bigger)
            && let Some(blocks) = crate::sampler::coverage::Blocks::new(plan)
        {
            queue.write_buffer(&self.near, 0, bytemuck::cast_slice(blocks.near_all()));
        }
    }

    /// Uploads the plan's radius map, if any.
    pub fn upload(&self, queue: &wgpu::Queue, plan: &Plan) {
        let Some(map) = &plan.map else { return };
        let with_cross: Vec<u32>;
        let radii = match &plan.cross {
            Some(cross) if plan.classes() > 1 => {
                with_cross = map.radii_fx().iter().chain(cross.iter()).copied().collect();
                &with_cross[..]
            }
            _ => map.radii_fx(),
        };
        let narrow: Vec<u16>;
        let (data, texel): (&[u8], u32) = if self.narrow {
            narrow = radii.iter().map(|&r| r as u16).collect();
            (bytemuck::cast_slice(&narrow), 2)
        } else {
            (bytemuck::cast_slice(radii), 4)
        };
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(texel * plan.width),
                rows_per_image: Some(self.rows),
            },
            wgpu::Extent3d {
                width: plan.width,
                height: self.rows,
                depth_or_array_layers: 1,
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::{DART_BYTES, HEADER, held_capacity};

    #[test]
    fn the_held_samples_take_four_batches_within_the_slots_and_a_buffer() {
        let big = u64::MAX;
        // Room for four batches.
        assert_eq!(held_capacity(100_000, 1 << 24, big), 400_000);
        // At most a sixteenth of the slots, but 64K where there are more.
        assert_eq!(held_capacity(100_000, 1 << 22, big), 262_144);
        assert_eq!(held_capacity(20_000, 1 << 20, big), 65_536);
        // Never more than the slots.
        assert_eq!(held_capacity(2000, 9000, big), 8000);
        assert_eq!(held_capacity(4000, 9000, big), 9000);
        // Never more than a buffer holds after the header.
        let buffer = HEADER + 300_000 * DART_BYTES;
        assert_eq!(held_capacity(100_000, 1 << 24, buffer), 300_000);
        // Less than two batches: one, read back from the survivors.
        assert_eq!(held_capacity(5000, 9000, big), 5000);
        assert_eq!(held_capacity(200_000, 1 << 24, buffer), 200_000);
        assert_eq!(held_capacity(10_000_000, 1 << 28, big), 10_000_000);
    }
}
