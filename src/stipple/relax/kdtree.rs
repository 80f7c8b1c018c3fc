//! The points in a k-d tree (median splits along the longer side of each
//! node's bounding box), rebuilt every iteration: the point nearest to a
//! tile's centre, and every point at least as near as that one to some
//! corner of the tile. In periodic mode the queries search the points'
//! images in the eight neighbouring copies of the domain too.

use super::{dist2, wrap};

/// The most points in a leaf of the k-d tree.
const TREE_LEAF: usize = 8;

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
pub(super) struct SiteTree {
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
    pub(super) fn new(points: &[[f32; 2]], dom: [f64; 2], periodic: bool) -> SiteTree {
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
    pub(super) fn nearest(&self, q: [f64; 2]) -> Option<[f64; 2]> {
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
    pub(super) fn owners(
        &self,
        hull: &[f64; 4],
        s1: [f64; 2],
        f: &mut impl FnMut(usize, [f64; 2]),
    ) {
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
pub(super) fn site_position(p: [f32; 2], dom: [f64; 2], periodic: bool) -> [f64; 2] {
    let p = p.map(f64::from);
    match periodic {
        true => [wrap(p[0], dom[0]), wrap(p[1], dom[1])],
        false => p,
    }
}
