// Shared by every PixelPie shader (prepended at pipeline creation): the run's
// configuration, the dart struct, 64-bit helpers and the integer arithmetic of
// `src/sampler/fixed.rs`, function for function.

// Mirrors `gpu::Config` in src/gpu/mod.rs.
struct Config {
    width: u32,
    height: u32,
    period_x: u32,      // 1/256 px, 0 = not periodic
    period_y: u32,
    policy: u32,        // 0 prior, 1 current, 2 bigger, 3 smaller
    subpixel_bits: u32,
    index_bits: u32,
    radius_bits: u32,
    min_radius: u32,    // 1/64 px
    max_radius: u32,    // 1/64 px
    uniform_radius: u32,// 1/64 px, 0 = read the radius map
    iteration_key: u32,
    empty: u32,         // empty pixels
    darts: u32,         // darts this iteration
    first: u32,         // 1 = every pixel is empty (the first iteration)
    words: u32,         // coverage words, ceil(width * height / 32)
    splat: u32,         // 1 = S1 rasterized by splat.wgsl into a key buffer
    strip_y0: u32,      // the key buffer holds rows strip_y0 ..
    strip_rows: u32,    // .. strip_y0 + strip_rows (all rows unless chunked)
    classes: u32,       // classes: slot = class * width * height + pixel
}

// Mirrors `sampler::Dart` (src/sampler/run.rs).
struct Dart {
    x: u32,
    y: u32,
    pixel: u32,
    radius: u32,
}

// Exact mode's configuration (exact.wgsl, cover.wgsl). Mirrors
// `gpu::exact::ExactConfig`.
struct Exact {
    frac: u32,      // F
    g: u32,         // grid cell side in pixels
    cols: u32,      // grid cells per row
    cells: u32,     // grid cells
    cap: u32,       // darts the state arrays hold
    base: u32,      // samples accepted before this iteration
    period_x: u32,  // 1/2^F px, 0 = not periodic
    period_y: u32,
    level: u32,     // the cells' level: 0 = pixels
    live: u32,      // level >= 1: active cells; in a refinement: its parents
    pad0: u32,
    pad1: u32,
}

const POS_FRAC_BITS: u32 = 8u;
const RADIUS_FRAC_BITS: u32 = 6u;
const POLICY_PRIOR: u32 = 0u;
const POLICY_CURRENT: u32 = 1u;
const POLICY_BIGGER: u32 = 2u;
const POLICY_SMALLER: u32 = 3u;

fn mix(x0: u32) -> u32 {
    var x = x0;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

fn dart_hash(iteration_key: u32, dart: u32) -> u32 {
    return mix(iteration_key ^ mix(dart ^ 0x27d4eb2fu));
}

fn offset_hash(h: u32) -> u32 {
    return mix(h ^ 0x68e31da4u);
}

// 64-bit unsigned integers as vec2(lo, hi).
fn mul_wide(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xffffu;
    let a1 = a >> 16u;
    let b0 = b & 0xffffu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let p11 = a1 * b1;
    let mid = (p00 >> 16u) + (p01 & 0xffffu) + (p10 & 0xffffu);
    let lo = (p00 & 0xffffu) | (mid << 16u);
    let hi = p11 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u);
    return vec2<u32>(lo, hi);
}

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

fn lt64(a: vec2<u32>, b: vec2<u32>) -> bool {
    return a.y < b.y || (a.y == b.y && a.x < b.x);
}

fn pick(hash: u32, n: u32) -> u32 {
    return mul_wide(hash, n).y;
}

fn dart_coord(p: u32, o: u32, bits: u32) -> u32 {
    return (p << POS_FRAC_BITS) + ((2u * o + 1u) << (POS_FRAC_BITS - 1u - bits));
}

fn pixel_centre(p: u32) -> u32 {
    return (p << POS_FRAC_BITS) + (1u << (POS_FRAC_BITS - 1u));
}

fn axis_delta(a: u32, b: u32, period: u32) -> u32 {
    let d = max(a, b) - min(a, b);
    if period != 0u && period - d < d {
        return period - d;
    }
    return d;
}

fn inside(dx: u32, dy: u32, r_fx: u32) -> bool {
    let r = r_fx << (POS_FRAC_BITS - RADIUS_FRAC_BITS);
    return lt64(add64(mul_wide(dx, dx), mul_wide(dy, dy)), mul_wide(r, r));
}

fn dart_key(cfg: Config, index: u32, radius: u32) -> u32 {
    if cfg.radius_bits == 0u {
        return index;
    }
    return ((radius - cfg.min_radius) << cfg.index_bits) | index;
}

fn key_to_depth(key: u32) -> f32 {
    return bitcast<f32>(0x00800000u + key);
}

fn depth_to_key(depth: f32) -> u32 {
    return bitcast<u32>(depth) - 0x00800000u;
}

fn coverage_radius(policy: u32, r_sample: u32, r_pixel: u32) -> u32 {
    switch policy {
        case 0u: { return r_sample; }
        case 1u: { return r_pixel; }
        case 2u: { return max(r_sample, r_pixel); }
        default: { return min(r_sample, r_pixel); }
    }
}

fn sub64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    return vec2<u32>(a.x - b.x, a.y - b.y - select(0u, 1u, a.x < b.x));
}

// The flat index of a workgroup in a 2D grid of them.
fn block_index(wg: vec3<u32>, groups: vec3<u32>) -> u32 {
    return wg.y * groups.x + wg.x;
}

// The flat index of a thread in a 2D grid of 256-thread workgroups.
fn thread_index(wg: vec3<u32>, groups: vec3<u32>, local: u32) -> u32 {
    return block_index(wg, groups) * 256u + local;
}

// The largest d with d * d <= m.
fn isqrt64(m: vec2<u32>) -> u32 {
    var d = u32(sqrt(f32(m.y) * 4294967296.0 + f32(m.x)));
    while lt64(m, mul_wide(d, d)) {
        d -= 1u;
    }
    while !lt64(m, mul_wide(d + 1u, d + 1u)) {
        d += 1u;
    }
    return d;
}

fn wrap(q: i32, n: u32) -> i32 {
    let m = i32(n);
    return ((q % m) + m) % m;
}

// A key as stored by splat.wgsl: the winner is always the largest value, and
// 0 (a cleared buffer) loses to every dart.
fn encode_key(cfg: Config, key: u32) -> u32 {
    if cfg.policy == POLICY_CURRENT || cfg.policy == POLICY_BIGGER {
        return key + 1u;
    }
    return (1u << 29u) - key;
}

// Row `row` (counted from the top) of the pixels whose centres lie strictly
// within r (1/256 px) of (cx, cy): the row and its x range, wrapped or
// clipped to the domain. Shared by cover.wgsl and splat.wgsl, which give
// each row to its own thread.
struct DiskRow {
    valid: bool,
    y: i32,
    dy: u32,
    x0: i32,
    x1: i32,
}

fn disk_row(cfg: Config, cx: i32, cy: i32, r: i32, row: u32) -> DiskRow {
    var out: DiskRow;
    out.valid = false;
    let qy = -((-(cy - r + 1 - 128)) >> 8u) + i32(row);
    if qy > (cy + r - 1 - 128) >> 8u {
        return out;
    }
    let periodic = cfg.period_x != 0u;
    out.y = qy;
    if periodic {
        out.y = wrap(qy, cfg.height);
    } else if qy < 0 || qy >= i32(cfg.height) {
        return out;
    }
    out.dy = u32(abs(qy * 256 + 128 - cy));
    let m = sub64(sub64(mul_wide(u32(r), u32(r)), mul_wide(out.dy, out.dy)), vec2<u32>(1u, 0u));
    let dx_max = i32(isqrt64(m));
    out.x0 = -((-(cx - dx_max - 128)) >> 8u);
    out.x1 = (cx + dx_max - 128) >> 8u;
    if !periodic {
        out.x0 = max(out.x0, 0);
        out.x1 = min(out.x1, i32(cfg.width) - 1);
    }
    out.valid = true;
    return out;
}
