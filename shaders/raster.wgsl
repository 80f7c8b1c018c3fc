// The rasterization half of dart throwing (S1): see throw.wgsl. Kept in its
// own module because a vertex stage may only read storage buffers.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read> darts: array<Dart>;

struct VsOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) dart: u32,
}

@vertex
fn vs_disk(@builtin(vertex_index) v: u32, @builtin(instance_index) instance: u32) -> VsOut {
    // Periodic domains draw each dart nine times, shifted by the period.
    var k = instance;
    var copy = 4u;
    if cfg.period_x != 0u {
        k = instance / 9u;
        copy = instance % 9u;
    }
    let d = darts[k];
    let size = vec2<f32>(f32(cfg.width), f32(cfg.height));
    let shift = vec2<f32>(f32(i32(copy % 3u) - 1), f32(i32(copy / 3u) - 1)) * size;
    let centre = vec2<f32>(f32(d.x), f32(d.y)) / 256.0 + shift;
    // One pixel of margin keeps every pixel centre inside the disk within the quad.
    let extent = f32(d.radius) / 64.0 + 1.0;
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0),
        vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    );
    var out: VsOut;
    out.dart = k;
    let lo = centre - extent;
    let hi = centre + extent;
    if hi.x < 0.0 || hi.y < 0.0 || lo.x > size.x || lo.y > size.y {
        out.pos = vec4<f32>(2.0, 2.0, 0.5, 1.0);
        return out;
    }
    let p = centre + corners[v] * extent;
    out.pos = vec4<f32>(p.x / size.x * 2.0 - 1.0, 1.0 - p.y / size.y * 2.0, 0.5, 1.0);
    return out;
}

@fragment
fn fs_disk(in: VsOut) -> @builtin(frag_depth) f32 {
    let d = darts[in.dart];
    let px = u32(in.pos.x);
    let py = u32(in.pos.y);
    let dx = axis_delta(d.x, pixel_centre(px), cfg.period_x);
    let dy = axis_delta(d.y, pixel_centre(py), cfg.period_y);
    if !inside(dx, dy, d.radius) {
        discard;
    }
    return key_to_depth(dart_key(cfg, in.dart, d.radius));
}
