// Dart throwing's rasterization (S1) as a compute pass: the path for GPUs that
// shade fragments slowly. Each thread takes one row of one dart's disk, keeping the winning key per pixel with atomicMax on encoded keys
// (see `encode_key`). The set of pixels and the winner per pixel are exactly
// those of raster.wgsl's depth test. CPU mirror: src/sampler/cpu/throw.rs.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read> darts: array<Dart>;
@group(0) @binding(2) var<storage, read_write> keys: array<atomic<u32>>;

// Thread (k, row) handles one row of dart k's disk, as in cover.wgsl. The key
// buffer holds the strip of rows strip_y0 .. strip_y0 + strip_rows: the whole
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
    let r = i32(d.radius << (POS_FRAC_BITS - RADIUS_FRAC_BITS));
    let row = disk_row(cfg, i32(d.x), i32(d.y), r, wg.y);
    if !row.valid || u32(row.y) - cfg.strip_y0 >= cfg.strip_rows {
        return;
    }
    for (var qx = row.x0; qx <= row.x1; qx++) {
        var x = qx;
        if cfg.period_x != 0u {
            x = wrap(qx, cfg.width);
        }
        let p = (u32(row.y) - cfg.strip_y0) * cfg.width + u32(x);
        if atomicLoad(&keys[p]) < value {
            atomicMax(&keys[p], value);
        }
    }
}
