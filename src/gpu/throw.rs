//! Dart throwing (paper §3.1, step S1) on wgpu. A compute pass makes the darts
//! from the counter-based hash; an instanced, depth-only draw then rasterizes
//! them: the vertex shader pulls dart i from a storage buffer and scales its
//! quad by the dart's radius (the paper's geometry stage), the fragment shader
//! trims it to the disk and writes the dart's key as depth, compared Less or
//! Greater by policy. GPUs that shade fragments slowly take the other path:
//! `shaders/splat.wgsl` rasterizes the disks in a compute pass with atomicMax
//! into a key buffer, with the same winners: a thread per row of a disk, or
//! (coalesced) the lanes of a warp along one disk's rows.
//! Shaders: `shaders/throw.wgsl`, `shaders/raster.wgsl`, `shaders/splat.wgsl`;
//! CPU mirror: `sampler::cpu::throw`.

use super::util;
use super::util::Bindings;
use crate::sampler::Plan;

/// S1's bind groups on one run's resources.
pub struct ThrowGroups {
    /// The dart kernel's.
    pub throw: wgpu::BindGroup,
    /// The raster draw's.
    pub raster: wgpu::BindGroup,
    /// The splat kernel's.
    pub splat: wgpu::BindGroup,
}

/// The dart kernel and the two raster pipelines (Less, Greater).
pub struct ThrowStage {
    /// The kernel's layout: config, darts, coverage, prefix, radius map.
    pub layout: wgpu::BindGroupLayout,
    /// The raster layout: config, darts.
    pub raster_layout: wgpu::BindGroupLayout,
    /// The splat layout: config, darts, key buffer, radius map.
    pub splat_layout: wgpu::BindGroupLayout,
    throw: wgpu::ComputePipeline,
    splat: wgpu::ComputePipeline,
    splat_coalesced: wgpu::ComputePipeline,
    less: wgpu::RenderPipeline,
    greater: wgpu::RenderPipeline,
}

impl ThrowStage {
    /// Compiles the kernel and the raster pipelines.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = util::layout(
            device,
            "throw",
            &[
                util::uniform(0, c),
                util::storage(1, c, false),
                util::storage(2, c, true),
                util::storage(3, c, true),
                util::texture(4, wgpu::TextureSampleType::Uint),
            ],
        );
        let module = util::module(device, "throw.wgsl", util::SHADERS[0].1);
        let throw = util::compute(
            device,
            &util::pipeline_layout(device, &layout),
            &module,
            "throw_darts",
        );
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let raster_layout = util::layout(
            device,
            "raster",
            &[util::uniform(0, vf), util::storage(1, vf, true)],
        );
        let raster_pl = util::pipeline_layout(device, &raster_layout);
        let raster = util::module(device, "raster.wgsl", util::SHADERS[1].1);
        let pipeline = |compare| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("raster"),
                layout: Some(&raster_pl),
                vertex: wgpu::VertexState {
                    module: &raster,
                    entry_point: Some("vs_disk"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(compare),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &raster,
                    entry_point: Some("fs_disk"),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let splat_layout = util::layout(
            device,
            "splat",
            &[
                util::uniform(0, c),
                util::storage(1, c, true),
                util::storage(2, c, false),
                util::texture(3, wgpu::TextureSampleType::Uint),
            ],
        );
        let splat_module = util::module(device, "splat.wgsl", util::SHADERS[5].1);
        let splat_pl = util::pipeline_layout(device, &splat_layout);
        let splat = util::compute(device, &splat_pl, &splat_module, "splat");
        let splat_coalesced = util::compute(device, &splat_pl, &splat_module, "splat_coalesced");
        Self {
            splat_layout,
            splat,
            splat_coalesced,
            less: pipeline(wgpu::CompareFunction::Less),
            greater: pipeline(wgpu::CompareFunction::Greater),
            throw,
            layout,
            raster_layout,
        }
    }

    /// Binds the stage to one run's resources.
    pub fn bind(&self, device: &wgpu::Device, b: &Bindings<'_>) -> ThrowGroups {
        ThrowGroups {
            throw: util::bind_group(
                device,
                &self.layout,
                &[
                    b.config.as_entire_binding(),
                    b.darts.as_entire_binding(),
                    b.coverage.as_entire_binding(),
                    b.empty_scan.as_entire_binding(),
                    wgpu::BindingResource::TextureView(b.radius),
                ],
            ),
            raster: util::bind_group(
                device,
                &self.raster_layout,
                &[b.config.as_entire_binding(), b.darts.as_entire_binding()],
            ),
            splat: util::bind_group(
                device,
                &self.splat_layout,
                &[
                    b.config.as_entire_binding(),
                    b.darts.as_entire_binding(),
                    b.keys.as_entire_binding(),
                    wgpu::BindingResource::TextureView(b.radius),
                ],
            ),
        }
    }

    /// Makes `darts` darts.
    pub fn encode_throw(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
    ) {
        pass.set_pipeline(&self.throw);
        pass.set_bind_group(0, group, &[]);
        util::dispatch(pass, darts.div_ceil(256));
    }

    /// Rasterizes `darts` darts into the key buffer with a compute pass (the
    /// buffer must be cleared to 0 first), on each of `classes` key layers:
    /// a thread per row of a disk, or with `coalesced` the lanes of a warp
    /// along one disk's rows.
    pub fn encode_splat(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
        max_radius: u32,
        classes: u32,
        coalesced: bool,
    ) {
        pass.set_bind_group(0, group, &[]);
        if coalesced {
            pass.set_pipeline(&self.splat_coalesced);
            let lanes = u64::from(util::splat_lanes(max_radius));
            let groups = (u64::from(darts) * lanes).div_ceil(256);
            util::dispatch_layers(pass, u32::try_from(groups).unwrap_or(u32::MAX), classes);
        } else {
            pass.set_pipeline(&self.splat);
            util::dispatch_rows(pass, darts, util::disk_rows(max_radius), classes);
        }
    }

    /// Rasterizes `darts` darts into `depth`, cleared to the losing end.
    pub fn encode_raster(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        group: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
        darts: u32,
        plan: &Plan,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let greater_wins = plan.layout.greater_wins;
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("S1 raster"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(if greater_wins { 0.0 } else { 1.0 }),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(if greater_wins {
            &self.greater
        } else {
            &self.less
        });
        pass.set_bind_group(0, group, &[]);
        let copies = if plan.periodic { 9 } else { 1 };
        pass.draw(0..6, 0..darts * copies);
    }
}
