//! Weighted Lloyd relaxation: weighted Voronoi stippling (Secord 2002, the
//! algorithm of StippleGen).
//!
//! Each iteration moves every point to the darkness-weighted centroid of its
//! Voronoi cell. Cells are restricted to pixel centres: pixel `(x, y)`, centre
//! `(x + 0.5, y + 0.5)`, belongs to the point nearest to that centre, and the
//! centroid is the weighted mean of the centres of the cell's pixels.
//!
//! # How the Voronoi diagram is computed
//!
//! Exactly (every weighted pixel goes to its nearest point, ties to the point
//! with the lowest index), without visiting most pixels one by one:
//!
//! - Each iteration puts the points in a k-d tree.
//! - The image is cut into 16×16 tiles. For each tile, the tree gives `s1`, the
//!   point nearest to the tile's centre, and then every point that is at least
//!   as near as `s1` to one of the tile's corners. Those are exactly the points
//!   that can own a pixel of the tile: `|q - p|² - |q - s1|²` is linear in `q`,
//!   so if `p` beats `s1` anywhere in the tile it does at a corner. The tree
//!   prunes its boxes by the same test, so the search stays short whether the
//!   points are dense, sparse or far away from the tile.
//! - If only `s1` is left, the whole tile is its, and the tile's weight
//!   moments `[Σw, Σw·x, Σw·y]` come from a precomputed pyramid (4×4 to 16×16
//!   blocks) in O(1). Otherwise the tile is split in four and each quarter
//!   prunes the list again against its own nearest candidate, down to 4×4
//!   blocks whose pixels are assigned one by one.
//! - Tiles and blocks of zero weight are skipped at once: white paper costs
//!   nothing.
//!
//! Rows of tiles run in parallel with rayon; each produces its partial sums
//! (`Σw`, `Σw·dx`, `Σw·dy` per point, in `f64`, `dx` relative to the point) in
//! a fixed order, and these are added up row by row, so the result is the same
//! bit for bit whatever the number of threads.
//!
//! In periodic mode distances wrap around the domain (a torus): the tree is
//! searched for the points' images in the eight neighbouring copies of the
//! domain too, pixel offsets are taken from the nearest image of the point
//! (so they lie in `(-W/2, W/2] × (-H/2, H/2]`), and the new position is
//! wrapped back into `[0, W) × [0, H)`.
//!
//! With 100 000 points on 3200×2400 pixels, an iteration takes about 0.1 s on
//! two cores.

use rayon::prelude::*;
use std::borrow::Cow;

/// The pyramid's finest level: blocks of 4×4 pixels, assigned pixel by pixel
/// when more than one point may own them.
const LEAF_LEVEL: u32 = 2;
/// The coarsest level: the 16×16 tiles whose candidates come from the k-d tree.
const TOP_LEVEL: u32 = 4;
/// The most points in a leaf of the k-d tree.
const TREE_LEAF: usize = 8;

/// A darkness (weight) field on the pixel grid: `weights[y * width + x] >= 0`, finite.
#[derive(Clone, Copy, Debug)]
pub struct Density<'a> {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major weights, `width * height` of them.
    pub weights: &'a [f32],
}

/// Options.
#[derive(Clone, Copy, Debug)]
pub struct RelaxOptions {
    /// Lloyd iterations.
    pub iterations: u32,
    /// Distances wrap around the domain (torus); centroids wrap too.
    pub periodic: bool,
}

/// Checks a density: `width` and `height` > 0, `width * height` weights, all
/// finite and >= 0. The error is a one-line message.
pub fn check(density: &Density<'_>) -> Result<(), String> {
    let (w, h) = (density.width, density.height);
    if w == 0 || h == 0 {
        return Err(format!("density is {w}×{h}: width and height must be > 0"));
    }
    let expected = u64::from(w) * u64::from(h);
    if density.weights.len() as u64 != expected {
        let len = density.weights.len();
        return Err(format!(
            "density has {len} weights, expected {w}×{h} = {expected}"
        ));
    }
    match density
        .weights
        .iter()
        .position(|v| !(v.is_finite() && *v >= 0.0))
    {
        Some(i) => {
            let (x, y, v) = (i % w as usize, i / w as usize, density.weights[i]);
            Err(format!(
                "weight at pixel ({x}, {y}) is {v}: weights must be finite and >= 0"
            ))
        }
        None => Ok(()),
    }
}

/// Moves each point to the darkness-weighted centroid of its Voronoi cell
/// (cells restricted to pixel centres: pixel (x,y) has centre (x+0.5, y+0.5)),
/// `options.iterations` times. Points are (x, y) in pixel units, 0..width, 0..height.
///
/// A point whose cell has zero total weight stays where it is (so does a point
/// with a non-finite coordinate, which owns no pixel).
/// `progress(done_iterations)` is called after each iteration; if it returns false,
/// relaxation stops early and returns the points as they are then.
///
/// Deterministic: the same input gives the same output bit for bit whatever
/// the number of rayon threads.
///
/// Call [`check`] first: here, weights that are negative or not finite count
/// as zero, and a density with no pixels or the wrong number of weights
/// returns the points unchanged without calling `progress`.
pub fn relax(
    points: &[[f32; 2]],
    density: &Density<'_>,
    options: RelaxOptions,
    mut progress: impl FnMut(u32) -> bool,
) -> Vec<[f32; 2]> {
    let mut current = points.to_vec();
    let Some(field) = Field::new(density) else {
        return current;
    };
    for done in 1..=options.iterations {
        current = lloyd_step(&current, &field, options.periodic);
        if !progress(done) {
            break;
        }
    }
    current
}

/// `n` points drawn at random with probability proportional to the weights
/// (CDF inversion), positions uniform inside the chosen pixel, from `seed`
/// (deterministic). This is the "random start" of StippleGen's method, used as
/// the baseline the project compares against.
///
/// Weights that are negative or not finite count as zero. If no weight is
/// positive (or the density has the wrong number of weights), the points are
/// uniform over the domain.
pub fn random_start(n: usize, density: &Density<'_>, seed: u64) -> Vec<[f32; 2]> {
    let (w, h) = (density.width as usize, density.height as usize);
    let cdf = Cdf::new(density);
    (0..n as u64)
        .map(|i| {
            let u = |j: u64| unit(seed, 3 * i + j);
            match &cdf {
                Some(cdf) => {
                    let pixel = cdf.pick(u(0));
                    [in_cell(pixel % w, u(1)), in_cell(pixel / w, u(2))]
                }
                None => [(u(1) * w as f64) as f32, (u(2) * h as f64) as f32],
            }
        })
        .collect()
}

/// `cell + u` as `f32`, kept below `cell + 1` (`u` in `[0, 1)`).
fn in_cell(cell: usize, u: f64) -> f32 {
    let end = (cell + 1) as f32;
    let v = (cell as f64 + u) as f32;
    if v >= end { end.next_down() } else { v }
}

/// The splitmix64 finaliser: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniform number in `[0, 1)` from the counter `(seed, i)`.
fn unit(seed: u64, i: u64) -> f64 {
    let h = mix(mix(seed ^ 0x9e37_79b9_7f4a_7c15).wrapping_add(i));
    (h >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Cumulative weights over the pixels in row-major order.
struct Cdf {
    /// `sums[i]`: the sum of the weights of pixels `0..=i`.
    sums: Vec<f64>,
    /// The last pixel with a positive weight.
    last: usize,
}

impl Cdf {
    /// `None` if the density is malformed or has no positive weight.
    fn new(density: &Density<'_>) -> Option<Cdf> {
        let len = density.width as usize * density.height as usize;
        if len == 0 || density.weights.len() != len {
            return None;
        }
        let mut total = 0.0f64;
        let mut last = None;
        let sums = (density.weights.iter().enumerate())
            .map(|(i, &v)| {
                if v.is_finite() && v > 0.0 {
                    total += f64::from(v);
                    last = Some(i);
                }
                total
            })
            .collect();
        last.map(|last| Cdf { sums, last })
    }

    /// The pixel whose weight interval holds `u * total` (`u` in `[0, 1)`).
    fn pick(&self, u: f64) -> usize {
        let target = u * self.sums[self.last];
        self.sums.partition_point(|&s| s <= target).min(self.last)
    }
}

/// The weights, checked, with their pyramid of block moments.
struct Field<'a> {
    /// Width in pixels.
    width: usize,
    /// Height in pixels.
    height: usize,
    /// Row-major weights, all finite and >= 0.
    weights: Cow<'a, [f32]>,
    /// Levels `LEAF_LEVEL..=TOP_LEVEL`, finest first.
    levels: Vec<Level>,
}

/// Moments `[Σw, Σw·x, Σw·y]` (pixel centres) of the aligned square blocks of
/// one size, clipped to the image.
struct Level {
    /// Blocks per row.
    cols: usize,
    /// Row-major block moments.
    sums: Vec<[f64; 3]>,
}

impl<'a> Field<'a> {
    /// `None` for a density with no pixels or the wrong number of weights.
    fn new(density: &Density<'a>) -> Option<Field<'a>> {
        let (width, height) = (density.width as usize, density.height as usize);
        if width == 0 || height == 0 || density.weights.len() != width * height {
            return None;
        }
        let clean = |v: &f32| v.is_finite() && *v >= 0.0;
        let weights = if density.weights.iter().all(clean) {
            Cow::Borrowed(density.weights)
        } else {
            let fixed = density
                .weights
                .iter()
                .map(|v| if clean(v) { *v } else { 0.0 });
            Cow::Owned(fixed.collect())
        };
        let mut levels = vec![leaf_level(&weights, width, height)];
        for level in LEAF_LEVEL + 1..=TOP_LEVEL {
            let finer = levels.last()?;
            levels.push(coarser_level(finer, height.div_ceil(1 << level)));
        }
        Some(Field {
            width,
            height,
            weights,
            levels,
        })
    }

    /// The moments of an aligned tile of the pyramid.
    fn moments(&self, tile: &Tile) -> [f64; 3] {
        let level = &self.levels[(tile.level - LEAF_LEVEL) as usize];
        let (bx, by) = (tile.x0 >> tile.level, tile.y0 >> tile.level);
        level.sums[by * level.cols + bx]
    }
}

/// The finest level of the pyramid, straight from the weights.
fn leaf_level(weights: &[f32], width: usize, height: usize) -> Level {
    let side = 1usize << LEAF_LEVEL;
    let (cols, rows) = (width.div_ceil(side), height.div_ceil(side));
    let block_row = |by: usize| {
        let mut out = vec![[0.0f64; 3]; cols];
        for y in by * side..((by + 1) * side).min(height) {
            let py = y as f64 + 0.5;
            for (x, &v) in weights[y * width..(y + 1) * width].iter().enumerate() {
                if v > 0.0 {
                    let (v, a) = (f64::from(v), &mut out[x >> LEAF_LEVEL]);
                    a[0] += v;
                    a[1] += v * (x as f64 + 0.5);
                    a[2] += v * py;
                }
            }
        }
        out
    };
    let parts: Vec<Vec<[f64; 3]>> = (0..rows).into_par_iter().map(block_row).collect();
    Level {
        cols,
        sums: parts.concat(),
    }
}

/// The next coarser level (blocks twice the side), `rows` blocks high.
fn coarser_level(finer: &Level, rows: usize) -> Level {
    let cols = finer.cols.div_ceil(2);
    let finer_rows = finer.sums.len() / finer.cols.max(1);
    let mut sums = vec![[0.0f64; 3]; cols * rows];
    for (i, out) in sums.iter_mut().enumerate() {
        let (bx, by) = (i % cols, i / cols);
        for fy in 2 * by..(2 * by + 2).min(finer_rows) {
            for fx in 2 * bx..(2 * bx + 2).min(finer.cols) {
                let m = finer.sums[fy * finer.cols + fx];
                (0..3).for_each(|k| out[k] += m[k]);
            }
        }
    }
    Level { cols, sums }
}

/// An aligned square block of pixels, `2^level` on a side, clipped to the image.
#[derive(Clone, Copy, Debug)]
struct Tile {
    /// log2 of the side.
    level: u32,
    /// First column.
    x0: usize,
    /// First row.
    y0: usize,
    /// One past the last column.
    x1: usize,
    /// One past the last row.
    y1: usize,
}

impl Tile {
    /// The block at `(x0, y0)` (aligned to its side), or `None` if it lies outside.
    fn new(level: u32, x0: usize, y0: usize, field: &Field<'_>) -> Option<Tile> {
        let side = 1usize << level;
        (x0 < field.width && y0 < field.height).then(|| Tile {
            level,
            x0,
            y0,
            x1: (x0 + side).min(field.width),
            y1: (y0 + side).min(field.height),
        })
    }

    /// The box spanned by the pixel centres: `[xmin, ymin, xmax, ymax]`.
    fn hull(&self) -> [f64; 4] {
        [
            self.x0 as f64 + 0.5,
            self.y0 as f64 + 0.5,
            self.x1 as f64 - 0.5,
            self.y1 as f64 - 0.5,
        ]
    }

    /// The centre of the hull.
    fn centre(&self) -> [f64; 2] {
        let [ax, ay, bx, by] = self.hull();
        [(ax + bx) * 0.5, (ay + by) * 0.5]
    }

    /// The four quarters that lie inside the image.
    fn children(&self, field: &Field<'_>) -> impl Iterator<Item = Tile> {
        let (level, half) = (self.level - 1, 1usize << (self.level - 1));
        let (x0, y0) = (self.x0, self.y0);
        [(0, 0), (half, 0), (0, half), (half, half)]
            .into_iter()
            .filter_map(move |(dx, dy)| Tile::new(level, x0 + dx, y0 + dy, field))
    }
}

/// Squared distance.
fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

/// `x` wrapped into `[0, len)`.
fn wrap(x: f64, len: f64) -> f64 {
    let r = x.rem_euclid(len);
    if r >= len { 0.0 } else { r }
}

/// A node of the [`SiteTree`]: the bounding box of its points and either a
/// range of points (a leaf) or two children.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// `[xmin, ymin, xmax, ymax]` of the node's points.
    bbox: [f64; 4],
    /// First point, in [`SiteTree::pos`].
    start: usize,
    /// One past the last point.
    end: usize,
    /// Child nodes, `None` for a leaf.
    children: Option<[usize; 2]>,
}

/// The squared distance from `q` to the box `[xmin, ymin, xmax, ymax]`.
fn box_dist2(b: &[f64; 4], q: [f64; 2]) -> f64 {
    let dx = (b[0] - q[0]).max(q[0] - b[2]).max(0.0);
    let dy = (b[1] - q[1]).max(q[1] - b[3]).max(0.0);
    dx * dx + dy * dy
}

/// The points in a k-d tree (median splits along the longer side of each
/// node's bounding box), for nearest-point and owner queries whatever their
/// spacing.
struct SiteTree {
    /// Distances wrap around the domain.
    periodic: bool,
    /// Domain width and height.
    dom: [f64; 2],
    /// Positions (wrapped into the domain when periodic), in tree order.
    pos: Vec<[f64; 2]>,
    /// Indices into the caller's points, in tree order.
    ids: Vec<usize>,
    /// The nodes, root first; empty when there are no points.
    nodes: Vec<Node>,
}

impl SiteTree {
    /// The tree of the points with finite coordinates.
    fn new(points: &[[f32; 2]], dom: [f64; 2], periodic: bool) -> SiteTree {
        let mut sites: Vec<(usize, [f64; 2])> = (points.iter().enumerate())
            .filter(|(_, p)| p[0].is_finite() && p[1].is_finite())
            .map(|(i, p)| (i, site_position(*p, dom, periodic)))
            .collect();
        let mut nodes = Vec::with_capacity(2 * sites.len() / TREE_LEAF + 1);
        if !sites.is_empty() {
            build_node(&mut sites, 0, &mut nodes);
        }
        let (ids, pos) = sites.into_iter().unzip();
        SiteTree {
            periodic,
            dom,
            pos,
            ids,
            nodes,
        }
    }

    /// The offsets of the images of the points to search: none but zero
    /// unless periodic (then the eight neighbouring copies of the domain too,
    /// enough to find the nearest image of any point from inside the domain).
    fn offsets(&self) -> impl Iterator<Item = [f64; 2]> {
        let ([w, h], n) = (self.dom, if self.periodic { 9 } else { 1 });
        [
            [0.0, 0.0],
            [-w, 0.0],
            [w, 0.0],
            [0.0, -h],
            [0.0, h],
            [-w, -h],
            [w, -h],
            [-w, h],
            [w, h],
        ]
        .into_iter()
        .take(n)
    }

    /// The image of a point nearest to `q` (inside the domain), if any point.
    fn nearest(&self, q: [f64; 2]) -> Option<[f64; 2]> {
        let mut best = (f64::INFINITY, None);
        for o in self.offsets() {
            self.nearest_in(0, [q[0] - o[0], q[1] - o[1]], o, &mut best);
        }
        best.1
    }

    /// [`SiteTree::nearest`] within a node, for the query `q` shifted by `-o`.
    fn nearest_in(
        &self,
        node: usize,
        q: [f64; 2],
        o: [f64; 2],
        best: &mut (f64, Option<[f64; 2]>),
    ) {
        let Some(n) = self.nodes.get(node) else {
            return;
        };
        if box_dist2(&n.bbox, q) >= best.0 {
            return;
        }
        match n.children {
            None => {
                for p in &self.pos[n.start..n.end] {
                    let d = dist2(*p, q);
                    if d < best.0 {
                        *best = (d, Some([p[0] + o[0], p[1] + o[1]]));
                    }
                }
            }
            Some([a, b]) => {
                let (da, db) = (
                    box_dist2(&self.nodes[a].bbox, q),
                    box_dist2(&self.nodes[b].bbox, q),
                );
                let (first, second) = if da <= db { (a, b) } else { (b, a) };
                self.nearest_in(first, q, o, best);
                self.nearest_in(second, q, o, best);
            }
        }
    }

    /// Calls `f(id, image position)` for every point image that is at least as
    /// near as `s1` to some corner of `hull` (`[xmin, ymin, xmax, ymax]`):
    /// exactly the images that can be nearest to some point of the box.
    fn owners(&self, hull: &[f64; 4], s1: [f64; 2], f: &mut impl FnMut(usize, [f64; 2])) {
        let corners = [
            [hull[0], hull[1]],
            [hull[2], hull[1]],
            [hull[0], hull[3]],
            [hull[2], hull[3]],
        ];
        // A little slack: extra candidates cost time, missing ones would be wrong.
        let radii2 = corners.map(|c| dist2(c, s1) * (1.0 + 1e-12) + 1e-12);
        for o in self.offsets() {
            let shifted = corners.map(|c| [c[0] - o[0], c[1] - o[1]]);
            self.owners_in(
                0,
                &Discs {
                    centres: shifted,
                    radii2,
                },
                o,
                f,
            );
        }
    }

    /// [`SiteTree::owners`] within a node, the discs shifted by `-o`.
    fn owners_in(
        &self,
        node: usize,
        discs: &Discs,
        o: [f64; 2],
        f: &mut impl FnMut(usize, [f64; 2]),
    ) {
        let Some(n) = self.nodes.get(node) else {
            return;
        };
        if !discs.reach(|c| box_dist2(&n.bbox, c)) {
            return;
        }
        match n.children {
            None => {
                for (&id, &p) in self.ids[n.start..n.end]
                    .iter()
                    .zip(&self.pos[n.start..n.end])
                {
                    if discs.reach(|c| dist2(p, c)) {
                        f(id, [p[0] + o[0], p[1] + o[1]]);
                    }
                }
            }
            Some([a, b]) => {
                self.owners_in(a, discs, o, f);
                self.owners_in(b, discs, o, f);
            }
        }
    }
}

/// Four discs, one per corner of a box.
struct Discs {
    /// Centres.
    centres: [[f64; 2]; 4],
    /// Squared radii.
    radii2: [f64; 4],
}

impl Discs {
    /// Whether some disc holds a point at squared distance `dist2(centre)`.
    fn reach(&self, dist2: impl Fn([f64; 2]) -> f64) -> bool {
        (0..4).any(|i| dist2(self.centres[i]) <= self.radii2[i])
    }
}

/// Builds the subtree of `sites` (which start at `start` in the tree order)
/// and returns its root's index.
fn build_node(sites: &mut [(usize, [f64; 2])], start: usize, nodes: &mut Vec<Node>) -> usize {
    let mut bbox = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for (_, p) in sites.iter() {
        bbox = [
            bbox[0].min(p[0]),
            bbox[1].min(p[1]),
            bbox[2].max(p[0]),
            bbox[3].max(p[1]),
        ];
    }
    let index = nodes.len();
    nodes.push(Node {
        bbox,
        start,
        end: start + sites.len(),
        children: None,
    });
    if sites.len() > TREE_LEAF {
        let axis = if bbox[2] - bbox[0] >= bbox[3] - bbox[1] {
            0
        } else {
            1
        };
        let mid = sites.len() / 2;
        sites.select_nth_unstable_by(mid, |a, b| a.1[axis].total_cmp(&b.1[axis]));
        let (left, right) = sites.split_at_mut(mid);
        let a = build_node(left, start, nodes);
        let b = build_node(right, start + mid, nodes);
        nodes[index].children = Some([a, b]);
    }
    index
}

/// The position a point's pixel offsets are taken from: the point itself,
/// wrapped into the domain when periodic.
fn site_position(p: [f32; 2], dom: [f64; 2], periodic: bool) -> [f64; 2] {
    let p = p.map(f64::from);
    match periodic {
        true => [wrap(p[0], dom[0]), wrap(p[1], dom[1])],
        false => p,
    }
}

/// A point that may own pixels of a tile: an image position, its index in the
/// tile's candidate list and its index in the caller's points.
#[derive(Clone, Copy, Debug)]
struct Cand {
    /// Position (an image of the point in periodic mode).
    p: [f64; 2],
    /// Index into [`Scratch::sites`] and [`Scratch::acc`].
    k: usize,
    /// Index into the caller's points: the lowest wins ties.
    id: usize,
}

/// Working memory for one row of tiles.
#[derive(Default)]
struct Scratch {
    /// The current tile's candidates: the caller's index and image position.
    sites: Vec<(usize, [f64; 2])>,
    /// Per candidate: `[Σw, Σw·x, Σw·y]` of the pixels it owns in the tile.
    acc: Vec<[f64; 3]>,
    /// The candidate lists of the tiles being subdivided, nested as a stack.
    stack: Vec<Cand>,
    /// The row's partial sums: the caller's index, `[Σw, Σw·dx, Σw·dy]`.
    out: Vec<(usize, [f64; 3])>,
}

/// One Lloyd iteration.
fn lloyd_step(points: &[[f32; 2]], field: &Field<'_>, periodic: bool) -> Vec<[f32; 2]> {
    let dom = [field.width as f64, field.height as f64];
    let tree = SiteTree::new(points, dom, periodic);
    let tile_rows = field.height.div_ceil(1 << TOP_LEVEL);
    let rows: Vec<Vec<(usize, [f64; 3])>> = (0..tile_rows)
        .into_par_iter()
        .map(|ty| tile_row(field, &tree, ty << TOP_LEVEL))
        .collect();
    let mut sums = vec![[0.0f64; 3]; points.len()];
    for &(id, m) in rows.iter().flatten() {
        (0..3).for_each(|k| sums[id][k] += m[k]);
    }
    points
        .iter()
        .zip(&sums)
        .map(|(p, s)| centroid(*p, s, dom, periodic))
        .collect()
}

/// The new position of point `p` from its sums `[Σw, Σw·dx, Σw·dy]`.
fn centroid(p: [f32; 2], sums: &[f64; 3], dom: [f64; 2], periodic: bool) -> [f32; 2] {
    if sums[0] <= 0.0 {
        return p;
    }
    let base = site_position(p, dom, periodic);
    let q = [base[0] + sums[1] / sums[0], base[1] + sums[2] / sums[0]];
    match periodic {
        // Rounding to f32 may land on the far edge, which is the near one.
        true => [0, 1].map(|a| {
            Some(wrap(q[a], dom[a]) as f32)
                .filter(|&v| v < dom[a] as f32)
                .unwrap_or(0.0)
        }),
        false => q.map(|v| v as f32),
    }
}

/// The partial sums of one row of top tiles, starting at pixel row `y0`.
fn tile_row(field: &Field<'_>, tree: &SiteTree, y0: usize) -> Vec<(usize, [f64; 3])> {
    let mut scratch = Scratch::default();
    for x0 in (0..field.width).step_by(1 << TOP_LEVEL) {
        if let Some(tile) = Tile::new(TOP_LEVEL, x0, y0, field) {
            top_tile(field, tree, tile, &mut scratch);
        }
    }
    scratch.out
}

/// Gathers a top tile's candidates, assigns its pixels and appends its sums.
fn top_tile(field: &Field<'_>, tree: &SiteTree, tile: Tile, s: &mut Scratch) {
    if field.moments(&tile)[0] <= 0.0 {
        return;
    }
    let Some(s1) = tree.nearest(tile.centre()) else {
        return;
    };
    s.sites.clear();
    s.stack.clear();
    tree.owners(&tile.hull(), s1, &mut |id, p| {
        s.stack.push(Cand {
            p,
            k: s.sites.len(),
            id,
        });
        s.sites.push((id, p));
    });
    s.acc.clear();
    s.acc.resize(s.sites.len(), [0.0; 3]);
    subdivide(field, tile, s, 0, s.stack.len());
    for (a, &(id, p)) in s.acc.iter().zip(&s.sites) {
        if a[0] > 0.0 {
            s.out
                .push((id, [a[0], a[1] - p[0] * a[0], a[2] - p[1] * a[0]]));
        }
    }
}

/// Assigns the pixels of `tile` among the candidates `s.stack[lo..hi]`
/// (a superset of the points that own some of them).
fn subdivide(field: &Field<'_>, tile: Tile, s: &mut Scratch, lo: usize, hi: usize) {
    let moments = field.moments(&tile);
    if moments[0] <= 0.0 {
        return;
    }
    let (lo, hi) = prune(&mut s.stack, lo, hi, &tile);
    if hi - lo == 1 {
        let a = &mut s.acc[s.stack[lo].k];
        (0..3).for_each(|k| a[k] += moments[k]);
    } else if tile.level <= LEAF_LEVEL {
        assign_pixels(field, &tile, &s.stack[lo..hi], &mut s.acc);
    } else {
        for child in tile.children(field) {
            subdivide(field, child, s, lo, hi);
        }
    }
    s.stack.truncate(lo);
}

/// Pushes onto the stack the candidates of `stack[lo..hi]` that may own a
/// pixel of `tile`, nearest to its centre first, and returns their range.
fn prune(stack: &mut Vec<Cand>, lo: usize, hi: usize, tile: &Tile) -> (usize, usize) {
    let centre = tile.centre();
    let (mut best, mut best_d) = (lo, f64::INFINITY);
    for (i, c) in stack[lo..hi].iter().enumerate() {
        let d = dist2(c.p, centre);
        if d < best_d {
            (best, best_d) = (lo + i, d);
        }
    }
    let (first, hull, new_lo) = (stack[best], tile.hull(), stack.len());
    stack.push(first);
    for i in lo..hi {
        let c = stack[i];
        if i != best && may_own(&c, &first, &hull) {
            stack.push(c);
        }
    }
    (new_lo, stack.len())
}

/// Whether `c` is at least as near as `first` to some point of the box `hull`
/// (`[xmin, ymin, xmax, ymax]`). The difference of squared distances is linear
/// over the box, so testing the corner farthest towards `c` is enough. Of two
/// points at the same place, the one with the higher index owns nothing.
fn may_own(c: &Cand, first: &Cand, hull: &[f64; 4]) -> bool {
    let (p, s1) = (c.p, first.p);
    if p == s1 {
        return c.id < first.id;
    }
    let x = if p[0] > s1[0] { hull[2] } else { hull[0] };
    let y = if p[1] > s1[1] { hull[3] } else { hull[1] };
    dist2(p, [x, y]) <= dist2(s1, [x, y])
}

/// Assigns each weighted pixel of `tile` to its nearest candidate.
fn assign_pixels(field: &Field<'_>, tile: &Tile, cands: &[Cand], acc: &mut [[f64; 3]]) {
    for y in tile.y0..tile.y1 {
        let py = y as f64 + 0.5;
        let row = &field.weights[y * field.width + tile.x0..y * field.width + tile.x1];
        for (x, &v) in (tile.x0..).zip(row) {
            if v > 0.0 {
                let q = [x as f64 + 0.5, py];
                let (v, a) = (f64::from(v), &mut acc[nearest_cand(cands, q)]);
                a[0] += v;
                a[1] += v * q[0];
                a[2] += v * q[1];
            }
        }
    }
}

/// The list index (`k`) of the candidate nearest to `q`. On ties, the one
/// with the lowest index in the caller's points; between two images of a
/// point, the one to the left (then above), so that offsets from a point to
/// its pixels lie in `(-W/2, W/2] × (-H/2, H/2]`.
fn nearest_cand(cands: &[Cand], q: [f64; 2]) -> usize {
    let mut best = (f64::INFINITY, usize::MAX, [0.0; 2], 0);
    for c in cands {
        let d = dist2(c.p, q);
        if d < best.0 || d == best.0 && (c.id < best.1 || c.id == best.1 && c.p < best.2) {
            best = (d, c.id, c.p, c.k);
        }
    }
    best.3
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random points uniform in `[0, w) × [0, h)`.
    fn uniform_points(n: usize, w: f64, h: f64, seed: u64) -> Vec<[f32; 2]> {
        let n = n as u64;
        (0..n)
            .map(|i| [(unit(seed, i) * w) as f32, (unit(seed, n + i) * h) as f32])
            .collect()
    }

    /// Random weights, about a third of them zero.
    fn random_weights(w: usize, h: usize, seed: u64) -> Vec<f32> {
        (0..(w * h) as u64)
            .map(|i| unit(seed, i) as f32 * 3.0 - 1.0)
            .map(|v| v.max(0.0))
            .collect()
    }

    /// One Lloyd step by brute force: every pixel against every point.
    fn reference_step(
        points: &[[f32; 2]],
        w: usize,
        h: usize,
        weights: &[f32],
        periodic: bool,
    ) -> Vec<[f32; 2]> {
        let dom = [w as f64, h as f64];
        let sites: Vec<[f64; 2]> = points
            .iter()
            .map(|p| site_position(*p, dom, periodic))
            .collect();
        // Offsets in (-len/2, len/2].
        let offset = |d: f64, len: f64| {
            if periodic {
                d - len * (d / len - 0.5).ceil()
            } else {
                d
            }
        };
        let mut sums = vec![[0.0f64; 3]; points.len()];
        for (i, &v) in weights.iter().enumerate().filter(|(_, v)| **v > 0.0) {
            let q = [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
            let (mut best, mut best_d, mut best_off) = (usize::MAX, f64::INFINITY, [0.0; 2]);
            for (k, s) in sites.iter().enumerate() {
                let off = [offset(q[0] - s[0], dom[0]), offset(q[1] - s[1], dom[1])];
                let d = off[0] * off[0] + off[1] * off[1];
                if d < best_d {
                    (best, best_d, best_off) = (k, d, off);
                }
            }
            if best != usize::MAX {
                let v = f64::from(v);
                sums[best] = [
                    sums[best][0] + v,
                    sums[best][1] + v * best_off[0],
                    sums[best][2] + v * best_off[1],
                ];
            }
        }
        points
            .iter()
            .zip(&sums)
            .map(|(p, s)| centroid(*p, s, dom, periodic))
            .collect()
    }

    /// Pixels per point.
    fn cell_areas(points: &[[f32; 2]], w: usize, h: usize) -> Vec<f64> {
        let mut areas = vec![0.0; points.len()];
        for i in 0..w * h {
            let q = [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
            let p = points.iter().map(|p| dist2(p.map(f64::from), q));
            let k = p
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(0, |m| m.0);
            areas[k] += 1.0;
        }
        areas
    }

    fn std_dev(v: &[f64]) -> f64 {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / v.len() as f64).sqrt()
    }

    fn min_nn_distance(points: &[[f32; 2]]) -> f64 {
        let mut best = f64::INFINITY;
        for (i, a) in points.iter().enumerate() {
            for b in &points[i + 1..] {
                best = best.min(dist2(a.map(f64::from), b.map(f64::from)).sqrt());
            }
        }
        best
    }

    fn opts(iterations: u32, periodic: bool) -> RelaxOptions {
        RelaxOptions {
            iterations,
            periodic,
        }
    }

    fn relax_all(
        points: &[[f32; 2]],
        density: &Density<'_>,
        options: RelaxOptions,
    ) -> Vec<[f32; 2]> {
        relax(points, density, options, |_| true)
    }

    fn assert_close(a: &[[f32; 2]], b: &[[f32; 2]], tol: f32, what: &str) {
        assert_eq!(a.len(), b.len());
        for (i, (p, q)) in a.iter().zip(b).enumerate() {
            let ok = (0..2).all(|k| (p[k] - q[k]).abs() <= tol || (p[k].is_nan() && q[k].is_nan()));
            assert!(ok, "{what}: point {i}: {p:?} vs {q:?}");
        }
    }

    #[test]
    fn one_step_matches_brute_force() {
        let sizes = [(1, 1), (5, 3), (37, 29), (64, 64), (101, 67), (17, 130)];
        for (case, &(w, h)) in sizes.iter().enumerate() {
            let weights = random_weights(w, h, case as u64);
            let density = Density {
                width: w as u32,
                height: h as u32,
                weights: &weights,
            };
            for n in [1, 2, 3, 10, 100, 500] {
                for periodic in [false, true] {
                    let seed = 100 * case as u64 + n as u64;
                    let mut points = uniform_points(n, w as f64, h as f64, seed);
                    for step in 0..3 {
                        let fast = relax_all(&points, &density, opts(1, periodic));
                        let slow = reference_step(&points, w, h, &weights, periodic);
                        let what = format!("{w}×{h}, {n} points, periodic {periodic}, step {step}");
                        assert_close(&fast, &slow, 1e-3, &what);
                        points = fast;
                    }
                }
            }
        }
    }

    #[test]
    fn varying_spacing_matches_brute_force() {
        let (w, h) = (170, 120);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 - 50.0, (i / w) as f32 - 40.0);
                if x > 100.0 {
                    0.0
                } else {
                    (-(x * x + y * y) / 2000.0).exp() * 64.0 + 1.0
                }
            })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        for periodic in [false, true] {
            let mut points = random_start(700, &density, 2);
            for step in 0..2 {
                let fast = relax_all(&points, &density, opts(1, periodic));
                let slow = reference_step(&points, w, h, &weights, periodic);
                assert_close(
                    &fast,
                    &slow,
                    1e-3,
                    &format!("periodic {periodic}, step {step}"),
                );
                points = fast;
            }
        }
    }

    #[test]
    fn clustered_and_stray_points_match_brute_force() {
        let (w, h) = (150, 90);
        let weights = random_weights(w, h, 9);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        // A tight cluster in a corner, a sparse spread, points outside, a NaN.
        let mut points: Vec<[f32; 2]> = uniform_points(300, 8.0, 5.0, 1)
            .iter()
            .map(|p| [p[0] + 140.0, p[1] + 2.0])
            .collect();
        points.extend(uniform_points(20, w as f64, h as f64, 2));
        points.extend([[-3.0, 40.0], [160.0, -7.5], [f32::NAN, 3.0], [75.0, 200.0]]);
        for periodic in [false, true] {
            let fast = relax_all(&points, &density, opts(1, periodic));
            let slow = reference_step(&points, w, h, &weights, periodic);
            assert_close(&fast, &slow, 1e-3, &format!("periodic {periodic}"));
        }
    }

    #[test]
    fn ties_and_duplicates_match_brute_force() {
        let (w, h) = (90, 70);
        let weights = random_weights(w, h, 3);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        for n in [2, 5, 40, 400] {
            // Points on the half-pixel lattice: many pixels are equally near to two or more.
            let mut points: Vec<[f32; 2]> = uniform_points(n, w as f64, h as f64, n as u64)
                .iter()
                .map(|p| p.map(|v| (v * 2.0).floor() / 2.0))
                .collect();
            points.extend_from_slice(&points.clone()[..n / 2]);
            for periodic in [false, true] {
                let fast = relax_all(&points, &density, opts(1, periodic));
                let slow = reference_step(&points, w, h, &weights, periodic);
                assert_close(
                    &fast,
                    &slow,
                    1e-4,
                    &format!("{n} points, periodic {periodic}"),
                );
            }
        }
    }

    #[test]
    fn regular_grid_stays_put_on_uniform_density() {
        let (w, h) = (160, 120);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let points: Vec<[f32; 2]> = (0..12)
            .flat_map(|j| (0..16).map(move |i| [5.0 + 10.0 * i as f32, 5.0 + 10.0 * j as f32]))
            .collect();
        for periodic in [false, true] {
            let out = relax_all(&points, &density, opts(5, periodic));
            assert_close(&out, &points, 1e-3, &format!("periodic {periodic}"));
        }
    }

    #[test]
    fn relaxation_spreads_random_points_evenly() {
        let (w, h) = (128, 96);
        let weights = vec![1.0f32; w * h];
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = random_start(150, &density, 3);
        let out = relax_all(&start, &density, opts(30, false));
        let (d0, d1) = (min_nn_distance(&start), min_nn_distance(&out));
        let (s0, s1) = (
            std_dev(&cell_areas(&start, w, h)),
            std_dev(&cell_areas(&out, w, h)),
        );
        assert!(d1 > 2.0 * d0 && d1 > 4.0, "min distance {d0} -> {d1}");
        assert!(s1 < 0.5 * s0, "std of cell areas {s0} -> {s1}");
    }

    #[test]
    fn points_leave_the_white_half() {
        let (w, h) = (80, 60);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| if i % w < w / 2 { 0.0 } else { 1.0 })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(40, w as f64, h as f64, 5);
        let out = relax_all(&start, &density, opts(10, false));
        let mut moved = 0;
        for (a, b) in start.iter().zip(&out) {
            if a != b {
                moved += 1;
                assert!(b[0] >= (w / 2) as f32 + 0.5, "{a:?} -> {b:?}");
            }
        }
        assert!(moved >= 20, "only {moved} points moved");
    }

    #[test]
    fn points_gather_in_a_dark_disc() {
        let (w, h) = (80, 80);
        let inside = |x: f32, y: f32| (x - 40.0).hypot(y - 40.0) < 15.0;
        let weights: Vec<f32> = (0..w * h)
            .map(|i| {
                if inside((i % w) as f32 + 0.5, (i / w) as f32 + 0.5) {
                    1.0
                } else {
                    0.01
                }
            })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(100, w as f64, h as f64, 11);
        let count = |v: &[[f32; 2]]| v.iter().filter(|p| inside(p[0], p[1])).count();
        let out = relax_all(&start, &density, opts(10, false));
        assert!(
            count(&out) >= 2 * count(&start),
            "{} -> {} points in the disc",
            count(&start),
            count(&out)
        );
    }

    #[test]
    fn same_result_for_any_thread_count() {
        let (w, h) = (300, 200);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| ((i % w) as f32 / 30.0).sin().abs() + (i / w) as f32 / 200.0)
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = random_start(3000, &density, 1);
        for periodic in [false, true] {
            let run = |threads| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("thread pool");
                pool.install(|| relax_all(&start, &density, opts(3, periodic)))
            };
            let bits = |v: Vec<[f32; 2]>| {
                v.iter()
                    .flat_map(|p| p.map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            let one = bits(run(1));
            assert_eq!(one, bits(run(2)));
            assert_eq!(one, bits(run(3)));
        }
    }

    #[test]
    fn progress_false_stops_after_the_first_iteration() {
        let (w, h) = (50, 40);
        let weights = random_weights(w, h, 4);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let start = uniform_points(30, w as f64, h as f64, 8);
        let mut calls = Vec::new();
        let out = relax(&start, &density, opts(10, false), |done| {
            calls.push(done);
            false
        });
        assert_eq!(calls, [1]);
        assert_eq!(out, relax_all(&start, &density, opts(1, false)));
        let mut all = Vec::new();
        relax(&start, &density, opts(4, true), |done| {
            all.push(done);
            true
        });
        assert_eq!(all, [1, 2, 3, 4]);
    }

    #[test]
    fn periodic_centroid_wraps_across_the_seam() {
        let (w, h) = (20, 10);
        let column = |c0: f32, c19: f32| -> Vec<f32> {
            (0..w * h)
                .map(|i| match i % w {
                    0 => c0,
                    19 => c19,
                    _ => 0.0,
                })
                .collect()
        };
        let weights = column(3.0, 1.0);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let one = |density: &Density<'_>, periodic| {
            relax_all(&[[1.0, 5.0]], density, opts(1, periodic))[0]
        };
        // Offsets -0.5 (column 0, weight 3) and -1.5 (column 19 seen across the seam).
        assert_close(&[one(&density, true)], &[[0.25, 5.0]], 1e-6, "periodic");
        assert_close(&[one(&density, false)], &[[5.25, 5.0]], 1e-6, "flat");
        let weights = column(1.0, 3.0);
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        // 1 - 1.25 = -0.25 wraps to 19.75.
        assert_close(
            &[one(&density, true)],
            &[[19.75, 5.0]],
            1e-5,
            "wrapped back",
        );
        // Two points across the seam split the columns between them.
        let two = relax_all(&[[19.0, 5.0], [1.0, 5.0]], &density, opts(1, true));
        assert_close(&two, &[[19.5, 5.0], [0.5, 5.0]], 1e-6, "two points");
    }

    #[test]
    fn random_start_follows_the_density() {
        let (w, h) = (64, 48);
        let weights: Vec<f32> = (0..w * h)
            .map(|i| if i % w < w / 2 { 0.0 } else { 2.0 })
            .collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &weights,
        };
        let points = random_start(2000, &density, 42);
        assert_eq!(points.len(), 2000);
        assert!(
            points
                .iter()
                .all(|p| p[0] >= 32.0 && p[0] < 64.0 && p[1] >= 0.0 && p[1] < 48.0)
        );
        assert_eq!(points, random_start(2000, &density, 42));
        assert_ne!(points, random_start(2000, &density, 43));
        let ramp: Vec<f32> = (0..w * h).map(|i| (i % w) as f32 + 0.5).collect();
        let density = Density {
            width: w as u32,
            height: h as u32,
            weights: &ramp,
        };
        let points = random_start(20000, &density, 1);
        let right = points.iter().filter(|p| p[0] >= 32.0).count() as f64 / 20000.0;
        assert!(
            (0.73..0.77).contains(&right),
            "fraction on the right: {right}"
        );
    }

    #[test]
    fn random_start_without_weight_is_uniform_over_the_domain() {
        let weights = vec![0.0f32; 30 * 20];
        let density = Density {
            width: 30,
            height: 20,
            weights: &weights,
        };
        let points = random_start(1000, &density, 5);
        assert!(
            points
                .iter()
                .all(|p| (0.0..30.0).contains(&p[0]) && (0.0..20.0).contains(&p[1]))
        );
        assert!(points.iter().filter(|p| p[0] < 15.0).count() > 400);
        let short = Density {
            width: 30,
            height: 20,
            weights: &weights[..10],
        };
        assert_eq!(random_start(7, &short, 5).len(), 7);
    }

    #[test]
    fn check_reports_bad_densities() {
        let good = vec![0.5f32; 6];
        assert!(
            check(&Density {
                width: 3,
                height: 2,
                weights: &good
            })
            .is_ok()
        );
        assert!(
            check(&Density {
                width: 0,
                height: 2,
                weights: &[]
            })
            .is_err()
        );
        let err = check(&Density {
            width: 4,
            height: 2,
            weights: &good,
        })
        .unwrap_err();
        assert!(err.contains("6 weights") && !err.contains('\n'), "{err}");
        for bad in [f32::NAN, f32::INFINITY, -1.0] {
            let mut weights = good.clone();
            weights[4] = bad;
            let err = check(&Density {
                width: 3,
                height: 2,
                weights: &weights,
            })
            .unwrap_err();
            assert!(err.contains("(1, 1)"), "{err}");
        }
    }

    #[test]
    fn bad_input_is_handled_without_panicking() {
        let points = uniform_points(10, 20.0, 10.0, 3);
        let weights = vec![1.0f32; 200];
        let short = Density {
            width: 20,
            height: 10,
            weights: &weights[..50],
        };
        let mut called = false;
        assert_eq!(
            relax(&points, &short, opts(3, false), |_| {
                called = true;
                true
            }),
            points
        );
        assert!(!called);
        // Bad weights count as zero.
        let mut bad = weights.clone();
        bad[..100]
            .iter_mut()
            .enumerate()
            .for_each(|(i, v)| *v = [f32::NAN, -2.0, f32::INFINITY][i % 3]);
        let zeroed: Vec<f32> = (0..200).map(|i| if i < 100 { 0.0 } else { 1.0 }).collect();
        let a = relax_all(
            &points,
            &Density {
                width: 20,
                height: 10,
                weights: &bad,
            },
            opts(2, false),
        );
        let b = relax_all(
            &points,
            &Density {
                width: 20,
                height: 10,
                weights: &zeroed,
            },
            opts(2, false),
        );
        assert_eq!(a, b);
        // No points, duplicate points.
        assert!(
            relax_all(
                &[],
                &Density {
                    width: 20,
                    height: 10,
                    weights: &weights
                },
                opts(2, true)
            )
            .is_empty()
        );
        let dup = relax_all(
            &[[3.0, 3.0], [3.0, 3.0]],
            &Density {
                width: 20,
                height: 10,
                weights: &weights,
            },
            opts(1, false),
        );
        assert_eq!(dup, [[10.0, 5.0], [3.0, 3.0]]);
    }
}
