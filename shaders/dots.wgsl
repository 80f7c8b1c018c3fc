// The app's stipple view. Not part of the sampler: it only displays points.
//
// The dots are not drawn on the screen each frame. A compute pass splats
// them once into a cache, an ink buffer at the screen's resolution that
// sums each pixel's coverage (fixed point, 1/65536), and every frame
// composites that buffer onto the screen as one quad, moved and scaled with
// the view: panning and zooming cost the same at 10K dots and at 2M. The
// cache is splatted again when the drawing changes or the view rests.
//
// Tone-true at every zoom: a dot adds its area's worth of ink, never a whole
// pixel's. A dot thinner than a pixel is drawn as a disc of `r_min` px with
// its ink scaled by the area ratio; coverage sums (the dots of a stipple do
// not overlap), so a pixel under ten dots of a tenth of a pixel each is as
// grey as their area, as the exported PNG's pixels are
// (`stipple::raster::render`).

// ---- The splat (compute) ----------------------------------------------

struct Splat {
    // Image px -> cache px: cache = image * scale + offset (+ the tile's
    // offset, in image px, first).
    offset: vec2<f32>,
    scale: f32,
    // Dots in the layer.
    count: u32,
    // The cache's size in px.
    size: vec2<u32>,
    // Copies of the drawing (a periodic drawing's 2x2 preview): 1 or 4.
    tiles: u32,
    // Dot radius = sample radius * radius_scale + calibrated radius *
    // drawn_scale (image px).
    radius_scale: f32,
    drawn_scale: f32,
    // The smallest disc drawn, cache px.
    r_min: f32,
    // Cache px per exported PNG px, at most 1: the PNG's anti-aliased edge
    // adds pi/12 of its px^2 to each dot of half a px or more; the view
    // shows that ink too (none when zoomed in past the PNG's scale).
    export_px: f32,
    // 1: the layer's dots put down ink, and where they overlap unseen (too
    // small on the screen) the overlap counts once; 0: the coverage disks.
    overlaps: u32,
    // The tiles' offsets in image px (xy, zw: two per entry).
    tile_offsets: array<vec4<f32>, 2>,
    // The ink of overlapping dots over their summed area, at t = dot radius
    // / sample radius = i * OVERLAP_STEP (from the measured ink curve,
    // importance::ink); four per entry.
    overlap: array<vec4<f32>, 16>,
}

struct Dot {
    x: f32,
    y: f32,
    radius: f32,
    drawn: f32,
}

@group(0) @binding(0) var<uniform> splat: Splat;
@group(0) @binding(1) var<storage, read> dots: array<Dot>;
@group(0) @binding(2) var<storage, read_write> ink: array<atomic<u32>>;

// Fixed point of the ink sums: 1.0 = this many units.
const INK_ONE: f32 = 65536.0;

// The step in t of `overlap`'s table.
const OVERLAP_STEP: f32 = 0.02;

fn overlap_at(i: u32) -> f32 {
    return splat.overlap[i / 4u][i % 4u];
}

// The ink of dots of radius t * their sample radius over their summed
// area: 1 while they do not touch, less as they overlap.
fn overlap(t: f32) -> f32 {
    let x = t / OVERLAP_STEP;
    if x >= 63.0 {
        // Past the table the dots cover everything: ink 1 over an area
        // growing as t^2.
        let last = 63.0 * OVERLAP_STEP;
        return overlap_at(63u) * (last * last) / (t * t);
    }
    let i = u32(floor(x));
    return mix(overlap_at(i), overlap_at(i + 1u), x - floor(x));
}

fn tile_offset(t: u32) -> vec2<f32> {
    let v = splat.tile_offsets[t / 2u];
    return select(v.xy, v.zw, (t & 1u) == 1u);
}

// One thread per dot (x) and tile (y): adds the dot's coverage to the
// pixels under it.
@compute @workgroup_size(256)
fn cs_splat(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    let t = id.y;
    if i >= splat.count || t >= splat.tiles {
        return;
    }
    let d = dots[i];
    let r = (d.radius * splat.radius_scale + d.drawn * splat.drawn_scale) * splat.scale;
    if !(r > 0.0) {
        return;
    }
    // The ink to lay, in units of pi px^2: the dot's area, plus the PNG's
    // edge allowance for dots that the PNG draws half a pixel wide or more.
    var target_ink = r * r;
    if r >= 0.5 * splat.export_px {
        target_ink += splat.export_px * splat.export_px / 12.0;
    }
    // A disc of radius R with a one-pixel ramp at its edge lays
    // pi (R^2 + 1/12) on average over the pixel grid: draw the radius that
    // lays the ink, or the smallest disc with its ink scaled down.
    // Overlapping dots put down less ink than their summed area. Where the
    // overlaps are too small to see (dots of half a pixel or less), each
    // dot lays its share of the union; from 2.5 px on, the sum meets its
    // limit (a pixel is at most covered) in the overlaps themselves; in
    // between, a mix (fitted to the exported PNG's tones).
    if splat.overlaps == 1u && d.radius > 0.0 {
        let t = (d.radius * splat.radius_scale + d.drawn * splat.drawn_scale) / d.radius;
        target_ink *= mix(overlap(t), 1.0, clamp((r - 0.5) / 2.0, 0.0, 1.0));
    }
    let floor_ink = splat.r_min * splat.r_min + 1.0 / 12.0;
    var big = splat.r_min;
    var weight = target_ink / floor_ink;
    if target_ink >= floor_ink {
        big = sqrt(target_ink - 1.0 / 12.0);
        weight = 1.0;
    }
    let c = (vec2<f32>(d.x, d.y) + tile_offset(t)) * splat.scale + splat.offset;
    let size = vec2<i32>(splat.size);
    let lo = max(vec2<i32>(floor(c - vec2<f32>(big + 0.5))), vec2<i32>(0));
    let hi = min(vec2<i32>(floor(c + vec2<f32>(big + 0.5))), size - vec2<i32>(1));
    for (var y = lo.y; y <= hi.y; y++) {
        let dy = f32(y) + 0.5 - c.y;
        let row = u32(y) * splat.size.x;
        for (var x = lo.x; x <= hi.x; x++) {
            let dx = f32(x) + 0.5 - c.x;
            let cover = clamp(big + 0.5 - sqrt(dx * dx + dy * dy), 0.0, 1.0) * weight;
            let units = u32(cover * INK_ONE + 0.5);
            if units > 0u {
                atomicAdd(&ink[row + u32(x)], units);
            }
        }
    }
}

// ---- The composite (a quad per layer, every frame) ---------------------

struct Composite {
    // The screen's size in physical px.
    screen: vec2<f32>,
    // Where the cache's corners are on the screen now, physical px.
    quad_min: vec2<f32>,
    quad_max: vec2<f32>,
    // The cache's size in px.
    size: vec2<u32>,
    // Straight RGBA: the ink (the coverage disks' blue and opacity).
    color: vec4<f32>,
}

@group(0) @binding(3) var<uniform> comp: Composite;
@group(0) @binding(4) var<storage, read> cells: array<u32>;

struct QuadOut {
    @builtin(position) pos: vec4<f32>,
    // Cache px.
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_quad(@builtin(vertex_index) v: u32) -> QuadOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0),
        vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
    );
    let k = corners[v];
    let p = mix(comp.quad_min, comp.quad_max, k);
    var out: QuadOut;
    out.pos = vec4<f32>(p.x / comp.screen.x * 2.0 - 1.0, 1.0 - p.y / comp.screen.y * 2.0, 0.0, 1.0);
    out.uv = k * vec2<f32>(comp.size);
    return out;
}

fn cell(x: i32, y: i32) -> f32 {
    let size = vec2<i32>(comp.size);
    let p = clamp(vec2<i32>(x, y), vec2<i32>(0), size - vec2<i32>(1));
    return f32(cells[u32(p.y) * comp.size.x + u32(p.x)]) / INK_ONE;
}

// The summed coverage under a fragment, bilinear between cache pixels
// (exact at rest, when the cache's pixels are the screen's).
fn coverage(uv: vec2<f32>) -> f32 {
    let p = uv - vec2<f32>(0.5);
    let i = vec2<i32>(floor(p));
    let f = p - floor(p);
    let top = mix(cell(i.x, i.y), cell(i.x + 1, i.y), f.x);
    let bottom = mix(cell(i.x, i.y + 1), cell(i.x + 1, i.y + 1), f.x);
    return mix(top, bottom, f.y);
}

// One ink over what is below (premultiplied): the pixel's ink is its
// summed coverage, at most all of it.
@fragment
fn fs_ink(in: QuadOut) -> @location(0) vec4<f32> {
    let a = min(coverage(in.uv), 1.0) * comp.color.a;
    if a <= 0.0 {
        discard;
    }
    return vec4<f32>(comp.color.rgb * a, a);
}

// A colour drawing's pen: its ink multiplies what is below (the render
// model's overprint), blended as src x dst.
@fragment
fn fs_multiply(in: QuadOut) -> @location(0) vec4<f32> {
    let a = min(coverage(in.uv), 1.0) * comp.color.a;
    if a <= 0.0 {
        discard;
    }
    return vec4<f32>(mix(vec3<f32>(1.0), comp.color.rgb, a), 1.0);
}

// The coverage disks (the paper's Figure 4): translucent disks, darker
// where they overlap, as layers of a translucent paint.
@fragment
fn fs_disks(in: QuadOut) -> @location(0) vec4<f32> {
    let v = coverage(in.uv);
    if v <= 0.0 {
        discard;
    }
    let a = 1.0 - pow(1.0 - comp.color.a, v);
    return vec4<f32>(comp.color.rgb * a, a);
}

// ---- Flat rectangles (the canvas, the sheet, the paper) ----------------
//
// egui's own shader costs a software rasterizer (lavapipe) far more per
// pixel than this one: the large flat areas of the canvas go through here.

struct Fills {
    // The screen's size in physical px.
    screen: vec2<f32>,
    count: u32,
    _pad: u32,
    // Left, top, right, bottom in physical px.
    rects: array<vec4<f32>, 8>,
    // Premultiplied RGBA.
    colors: array<vec4<f32>, 8>,
}

@group(0) @binding(5) var<uniform> fills: Fills;

struct FillOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) color: vec4<f32>,
}

@vertex
fn vs_fill(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> FillOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0),
        vec2<f32>(0.0, 1.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
    );
    let r = fills.rects[i];
    let p = mix(r.xy, r.zw, corners[v]);
    var out: FillOut;
    out.pos = vec4<f32>(p.x / fills.screen.x * 2.0 - 1.0, 1.0 - p.y / fills.screen.y * 2.0, 0.0, 1.0);
    out.color = fills.colors[i];
    return out;
}

@fragment
fn fs_fill(in: FillOut) -> @location(0) vec4<f32> {
    return in.color;
}
