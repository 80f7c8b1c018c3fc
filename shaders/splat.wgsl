// Dart throwing's rasterization (S1) as a compute pass: the path for GPUs that
// shade fragments slowly. A thread takes one row of one dart's disk (`splat`),
// or the lanes of a warp share one dart's rows (`splat_coalesced`), keeping
// the winning key per pixel with atomicMax on encoded keys (see `encode_key`). The set of pixels and the winner per pixel are exactly
// those of raster.wgsl's depth test. CPU mirror: src/sampler/cpu/throw.rs.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read> darts: array<Dart>;
@group(0) @binding(2) var<storage, read_write> keys: array<atomic<u32>>;
@group(0) @binding(3) var radius_map: texture_2d<u32>;

// The cross-class radius at pixel `p`: the rows below the classes' maps.
fn cross_at(p: u32) -> u32 {
    let xy = vec2<i32>(i32(p % cfg.width), i32(cfg.classes * cfg.height + p / cfg.width));
    return textureLoad(radius_map, xy, 0).x;
}

// What dart k writes on the key layer of class `layer`: its key, and its
// radius there (its own on its own class's layer, the cross radius on the
// others; one layer without classes) in 1/256 px.
struct SplatDart {
    d: Dart,
    value: u32,
    r: i32,
}

fn splat_dart(k: u32, layer: u32) -> SplatDart {
    var out: SplatDart;
    out.d = darts[k];
    out.value = encode_key(cfg, dart_key(cfg, k, out.d.radius));
    let pixels = cfg.width * cfg.height;
    var radius = out.d.radius;
    if layer != out.d.pixel / pixels {
        radius = cross_at(out.d.pixel % pixels);
    }
    out.r = i32(radius << (POS_FRAC_BITS - RADIUS_FRAC_BITS));
    return out;
}

// Pixels first, first + step, … of row `row` of the disk of `s` on layer
// `layer`. The key buffer holds the strip of stacked rows strip_y0 ..
// strip_y0 + strip_rows: the whole domain, or one chunk of it when the
// whole exceeds the adapter's largest storage binding; rows outside the
// strip are left to the other strips' passes.
fn splat_row(s: SplatDart, layer: u32, row: u32, first: u32, step: u32) {
    let span = disk_row(cfg, i32(s.d.x), i32(s.d.y), s.r, row);
    let y = layer * cfg.height + u32(span.y);
    if !span.valid || y - cfg.strip_y0 >= cfg.strip_rows {
        return;
    }
    for (var qx = span.x0 + i32(first); qx <= span.x1; qx += i32(step)) {
        var x = qx;
        if cfg.period_x != 0u {
            x = wrap(qx, cfg.width);
        }
        let p = (y - cfg.strip_y0) * cfg.width + u32(x);
        if atomicLoad(&keys[p]) < s.value {
            atomicMax(&keys[p], s.value);
        }
    }
}

// The compute path: thread (k, row, layer) takes one row (wg.y) of dart k's
// disk on layer wg.z, pixel by pixel.
@compute @workgroup_size(256)
fn splat(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = wg.x * 256u + local;
    if k >= cfg.darts {
        return;
    }
    splat_row(splat_dart(k, wg.z), wg.z, wg.y, 0u, 1u);
}

// The lanes that share one dart on the coalesced path: the disk's widest
// row (2 ceil(r) + 1 pixels) rounded up to a power of two, at most 32.
// Mirrors `gpu::util::splat_lanes`, which sizes the dispatch.
fn splat_lanes() -> u32 {
    let width = 2u * ((cfg.max_radius + (1u << RADIUS_FRAC_BITS) - 1u) >> RADIUS_FRAC_BITS) + 1u;
    var lanes = 1u;
    while lanes < width && lanes < 32u {
        lanes = lanes * 2u;
    }
    return lanes;
}

// The coalesced path: the lanes of dart k (k and lane from the flattened
// x-y grid) walk every row of its disk on layer wg.z together, lane l taking
// pixels l, l + lanes, …, so that neighbouring threads write neighbouring
// keys (a cache line or two per row, not one per thread).
@compute @workgroup_size(256)
fn splat_coalesced(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let lanes = splat_lanes();
    let k = block_index(wg, groups) * (256u / lanes) + local / lanes;
    if k >= cfg.darts {
        return;
    }
    let s = splat_dart(k, wg.z);
    // 2 ceil(r) + 2 rows, as `gpu::util::disk_rows`.
    let rows = 2u * ((u32(s.r) + (1u << POS_FRAC_BITS) - 1u) >> POS_FRAC_BITS) + 2u;
    for (var row = 0u; row < rows; row++) {
        splat_row(s, wg.z, row, local % lanes, lanes);
    }
}
