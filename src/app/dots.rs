//! The stipple drawn on the GPU as a cached layer (`shaders/dots.wgsl`),
//! through an `egui_wgpu` paint callback on egui's device.
//!
//! Each layer of dots (the ink, a pen, the coverage disks) is splatted by a
//! compute pass into a cache: an ink buffer at the screen's resolution that
//! sums each pixel's coverage. Every frame composites the caches onto the
//! screen, one quad each, moved and scaled with the view; the view code
//! ([`super::view`]) asks for a new cache when the drawing changes or the
//! view comes to rest. Frames while panning and zooming thus cost the same
//! at 10K and at 2M dots, and the dots upload once per drawing.

use std::sync::Arc;

use egui_wgpu::wgpu;

/// The dot shader's source.
pub const SHADER: &str = include_str!("../../shaders/dots.wgsl");

/// The smallest disc splatted, in screen px: thinner dots are drawn this
/// wide with their ink scaled by the area ratio.
pub const R_MIN: f32 = 1.0;

/// `struct Splat` in `shaders/dots.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SplatUniform {
    /// Image px to cache px: `cache = image × scale + offset`.
    pub offset: [f32; 2],
    /// Cache px per image px.
    pub scale: f32,
    /// Dots in the layer.
    pub count: u32,
    /// The cache's size in px.
    pub size: [u32; 2],
    /// Copies of the drawing (1, or 4 for the 2×2 preview).
    pub tiles: u32,
    /// Dot radius per sample radius.
    pub radius_scale: f32,
    /// Dot radius per calibrated (drawn) radius; the two add up.
    pub drawn_scale: f32,
    /// The smallest disc, cache px.
    pub r_min: f32,
    /// Cache px per exported PNG px, at most 1.
    pub export_px: f32,
    /// 1 where overlaps count once (ink), 0 for the coverage disks.
    pub overlaps: u32,
    /// The tiles' offsets in image px, two per entry.
    pub tile_offsets: [[f32; 4]; 2],
    /// [`overlap_table`], four per entry.
    pub overlap: [[f32; 4]; 16],
}

/// The step in t (dot radius / sample radius) of [`overlap_table`]
/// (`OVERLAP_STEP` in `shaders/dots.wgsl`).
pub const OVERLAP_STEP: f64 = 0.02;

/// The ink of dots of radius t·r on a maximal set of sample radius
/// `radius` (domain px) over their summed area, at t = i ×
/// [`OVERLAP_STEP`]: 1 while the dots do not touch, less as they overlap
/// (from the measured ink curve, [`crate::importance::ink`]).
#[must_use]
pub fn overlap_table(radius: f32) -> [[f32; 4]; 16] {
    use crate::importance::ink::ink;
    let r = f64::from(radius.max(1.0));
    // The ink per t² while the dots are apart.
    let apart = 0.4;
    let per_area = ink(apart, r) / (apart * apart);
    let mut table = [[1.0; 4]; 16];
    for i in 0..64 {
        let t = i as f64 * OVERLAP_STEP;
        if t > apart && per_area > 0.0 {
            table[i / 4][i % 4] = (ink(t, r) / (per_area * t * t)).min(1.0) as f32;
        }
    }
    table
}

/// `struct Composite` in `shaders/dots.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CompositeUniform {
    /// The screen's size in physical px.
    pub screen: [f32; 2],
    /// The cache's top left corner on the screen now, physical px.
    pub quad_min: [f32; 2],
    /// Its bottom right corner.
    pub quad_max: [f32; 2],
    /// The cache's size in px.
    pub size: [u32; 2],
    /// Straight RGBA.
    pub color: [f32; 4],
}

/// `struct Fills` in `shaders/dots.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FillsUniform {
    /// The screen's size in physical px.
    pub screen: [f32; 2],
    /// Rectangles to fill.
    pub count: u32,
    /// Padding.
    pub _pad: u32,
    /// Left, top, right, bottom in physical px.
    pub rects: [[f32; 4]; MAX_FILLS],
    /// Premultiplied RGBA.
    pub colors: [[f32; 4]; MAX_FILLS],
}

/// The most rectangles of one [`FillFrame`].
pub const MAX_FILLS: usize = 8;

/// Flat rectangles, in points, in their colours, bottom first: the
/// canvas's large areas, drawn by a shader that a software rasterizer runs
/// much faster than egui's.
pub struct FillFrame {
    /// The rectangles and their colours.
    pub rects: Vec<(egui::Rect, egui::Color32)>,
}

impl egui_wgpu::CallbackTrait for FillFrame {
    fn prepare(
        &self,
        _device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(r) = resources.get_mut::<DotRenderer>() {
            let ppp = screen.pixels_per_point;
            let mut u = FillsUniform {
                screen: screen.size_in_pixels.map(|v| v as f32),
                count: self.rects.len().min(MAX_FILLS) as u32,
                ..Default::default()
            };
            for (i, (rect, color)) in self.rects.iter().take(MAX_FILLS).enumerate() {
                u.rects[i] = [
                    rect.min.x * ppp,
                    rect.min.y * ppp,
                    rect.max.x * ppp,
                    rect.max.y * ppp,
                ];
                u.colors[i] = color.to_array().map(|c| f32::from(c) / 255.0);
            }
            queue.write_buffer(&r.fills_uniform, 0, bytemuck::bytes_of(&u));
        }
        Vec::new()
    }

    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(r) = resources.get::<DotRenderer>() else {
            return;
        };
        let [w, h] = info.screen_size_px;
        pass.set_viewport(0.0, 0.0, w as f32, h as f32, 0.0, 1.0);
        pass.set_pipeline(&r.fill);
        pass.set_bind_group(0, &r.fills_group, &[]);
        pass.draw(0..6, 0..self.rects.len().min(MAX_FILLS) as u32);
    }
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

/// How a layer's ink goes onto what is below it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// One ink, over (premultiplied).
    Ink,
    /// A pen's ink multiplies what is below.
    Multiply,
    /// Translucent coverage disks, darker where they overlap.
    Disks,
}

/// A layer of dots to draw: the instances (shared, uploaded when their
/// generation changes) and how to draw them.
#[derive(Clone)]
pub struct DotLayer {
    /// The dots.
    pub dots: Arc<Vec<DotInstance>>,
    /// Changes whenever `dots` does.
    pub generation: u64,
    /// Dot radius per sample radius (image px).
    pub radius_scale: f32,
    /// Dot radius per calibrated radius (image px).
    pub drawn_scale: f32,
    /// Straight RGBA (applied when compositing: a new colour needs no new
    /// cache).
    pub color: [f32; 4],
    /// Which slot of the renderer holds the layer: 0 = coverage, 1 + k =
    /// the dots of pen k (or the one ink).
    pub slot: usize,
    /// How the layer goes onto what is below.
    pub blend: Blend,
}

impl DotLayer {
    /// What the layer's cache depends on, besides the view.
    fn content(&self) -> (u64, usize, u32, u32) {
        (
            self.generation,
            Arc::as_ptr(&self.dots) as usize,
            self.radius_scale.to_bits(),
            self.drawn_scale.to_bits(),
        )
    }
}

/// Where the image is on the screen: `screen px = image px × scale +
/// offset` (physical px).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Placement {
    /// Physical px per image px.
    pub scale: f32,
    /// The image origin's screen position, physical px.
    pub offset: [f32; 2],
}

impl Placement {
    /// A screen point (physical px) of `from` where `self` puts the same
    /// image point.
    #[must_use]
    pub fn map_from(&self, from: &Self, p: [f32; 2]) -> [f32; 2] {
        let k = self.scale / from.scale;
        [
            (p[0] - from.offset[0]) * k + self.offset[0],
            (p[1] - from.offset[1]) * k + self.offset[1],
        ]
    }
}

/// A cache the view asks for: the screen region it covers and how the
/// image lay on the screen when it was made.
#[derive(Clone, Debug, PartialEq)]
pub struct CacheSpec {
    /// The image's placement on the screen.
    pub at: Placement,
    /// The region, physical screen px: left, top, width, height.
    pub region: [i32; 4],
    /// The tiles' offsets in image px.
    pub tiles: Vec<[f32; 2]>,
    /// Cache px per exported PNG px, at most 1.
    pub export_px: f32,
    /// The drawing's median sample radius, domain px (the overlaps of its
    /// dots depend on it a little).
    pub sample_radius: f32,
}

/// The frame's dots: the layers, the cache they are splatted into and
/// where the image is now.
pub struct DotFrame {
    /// The layers, bottom first.
    pub layers: Vec<DotLayer>,
    /// The cache to show (splatted anew when it is not the one held).
    pub cache: CacheSpec,
    /// The image's placement now.
    pub now: Placement,
}

struct Slot {
    generation: (u64, usize),
    count: u32,
    instances: wgpu::Buffer,
    splat_uniform: wgpu::Buffer,
    composite_uniform: wgpu::Buffer,
    ink: Option<wgpu::Buffer>,
    splat_group: Option<wgpu::BindGroup>,
    composite_group: Option<wgpu::BindGroup>,
    /// What the ink buffer holds: the cache and the layer's content.
    holds: Option<(CacheSpec, (u64, usize, u32, u32))>,
}

/// GPU state kept in egui_wgpu's callback resources.
pub struct DotRenderer {
    splat: wgpu::ComputePipeline,
    ink: wgpu::RenderPipeline,
    multiply: wgpu::RenderPipeline,
    disks: wgpu::RenderPipeline,
    fill: wgpu::RenderPipeline,
    fills_uniform: wgpu::Buffer,
    fills_group: wgpu::BindGroup,
    splat_layout: wgpu::BindGroupLayout,
    composite_layout: wgpu::BindGroupLayout,
    slots: [Option<Slot>; LAYERS],
}

/// Layers: the coverage disks and one per pen.
pub const LAYERS: usize = 1 + crate::colour::pens::MAX_PENS;

/// The largest cache, in px (a layer's buffer is 4 bytes a px).
pub const MAX_CACHE_PX: i64 = 1 << 23;

impl DotRenderer {
    /// Builds the pipelines for egui's target format.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        use crate::gpu::util::{layout, pipeline_layout, storage, uniform};
        let cs = wgpu::ShaderStages::COMPUTE;
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let splat_layout = layout(
            device,
            "dots splat",
            &[uniform(0, cs), storage(1, cs, true), storage(2, cs, false)],
        );
        let composite_layout = layout(
            device,
            "dots composite",
            &[
                uniform(3, vf),
                storage(4, wgpu::ShaderStages::FRAGMENT, true),
            ],
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("dots.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let splat = crate::gpu::util::compute(
            device,
            &pipeline_layout(device, &splat_layout),
            &module,
            "cs_splat",
        );
        let composite = pipeline_layout(device, &composite_layout);
        let fills_layout = layout(device, "fills", &[uniform(5, wgpu::ShaderStages::VERTEX)]);
        let fills_pipeline = pipeline_layout(device, &fills_layout);
        let make_with =
            |layout: &wgpu::PipelineLayout, vs: &str, entry: &str, blend: wgpu::BlendState| {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(entry),
                    layout: Some(layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some(vs),
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
        let make = |entry: &str, blend| make_with(&composite, "vs_quad", entry, blend);
        let over = wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING;
        // out = src × dst: each pen's ink multiplies what is below it.
        let multiply = wgpu::BlendState {
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
        };
        let fills_uniform = crate::gpu::util::buffer_of(
            device,
            "fills",
            std::mem::size_of::<FillsUniform>() as u64,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::UNIFORM,
        );
        let fills_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fills"),
            layout: &fills_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 5,
                resource: fills_uniform.as_entire_binding(),
            }],
        });
        Self {
            splat,
            fill: make_with(&fills_pipeline, "vs_fill", "fs_fill", over),
            fills_uniform,
            fills_group,
            ink: make("fs_ink", over),
            multiply: make("fs_multiply", multiply),
            disks: make("fs_disks", over),
            splat_layout,
            composite_layout,
            slots: std::array::from_fn(|_| None),
        }
    }

    /// Uploads a layer's dots when they changed, splats its cache when it
    /// is not the one asked for, and sets where the cache shows now.
    fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        frame: &DotFrame,
        layer: &DotLayer,
        screen: [f32; 2],
    ) {
        use crate::gpu::util::buffer_of;
        let copy = wgpu::BufferUsages::COPY_DST;
        let bytes = std::mem::size_of_val(layer.dots.as_slice()) as u64;
        let generation = (layer.generation, Arc::as_ptr(&layer.dots) as usize);
        let slot = self.slots[layer.slot].get_or_insert_with(|| Slot {
            generation: (u64::MAX, 0),
            count: 0,
            instances: buffer_of(device, "dots", 16, copy | wgpu::BufferUsages::STORAGE),
            splat_uniform: buffer_of(
                device,
                "dots splat",
                std::mem::size_of::<SplatUniform>() as u64,
                copy | wgpu::BufferUsages::UNIFORM,
            ),
            composite_uniform: buffer_of(
                device,
                "dots composite",
                std::mem::size_of::<CompositeUniform>() as u64,
                copy | wgpu::BufferUsages::UNIFORM,
            ),
            ink: None,
            splat_group: None,
            composite_group: None,
            holds: None,
        });
        if slot.generation != generation {
            if slot.instances.size() < bytes {
                slot.instances = buffer_of(
                    device,
                    "dots",
                    bytes.next_power_of_two(),
                    copy | wgpu::BufferUsages::STORAGE,
                );
                slot.splat_group = None;
            }
            if !layer.dots.is_empty() {
                queue.write_buffer(&slot.instances, 0, bytemuck::cast_slice(&layer.dots));
            }
            slot.generation = generation;
            slot.count = layer.dots.len() as u32;
            slot.holds = None;
        }
        let [_, _, w, h] = frame.cache.region;
        let (w, h) = (w.max(1) as u32, h.max(1) as u32);
        let want = (frame.cache.clone(), layer.content());
        if slot.holds.as_ref() != Some(&want) {
            let need = u64::from(w) * u64::from(h) * 4;
            if slot.ink.as_ref().is_none_or(|b| b.size() < need) {
                slot.ink = Some(buffer_of(
                    device,
                    "dots ink",
                    need,
                    copy | wgpu::BufferUsages::STORAGE,
                ));
                slot.splat_group = None;
                slot.composite_group = None;
            }
            let Some(ink) = &slot.ink else { return };
            let cache = &frame.cache;
            let mut tile_offsets = [[0.0; 4]; 2];
            for (t, o) in cache.tiles.iter().take(4).enumerate() {
                tile_offsets[t / 2][(t % 2) * 2] = o[0];
                tile_offsets[t / 2][(t % 2) * 2 + 1] = o[1];
            }
            let uniform = SplatUniform {
                offset: [
                    cache.at.offset[0] - cache.region[0] as f32,
                    cache.at.offset[1] - cache.region[1] as f32,
                ],
                scale: cache.at.scale,
                count: slot.count,
                size: [w, h],
                tiles: cache.tiles.len().clamp(1, 4) as u32,
                radius_scale: layer.radius_scale,
                drawn_scale: layer.drawn_scale,
                r_min: R_MIN,
                export_px: cache.export_px,
                overlaps: u32::from(layer.blend != Blend::Disks),
                tile_offsets,
                overlap: overlap_table(cache.sample_radius),
            };
            queue.write_buffer(&slot.splat_uniform, 0, bytemuck::bytes_of(&uniform));
            let group = slot.splat_group.get_or_insert_with(|| {
                crate::gpu::util::bind_group(
                    device,
                    &self.splat_layout,
                    &[
                        slot.splat_uniform.as_entire_binding(),
                        slot.instances.as_entire_binding(),
                        ink.as_entire_binding(),
                    ],
                )
            });
            encoder.clear_buffer(ink, 0, None);
            if slot.count > 0 {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("dots splat"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.splat);
                pass.set_bind_group(0, &*group, &[]);
                pass.dispatch_workgroups(slot.count.div_ceil(256), uniform.tiles, 1);
            }
            slot.holds = Some(want);
        }
        let Some(ink) = &slot.ink else { return };
        // The cache held is the one asked for: moved and scaled to now.
        let held = &frame.cache;
        let [x, y, _, _] = held.region;
        let quad_min = frame.now.map_from(&held.at, [x as f32, y as f32]);
        let quad_max = frame
            .now
            .map_from(&held.at, [x as f32 + w as f32, y as f32 + h as f32]);
        let uniform = CompositeUniform {
            screen,
            quad_min,
            quad_max,
            size: [w, h],
            color: layer.color,
        };
        queue.write_buffer(&slot.composite_uniform, 0, bytemuck::bytes_of(&uniform));
        slot.composite_group.get_or_insert_with(|| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("dots composite"),
                layout: &self.composite_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: slot.composite_uniform.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: ink.as_entire_binding(),
                    },
                ],
            })
        });
    }
}

impl egui_wgpu::CallbackTrait for DotFrame {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(r) = resources.get_mut::<DotRenderer>() {
            let size = [
                screen.size_in_pixels[0] as f32,
                screen.size_in_pixels[1] as f32,
            ];
            for layer in &self.layers {
                r.prepare(device, queue, encoder, self, layer, size);
            }
        }
        Vec::new()
    }

    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(r) = resources.get::<DotRenderer>() else {
            return;
        };
        // The whole screen: the quads are placed in screen px (the clip
        // rectangle keeps them in the canvas).
        let [w, h] = info.screen_size_px;
        pass.set_viewport(0.0, 0.0, w as f32, h as f32, 0.0, 1.0);
        for layer in &self.layers {
            let Some(s) = &r.slots[layer.slot] else {
                continue;
            };
            let Some(group) = &s.composite_group else {
                continue;
            };
            if s.count == 0 || s.holds.is_none() {
                continue;
            }
            pass.set_pipeline(match layer.blend {
                Blend::Ink => &r.ink,
                Blend::Multiply => &r.multiply,
                Blend::Disks => &r.disks,
            });
            pass.set_bind_group(0, group, &[]);
            pass.draw(0..6, 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::gpu::util::{rust_layout, wgsl_layout};

    #[test]
    fn the_uniforms_and_the_dot_mirror_the_layout_naga_reads_from_dots_wgsl() {
        let splat = rust_layout!(super::SplatUniform;
            offset, scale, count, size, tiles, radius_scale, drawn_scale, r_min, export_px,
            overlaps, tile_offsets, overlap);
        assert_eq!(splat, wgsl_layout(super::SHADER, "Splat"));
        let comp = rust_layout!(super::CompositeUniform; screen, quad_min, quad_max, size, color);
        assert_eq!(comp, wgsl_layout(super::SHADER, "Composite"));
        let fills = rust_layout!(super::FillsUniform; screen, count, _pad, rects, colors);
        assert_eq!(fills, wgsl_layout(super::SHADER, "Fills"));
        let dot = rust_layout!(super::DotInstance; x, y, radius, drawn);
        assert_eq!(dot, wgsl_layout(super::SHADER, "Dot"));
    }

    #[test]
    fn the_overlap_table_is_one_while_dots_are_apart_and_falls_as_they_overlap() {
        let t = super::overlap_table(6.0);
        let at = |i: usize| t[i / 4][i % 4];
        assert!((0..=20).all(|i| at(i) == 1.0));
        assert!((0..64).all(|i| at(i) <= 1.0));
        // Falling once the dots touch (t = ½).
        assert!((26..63).all(|i| at(i + 1) <= at(i)));
        // Dots as wide as the disks cover about everything.
        assert!(at(50) < 0.5 && at(50) > 0.2, "{}", at(50));
    }

    #[test]
    fn a_placement_maps_the_screen_of_another() {
        let a = super::Placement {
            scale: 2.0,
            offset: [10.0, 20.0],
        };
        let b = super::Placement {
            scale: 4.0,
            offset: [-5.0, 0.0],
        };
        // Image point (3, 4): (16, 28) under a, (7, 16) under b.
        assert_eq!(b.map_from(&a, [16.0, 28.0]), [7.0, 16.0]);
        assert_eq!(a.map_from(&a, [16.0, 28.0]), [16.0, 28.0]);
    }
}
