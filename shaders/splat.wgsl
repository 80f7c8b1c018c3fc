// Dart throwing's rasterization (S1) as a compute pass: the path for GPUs that
// shade fragments slowly. Each thread takes one row of one dart's disk, keeping the winning key per pixel with atomicMax on encoded keys
// (see `encode_key`). The set of pixels and the winner per pixel are exactly
// those of raster.wgsl's depth test. CPU mirror: src/sampler/cpu/throw.rs.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read> darts: array<Dart>;
@group(0) @binding(2) var<storage, read_write> keys: array<atomic<u32>>;

// Thread (k, row) handles one row of dart k's disk, as in cover.wgsl.
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
    let cx = i32(d.x);
    let cy = i32(d.y);
    let periodic = cfg.period_x != 0u;
    let qy = -((-(cy - r + 1 - 128)) >> 8u) + i32(wg.y);
    if qy > (cy + r - 1 - 128) >> 8u {
        return;
    }
    var y = qy;
    if periodic {
        y = wrap(qy, cfg.height);
    } else if qy < 0 || qy >= i32(cfg.height) {
        return;
    }
    let dy = u32(abs(qy * 256 + 128 - cy));
    let m = sub64(sub64(mul_wide(u32(r), u32(r)), mul_wide(dy, dy)), vec2<u32>(1u, 0u));
    let dx_max = i32(isqrt64(m));
    var x0 = -((-(cx - dx_max - 128)) >> 8u);
    var x1 = (cx + dx_max - 128) >> 8u;
    if !periodic {
        x0 = max(x0, 0);
        x1 = min(x1, i32(cfg.width) - 1);
    }
    for (var qx = x0; qx <= x1; qx++) {
        var x = qx;
        if periodic {
            x = wrap(qx, cfg.width);
        }
        let p = u32(y) * cfg.width + u32(x);
        if atomicLoad(&keys[p]) < value {
            atomicMax(&keys[p], value);
        }
    }
}
