// The app's stipple view: one instanced, anti-aliased disk per dot, drawn by
// an egui_wgpu paint callback into egui's render pass. Not part of the
// sampler: it only displays points.

struct View {
    // Callback rectangle size in points, image-to-screen scale and offset
    // (screen = image * scale + offset, in points relative to the rectangle).
    rect: vec2<f32>,
    scale: f32,
    pixels_per_point: f32,
    offset: vec2<f32>,
    radius_scale: f32,   // dot radius = sample radius * radius_scale
    drawn_scale: f32,    //            + calibrated radius * drawn_scale (image px)
    color: vec4<f32>,
}

struct Dot {
    x: f32,
    y: f32,
    radius: f32,
    drawn: f32,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<storage, read> dots: array<Dot>;

struct VsOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) local: vec2<f32>,
    @location(1) @interpolate(flat) radius_px: f32,
}

@vertex
fn vs_dot(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VsOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0),
        vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    );
    let d = dots[i];
    let r = d.radius * view.radius_scale + d.drawn * view.drawn_scale;
    // Radius on screen in physical pixels, at least half a pixel, plus one
    // pixel of margin for the anti-aliased edge.
    let r_px = max(r * view.scale * view.pixels_per_point, 0.5);
    let extent = (r_px + 1.0) / view.pixels_per_point;
    let centre = vec2<f32>(d.x, d.y) * view.scale + view.offset;
    let p = centre + corners[v] * extent;
    var out: VsOut;
    out.pos = vec4<f32>(p.x / view.rect.x * 2.0 - 1.0, 1.0 - p.y / view.rect.y * 2.0, 0.0, 1.0);
    out.local = corners[v] * (r_px + 1.0);
    out.radius_px = r_px;
    return out;
}

@fragment
fn fs_dot(in: VsOut) -> @location(0) vec4<f32> {
    let coverage = clamp(in.radius_px + 0.5 - length(in.local), 0.0, 1.0);
    if coverage <= 0.0 {
        discard;
    }
    return vec4<f32>(view.color.rgb * view.color.a * coverage, view.color.a * coverage);
}

// A colour drawing's pens: the ink multiplies what is below (the render
// model's overprint), blended as src × dst; the partly covered edge mixes
// paper and ink.
@fragment
fn fs_dot_multiply(in: VsOut) -> @location(0) vec4<f32> {
    let coverage = clamp(in.radius_px + 0.5 - length(in.local), 0.0, 1.0);
    if coverage <= 0.0 {
        discard;
    }
    return vec4<f32>(mix(vec3<f32>(1.0), view.color.rgb, coverage * view.color.a), 1.0);
}
