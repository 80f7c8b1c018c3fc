// Dart throwing (paper §3.1, step S1). CPU mirror: src/sampler/cpu/throw.rs.
//
// `throw_darts` makes dart k from the counter-based hash, on the k-th draw of
// an empty pixel. `vs_disk`/`fs_disk` rasterize the batch into the depth map:
// vertex pulling of an instanced quad per dart (the geometry stage that scales
// disk radii per dart), trimmed to the disk by an exact integer test, with the
// dart's key written as its depth.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read_write> darts: array<Dart>;
@group(0) @binding(2) var<storage, read> coverage: array<u32>;
@group(0) @binding(3) var<storage, read> prefix: array<u32>;
@group(0) @binding(4) var radius_map: texture_2d<u32>;

// The i-th empty pixel in index order: a binary search of the scanned empty
// counts per coverage word, then a select within the word.
fn select_empty(i: u32) -> u32 {
    if cfg.first == 1u {
        return i;
    }
    var lo = 0u;
    var hi = cfg.words;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if prefix[mid] <= i {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    var r = i - prefix[lo];
    let bits = coverage[lo];
    let total = cfg.width * cfg.height;
    for (var j = 0u; j < 32u; j++) {
        let p = lo * 32u + j;
        if p < total && ((bits >> j) & 1u) == 0u {
            if r == 0u {
                return p;
            }
            r -= 1u;
        }
    }
    return lo * 32u;
}

fn radius_at(pixel: u32) -> u32 {
    if cfg.uniform_radius != 0u {
        return cfg.uniform_radius;
    }
    let xy = vec2<i32>(i32(pixel % cfg.width), i32(pixel / cfg.width));
    return textureLoad(radius_map, xy, 0).x;
}

@compute @workgroup_size(256)
fn throw_darts(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = thread_index(wg, groups, local);
    if k >= cfg.darts {
        return;
    }
    let h = dart_hash(cfg.iteration_key, k);
    let pixel = select_empty(pick(h, cfg.empty));
    let o = offset_hash(h);
    let mask = (1u << cfg.subpixel_bits) - 1u;
    var d: Dart;
    d.x = dart_coord(pixel % cfg.width, o & mask, cfg.subpixel_bits);
    d.y = dart_coord(pixel / cfg.width, (o >> 16u) & mask, cfg.subpixel_bits);
    d.pixel = pixel;
    d.radius = radius_at(pixel);
    darts[k] = d;
}
