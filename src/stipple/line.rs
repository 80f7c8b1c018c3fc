//! One continuous pen line through the dots ("TSP art": the path of
//! [`super::tsp`] drawn as a stroke instead of dots): the stroke as a PNG
//! shows it ([`render_polyline`], the union of the pen's ink on 4×4 samples
//! a pixel, as [`super::raster::render_union`] draws dots), the places where
//! the path crosses itself ([`crossings`], which [`super::tsp::uncross`]
//! removes), and a smooth curve through the path's points ([`catmull_rom`],
//! made a polyline again by [`flatten`]).
//!
//! Coordinates are the sampling domain's pixels, origin top left.

use image::{GrayImage, Luma};
use rayon::prelude::*;

/// Samples a pixel has along each side: 4×4, as
/// [`super::raster::render_union`] takes them.
const SAMPLES: u32 = 4;

/// Pixel rows per band that one thread draws.
const BAND: u32 = 64;

/// The narrowest stroke drawn as it is, in output pixels: two samples
/// across, so that every column of samples it passes holds one or two of
/// them wherever the line lies (a thinner one would slip between the
/// sample rows). A thinner pen is drawn this wide with its ink thinned in
/// proportion, so that its mean ink stays the pen's.
const MIN_WIDTH: f64 = 0.5;

/// A segment of the stroke in sample coordinates (output pixels × 4,
/// less ½: sample (sx, sy) of the image is the point (sx, sy)), with the
/// sample rows its pen reaches (inclusive).
#[derive(Clone, Copy, Debug)]
struct Capsule {
    a: [f64; 2],
    b: [f64; 2],
    rows: (u64, u64),
}

/// Draws the open polyline through `points` (domain pixels) stroked by a
/// round pen `width` domain pixels wide (round caps and joins), on a `size`
/// image whose pixels are `scale` domain pixels' worth each (output px =
/// domain px × `scale`).
///
/// A pixel's ink is the share of its 4×4 samples within `width / 2` of the
/// line, counted once where the line passes over itself (the union, as a
/// real pen's ink), and its grey is 255 × (1 − ink): white paper 255, black
/// ink 0, as [`super::raster::render_union`] writes. A pen thinner than
/// half an output pixel is drawn half a pixel wide with its ink thinned in
/// proportion, so that it stays an unbroken line of the pen's mean ink.
/// One point draws a round dot of diameter
/// `width`; no points, a width or scale that is not a positive number, or
/// points that are not finite draw nothing there (a point that is not
/// finite drops its two segments). The image does not depend
/// on the number of threads.
///
/// ```
/// use pixelpie::stipple::line;
/// let img = line::render_polyline(&[[2.0, 8.0], [14.0, 8.0]], 2.0, (16, 16), 1.0);
/// assert_eq!(img.get_pixel(8, 7).0[0], 0); // ink on the line
/// assert_eq!(img.get_pixel(8, 2).0[0], 255); // paper away from it
/// ```
#[must_use]
pub fn render_polyline(points: &[[f64; 2]], width: f64, size: (u32, u32), scale: f64) -> GrayImage {
    let (w, h) = size;
    let mut img = GrayImage::from_pixel(w, h, Luma([255]));
    let drawn = width * scale;
    if !(width > 0.0 && scale > 0.0 && drawn.is_finite()) || w == 0 || h == 0 {
        return img;
    }
    let pen = drawn.max(MIN_WIDTH);
    let capsules = capsules(points, scale, pen, size);
    let band_rows = u64::from(BAND * SAMPLES);
    let mut in_band = vec![Vec::new(); h.div_ceil(BAND) as usize];
    for (i, c) in capsules.iter().enumerate() {
        for b in c.rows.0 / band_rows..=c.rows.1 / band_rows {
            in_band[b as usize].push(i);
        }
    }
    let radius = pen / 2.0 * f64::from(SAMPLES);
    // The grey of each count of inked samples, made once; a thin pen's
    // samples each carry its share of the drawn width's ink.
    let thin = drawn / pen;
    let all = f64::from(SAMPLES * SAMPLES);
    let greys: [u8; (SAMPLES * SAMPLES + 1) as usize] =
        std::array::from_fn(|k| grey(1.0 - k as f64 / all * thin));
    img.par_chunks_mut(BAND as usize * w as usize)
        .zip(in_band.par_iter())
        .enumerate()
        .for_each(|(b, (out, list))| {
            let top = b as u64 * band_rows;
            let bottom = top + (out.len() / w as usize * SAMPLES as usize) as u64;
            let mut masks = vec![0u16; out.len()];
            for &i in list {
                draw_capsule(&capsules[i], radius, (top, bottom), w as usize, &mut masks);
            }
            for (o, &m) in out.iter_mut().zip(&masks) {
                *o = greys[m.count_ones() as usize];
            }
        });
    img
}

/// The segments of the polyline through `points` (one point: a dot) that
/// reach a `size` image at `scale`, in sample coordinates, drawn by a pen
/// `pen` output pixels wide; those with a point that is not finite left
/// out.
fn capsules(points: &[[f64; 2]], scale: f64, pen: f64, size: (u32, u32)) -> Vec<Capsule> {
    let s = f64::from(SAMPLES);
    let radius = pen / 2.0 * s;
    let (max_x, max_y) = (f64::from(size.0) * s - 1.0, f64::from(size.1) * s - 1.0);
    let at = |p: [f64; 2]| [p[0] * scale * s - 0.5, p[1] * scale * s - 0.5];
    let dot = (points.len() == 1).then(|| (points[0], points[0]));
    points
        .windows(2)
        .map(|w| (w[0], w[1]))
        .chain(dot)
        .filter_map(|(p, q)| {
            let (a, b) = (at(p), at(q));
            if !a.iter().chain(&b).all(|v| v.is_finite()) {
                return None;
            }
            let y0 = (a[1].min(b[1]) - radius).ceil().max(0.0);
            let y1 = (a[1].max(b[1]) + radius).floor().min(max_y);
            let x0 = a[0].min(b[0]) - radius;
            let x1 = a[0].max(b[0]) + radius;
            (y0 <= y1 && x1 >= 0.0 && x0 <= max_x).then_some(Capsule {
                a,
                b,
                rows: (y0 as u64, y1 as u64),
            })
        })
        .collect()
}

/// Sets the bits of the samples within `radius` of capsule `c` among the
/// sample rows `top..bottom` of a band whose pixels' masks are `masks`
/// (`w` a row; bit 4k + i is sample i of the pixel's sample row k).
fn draw_capsule(c: &Capsule, radius: f64, (top, bottom): (u64, u64), w: usize, masks: &mut [u16]) {
    let last = (w * SAMPLES as usize - 1) as f64;
    for sy in c.rows.0.max(top)..=c.rows.1.min(bottom - 1) {
        let Some((lo, hi)) = row_span(c.a, c.b, radius, sy as f64) else {
            continue;
        };
        let (lo, hi) = (lo.ceil().max(0.0), hi.floor().min(last));
        if lo > hi {
            continue;
        }
        let row = ((sy - top) / u64::from(SAMPLES)) as usize * w;
        let shift = (sy % u64::from(SAMPLES)) as u32 * SAMPLES;
        fill_span(&mut masks[row..row + w], lo as usize, hi as usize, shift);
    }
}

/// The x interval of the points of sample row `y` within `r` of segment
/// `a`–`b`: the pen's shape there (two discs and the band between them) is
/// convex, so its three pieces' intervals join into one.
fn row_span(a: [f64; 2], b: [f64; 2], r: f64, y: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in [a, b] {
        let dy = y - p[1];
        let h2 = r * r - dy * dy;
        if h2 >= 0.0 {
            let half = h2.sqrt();
            lo = lo.min(p[0] - half);
            hi = hi.max(p[0] + half);
        }
    }
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    if len2 > 0.0 {
        let ey = y - a[1];
        // Where the projection on the segment falls within it:
        // 0 ≤ (x − a.x)·d.x + ey·d.y ≤ len².
        let along = if d[0] == 0.0 {
            (0.0..=len2)
                .contains(&(ey * d[1]))
                .then_some((f64::NEG_INFINITY, f64::INFINITY))
        } else {
            let (u, v) = ((-ey * d[1]) / d[0], (len2 - ey * d[1]) / d[0]);
            Some((u.min(v) + a[0], u.max(v) + a[0]))
        };
        // Where the distance to the segment's line is at most r:
        // |d.x·ey − d.y·(x − a.x)| ≤ r·len.
        let reach = r * len2.sqrt();
        let across = if d[1] == 0.0 {
            (d[0] * ey)
                .abs()
                .le(&reach)
                .then_some((f64::NEG_INFINITY, f64::INFINITY))
        } else {
            let (u, v) = ((d[0] * ey - reach) / d[1], (d[0] * ey + reach) / d[1]);
            Some((u.min(v) + a[0], u.max(v) + a[0]))
        };
        if let (Some(p), Some(q)) = (along, across) {
            let (l, h) = (p.0.max(q.0), p.1.min(q.1));
            if l <= h {
                lo = lo.min(l);
                hi = hi.max(h);
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Sets samples `lo..=hi` (sample columns) of one sample row in a row of
/// pixels' masks, the row's bits at `shift`.
fn fill_span(row: &mut [u16], lo: usize, hi: usize, shift: u32) {
    let bits = |a: u32, z: u32| (((1u32 << (z + 1)) - (1u32 << a)) as u16) << shift;
    let n = SAMPLES as usize;
    let (first, last) = (lo / n, hi / n);
    let (a, z) = ((lo % n) as u32, (hi % n) as u32);
    if first == last {
        row[first] |= bits(a, z);
        return;
    }
    row[first] |= bits(a, SAMPLES - 1);
    let whole = bits(0, SAMPLES - 1);
    for m in &mut row[first + 1..last] {
        *m |= whole;
    }
    row[last] |= bits(0, z);
}

/// The 8-bit grey of paper fraction `p` ∈ [0, 1], rounded.
fn grey(p: f64) -> u8 {
    (255.0 * p.clamp(0.0, 1.0) + 0.5) as u8
}

/// The mean ink of `img` (1 − grey/255 over its pixels; 0 for no pixels).
///
/// ```
/// let img = image::GrayImage::from_raw(2, 1, vec![0, 255]).unwrap();
/// assert_eq!(pixelpie::stipple::line::coverage_mean(&img), 0.5);
/// ```
#[must_use]
pub fn coverage_mean(img: &GrayImage) -> f64 {
    let n = img.as_raw().len();
    if n == 0 {
        return 0.0;
    }
    let ink: u64 = img
        .as_raw()
        .par_chunks(1 << 16)
        .map(|c| c.iter().map(|&v| u64::from(255 - v)).sum::<u64>())
        .sum();
    ink as f64 / (255.0 * n as f64)
}

/// The pairs `(i, j)`, `i < j`, of segments of the open polyline through
/// `points` that cross (segment `k` joins `points[k]` and `points[k + 1]`),
/// sorted.
///
/// Two segments cross where their interiors meet at one point, or where
/// they lie on one line and overlap over a length. Adjacent segments
/// (`j = i + 1`), segments of length zero, those with a point that is not
/// finite, and segments that only touch (a point of the path lying on
/// another segment, or two points at one place) do not count. The test is
/// f64 cross products: exact for integer coordinates, and for others right
/// except where a point lies within rounding of the other segment's line.
///
/// The segments are bucketed in a grid of cells about the mean segment long
/// (a segment in each cell it passes), so that a tour's crossings are found
/// in about linear time (fewer than 2³² points, as [`super::tsp`]'s).
///
/// ```
/// use pixelpie::stipple::line;
/// // An hourglass: the first and the third segment cross at (5, 5).
/// let pts = [[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]];
/// assert_eq!(line::crossings(&pts), [(0, 2)]);
/// ```
#[must_use]
pub fn crossings(points: &[[f64; 2]]) -> Vec<(usize, usize)> {
    let segments: Vec<usize> = (0..points.len().saturating_sub(1))
        .filter(|&k| {
            let (a, b) = (points[k], points[k + 1]);
            a.iter().chain(&b).all(|v| v.is_finite()) && a != b
        })
        .collect();
    if segments.len() < 2 {
        return Vec::new();
    }
    let grid = Grid::new(points, &segments);
    let mut entries: Vec<(u32, u32)> = segments
        .par_iter()
        .fold(Vec::new, |mut acc, &k| {
            grid.cells(points[k], points[k + 1], |c| acc.push((c, k as u32)));
            acc
        })
        .flatten()
        .collect();
    entries.par_sort_unstable();

    // Each cell's run of segments, tested pair by pair.
    let mut runs: Vec<usize> = (0..entries.len())
        .filter(|&e| e == 0 || entries[e].0 != entries[e - 1].0)
        .collect();
    runs.push(entries.len());
    let mut pairs: Vec<(usize, usize)> = runs
        .par_windows(2)
        .fold(
            || (Vec::new(), Vec::new()),
            |(mut near, mut acc), r| {
                pairs_in(points, &entries[r[0]..r[1]], &mut near, &mut acc);
                (near, acc)
            },
        )
        .flat_map_iter(|(_, acc)| acc)
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    pairs
}

/// The crossing pairs among one cell's segments (sorted by index).
fn pairs_in(
    points: &[[f64; 2]],
    cell: &[(u32, u32)],
    near: &mut Vec<(usize, [f64; 2], [f64; 2])>,
    out: &mut Vec<(usize, usize)>,
) {
    // The cell's segments gathered once (a path's segments in one cell
    // lie far apart in memory), then paired.
    near.clear();
    near.extend(
        cell.iter()
            .map(|&(_, k)| (k as usize, points[k as usize], points[k as usize + 1])),
    );
    for (n, &(i, a, b)) in near.iter().enumerate() {
        for &(j, c, d) in &near[n + 1..] {
            if j == i + 1 {
                continue;
            }
            // The boxes first: most pairs of a cell are apart.
            if a[0].max(b[0]) < c[0].min(d[0])
                || c[0].max(d[0]) < a[0].min(b[0])
                || a[1].max(b[1]) < c[1].min(d[1])
                || c[1].max(d[1]) < a[1].min(b[1])
            {
                continue;
            }
            if segments_cross(a, b, c, d) {
                out.push((i, j));
            }
        }
    }
}

/// The sign of the turn `a` → `b` → `c` (positive: counter-clockwise in
/// x-right, y-up axes), as an f64 cross product.
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether segments `a`–`b` and `c`–`d` (each of nonzero length) cross as
/// [`crossings`] counts it: interiors meeting at one point, or collinear
/// and overlapping over a length.
pub(crate) fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    if o1 == 0.0 && o2 == 0.0 {
        // On one line: the overlap along the line's longer axis.
        let k = usize::from((b[0] - a[0]).abs() < (b[1] - a[1]).abs());
        let lo = a[k].min(b[k]).max(c[k].min(d[k]));
        let hi = a[k].max(b[k]).min(c[k].max(d[k]));
        return hi > lo;
    }
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    opposite(o1, o2) && opposite(o3, o4)
}

/// Whether `u` and `v` have strictly opposite signs.
fn opposite(u: f64, v: f64) -> bool {
    (u > 0.0 && v < 0.0) || (u < 0.0 && v > 0.0)
}

/// The most cells a [`crossings`] grid has per segment: with cells about a
/// segment long a tour's segments fill few of them, and a path spread far
/// from its points (a few long jumps) gets larger cells rather than a grid
/// of mostly empty ones.
const CELLS_PER_SEGMENT: f64 = 4.0;

/// The side of a [`crossings`] cell, in mean segments: on a 1M-point
/// random walk half as long found the pairs no sooner (more cells a
/// segment, each pair found in more of them), twice as long no sooner
/// either (more pairs a cell).
const CELL_SIDE: f64 = 1.0;

/// A uniform grid of square cells over the points' bounding box.
struct Grid {
    origin: [f64; 2],
    /// Cells per unit length (1 / the cell's side).
    inv: f64,
    nx: u32,
    ny: u32,
}

impl Grid {
    /// A grid over the segments `segments` of the path through `points`
    /// (each finite and of nonzero length), its cells about the mean
    /// segment long.
    fn new(points: &[[f64; 2]], segments: &[usize]) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut total = 0.0;
        for &k in segments {
            for p in [points[k], points[k + 1]] {
                for a in 0..2 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            let (dx, dy) = (
                points[k + 1][0] - points[k][0],
                points[k + 1][1] - points[k][1],
            );
            total += (dx * dx + dy * dy).sqrt();
        }
        let (ex, ey) = (hi[0] - lo[0], hi[1] - lo[1]);
        let n = segments.len() as f64;
        let side = (CELL_SIDE * total / n).max((ex * ey / (CELLS_PER_SEGMENT * n)).sqrt());
        // Each side's count is at most its extent over the mean segment
        // (the path spans it), about n; past u32 (or coordinates whose
        // extent is not finite) one cell holds all.
        let count = |e: f64| (e / side).floor() + 1.0;
        let (nx, ny) = (count(ex), count(ey));
        if !(side.is_finite() && side > 0.0 && nx * ny < f64::from(u32::MAX)) {
            return Self {
                origin: lo,
                inv: 0.0,
                nx: 1,
                ny: 1,
            };
        }
        Self {
            origin: lo,
            inv: 1.0 / side,
            nx: nx as u32,
            ny: ny as u32,
        }
    }

    /// Calls `each` with every cell segment `a`–`b` passes, row by row
    /// (with a margin of rounding around it, so that two segments that
    /// meet share a cell): its cost is the rows and columns it spans, not
    /// its bounding box's area.
    fn cells(&self, a: [f64; 2], b: [f64; 2], mut each: impl FnMut(u32)) {
        const MARGIN: f64 = 1e-9;
        let at = |p: [f64; 2]| {
            [
                (p[0] - self.origin[0]) * self.inv,
                (p[1] - self.origin[1]) * self.inv,
            ]
        };
        let (a, b) = (at(a), at(b));
        let col = |x: f64| x.floor().clamp(0.0, f64::from(self.nx - 1)) as u32;
        let row = |y: f64| y.floor().clamp(0.0, f64::from(self.ny - 1)) as u32;
        let (y_lo, y_hi) = (a[1].min(b[1]), a[1].max(b[1]));
        for cy in row(y_lo - MARGIN)..=row(y_hi + MARGIN) {
            // The part of the segment within this row's band of y (the
            // first and last rows reach to the grid's edges).
            let (x_lo, x_hi) = if b[1] == a[1] || self.ny == 1 {
                (a[0].min(b[0]), a[0].max(b[0]))
            } else {
                let band = |y: f64| ((y - a[1]) / (b[1] - a[1])).clamp(0.0, 1.0);
                let (t0, t1) = (
                    band(f64::from(cy) - MARGIN),
                    band(f64::from(cy + 1) + MARGIN),
                );
                let (x0, x1) = (a[0] + t0 * (b[0] - a[0]), a[0] + t1 * (b[0] - a[0]));
                (x0.min(x1), x0.max(x1))
            };
            let base = cy * self.nx;
            for cx in col(x_lo - MARGIN)..=col(x_hi + MARGIN) {
                each(base + cx);
            }
        }
    }
}

/// Chords shorter than this (domain pixels) join points taken as one:
/// they give no direction and no parameter length.
const COINCIDENT: f64 = 1e-9;

/// The centripetal Catmull–Rom curve (α = ½) through every point of
/// `points`, as one cubic Bézier `[p0, c1, c2, p1]` per consecutive pair:
/// it passes through each point with a continuous tangent, and, unlike the
/// uniform one, makes no cusp or loop within a segment however unevenly the
/// points are spaced. At the ends the missing neighbour is the end's
/// neighbour reflected through it (a straight start and end). Coincident
/// points give a Bézier that is a point, and their neighbours take their
/// tangents from the nearest points apart from them, so that nothing is
/// divided by zero. Fewer than two points give none; the points must be
/// finite.
///
/// ```
/// use pixelpie::stipple::line;
/// let b = line::catmull_rom(&[[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]]);
/// assert_eq!((b.len(), b[0][0], b[0][3], b[1][3]), (2, [0.0, 0.0], [1.0, 1.0], [2.0, 0.0]));
/// ```
#[must_use]
pub fn catmull_rom(points: &[[f64; 2]]) -> Vec<[[f64; 2]; 4]> {
    let n = points.len();
    if n < 2 {
        return Vec::new();
    }
    // The nearest point before each that lies apart from it, and after.
    let apart = |i: usize, j: usize| chord(points[i], points[j]) >= COINCIDENT;
    let mut before = vec![None; n];
    for k in 1..n {
        before[k] = if apart(k - 1, k) {
            Some(k - 1)
        } else {
            before[k - 1]
        };
    }
    let mut after = vec![None; n];
    for k in (0..n - 1).rev() {
        after[k] = if apart(k + 1, k) {
            Some(k + 1)
        } else {
            after[k + 1]
        };
    }
    (0..n - 1)
        .map(|k| {
            let (p1, p2) = (points[k], points[k + 1]);
            if !apart(k, k + 1) {
                return [p1, p1, p2, p2];
            }
            let c1 = control(before[k].map(|i| points[i]), p1, p2);
            let c2 = control(after[k + 1].map(|i| points[i]), p2, p1);
            [p1, c1, c2, p2]
        })
        .collect()
}

/// The length of chord `a`–`b`.
fn chord(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// The Bézier control point next to `p1` of the centripetal Catmull–Rom
/// segment from `p1` to `p2` (apart), `p0` the point before `p1` (none at
/// an end, or where it coincides with `p1`: the reflection of `p2`, which
/// makes the tangent the chord's): `p1` + m·d₁/3, m the curve's derivative
/// at `p1` in the knot parameter, dᵢ the chords' square roots.
fn control(p0: Option<[f64; 2]>, p1: [f64; 2], p2: [f64; 2]) -> [f64; 2] {
    let d1 = chord(p1, p2).sqrt();
    let Some(p0) = p0.filter(|&p| chord(p, p1) >= COINCIDENT) else {
        return std::array::from_fn(|a| p1[a] + (p2[a] - p1[a]) / 3.0);
    };
    let d0 = chord(p0, p1).sqrt();
    std::array::from_fn(|a| {
        let m = (p1[a] - p0[a]) / d0 - (p2[a] - p0[a]) / (d0 + d1) + (p2[a] - p1[a]) / d1;
        p1[a] + m * d1 / 3.0
    })
}

/// The most straight pieces [`flatten`] makes of one Bézier.
const MAX_PIECES: usize = 4096;

/// The curve of `beziers` as a polyline within `tolerance` of it: each
/// Bézier cut at even steps of its parameter into n pieces, n the least
/// whole number with ¾·M/n² ≤ `tolerance` (M the larger of its control
/// polygon's two second differences |p0 − 2c1 + c2| and |c1 − 2c2 + p1|: a
/// chord over a parameter step h strays at most h²/8 of the curve's largest
/// second derivative, 6M, from it), at most 4096 a Bézier (which a
/// tolerance that is not a positive number takes, and which M needs only
/// past 2·10⁷ tolerances). Every Bézier's end points are in it exactly,
/// and no point twice in a row.
///
/// ```
/// use pixelpie::stipple::line;
/// let straight = [[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]];
/// assert_eq!(line::flatten(&straight, 0.1), [[0.0, 0.0], [3.0, 0.0]]);
/// ```
#[must_use]
pub fn flatten(beziers: &[[[f64; 2]; 4]], tolerance: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    let mut push = |p: [f64; 2]| {
        if out.last() != Some(&p) {
            out.push(p);
        }
    };
    for b in beziers {
        let n = pieces(b, tolerance);
        push(b[0]);
        for k in 1..n {
            push(bezier_at(b, k as f64 / n as f64));
        }
        push(b[3]);
    }
    out
}

/// How many straight pieces [`flatten`] cuts Bézier `b` into.
fn pieces(b: &[[f64; 2]; 4], tolerance: f64) -> usize {
    let second = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (p[0] - 2.0 * q[0] + r[0]).hypot(p[1] - 2.0 * q[1] + r[1])
    };
    let m = second(b[0], b[1], b[2]).max(second(b[1], b[2], b[3]));
    if !(m > 0.0 && m.is_finite()) {
        return 1;
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return MAX_PIECES;
    }
    let n = (0.75 * m / tolerance).sqrt().ceil();
    if n >= MAX_PIECES as f64 {
        MAX_PIECES
    } else {
        (n as usize).max(1)
    }
}

/// The point of Bézier `b` at parameter `t`.
fn bezier_at(b: &[[f64; 2]; 4], t: f64) -> [f64; 2] {
    let u = 1.0 - t;
    let w = [u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t];
    std::array::from_fn(|a| w[0] * b[0][a] + w[1] * b[1][a] + w[2] * b[2][a] + w[3] * b[3][a])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng, rngs::StdRng};

    /// A random walk of `n` points in steps of `step` px, kept within a
    /// `side` square by reflection at its edges.
    fn walk(n: usize, step: f64, side: f64, seed: u64) -> Vec<[f64; 2]> {
        let mut rng = StdRng::seed_from_u64(seed);
        let mut p = [side / 2.0, side / 2.0];
        (0..n)
            .map(|_| {
                let t: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                for (a, d) in [t.cos(), t.sin()].into_iter().enumerate() {
                    p[a] += step * d;
                    if p[a] < 0.0 {
                        p[a] = -p[a];
                    }
                    if p[a] > side {
                        p[a] = 2.0 * side - p[a];
                    }
                }
                p
            })
            .collect()
    }

    /// The crossings by testing every pair, as [`crossings`] defines them.
    fn brute(points: &[[f64; 2]]) -> Vec<(usize, usize)> {
        let ok = |k: usize| points[k] != points[k + 1];
        let m = points.len().saturating_sub(1);
        let mut out = Vec::new();
        for i in 0..m {
            for j in i + 2..m {
                if ok(i)
                    && ok(j)
                    && segments_cross(points[i], points[i + 1], points[j], points[j + 1])
                {
                    out.push((i, j));
                }
            }
        }
        out
    }

    /// A line 2 px wide inks a band 2 px high: whole pixels on it, paper
    /// beside it, and its mean ink is its area (with the round caps) at
    /// any scale.
    #[test]
    fn a_line_inks_a_band_its_width() {
        let line = [[8.0, 32.0], [56.0, 32.0]];
        let want = (48.0 * 2.0 + std::f64::consts::PI) / (64.0 * 64.0);
        for scale in [1.0, 2.0, 0.5] {
            let side = (64.0 * scale) as u32;
            let img = render_polyline(&line, 2.0, (side, side), scale);
            let got = coverage_mean(&img);
            assert!(
                (got / want - 1.0).abs() < 0.03,
                "scale {scale}: {got} vs {want}"
            );
        }
        let img = render_polyline(&line, 2.0, (64, 64), 1.0);
        for x in 10..54 {
            let column: Vec<u8> = (29..35).map(|y| img.get_pixel(x, y).0[0]).collect();
            assert_eq!(column, [255, 255, 0, 0, 255, 255], "column {x}");
        }
        // Slanted, the same ink for its length.
        let slant = [[10.0, 10.0], [50.0, 40.0]];
        let img = render_polyline(&slant, 3.0, (64, 64), 1.0);
        let want = (50.0 * 3.0 + std::f64::consts::PI * 2.25) / 4096.0;
        let got = coverage_mean(&img);
        assert!((got / want - 1.0).abs() < 0.03, "{got} vs {want}");
    }

    /// The ink is the union of the pen's passes: a line drawn back over
    /// itself, or in several pieces, inks as once, and two crossing lines
    /// less than the sum of theirs.
    #[test]
    fn ink_where_the_line_passes_twice_is_counted_once() {
        let (a, b) = ([5.3, 7.1], [41.7, 28.2]);
        let once = render_polyline(&[a, b], 2.5, (48, 48), 1.0);
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        for path in [vec![a, b, a, b], vec![a, mid, b], vec![b, a, mid, a, b]] {
            assert_eq!(render_polyline(&path, 2.5, (48, 48), 1.0), once, "{path:?}");
        }
        let other = [[5.0, 40.0], [42.0, 4.0]];
        let both = render_polyline(&[a, b, other[0], other[1]], 1.5, (48, 48), 1.0);
        let one = coverage_mean(&render_polyline(&[a, b], 1.5, (48, 48), 1.0));
        let two = coverage_mean(&render_polyline(&other, 1.5, (48, 48), 1.0));
        let three = coverage_mean(&render_polyline(&[b, other[0]], 1.5, (48, 48), 1.0));
        let got = coverage_mean(&both);
        assert!(
            got < one + two + three - 1e-3,
            "{got} vs {one} + {two} + {three}"
        );
    }

    /// A pen thinner than a pixel still draws a continuous grey line,
    /// whose mean ink is its width times its length.
    #[test]
    fn a_thin_pen_is_a_faint_unbroken_line() {
        for (width, y) in [(0.1, 20.0), (0.3, 20.37), (0.2, 20.5)] {
            let line = [[8.0, y], [56.0, y + 9.0]];
            let img = render_polyline(&line, width, (64, 64), 1.0);
            for x in 9..55 {
                assert!(
                    (0..64).any(|yy| img.get_pixel(x, yy).0[0] < 255),
                    "width {width}: column {x} is blank"
                );
            }
            let length = 48f64.hypot(9.0);
            let want = width * length / 4096.0;
            let got = coverage_mean(&img);
            // The half-pixel pen's round caps add a little.
            assert!(
                (got / want - 1.0).abs() < 0.05,
                "width {width}: {got} vs {want}"
            );
        }
    }

    /// One point is a round dot the pen's width across; no points, or
    /// points that are not finite, nothing; a pen of no width, nothing.
    #[test]
    fn a_point_is_a_dot_and_nothing_is_paper() {
        let img = render_polyline(&[[16.0, 16.0]], 6.0, (32, 32), 1.0);
        let want = std::f64::consts::PI * 9.0 / 1024.0;
        let got = coverage_mean(&img);
        assert!((got / want - 1.0).abs() < 0.03, "{got} vs {want}");
        assert_eq!(img.get_pixel(16, 16).0[0], 0);
        let blank = GrayImage::from_pixel(32, 32, Luma([255]));
        assert_eq!(render_polyline(&[], 2.0, (32, 32), 1.0), blank);
        assert_eq!(
            render_polyline(&[[f64::NAN, 3.0]], 2.0, (32, 32), 1.0),
            blank
        );
        assert_eq!(
            render_polyline(&[[3.0, 3.0], [9.0, 9.0]], 0.0, (32, 32), 1.0),
            blank
        );
        assert_eq!(render_polyline(&[[3.0, 3.0]], 2.0, (0, 0), 1.0).len(), 0);
        // A point that is not finite drops its two segments only.
        let with_nan = render_polyline(
            &[
                [2.0, 2.0],
                [30.0, 2.0],
                [f64::NAN, 0.0],
                [2.0, 30.0],
                [30.0, 30.0],
            ],
            2.0,
            (32, 32),
            1.0,
        );
        let without = render_polyline(&[[2.0, 2.0], [30.0, 2.0]], 2.0, (32, 32), 1.0);
        let bottom = render_polyline(&[[2.0, 30.0], [30.0, 30.0]], 2.0, (32, 32), 1.0);
        let darker: Vec<u8> = without
            .as_raw()
            .iter()
            .zip(bottom.as_raw())
            .map(|(&p, &q)| p.min(q))
            .collect();
        assert_eq!(with_nan.as_raw(), &darker);
        // Segments far off the image are left out, and those partly on it
        // drawn.
        let off = render_polyline(&[[-1e9, 5.0], [1e9, 5.0]], 2.0, (32, 32), 1.0);
        assert_eq!(off.get_pixel(20, 4).0[0], 0);
        let far = render_polyline(&[[-1e9, -1e9], [-2e9, 5.0]], 2.0, (32, 32), 1.0);
        assert_eq!(far, blank);
    }

    /// The image is the same for any number of threads, and across the
    /// bands' edges (a line on a band's edge row).
    #[test]
    fn the_render_does_not_depend_on_the_threads() {
        let pts = walk(4000, 3.0, 300.0, 5);
        let draw = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| render_polyline(&pts, 1.3, (450, 450), 1.5))
        };
        assert_eq!(draw(1), draw(3));
        let edge = [[5.0, f64::from(BAND)], [100.0, f64::from(BAND)]];
        let img = render_polyline(&edge, 2.0, (128, 2 * BAND), 1.0);
        for y in [BAND - 1, BAND] {
            assert_eq!(img.get_pixel(50, y).0[0], 0, "row {y}");
        }
    }

    /// The crossing of an hourglass is found; a spiral, a zig-zag, a path
    /// doubling back on its last segment and touches are none; a
    /// collinear overlap is one.
    #[test]
    fn crossings_are_the_places_the_path_crosses_itself() {
        let hourglass = [[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]];
        assert_eq!(crossings(&hourglass), [(0, 2)]);
        // Two crossings, a duplicated point on the way, and a pass through
        // the path's first point (a touch: not one).
        let eight = [
            [0.0, 0.0],
            [10.0, 10.0],
            [10.0, 10.0],
            [10.0, 0.0],
            [0.0, 10.0],
            [-10.0, 0.0],
            [-10.0, 10.0],
            [1.0, -1.0],
        ];
        assert_eq!(crossings(&eight), [(0, 3), (4, 6)]);
        let spiral: Vec<[f64; 2]> = (0..2000)
            .map(|k| {
                let t = k as f64 * 0.05;
                [(5.0 + 2.0 * t) * t.cos(), (5.0 + 2.0 * t) * t.sin()]
            })
            .collect();
        assert!(crossings(&spiral).is_empty());
        let zigzag: Vec<[f64; 2]> = (0..500)
            .map(|k| [k as f64, f64::from(k % 2 == 0)])
            .collect();
        assert!(crossings(&zigzag).is_empty());
        // Adjacent segments folding back do not count; touching does not.
        assert!(crossings(&[[0.0, 0.0], [4.0, 0.0], [1.0, 0.0]]).is_empty());
        let touch = [[0.0, 0.0], [4.0, 0.0], [2.0, 3.0], [2.0, 0.0], [2.0, -3.0]];
        assert!(crossings(&touch).is_empty());
        // Two segments on one line, overlapping.
        let overlap = [[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [2.0, 0.0], [6.0, 0.0]];
        assert_eq!(crossings(&overlap), [(0, 3)]);
        let end_to_end = [[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [4.0, 0.0], [6.0, 0.0]];
        assert!(crossings(&end_to_end).is_empty());
    }

    /// The grid finds what testing every pair finds: random orders (long
    /// segments over many cells), walks with a few long jumps, points on
    /// an integer lattice (many collinear and touching pairs).
    #[test]
    fn crossings_agree_with_every_pair_tested() {
        let mut rng = StdRng::seed_from_u64(3);
        for round in 0..30 {
            let n = rng.random_range(2..320usize);
            let pts: Vec<[f64; 2]> = match round % 3 {
                0 => (0..n)
                    .map(|_| [rng.random_range(0.0..100.0), rng.random_range(0.0..60.0)])
                    .collect(),
                1 => {
                    let mut w = walk(n, 2.0, 50.0, round);
                    for _ in 0..3 {
                        let k = rng.random_range(0..n);
                        w[k] = [rng.random_range(-500.0..500.0), 25.0];
                    }
                    w
                }
                _ => (0..n)
                    .map(|_| {
                        [
                            f64::from(rng.random_range(0..12u8)),
                            f64::from(rng.random_range(0..12u8)),
                        ]
                    })
                    .collect(),
            };
            assert_eq!(crossings(&pts), brute(&pts), "round {round}, {n} points");
        }
    }

    /// The Béziers pass through every point, their flattened polyline
    /// stays within the tolerance of the curve (and the curve of it), and
    /// coincident points make no NaN.
    #[test]
    fn catmull_rom_passes_through_the_points_and_flattens_within_tolerance() {
        let mut rng = StdRng::seed_from_u64(9);
        let mut pts: Vec<[f64; 2]> = (0..40)
            .map(|_| [rng.random_range(0.0..50.0), rng.random_range(0.0..50.0)])
            .collect();
        // Duplicates, inside and at an end, and points very near.
        pts.insert(10, pts[10]);
        pts.insert(20, pts[20]);
        pts.insert(20, pts[20]);
        pts.push(pts[pts.len() - 1]);
        pts.insert(0, pts[0]);
        pts.insert(30, [pts[30][0] + 1e-12, pts[30][1]]);
        let curve = catmull_rom(&pts);
        assert_eq!(curve.len(), pts.len() - 1);
        for (k, b) in curve.iter().enumerate() {
            assert_eq!((b[0], b[3]), (pts[k], pts[k + 1]), "segment {k}");
            assert!(b.iter().flatten().all(|v| v.is_finite()), "{b:?}");
        }
        for tolerance in [0.5, 0.05, 0.002] {
            let flat = flatten(&curve, tolerance);
            assert!(flat.windows(2).all(|w| w[0] != w[1]), "a point twice");
            let mut ends: Vec<[f64; 2]> = pts.clone();
            ends.dedup();
            let mut at = 0;
            for p in &ends {
                at += flat[at..]
                    .iter()
                    .position(|q| q == p)
                    .expect("an end point");
            }
            for b in &curve {
                for m in 0..=64 {
                    let p = bezier_at(b, f64::from(m) / 64.0);
                    let d = flat
                        .windows(2)
                        .map(|w| point_to_segment(p, w[0], w[1]))
                        .fold(f64::INFINITY, f64::min);
                    assert!(d <= tolerance * (1.0 + 1e-9), "{d} > {tolerance}");
                }
            }
        }
        assert!(catmull_rom(&[[1.0, 1.0]]).is_empty());
        let same = catmull_rom(&[[1.0, 1.0]; 3]);
        assert!(same.iter().flatten().flatten().all(|v| *v == 1.0));
        assert_eq!(flatten(&same, 0.1), [[1.0, 1.0]]);
    }

    fn point_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
        let d = [b[0] - a[0], b[1] - a[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let t = if len2 > 0.0 {
            (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p[0] - a[0] - t * d[0]).hypot(p[1] - a[1] - t * d[1])
    }

    /// Times the render and the crossings of a 1M-point random walk on a
    /// 4096² image (`cargo test --release --lib line::tests::timing --
    /// --ignored --nocapture`).
    #[test]
    #[ignore = "a timing, printed"]
    fn timing() {
        let pts = walk(1_000_000, 4.0, 4096.0, 1);
        for width in [1.0, 3.0] {
            let t = std::time::Instant::now();
            let img = render_polyline(&pts, width, (4096, 4096), 1.0);
            println!(
                "render_polyline 1M points, width {width}, 4096²: {:.3} s (ink {:.3})",
                t.elapsed().as_secs_f64(),
                coverage_mean(&img)
            );
        }
        let t = std::time::Instant::now();
        let found = crossings(&pts);
        println!(
            "crossings 1M-point walk: {:.3} s ({} pairs)",
            t.elapsed().as_secs_f64(),
            found.len()
        );
        // A tour's like: 1M random points along a Hilbert curve.
        let mut rng = StdRng::seed_from_u64(2);
        let dots: Vec<[f64; 2]> = (0..1_000_000)
            .map(|_| [rng.random_range(0.0..4096.0), rng.random_range(0.0..4096.0)])
            .collect();
        let tour: Vec<[f64; 2]> = crate::stipple::spatial::hilbert_path(&dots)
            .into_iter()
            .map(|i| dots[i])
            .collect();
        let t = std::time::Instant::now();
        let found = crossings(&tour);
        println!(
            "crossings 1M points in Hilbert order: {:.3} s ({} pairs)",
            t.elapsed().as_secs_f64(),
            found.len()
        );
        let t = std::time::Instant::now();
        let img = render_polyline(&tour, 1.0, (4096, 4096), 1.0);
        println!(
            "render_polyline of it, width 1: {:.3} s (ink {:.3})",
            t.elapsed().as_secs_f64(),
            coverage_mean(&img)
        );
    }
}
