//! Small wgpu helpers: shader assembly, bind-group-layout entries, dispatch
//! sizes and error scopes.

use std::borrow::Cow;

/// The WGSL shared by every stage (prepended to each).
pub const COMMON: &str = include_str!("../../shaders/common.wgsl");

/// Every shader of the pipeline, by file name, without the common prelude
/// (throw.wgsl and exact.wgsl with `empty.wgsl` appended).
pub const SHADERS: [(&str, &str); 7] = [
    (
        "throw.wgsl",
        concat!(
            include_str!("../../shaders/throw.wgsl"),
            include_str!("../../shaders/empty.wgsl")
        ),
    ),
    ("raster.wgsl", include_str!("../../shaders/raster.wgsl")),
    ("cull.wgsl", include_str!("../../shaders/cull.wgsl")),
    ("cover.wgsl", include_str!("../../shaders/cover.wgsl")),
    ("compact.wgsl", include_str!("../../shaders/compact.wgsl")),
    ("splat.wgsl", include_str!("../../shaders/splat.wgsl")),
    (
        "exact.wgsl",
        concat!(
            include_str!("../../shaders/exact.wgsl"),
            include_str!("../../shaders/empty.wgsl")
        ),
    ),
];

/// The full source of a stage's shader: the common prelude and the stage.
#[must_use]
pub fn shader_source(stage: &str) -> String {
    format!("{COMMON}\n{stage}")
}

/// Compiles a stage's shader.
pub fn module(device: &wgpu::Device, label: &str, stage: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(Cow::Owned(shader_source(stage))),
    })
}

/// A uniform-buffer layout entry.
pub fn uniform(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    buffer(binding, visibility, wgpu::BufferBindingType::Uniform)
}

/// A storage-buffer layout entry.
pub fn storage(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    buffer(
        binding,
        visibility,
        wgpu::BufferBindingType::Storage { read_only },
    )
}

fn buffer(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A 2D texture layout entry read with `textureLoad`. Depth is bound as an
/// unfilterable float texture, the form that works on Vulkan and GL alike.
pub fn texture(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A bind group layout.
pub fn layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    })
}

/// A pipeline layout of one bind group.
pub fn pipeline_layout(device: &wgpu::Device, bgl: &wgpu::BindGroupLayout) -> wgpu::PipelineLayout {
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(bgl)],
        immediate_size: 0,
    })
}

/// A compute pipeline for one entry point.
pub fn compute(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A bind group of whole resources, in binding order.
pub fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<_> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &entries,
    })
}

/// The largest number of workgroups per dispatch dimension.
const MAX_GROUPS: u32 = 65535;

/// Dispatches `groups` workgroups as a 2D grid (the shaders flatten it).
pub fn dispatch(pass: &mut wgpu::ComputePass<'_>, groups: u32) {
    dispatch_layers(pass, groups, 1);
}

/// Dispatches `groups` workgroups as a 2D grid (the shaders flatten it) on
/// each of `layers` class layers (z).
pub fn dispatch_layers(pass: &mut wgpu::ComputePass<'_>, groups: u32, layers: u32) {
    if groups == 0 {
        return;
    }
    let x = groups.min(MAX_GROUPS);
    pass.dispatch_workgroups(x, groups.div_ceil(x), layers.max(1));
}

/// The threads that share one dart on the coalesced S1 path
/// (`splat_coalesced` in `splat.wgsl`): the widest row of a disk of radius
/// up to `r_fx` (1/64 px), 2⌈r⌉ + 1 pixels, rounded up to a power of two,
/// at most 32. Mirrors `splat_lanes` there.
#[must_use]
pub fn splat_lanes(r_fx: u32) -> u32 {
    let width = 2 * r_fx.div_ceil(crate::sampler::fixed::RADIUS_ONE) + 1;
    width.next_power_of_two().min(32)
}

/// The rows a disk of radius up to `r_fx` (1/64 px) spans: the second
/// dimension of the row-parallel dispatches of `cover.wgsl` and `splat.wgsl`.
#[must_use]
pub fn disk_rows(r_fx: u32) -> u32 {
    2 * r_fx.div_ceil(crate::sampler::fixed::RADIUS_ONE) + 2
}

/// Dispatches one thread per dart (x, 256 per workgroup), row (y) and
/// class layer (z).
pub fn dispatch_rows(pass: &mut wgpu::ComputePass<'_>, darts: u32, rows: u32, layers: u32) {
    if darts > 0 {
        pass.dispatch_workgroups(darts.div_ceil(256), rows.min(MAX_GROUPS), layers.max(1));
    }
}

/// Creates a buffer.
pub fn buffer_of(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16).next_multiple_of(16),
        usage,
        mapped_at_creation: false,
    })
}

/// Waits for the submitted work and copies the first `len` bytes of a
/// `MAP_READ` buffer out.
pub fn read_back(
    device: &wgpu::Device,
    staging: &wgpu::Buffer,
    len: u64,
) -> crate::sampler::Result<Vec<u8>> {
    read_back_with(device, staging, 0..len, <[u8]>::to_vec)
}

/// Waits for the submitted work and hands the bytes `range` of a `MAP_READ`
/// buffer to `read` while they are mapped (no copy of them in between).
pub fn read_back_with<T>(
    device: &wgpu::Device,
    staging: &wgpu::Buffer,
    range: std::ops::Range<u64>,
    read: impl FnOnce(&[u8]) -> T,
) -> crate::sampler::Result<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, range.clone(), move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| super::error::failed("device lost", e))?;
    rx.recv()
        .map_err(|e| super::error::failed("the read-back never answered", e))?
        .map_err(|e| super::error::failed("cannot read back", e))?;
    let out = read(
        &staging
            .get_mapped_range(range)
            .map_err(|e| super::error::unusable(format!("cannot read back: {e:?}")))?,
    );
    staging.unmap();
    Ok(out)
}

/// The buffers and views that the stages bind, for their `bind` functions.
pub struct Bindings<'a> {
    /// The run's configuration (uniform).
    pub config: &'a wgpu::Buffer,
    /// The batch's darts.
    pub darts: &'a wgpu::Buffer,
    /// The survivors, in dart order.
    pub survivors: &'a wgpu::Buffer,
    /// The coverage bitmap.
    pub coverage: &'a wgpu::Buffer,
    /// The scan of empty pixels per coverage word (the empty list's index).
    pub empty_scan: &'a wgpu::Buffer,
    /// The survivor flags and their scan.
    pub dart_flags: &'a wgpu::Buffer,
    /// The survivor count (the scan's total).
    pub survivor_count: &'a wgpu::Buffer,
    /// The compute path's key buffer.
    pub keys: &'a wgpu::Buffer,
    /// The raster path's depth map.
    pub depth: &'a wgpu::TextureView,
    /// The radius map.
    pub radius: &'a wgpu::TextureView,
    /// The largest radius within reach of each 8×8 block of the radius map.
    pub near: &'a wgpu::Buffer,
}

/// The layout naga reads from WGSL `source` for `struct name`: its size and
/// each member's name and offset, for the tests of the Rust mirrors.
#[cfg(test)]
pub(crate) fn wgsl_layout(source: &str, name: &str) -> (u32, Vec<(String, u32)>) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    module
        .types
        .iter()
        .find_map(|(_, ty)| match &ty.inner {
            naga::TypeInner::Struct { members, span } if ty.name.as_deref() == Some(name) => {
                let fields = members
                    .iter()
                    .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                    .collect();
                Some((*span, fields))
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("no struct {name} in the WGSL"))
}

/// The size and the fields' names and offsets of a `#[repr(C)]` Rust
/// struct, in the form of [`wgsl_layout`].
#[cfg(test)]
macro_rules! rust_layout {
    ($t:ty; $($field:ident),* $(,)?) => {
        (
            std::mem::size_of::<$t>() as u32,
            vec![$((stringify!($field).to_owned(), std::mem::offset_of!($t, $field) as u32)),*],
        )
    };
}
#[cfg(test)]
pub(crate) use rust_layout;
