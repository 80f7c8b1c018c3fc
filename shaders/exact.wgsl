// Exact mode's iterations (src/sampler/exact/mod.rs: "Darts", "Acceptance",
// "Coverage", "Refinement"), bit-identical to the CPU's, down to the finest
// level; the finest level and repairs run on the CPU (src/gpu/exact.rs).
//
// Positions and radii are in 1/2^F px, distances compared on 64-bit
// integers (mul_wide). Accepted samples are binned in square cells of g px,
// g = ceil(r_max) + 1, as in src/sampler/exact/grid.rs; so are the batch's
// valid darts. Cells are linked lists (index + 1, 0 ends a list), built with
// atomicExchange: their order varies from run to run, but every query below
// is a test over a whole list, so the results never do.
//
// Per iteration:
// * `exact_throw`: dart k (hash, k-th draw of an empty pixel or active cell,
//   F - L-bit offsets),
//   valid when no accepted sample lies within the policy's distance; valid
//   darts join the dart grid.
// * `exact_resolve`, in rounds: the lexicographically first independent set
//   of the valid darts, in dart order. A dart is accepted once every earlier
//   valid dart in conflict with it is refused, refused as soon as one is
//   accepted. States only ever go from undecided to final, and a final state
//   rests on final states only, so the rounds may read states being written.
// * `exact_flags`: the accepted flags for the scan (compact.wgsl), ended by a
//   0; counts the darts still undecided (more rounds run while any is).
// * `exact_gather`: the accepted darts, in dart order, to the survivors and
//   to the sample grid.
// Coverage of pixels by the corner rule is `cover_exact` in cover.wgsl.
// Below the pixel (level L >= 1, cells of 2^(F - L) units):
// * `exact_keep`, then the scan and `exact_pack`: the active cells that no
//   new sample holds whole stay, in order;
// * `exact_split`, the scan and `exact_emit`: refinement, each parent (an
//   empty pixel at level 0) split in four, children in the order (0,0),
//   (1,0), (0,1), (1,1), those that one sample holds whole dropped.
// Cells ping-pong between `cells_in` and `cells_out`.
// `select_empty` and `radius_at` come from empty.wgsl, appended.

// An accepted sample: position and radius in 1/2^F px, and the next sample
// of its grid cell (index + 1, 0 = none).
struct Sample {
    x: u32,
    y: u32,
    r: u32,
    next: u32,
}

const UNDECIDED: u32 = 0u;
const ACCEPTED: u32 = 1u;
const REFUSED: u32 = 2u;

@group(0) @binding(0) var<uniform> cfg: Config;
// Dart.radius in 1/2^F px.
@group(0) @binding(1) var<storage, read_write> darts: array<Dart>;
@group(0) @binding(2) var<storage, read> coverage: array<u32>;
@group(0) @binding(3) var<storage, read> prefix: array<u32>;
@group(0) @binding(4) var radius_map: texture_2d<u32>;
@group(0) @binding(5) var<uniform> ex: Exact;
@group(0) @binding(6) var<storage, read_write> samples: array<Sample>;
// [0, cells): sample heads; [cells, 2 cells): dart heads; then cap dart
// states, cap dart links, and the undecided count.
@group(0) @binding(7) var<storage, read_write> grid: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> flags: array<u32>;
@group(0) @binding(9) var<storage, read_write> survivors: array<Dart>;
@group(0) @binding(10) var<storage, read> cells_in: array<vec2<u32>>;
@group(0) @binding(11) var<storage, read_write> cells_out: array<vec2<u32>>;
// The cells' keep flags or child counts, scanned in place (compact.wgsl).
@group(0) @binding(12) var<storage, read_write> cell_flags: array<u32>;

fn dart_heads() -> u32 {
    return ex.cells;
}

fn states() -> u32 {
    return 2u * ex.cells;
}

fn links() -> u32 {
    return 2u * ex.cells + ex.cap;
}

fn undecided_count() -> u32 {
    return 2u * ex.cells + 2u * ex.cap;
}

// Whether (ax, ay) lies strictly within r of (bx, by), the short way round
// on a torus.
fn within(ax: u32, ay: u32, bx: u32, by: u32, r: u32) -> bool {
    let dx = axis_delta(ax, bx, ex.period_x);
    let dy = axis_delta(ay, by, ex.period_y);
    return lt64(add64(mul_wide(dx, dx), mul_wide(dy, dy)), mul_wide(r, r));
}

// The grid cells along one axis that may hold a sample within reach of
// pixel p: those of pixels p - g ..= p + g, clipped or wrapped, each once.
struct Cells {
    c: array<u32, 8>,
    n: u32,
}

fn axis_cells(p: u32, n: u32, periodic: bool) -> Cells {
    var out: Cells;
    out.n = 0u;
    let g = ex.g;
    if !periodic {
        let a = select(0u, p - g, p >= g) / g;
        let b = min(p + g, n - 1u) / g;
        for (var c = a; c <= b; c++) {
            out.c[out.n] = c;
            out.n += 1u;
        }
        return out;
    }
    var q = i32(p) - i32(g);
    let end = i32(p) + i32(g);
    while q <= end {
        let wq = u32(wrap(q, n));
        let c = wq / g;
        var seen = false;
        for (var i = 0u; i < out.n; i++) {
            seen = seen || out.c[i] == c;
        }
        if !seen && out.n < 8u {
            out.c[out.n] = c;
            out.n += 1u;
        }
        q += i32(min((c + 1u) * g, n) - wq);
    }
    return out;
}

fn cells_near(pixel: u32) -> array<Cells, 2> {
    return array<Cells, 2>(
        axis_cells(pixel % cfg.width, cfg.width, ex.period_x != 0u),
        axis_cells(pixel / cfg.width, cfg.height, ex.period_y != 0u),
    );
}

fn cell_of(pixel: u32) -> u32 {
    return (pixel / cfg.width / ex.g) * ex.cols + (pixel % cfg.width) / ex.g;
}

// Whether no accepted sample lies within the policy's distance of d.
fn free(d: Dart) -> bool {
    let near = cells_near(d.pixel);
    for (var b = 0u; b < near[1].n; b++) {
        for (var a = 0u; a < near[0].n; a++) {
            var i = atomicLoad(&grid[near[1].c[b] * ex.cols + near[0].c[a]]);
            while i != 0u {
                let s = samples[i - 1u];
                if within(s.x, s.y, d.x, d.y, coverage_radius(cfg.policy, s.r, d.radius)) {
                    return false;
                }
                i = s.next;
            }
        }
    }
    return true;
}

@compute @workgroup_size(256)
fn exact_throw(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = thread_index(wg, groups, local);
    if k >= cfg.darts {
        return;
    }
    let h = dart_hash(cfg.iteration_key, k);
    var c: vec2<u32>;
    if ex.level == 0u {
        let p = select_empty(pick(h, cfg.empty));
        c = vec2<u32>(p % cfg.width, p / cfg.width);
    } else {
        c = cells_in[pick(h, ex.live)];
    }
    let o = offset_hash(h);
    let shift = ex.frac - ex.level;
    let mask = (1u << shift) - 1u;
    var d: Dart;
    d.x = (c.x << shift) | (o & mask);
    d.y = (c.y << shift) | ((o >> 16u) & mask);
    let pixel = (d.y >> ex.frac) * cfg.width + (d.x >> ex.frac);
    d.pixel = pixel;
    d.radius = radius_at(pixel) << (ex.frac - RADIUS_FRAC_BITS);
    darts[k] = d;
    if free(d) {
        atomicStore(&grid[states() + k], UNDECIDED);
        let next = atomicExchange(&grid[dart_heads() + cell_of(pixel)], k + 1u);
        atomicStore(&grid[links() + k], next);
    } else {
        atomicStore(&grid[states() + k], REFUSED);
    }
}

@compute @workgroup_size(256)
fn exact_resolve(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = thread_index(wg, groups, local);
    if k >= cfg.darts || atomicLoad(&grid[states() + k]) != UNDECIDED {
        return;
    }
    let d = darts[k];
    let near = cells_near(d.pixel);
    var blocked = false;
    var refused = false;
    for (var b = 0u; b < near[1].n && !refused; b++) {
        for (var a = 0u; a < near[0].n && !refused; a++) {
            let cell = near[1].c[b] * ex.cols + near[0].c[a];
            var j1 = atomicLoad(&grid[dart_heads() + cell]);
            while j1 != 0u && !refused {
                let j = j1 - 1u;
                j1 = atomicLoad(&grid[links() + j]);
                if j >= k {
                    continue;
                }
                let sj = atomicLoad(&grid[states() + j]);
                if sj == REFUSED {
                    continue;
                }
                let e = darts[j];
                if within(e.x, e.y, d.x, d.y, coverage_radius(cfg.policy, e.radius, d.radius)) {
                    refused = sj == ACCEPTED;
                    blocked = true;
                }
            }
        }
    }
    if refused {
        atomicStore(&grid[states() + k], REFUSED);
    } else if !blocked {
        atomicStore(&grid[states() + k], ACCEPTED);
    }
}

@compute @workgroup_size(256)
fn exact_flags(
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
    let s = atomicLoad(&grid[states() + k]);
    flags[k] = select(0u, 1u, s == ACCEPTED);
    if s == UNDECIDED {
        atomicAdd(&grid[undecided_count()], 1u);
    }
}

@compute @workgroup_size(256)
fn exact_gather(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let k = thread_index(wg, groups, local);
    if k >= cfg.darts || flags[k + 1u] == flags[k] {
        return;
    }
    let d = darts[k];
    survivors[flags[k]] = d;
    let i = ex.base + flags[k];
    let next = atomicExchange(&grid[cell_of(d.pixel)], i + 1u);
    samples[i] = Sample(d.x, d.y, d.radius, next);
}

// Whether sample s holds the closed square (x0, y0)-(x1, y1), in a pixel of
// radius r_cell (1/2^F px), strictly within the policy's distance.
fn holds(s: Sample, x0: u32, y0: u32, x1: u32, y1: u32, r_cell: u32) -> bool {
    let f = coverage_radius(cfg.policy, s.r, r_cell);
    let dx = max(axis_delta(x0, s.x, ex.period_x), axis_delta(x1, s.x, ex.period_x));
    let dy = max(axis_delta(y0, s.y, ex.period_y), axis_delta(y1, s.y, ex.period_y));
    return lt64(add64(mul_wide(dx, dx), mul_wide(dy, dy)), mul_wide(f, f));
}

fn r_of_pixel(px: u32, py: u32) -> u32 {
    return radius_at(py * cfg.width + px) << (ex.frac - RADIUS_FRAC_BITS);
}

@compute @workgroup_size(256)
fn exact_keep(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let i = thread_index(wg, groups, local);
    if i == ex.live {
        cell_flags[i] = 0u;
    }
    if i >= ex.live {
        return;
    }
    let c = cells_in[i];
    let shift = ex.frac - ex.level;
    let x0 = c.x << shift;
    let y0 = c.y << shift;
    let x1 = x0 + (1u << shift);
    let y1 = y0 + (1u << shift);
    let px = x0 >> ex.frac;
    let py = y0 >> ex.frac;
    let r_cell = r_of_pixel(px, py);
    let near = cells_near(py * cfg.width + px);
    var covered = false;
    for (var b = 0u; b < near[1].n && !covered; b++) {
        for (var a = 0u; a < near[0].n && !covered; a++) {
            var j = atomicLoad(&grid[near[1].c[b] * ex.cols + near[0].c[a]]);
            while j != 0u && !covered {
                let s = samples[j - 1u];
                covered = j > ex.base && holds(s, x0, y0, x1, y1, r_cell);
                j = s.next;
            }
        }
    }
    cell_flags[i] = select(1u, 0u, covered);
}

@compute @workgroup_size(256)
fn exact_pack(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let i = thread_index(wg, groups, local);
    if i < ex.live && cell_flags[i + 1u] > cell_flags[i] {
        cells_out[cell_flags[i]] = cells_in[i];
    }
}

// Parent i of a refinement, in cells of the current level.
fn parent(i: u32) -> vec2<u32> {
    if ex.level == 0u {
        let p = select_empty(i);
        return vec2<u32>(p % cfg.width, p / cfg.width);
    }
    return cells_in[i];
}

// The children of `c` that no sample holds whole: bit n for child n.
fn kept_children(c: vec2<u32>) -> u32 {
    let shift = ex.frac - ex.level;
    let x0 = c.x << shift;
    let y0 = c.y << shift;
    let half = 1u << (shift - 1u);
    let px = x0 >> ex.frac;
    let py = y0 >> ex.frac;
    let r_cell = r_of_pixel(px, py);
    let near = cells_near(py * cfg.width + px);
    var covered = 0u;
    for (var b = 0u; b < near[1].n && covered != 15u; b++) {
        for (var a = 0u; a < near[0].n && covered != 15u; a++) {
            var j = atomicLoad(&grid[near[1].c[b] * ex.cols + near[0].c[a]]);
            while j != 0u && covered != 15u {
                let s = samples[j - 1u];
                for (var n = 0u; n < 4u; n++) {
                    let cx = x0 + (n % 2u) * half;
                    let cy = y0 + (n / 2u) * half;
                    if holds(s, cx, cy, cx + half, cy + half, r_cell) {
                        covered |= 1u << n;
                    }
                }
                j = s.next;
            }
        }
    }
    return ~covered & 15u;
}

@compute @workgroup_size(256)
fn exact_split(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let i = thread_index(wg, groups, local);
    if i == ex.live {
        cell_flags[i] = 0u;
    }
    if i < ex.live {
        cell_flags[i] = countOneBits(kept_children(parent(i)));
    }
}

@compute @workgroup_size(256)
fn exact_emit(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let i = thread_index(wg, groups, local);
    if i >= ex.live || cell_flags[i + 1u] == cell_flags[i] {
        return;
    }
    let c = parent(i);
    let kept = kept_children(c);
    var at = cell_flags[i];
    for (var n = 0u; n < 4u; n++) {
        if ((kept >> n) & 1u) == 1u {
            cells_out[at] = vec2<u32>(2u * c.x + n % 2u, 2u * c.y + n / 2u);
            at += 1u;
        }
    }
}
