//! Depth keys survive a Depth32Float target exactly: a key is written as
//! `frag_depth` by a raster pass, read back by a compute pass bound the way
//! `cull.wgsl` binds the depth map, and compared as an integer.

use pixelpie::gpu::GpuContext;
use pixelpie::gpu::util::{self, COMMON};
use pixelpie::sampler::fixed::KEY_BITS;

const SIDE: u32 = 256;

const SHADER: &str = r#"
@group(0) @binding(0) var<storage, read> keys: array<u32>;
struct VsOut { @builtin(position) pos: vec4<f32>, @location(0) @interpolate(flat) key: u32 }
@vertex fn vs(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VsOut {
    var corners = array<vec2<f32>, 6>(vec2(0.0, 0.0), vec2(1.0, 0.0), vec2(0.0, 1.0),
                                      vec2(0.0, 1.0), vec2(1.0, 0.0), vec2(1.0, 1.0));
    let p = (vec2<f32>(f32(i % 256u), f32(i / 256u)) + corners[v]) / 256.0;
    var o: VsOut;
    o.pos = vec4<f32>(p.x * 2.0 - 1.0, 1.0 - p.y * 2.0, 0.5, 1.0);
    o.key = keys[i];
    return o;
}
@fragment fn fs(in: VsOut) -> @builtin(frag_depth) f32 { return key_to_depth(in.key); }

@group(0) @binding(1) var depth: texture_2d<f32>;
@group(0) @binding(2) var<storage, read_write> back: array<u32>;
@compute @workgroup_size(64) fn read_back(@builtin(global_invocation_id) id: vec3<u32>) {
    let xy = vec2<i32>(i32(id.x % 256u), i32(id.x / 256u));
    back[id.x] = depth_to_key(textureLoad(depth, xy, 0).x);
}
"#;

#[test]
fn every_depth_key_reads_back_exactly() {
    let ctx = match GpuContext::new() {
        Ok(c) => c,
        Err(e) => {
            assert!(
                std::env::var("PIXELPIE_EXPECT_GPU").as_deref() != Ok("1"),
                "a GPU adapter is expected: {e}"
            );
            eprintln!("skipping: {e}");
            return;
        }
    };
    let (device, queue) = (&ctx.device, &ctx.queue);
    let n = SIDE * SIDE;
    // Keys across the whole 29-bit range: both ends, powers of two and their
    // neighbours, and a stride through the rest.
    let max = (1u32 << KEY_BITS) - 1;
    let mut keys: Vec<u32> = vec![0, 1, 2, max - 1, max];
    for b in 1..KEY_BITS {
        keys.extend([(1 << b) - 1, 1 << b, (1 << b) + 1]);
    }
    let stride = max / (n - keys.len() as u32);
    keys.extend((0..n - keys.len() as u32).map(|i| i * stride + (i % 7)));
    assert_eq!(keys.len() as u32, n);

    use wgpu::util::DeviceExt;
    let key_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&keys),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let back = util::buffer_of(
        device,
        "back",
        4 * u64::from(n),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let staging = util::buffer_of(
        device,
        "staging",
        4 * u64::from(n),
        wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
    );
    let depth = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d {
            width: SIDE,
            height: SIDE,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let view = depth.create_view(&Default::default());
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(format!("{COMMON}\n{SHADER}").into()),
    });
    let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let raster_layout = util::layout(device, "raster", &[util::storage(0, vf, true)]);
    let raster = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: Some(&util::pipeline_layout(device, &raster_layout)),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    });
    let c = wgpu::ShaderStages::COMPUTE;
    let read_layout = util::layout(
        device,
        "read",
        &[
            util::storage(0, c, true),
            util::texture(1, wgpu::TextureSampleType::Float { filterable: false }),
            util::storage(2, c, false),
        ],
    );
    let read = util::compute(
        device,
        &util::pipeline_layout(device, &read_layout),
        &module,
        "read_back",
    );
    let raster_group = util::bind_group(device, &raster_layout, &[key_buf.as_entire_binding()]);
    let read_group = util::bind_group(
        device,
        &read_layout,
        &[
            key_buf.as_entire_binding(),
            wgpu::BindingResource::TextureView(&view),
            back.as_entire_binding(),
        ],
    );
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&raster);
        pass.set_bind_group(0, &raster_group, &[]);
        pass.draw(0..6, 0..n);
    }
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&read);
        pass.set_bind_group(0, &read_group, &[]);
        pass.dispatch_workgroups(n / 64, 1, 1);
    }
    enc.copy_buffer_to_buffer(&back, 0, &staging, 0, 4 * u64::from(n));
    queue.submit([enc.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |r| r.expect("map"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let view = staging.get_mapped_range(..).expect("mapped");
    let got: &[u32] = bytemuck::cast_slice(&view);
    let wrong: Vec<_> = keys
        .iter()
        .zip(got)
        .filter(|(a, b)| a != b)
        .take(5)
        .collect();
    assert!(wrong.is_empty(), "keys changed in the depth map: {wrong:?}");
}
