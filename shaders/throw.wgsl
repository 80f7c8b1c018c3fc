// Dart throwing (paper §3.1, step S1). CPU mirror: src/sampler/cpu/throw.rs.
//
// `throw_darts` makes dart k from the counter-based hash, on the k-th draw of
// an empty pixel. `vs_disk`/`fs_disk` rasterize the batch into the depth map:
// vertex pulling of an instanced quad per dart (the geometry stage that scales
// disk radii per dart), trimmed to the disk by an exact integer test, with the
// dart's key written as its depth. `select_empty` and `radius_at` come from
// empty.wgsl, appended.

@group(0) @binding(0) var<uniform> cfg: Config;
@group(0) @binding(1) var<storage, read_write> darts: array<Dart>;
@group(0) @binding(2) var<storage, read> coverage: array<u32>;
@group(0) @binding(3) var<storage, read> prefix: array<u32>;
@group(0) @binding(4) var radius_map: texture_2d<u32>;

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
    // With classes `pixel` is a slot; its row within its class's layer.
    d.y = dart_coord((pixel / cfg.width) % cfg.height, (o >> 16u) & mask, cfg.subpixel_bits);
    d.pixel = pixel;
    d.radius = radius_at(pixel);
    darts[k] = d;
}
