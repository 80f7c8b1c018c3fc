// Conflict removal (paper §3.2, step S2). CPU mirror: src/sampler/cpu/cull.rs.
//
// `cull` flags the darts whose key won the depth test at the centre of their
// own pixel (read from the depth map, or from splat.wgsl's key buffer, one
// strip of rows at a time when it is chunked) and ends the flags with a 0;
// after the flags are scanned (compact.wgsl), `gather` writes each survivor,
// a dart whose offset differs from the next one, in dart order.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read> darts: array<Dart>;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> flags: array<u32>;
@group(0) @binding(4) var<storage, read_write> survivors: array<Dart>;
@group(0) @binding(5) var<storage, read> splat_keys: array<u32>;

fn survives(k: u32) -> bool {
    let d = darts[k];
    let key = dart_key(cfg, k, d.radius);
    if cfg.splat == 1u {
        return splat_keys[d.pixel - cfg.strip_y0 * cfg.width] == encode_key(cfg, key);
    }
    let xy = vec2<i32>(i32(d.pixel % cfg.width), i32(d.pixel / cfg.width));
    return depth_to_key(textureLoad(depth, xy, 0).x) == key;
}

@compute @workgroup_size(256)
fn cull(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = thread_index(wg, groups, local);
    if k == cfg.darts {
        flags[k] = 0u;
    }
    if k >= cfg.darts {
        return;
    }
    let y = darts[k].pixel / cfg.width;
    if cfg.splat == 0u || y - cfg.strip_y0 < cfg.strip_rows {
        flags[k] = select(0u, 1u, survives(k));
    }
}

@compute @workgroup_size(256)
fn gather(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = thread_index(wg, groups, local);
    if k < cfg.darts && flags[k + 1u] > flags[k] {
        survivors[flags[k]] = darts[k];
    }
}
