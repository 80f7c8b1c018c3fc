// The implicit empty-pixel list and the radius map, as dart throwing reads
// them: appended to throw.wgsl and exact.wgsl, which both declare `cfg`,
// `coverage`, `prefix` and `radius_map`.

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
    let total = cfg.width * cfg.height * cfg.classes;
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

// The radius of a pixel, or of a slot (classes stack their maps' rows).
fn radius_at(pixel: u32) -> u32 {
    if cfg.uniform_radius != 0u {
        return cfg.uniform_radius;
    }
    let xy = vec2<i32>(i32(pixel % cfg.width), i32(pixel / cfg.width));
    return textureLoad(radius_map, xy, 0).x;
}
