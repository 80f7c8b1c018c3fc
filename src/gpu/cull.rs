//! Conflict removal (paper §3.2, step S2) on wgpu: a compute pass reads the
//! depth map (or key buffer) at each dart's pixel and flags the darts whose
//! key won; the flags are scanned and the survivors gathered in dart order.
//! Shader: `shaders/cull.wgsl`; CPU mirror: `sampler::cpu::cull`.

use super::util;
use super::util::Bindings;

/// The cull and gather kernels.
pub struct CullStage {
    /// The layout: config, darts, depth, flags, survivors, splat keys.
    pub layout: wgpu::BindGroupLayout,
    cull: wgpu::ComputePipeline,
    gather: wgpu::ComputePipeline,
}

impl CullStage {
    /// Compiles the kernels.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = util::layout(
            device,
            "cull",
            &[
                util::uniform(0, c),
                util::storage(1, c, true),
                util::texture(2, wgpu::TextureSampleType::Float { filterable: false }),
                util::storage(3, c, false),
                util::storage(4, c, false),
                util::storage(5, c, true),
            ],
        );
        let pl = util::pipeline_layout(device, &layout);
        let module = util::module(device, "cull.wgsl", util::SHADERS[2].1);
        Self {
            cull: util::compute(device, &pl, &module, "cull"),
            gather: util::compute(device, &pl, &module, "gather"),
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
                b.darts.as_entire_binding(),
                wgpu::BindingResource::TextureView(b.depth),
                b.dart_flags.as_entire_binding(),
                b.survivors.as_entire_binding(),
                b.keys.as_entire_binding(),
            ],
        )
    }

    /// Flags the winners of `darts` darts, and ends the flags with a 0.
    pub fn encode_cull(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
    ) {
        pass.set_pipeline(&self.cull);
        pass.set_bind_group(0, group, &[]);
        util::dispatch(pass, (darts + 1).div_ceil(256));
    }

    /// Writes the winners to the survivor buffer, in dart order.
    pub fn encode_gather(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
    ) {
        pass.set_pipeline(&self.gather);
        pass.set_bind_group(0, group, &[]);
        util::dispatch(pass, darts.div_ceil(256));
    }
}
