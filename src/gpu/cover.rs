//! Coverage (paper §3.2, second half of S2) on wgpu: a compute pass marks in
//! the coverage bitmap the pixels each survivor covers under the policy (in
//! exact mode: holds whole, by the corner rule).
//! Shader: `shaders/cover.wgsl`; CPU mirrors: `sampler::cpu::cover`, and
//! `cover_band` in `sampler::exact`.

use super::util;
use super::util::Bindings;

/// The cover kernel.
pub struct CoverStage {
    /// The layout: config, survivors, survivor count, coverage, radius map,
    /// the blocks' reach (binding 6).
    pub layout: wgpu::BindGroupLayout,
    /// Exact mode's layout: the same, and its configuration.
    pub exact_layout: wgpu::BindGroupLayout,
    cover: wgpu::ComputePipeline,
    cover_exact: wgpu::ComputePipeline,
}

impl CoverStage {
    /// Compiles the kernel.
    pub fn new(device: &wgpu::Device) -> Self {
        let c = wgpu::ShaderStages::COMPUTE;
        let entries = [
            util::uniform(0, c),
            util::storage(1, c, true),
            util::storage(2, c, true),
            util::storage(3, c, false),
            util::texture(4, wgpu::TextureSampleType::Uint),
            util::uniform(5, c),
            util::storage(6, c, true),
        ];
        let pixel_entries = [&entries[..5], &entries[6..]].concat();
        let layout = util::layout(device, "cover", &pixel_entries);
        let exact_layout = util::layout(device, "cover exact", &entries[..6]);
        let module = util::module(device, "cover.wgsl", util::SHADERS[3].1);
        Self {
            cover: util::compute(
                device,
                &util::pipeline_layout(device, &layout),
                &module,
                "cover",
            ),
            cover_exact: util::compute(
                device,
                &util::pipeline_layout(device, &exact_layout),
                &module,
                "cover_exact",
            ),
            layout,
            exact_layout,
        }
    }

    /// Binds the stage to one run's resources.
    pub fn bind(&self, device: &wgpu::Device, b: &Bindings<'_>) -> wgpu::BindGroup {
        let resources = [
            (0, b.config.as_entire_binding()),
            (1, b.survivors.as_entire_binding()),
            (2, b.survivor_count.as_entire_binding()),
            (3, b.coverage.as_entire_binding()),
            (4, wgpu::BindingResource::TextureView(b.radius)),
            (6, b.near.as_entire_binding()),
        ];
        let entries: Vec<_> = resources
            .into_iter()
            .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cover"),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Binds exact mode's kernel: the config, the survivors, their count,
    /// the coverage bitmap, the radius map and exact mode's configuration.
    pub fn bind_exact(
        &self,
        device: &wgpu::Device,
        [config, survivors, count, coverage, exact]: [&wgpu::Buffer; 5],
        radius: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        util::bind_group(
            device,
            &self.exact_layout,
            &[
                config.as_entire_binding(),
                survivors.as_entire_binding(),
                count.as_entire_binding(),
                coverage.as_entire_binding(),
                wgpu::BindingResource::TextureView(radius),
                exact.as_entire_binding(),
            ],
        )
    }

    /// Exact mode: covers the pixels that up to `darts` survivors (in
    /// 1/2^F px) hold whole, for a reach of at most `reach` (1/64 px).
    pub fn encode_exact(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
        reach: u32,
    ) {
        pass.set_pipeline(&self.cover_exact);
        pass.set_bind_group(0, group, &[]);
        util::dispatch_rows(pass, darts, util::disk_rows(reach), 1);
    }

    /// Covers the pixels of up to `darts` survivors whose reach is at most
    /// `reach` (1/64 px) on each of `classes` coverage layers: one thread per
    /// survivor, row and layer.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        darts: u32,
        reach: u32,
        classes: u32,
    ) {
        pass.set_pipeline(&self.cover);
        pass.set_bind_group(0, group, &[]);
        util::dispatch_rows(pass, darts, util::disk_rows(reach), classes);
    }
}
