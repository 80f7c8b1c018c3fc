//! Coverage (paper §3.2, second half of S2) on wgpu: a compute pass marks in
//! the coverage bitmap the pixels each survivor covers under the policy.
//! Shader: `shaders/cover.wgsl`; CPU mirror: `sampler::cpu::cover`.

use super::resources::Bindings;
use super::util;

/// The cover kernel.
pub struct CoverStage {
    /// The layout: config, survivors, survivor count, coverage, radius map.
    pub layout: wgpu::BindGroupLayout,
    cover: wgpu::ComputePipeline,
}

impl CoverStage {
    /// Compiles the kernel.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = util::layout(
            device,
            "cover",
            &[
                util::uniform(0, c),
                util::storage(1, c, true),
                util::storage(2, c, true),
                util::storage(3, c, false),
                util::texture(4, wgpu::TextureSampleType::Uint),
            ],
        );
        let pl = util::pipeline_layout(device, &layout);
        let module = util::module(device, "cover.wgsl", util::SHADERS[3].1);
        Self {
            cover: util::compute(device, &pl, &module, "cover"),
            layout,
        }
    }

    /// Binds the stage to one run's resources.
    pub fn bind(&self, device: &wgpu::Device, b: &Bindings<'_>) -> wgpu::BindGroup {
        util::bind_group(
            device,
            &self.layout,
            &[
                b.config.as_entire_binding(),
                b.survivors.as_entire_binding(),
                b.survivor_count.as_entire_binding(),
                b.coverage.as_entire_binding(),
                wgpu::BindingResource::TextureView(b.radius),
            ],
        )
    }

    /// Covers the pixels of up to `darts` survivors whose reach is at most
    /// `reach` (1/64 px): one thread per survivor and row.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
        reach: u32,
    ) {
        pass.set_pipeline(&self.cover);
        pass.set_bind_group(0, group, &[]);
        util::dispatch_rows(pass, darts, util::disk_rows(reach));
    }
}
