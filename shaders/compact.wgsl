// Post-processing (paper §3.3, step PP). CPU mirror: src/sampler/cpu/compact.rs.
//
// The paper compacts the empty-pixel list with Thrust. Here the ordered list
// is kept implicit: `count_words` counts the empty pixels of each 32-pixel
// coverage word and `scan_blocks`/`add_sums` turn the counts into an exclusive
// prefix sum, so the i-th empty pixel (in index order, as compaction keeps it)
// is found by a binary search in throw.wgsl. The same scan gathers survivors.

struct ScanInfo {
    n: u32,
    words: u32,
    pixels: u32,
    pad: u32,
}

@group(0) @binding(0) var<uniform> info: ScanInfo;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> sums: array<u32>;

var<workgroup> partial: array<u32, 256>;

// data = coverage words in, empty counts out (in place).
@compute @workgroup_size(256)
fn count_words(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let w = block_index(wg, groups) * 256u + local;
    if w >= info.words {
        return;
    }
    var valid = 0xffffffffu;
    let left = info.pixels - w * 32u;
    if left < 32u {
        valid = (1u << left) - 1u;
    }
    sums[w] = countOneBits(~data[w] & valid);
}

// An exclusive scan of 1024 elements per workgroup; the block's total goes to sums.
@compute @workgroup_size(256)
fn scan_blocks(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let block = block_index(wg, groups);
    let base = block * 1024u + local * 4u;
    var v = array<u32, 4>(0u, 0u, 0u, 0u);
    var total = 0u;
    for (var i = 0u; i < 4u; i++) {
        var x = 0u;
        if base + i < info.n {
            x = data[base + i];
        }
        v[i] = total;
        total += x;
    }
    partial[local] = total;
    workgroupBarrier();
    for (var off = 1u; off < 256u; off <<= 1u) {
        var t = 0u;
        if local >= off {
            t = partial[local - off];
        }
        workgroupBarrier();
        partial[local] += t;
        workgroupBarrier();
    }
    let before = partial[local] - total;
    for (var i = 0u; i < 4u; i++) {
        if base + i < info.n {
            data[base + i] = v[i] + before;
        }
    }
    if local == 255u {
        sums[block] = partial[255];
    }
}

// Adds each block's scanned offset to its 1024 elements.
@compute @workgroup_size(256)
fn add_sums(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let block = block_index(wg, groups);
    let add = sums[block];
    let base = block * 1024u + local * 4u;
    for (var i = 0u; i < 4u; i++) {
        if base + i < info.n {
            data[base + i] += add;
        }
    }
}
