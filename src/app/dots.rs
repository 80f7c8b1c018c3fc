//! The stipple drawn on the GPU: instanced anti-aliased dots through an
//! `egui_wgpu` paint callback, sharing egui's device. Shader: `shaders/dots.wgsl`.

use std::sync::Arc;

use egui_wgpu::wgpu;

/// The dot shader's source.
pub const SHADER: &str = include_str!("../../shaders/dots.wgsl");

/// `struct View` in `shaders/dots.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewUniform {
    /// Callback rectangle size in points.
    pub rect: [f32; 2],
    /// Image-to-screen scale (points per image pixel).
    pub scale: f32,
    /// Physical pixels per point.
    pub pixels_per_point: f32,
    /// Screen position of the image origin, in points from the rectangle's corner.
    pub offset: [f32; 2],
    /// Dot radius per sample radius.
    pub radius_scale: f32,
    /// Dot radius per calibrated (drawn) radius; the two add up.
    pub drawn_scale: f32,
    /// Premultiplied later: straight RGBA.
    pub color: [f32; 4],
}

/// One dot: `struct Dot` in `shaders/dots.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DotInstance {
    /// x in image pixels.
    pub x: f32,
    /// y in image pixels.
    pub y: f32,
    /// Sample radius in image pixels.
    pub radius: f32,
    /// The calibrated dot radius in image pixels.
    pub drawn: f32,
}

/// A layer of dots to draw: the instances (shared, uploaded when their
/// generation changes) and how to draw them.
#[derive(Clone)]
pub struct DotLayer {
    /// The dots.
    pub dots: Arc<Vec<DotInstance>>,
    /// Changes whenever `dots` does.
    pub generation: u64,
    /// The view transform and style.
    pub view: ViewUniform,
    /// Which slot of the renderer holds the layer: [`LAYERS`] × tile + (0 =
    /// coverage, 1 + k = the dots of pen k), for up to four tiles.
    pub slot: usize,
    /// Multiply the dots into what is below (a colour drawing's inks, as
    /// the render model overprints them) instead of covering it.
    pub multiply: bool,
}

struct Slot {
    generation: u64,
    count: u32,
    instances: wgpu::Buffer,
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
}

/// GPU state kept in egui_wgpu's callback resources.
pub struct DotRenderer {
    pipeline: wgpu::RenderPipeline,
    multiply: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    slots: [Option<Slot>; SLOTS],
}

/// Layers per tile: the coverage disks and one per pen.
pub const LAYERS: usize = 1 + crate::colour::pens::MAX_PENS;
/// Layers the renderer holds: [`LAYERS`] for each of 2×2 tiles.
pub const SLOTS: usize = 4 * LAYERS;

impl DotRenderer {
    /// Builds the pipeline for egui's target format.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let layout = crate::gpu::util::layout(
            device,
            "dots",
            &[
                crate::gpu::util::uniform(0, vf),
                crate::gpu::util::storage(1, vf, true),
            ],
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("dots.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let make = |entry: &str, blend: wgpu::BlendState| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("dots"),
                layout: Some(&crate::gpu::util::pipeline_layout(device, &layout)),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_dot"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: Some(blend),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let pipeline = make("fs_dot", wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
        // out = src × dst: each pen's ink multiplies what is below it.
        let multiply = make(
            "fs_dot_multiply",
            wgpu::BlendState {
                color: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::Dst,
                    dst_factor: wgpu::BlendFactor::Zero,
                    operation: wgpu::BlendOperation::Add,
                },
                alpha: wgpu::BlendComponent {
                    src_factor: wgpu::BlendFactor::Zero,
                    dst_factor: wgpu::BlendFactor::One,
                    operation: wgpu::BlendOperation::Add,
                },
            },
        );
        Self {
            pipeline,
            multiply,
            layout,
            slots: std::array::from_fn(|_| None),
        }
    }

    fn prepare(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, layer: &DotLayer) {
        let bytes = std::mem::size_of_val(layer.dots.as_slice()).max(16) as u64;
        let stale = match &self.slots[layer.slot] {
            Some(s) => s.generation != layer.generation || s.instances.size() < bytes,
            None => true,
        };
        if stale {
            let grow = self.slots[layer.slot]
                .as_ref()
                .is_none_or(|s| s.instances.size() < bytes);
            if grow {
                let usage = wgpu::BufferUsages::COPY_DST;
                let instances = crate::gpu::util::buffer_of(
                    device,
                    "dots",
                    bytes.next_power_of_two(),
                    usage | wgpu::BufferUsages::STORAGE,
                );
                let uniform = crate::gpu::util::buffer_of(
                    device,
                    "view",
                    std::mem::size_of::<ViewUniform>() as u64,
                    usage | wgpu::BufferUsages::UNIFORM,
                );
                let group = crate::gpu::util::bind_group(
                    device,
                    &self.layout,
                    &[uniform.as_entire_binding(), instances.as_entire_binding()],
                );
                self.slots[layer.slot] = Some(Slot {
                    generation: 0,
                    count: 0,
                    instances,
                    uniform,
                    group,
                });
            }
            if let Some(s) = &mut self.slots[layer.slot] {
                if !layer.dots.is_empty() {
                    queue.write_buffer(
                        &s.instances,
                        0,
                        bytemuck::cast_slice(layer.dots.as_slice()),
                    );
                }
                s.generation = layer.generation;
                s.count = layer.dots.len() as u32;
            }
        }
        if let Some(s) = &self.slots[layer.slot] {
            queue.write_buffer(&s.uniform, 0, bytemuck::bytes_of(&layer.view));
        }
    }
}

impl egui_wgpu::CallbackTrait for DotLayer {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(r) = resources.get_mut::<DotRenderer>() {
            r.prepare(device, queue, self);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(r) = resources.get::<DotRenderer>() else {
            return;
        };
        let Some(s) = &r.slots[self.slot] else { return };
        if s.count == 0 {
            return;
        }
        pass.set_pipeline(if self.multiply {
            &r.multiply
        } else {
            &r.pipeline
        });
        pass.set_bind_group(0, &s.group, &[]);
        pass.draw(0..6, 0..s.count);
    }
}

#[cfg(test)]
mod tests {
    use crate::gpu::util::{rust_layout, wgsl_layout};

    #[test]
    fn the_view_and_the_dot_mirror_the_layout_naga_reads_from_dots_wgsl() {
        let view = rust_layout!(super::ViewUniform;
            rect, scale, pixels_per_point, offset, radius_scale, drawn_scale, color);
        assert_eq!(view, wgsl_layout(super::SHADER, "View"));
        let dot = rust_layout!(super::DotInstance; x, y, radius, drawn);
        assert_eq!(dot, wgsl_layout(super::SHADER, "Dot"));
    }
}
