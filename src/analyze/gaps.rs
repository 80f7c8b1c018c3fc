//! The largest gap of a point set and whether its disks cover the domain in
//! the continuous sense, for any point set.
//!
//! * The **largest gap** is the radius of the largest empty circle centred
//!   in the domain: the largest distance from a point of the closed domain
//!   to its nearest sample. It is attained at a Voronoi vertex, where the
//!   Voronoi diagram meets the boundary, or at a corner. The boundary is
//!   handled by mirroring the points near each side (and corner) across it,
//!   which turns the boundary into Voronoi edges; a periodic domain is
//!   handled by adding the wrapped copies of the points near its sides. The
//!   vertices are the circumcentres of the Delaunay triangles (`delaunator`).
//! * **Continuous maximality**: every point x of the closed domain lies
//!   strictly inside some sample's disk, |x − c_i| < r_i. Each pixel is a
//!   closed cell; a cell inside one disk is covered, and otherwise the
//!   disks near it are tested together by
//!   [`crate::sampler::exact::union::covers`], which errs towards "not
//!   covered".

use super::{CoverRadius, Domain, Result};
use crate::sampler::Control;
use crate::sampler::exact::union::{self, Disk};

/// The largest empty circle centred in the domain.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Gap {
    /// Its radius in pixels.
    pub radius: f64,
    /// Its centre.
    pub at: [f64; 2],
}

fn nearest(points: &[[f64; 2]], q: [f64; 2], domain: Domain) -> f64 {
    points
        .iter()
        .map(|&p| super::metrics::distance(p, q, domain))
        .fold(f64::INFINITY, f64::min)
}

/// The points with their mirror images (bounded) or wrapped copies
/// (periodic) within `margin` of each side.
fn augmented(points: &[[f64; 2]], domain: Domain, margin: f64) -> Vec<[f64; 2]> {
    let (w, h) = (domain.width, domain.height);
    let mut out = points.to_vec();
    for &[x, y] in points {
        let xs: Vec<f64> = if domain.periodic {
            [
                Some(x),
                (x < margin).then_some(x + w),
                (x > w - margin).then_some(x - w),
            ]
        } else {
            [
                Some(x),
                (x < margin).then_some(-x),
                (x > w - margin).then_some(2.0 * w - x),
            ]
        }
        .into_iter()
        .flatten()
        .collect();
        let ys: Vec<f64> = if domain.periodic {
            [
                Some(y),
                (y < margin).then_some(y + h),
                (y > h - margin).then_some(y - h),
            ]
        } else {
            [
                Some(y),
                (y < margin).then_some(-y),
                (y > h - margin).then_some(2.0 * h - y),
            ]
        }
        .into_iter()
        .flatten()
        .collect();
        for (i, &a) in xs.iter().enumerate() {
            for (j, &b) in ys.iter().enumerate() {
                if i + j > 0 {
                    out.push([a, b]);
                }
            }
        }
    }
    out
}

/// The largest empty circle centred in the closed domain (`None` without
/// points).
///
/// ```
/// use pixelpie::analyze::{Domain, gaps};
/// let d = Domain { width: 4.0, height: 4.0, periodic: false };
/// let g = gaps::largest_gap(&[[1.0, 1.0], [3.0, 1.0], [1.0, 3.0], [3.0, 3.0]], d).unwrap();
/// assert!((g.radius - 2f64.sqrt()).abs() < 1e-12); // at a corner or the centre
/// ```
#[must_use]
pub fn largest_gap(points: &[[f64; 2]], domain: Domain) -> Option<Gap> {
    largest_gap_with(points, domain, &Control::new())
        .ok()
        .flatten()
}

/// [`largest_gap`], polling `ctl`'s cancel flag between its steps
/// ([`super::report_with`]).
pub(crate) fn largest_gap_with(
    points: &[[f64; 2]],
    domain: Domain,
    ctl: &Control<'_>,
) -> Result<Option<Gap>> {
    if points.is_empty() {
        return Ok(None);
    }
    let corners = [
        [0.0, 0.0],
        [domain.width, 0.0],
        [0.0, domain.height],
        [domain.width, domain.height],
    ];
    let mut best = Gap {
        radius: nearest(points, corners[0], domain),
        at: corners[0],
    };
    if !domain.periodic {
        for c in &corners[1..] {
            let r = nearest(points, *c, domain);
            if r > best.radius {
                best = Gap { radius: r, at: *c };
            }
        }
    }
    // A margin of twice the gap found suffices: every Voronoi vertex in the
    // domain then has its three points, or their images, in the set.
    let mut margin = 4.0 * (domain.area() / points.len() as f64).sqrt();
    loop {
        super::heed(ctl)?;
        let all = augmented(points, domain, margin.min(domain.width.max(domain.height)));
        let mut found = best;
        if all.len() >= 3 {
            let pts: Vec<delaunator::Point> = all
                .iter()
                .map(|p| delaunator::Point { x: p[0], y: p[1] })
                .collect();
            super::heed(ctl)?;
            let t = delaunator::triangulate(&pts);
            super::heed(ctl)?;
            for tri in t.triangles.chunks_exact(3) {
                let (a, b, c) = (all[tri[0]], all[tri[1]], all[tri[2]]);
                let Some(centre) = circumcentre(a, b, c) else {
                    continue;
                };
                let inside = (0.0..=domain.width).contains(&centre[0])
                    && (0.0..=domain.height).contains(&centre[1]);
                if !inside {
                    continue;
                }
                let r = (centre[0] - a[0]).hypot(centre[1] - a[1]);
                if r > found.radius {
                    found = Gap {
                        radius: r,
                        at: centre,
                    };
                }
            }
        } else {
            // One or two points: the farthest point is a corner (done above)
            // or, on a torus, checked on a fine grid of candidates.
            for i in 0..=64 {
                for j in 0..=64 {
                    let q = [
                        domain.width * f64::from(i) / 64.0,
                        domain.height * f64::from(j) / 64.0,
                    ];
                    let r = nearest(points, q, domain);
                    if r > found.radius {
                        found = Gap { radius: r, at: q };
                    }
                }
            }
        }
        if 2.0 * found.radius <= margin || margin >= domain.width.max(domain.height) {
            return Ok(Some(found));
        }
        margin = 2.0 * found.radius + 1.0;
        best = found;
    }
}

fn circumcentre(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Option<[f64; 2]> {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    if d == 0.0 {
        return None;
    }
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    Some([
        a[0] + (cy * b2 - by * c2) / d,
        a[1] + (bx * c2 - cx * b2) / d,
    ])
}

/// Whether every point of the closed domain lies strictly inside the disk
/// of some point (radius `radius`): maximality in the continuous sense.
/// Returns the number of pixels (unit cells) not found covered.
pub fn uncovered_cells(
    points: &[[f64; 2]],
    radius: CoverRadius<'_>,
    domain: Domain,
) -> Result<u64> {
    uncovered_cells_with(points, radius, domain, &Control::new())
}

/// [`uncovered_cells`], polling `ctl`'s cancel flag: each row of cells
/// first ([`super::report_with`]).
pub(crate) fn uncovered_cells_with(
    points: &[[f64; 2]],
    radius: CoverRadius<'_>,
    domain: Domain,
    ctl: &Control<'_>,
) -> Result<u64> {
    domain.validate()?;
    if domain.area() > super::metrics::MAX_PIXELS {
        return Err(super::Error::InvalidParameter(format!(
            "a {}x{} domain is too large to test cell by cell",
            domain.width, domain.height
        )));
    }
    let r_max = (0..points.len()).map(|i| radius.of(i)).fold(0.0, f64::max);
    let (cols, rows) = (domain.width.ceil() as usize, domain.height.ceil() as usize);
    if points.is_empty() || r_max.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Ok((cols * rows) as u64);
    }
    // On a torus, the wrapped copies of the points near the sides join
    // them, so that the cells see every disk reaching them unwrapped.
    let m = r_max + 1.0;
    let mut disks_all: Vec<Disk> = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let r = radius.of(i);
        if domain.periodic {
            for img in augmented(&[*p], domain, m) {
                disks_all.push(Disk {
                    x: img[0],
                    y: img[1],
                    r,
                });
            }
        } else {
            disks_all.push(Disk {
                x: p[0],
                y: p[1],
                r,
            });
        }
    }
    // Disks binned by cells of side g > r_max + 1 over [-m, W + m] x
    // [-m, H + m]: a disk reaching a pixel lies in its bin or a neighbour.
    let g = (r_max + 1.0).ceil();
    let gc = ((domain.width + 2.0 * m) / g).ceil() as usize + 1;
    let gr = ((domain.height + 2.0 * m) / g).ceil() as usize + 1;
    let bin = |v: f64, n: usize| (((v + m) / g).floor().max(0.0) as usize).min(n - 1);
    let mut bins = vec![Vec::new(); gc * gr];
    for (k, d) in disks_all.iter().enumerate() {
        bins[bin(d.y, gr) * gc + bin(d.x, gc)].push(k);
    }
    use rayon::prelude::*;
    super::heed(ctl)?;
    let count = (0..rows)
        .into_par_iter()
        .map(|j| {
            let mut missed = 0u64;
            if ctl.cancelled() {
                return missed;
            }
            let mut disks = Vec::new();
            for i in 0..cols {
                let (x0, y0) = (i as f64, j as f64);
                let (x1, y1) = ((x0 + 1.0).min(domain.width), (y0 + 1.0).min(domain.height));
                disks.clear();
                let (bx, by) = (bin(x0, gc), bin(y0, gr));
                for cy in by.saturating_sub(1)..=(by + 1).min(gr - 1) {
                    for cx in bx.saturating_sub(1)..=(bx + 1).min(gc - 1) {
                        disks.extend(bins[cy * gc + cx].iter().map(|&k| disks_all[k]));
                    }
                }
                let whole = disks.iter().any(|d| {
                    let fx = (x0 - d.x).abs().max((x1 - d.x).abs());
                    let fy = (y0 - d.y).abs().max((y1 - d.y).abs());
                    fx.hypot(fy) < d.r - union::MARGIN
                });
                if !whole && !union::covers(&disks, (x0, y0, x1, y1)) {
                    missed += 1;
                }
            }
            missed
        })
        .sum();
    // A row skipped for a cancel would make the count wrong: it is not
    // returned.
    super::heed(ctl)?;
    Ok(count)
}
