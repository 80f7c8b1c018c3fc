// Dart throwing's rasterization (S1) as a compute pass: the path for GPUs that
// shade fragments slowly. Each thread takes one row of one dart's disk, keeping the winning key per pixel with atomicMax on encoded keys
// (see `encode_key`). The set of pixels and the winner per pixel are exactly
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

// Thread (k, row, layer) handles one row of dart k's disk on the key layer of
// class `layer` (wg.z): its own radius on its own class's layer, the cross
// radius on the others (one layer without classes). The key buffer holds
// the strip of stacked rows strip_y0 .. strip_y0 + strip_rows: the whole
// domain, or one chunk of it when the whole exceeds the adapter's largest
// storage binding; rows outside the strip are left to the other strips' passes.
@compute @workgroup_size(256)
fn splat(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = wg.x * 256u + local;
    if k >= cfg.darts {
        return;
    }
    let d = darts[k];
    let value = encode_key(cfg, dart_key(cfg, k, d.radius));
    let layer = wg.z;
    let pixels = cfg.width * cfg.height;
    var radius = d.radius;
    if layer != d.pixel / pixels {
        radius = cross_at(d.pixel % pixels);
    }
    let r = i32(radius << (POS_FRAC_BITS - RADIUS_FRAC_BITS));
    let row = disk_row(cfg, i32(d.x), i32(d.y), r, wg.y);
    let y = layer * cfg.height + u32(row.y);
    if !row.valid || y - cfg.strip_y0 >= cfg.strip_rows {
        return;
    }
    for (var qx = row.x0; qx <= row.x1; qx++) {
        var x = qx;
        if cfg.period_x != 0u {
            x = wrap(qx, cfg.width);
        }
        let p = (y - cfg.strip_y0) * cfg.width + u32(x);
        if atomicLoad(&keys[p]) < value {
            atomicMax(&keys[p], value);
        }
    }
}
