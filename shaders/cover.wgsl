// Coverage (paper §3.2, second half of S2). CPU mirror: src/sampler/cpu/cover.rs.
//
// One thread per survivor and row of its reach; each row's span comes from an
// exact integer square root, and the bits of the coverage map are set a word
// at a time with atomicOr. `cover` marks the pixels whose centre a survivor's
// disk holds; `cover_exact`, exact mode's pixel pass, those whose four
// corners it holds (src/sampler/exact/mod.rs, `cover_band`), in 1/2^F px.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read> survivors: array<Dart>;
@group(0) @binding(2) var<storage, read> survivor_count: array<u32>;
@group(0) @binding(3) var<storage, read_write> coverage: array<atomic<u32>>;
@group(0) @binding(4) var radius_map: texture_2d<u32>;
@group(0) @binding(5) var<uniform> ex: Exact;
// The largest pixel radius within reach of each 8×8 block of the radius map,
// layer by layer (one per class, then the cross radii): pixel mode, Current
// and Bigger, with a map. CPU mirror: `Blocks` in src/sampler/cpu/cover.rs.
@group(0) @binding(6) var<storage, read> near: array<u32>;

fn radius_at(x: u32, y: u32) -> u32 {
    if cfg.uniform_radius != 0u {
        return cfg.uniform_radius;
    }
    return textureLoad(radius_map, vec2<i32>(i32(x), i32(y)), 0).x;
}

// The cross-class radius at (x, y): the rows below the classes' maps.
fn cross_at(x: u32, y: u32) -> u32 {
    return textureLoad(radius_map, vec2<i32>(i32(x), i32(cfg.classes * cfg.height + y)), 0).x;
}

// A row's bits, set a word at a time: `run` holds the word being filled
// and its mask, written with one atomicOr when the row leaves the word.
fn mark(run: ptr<function, vec2<u32>>, p: u32) {
    if (p >> 5u) != (*run).x {
        flush(*run);
        *run = vec2<u32>(p >> 5u, 0u);
    }
    (*run).y |= 1u << (p & 31u);
}

fn flush(run: vec2<u32>) {
    if run.y != 0u {
        atomicOr(&coverage[run.x], run.y);
    }
}

// Thread (k, row, layer) covers row `row` of survivor k's reach on the
// coverage layer of class `layer` (wg.z; one layer without classes): its own
// radius and the class's radii on its own class's layer, the cross radii on
// the others. One row per thread keeps every loop short (llvmpipe caps a
// loop at 65535 iterations) and gives a GPU many small tasks. Dispatched as
// (ceil(darts / 256), rows of the largest reach, classes).
@compute @workgroup_size(256)
fn cover(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = wg.x * 256u + local;
    if k >= survivor_count[0] {
        return;
    }
    let s = survivors[k];
    let layer = wg.z;
    let pixels = cfg.width * cfg.height;
    let own = layer == s.pixel / pixels;
    var radius = s.radius;
    if !own {
        let p = s.pixel % pixels;
        radius = cross_at(p % cfg.width, p / cfg.width);
    }
    var reach = radius;
    if cfg.policy == POLICY_CURRENT || cfg.policy == POLICY_BIGGER {
        if cfg.uniform_radius != 0u {
            reach = max(radius, cfg.max_radius);
        } else {
            // f(r_s, r) for the largest pixel radius r within reach of the
            // centre's block: no pixel farther can be covered.
            let cols = (cfg.width + 7u) / 8u;
            let blocks = cols * ((cfg.height + 7u) / 8u);
            var l = layer;
            if !own {
                l = cfg.classes;
            }
            let b = l * blocks + ((s.y >> POS_FRAC_BITS) / 8u) * cols + (s.x >> POS_FRAC_BITS) / 8u;
            reach = coverage_radius(cfg.policy, radius, near[b]);
        }
    }
    let r = i32(reach << (POS_FRAC_BITS - RADIUS_FRAC_BITS));
    let cx = i32(s.x);
    let row = disk_row(cfg, cx, i32(s.y), r, wg.y);
    if !row.valid {
        return;
    }
    let y = row.y;
    let top = layer * cfg.height;
    let dy = row.dy;
    var run = vec2<u32>(0xffffffffu, 0u);
    for (var qx = row.x0; qx <= row.x1; qx++) {
        var x = qx;
        if cfg.period_x != 0u {
            x = wrap(qx, cfg.width);
        }
        var covered = cfg.policy == POLICY_PRIOR;
        if !covered {
            let dx = u32(abs(qx * 256 + 128 - cx));
            var rp = 0u;
            if own {
                rp = radius_at(u32(x), top + u32(y));
            } else {
                rp = cross_at(u32(x), u32(y));
            }
            let f = coverage_radius(cfg.policy, radius, rp);
            covered = inside(dx, dy, f);
        }
        if covered {
            mark(&run, (top + u32(y)) * cfg.width + u32(x));
        }
    }
    flush(run);
}

// Thread (k, row): row `row` of the pixels that survivor k (in 1/2^F px)
// holds whole. Dispatched as (ceil(darts / 256), rows of the largest reach).
@compute @workgroup_size(256)
fn cover_exact(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = wg.x * 256u + local;
    if k >= survivor_count[0] {
        return;
    }
    let s = survivors[k];
    let shift = ex.frac - RADIUS_FRAC_BITS;
    var reach = s.radius;
    if cfg.policy == POLICY_CURRENT || cfg.policy == POLICY_BIGGER {
        reach = max(s.radius, cfg.max_radius << shift);
    }
    let one = 1 << ex.frac;
    let sx = i32(s.x);
    let sy = i32(s.y);
    let r = i32(reach);
    let qy = ((sy - r) >> ex.frac) + i32(wg.y);
    if qy > (sy + r) >> ex.frac {
        return;
    }
    var y = qy;
    if ex.period_y != 0u {
        y = wrap(qy, cfg.height);
    } else if qy < 0 || qy >= i32(cfg.height) {
        return;
    }
    let dy = u32(max(abs(qy * one - sy), abs(qy * one + one - sy)));
    if dy >= reach {
        return;
    }
    let m = sub64(sub64(mul_wide(reach, reach), mul_wide(dy, dy)), vec2<u32>(1u, 0u));
    let dx_max = i32(isqrt64(m));
    // The pixels whose both x corners lie within dx_max of sx.
    var x0 = (sx - dx_max + one - 1) >> ex.frac;
    var x1 = ((sx + dx_max) >> ex.frac) - 1;
    if ex.period_x == 0u {
        x0 = max(x0, 0);
        x1 = min(x1, i32(cfg.width) - 1);
    }
    var run = vec2<u32>(0xffffffffu, 0u);
    for (var qx = x0; qx <= x1; qx++) {
        var x = qx;
        if ex.period_x != 0u {
            x = wrap(qx, cfg.width);
        }
        var covered = cfg.policy == POLICY_PRIOR;
        if !covered {
            let dx = u32(max(abs(qx * one - sx), abs(qx * one + one - sx)));
            let f = coverage_radius(cfg.policy, s.radius, radius_at(u32(x), u32(y)) << shift);
            covered = lt64(add64(mul_wide(dx, dx), mul_wide(dy, dy)), mul_wide(f, f));
        }
        if covered {
            mark(&run, u32(y) * cfg.width + u32(x));
        }
    }
    flush(run);
}
