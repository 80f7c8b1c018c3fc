//! The last resort of the finest level: whether the disks cover a cell whose
//! one dart position is already covered, decided in `f64` with a margin that
//! errs towards "not covered".
//!
//! The uncovered part of a closed cell, when not empty, has a lowest-leftmost
//! point, and that point is a vertex: a corner of the cell, a crossing of a
//! circle with an edge, or a crossing of two circles (an uncovered region
//! lies outside every disk, so its boundary arcs never hold an extreme
//! point). The cell is covered when each such vertex lies inside some disk by
//! more than [`MARGIN`], far above the rounding of the few `f64` operations.

/// The margin in pixels: a vertex counts as covered only when it lies this
/// far inside a disk. Dart positions are at least 2^-16 px apart.
pub const MARGIN: f64 = 1e-6;

/// A disk in pixels.
#[derive(Clone, Copy, Debug)]
pub struct Disk {
    /// Centre x.
    pub x: f64,
    /// Centre y.
    pub y: f64,
    /// Radius.
    pub r: f64,
}

fn strictly_covered(disks: &[Disk], (x, y): (f64, f64)) -> bool {
    disks.iter().any(|d| {
        let (dx, dy) = (x - d.x, y - d.y);
        (dx * dx + dy * dy).sqrt() < d.r - MARGIN
    })
}

/// Whether `disks` cover the closed square `[x0, x1] × [y0, y1]` (pixels).
/// Centres are unwrapped to the cell's side of a periodic domain by the caller.
#[must_use]
pub fn covers(disks: &[Disk], (x0, y0, x1, y1): (f64, f64, f64, f64)) -> bool {
    let mut vertices = vec![(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
    for d in disks {
        // Crossings with the four edges.
        for &(fixed_x, c) in &[(true, x0), (true, x1), (false, y0), (false, y1)] {
            let off = if fixed_x { c - d.x } else { c - d.y };
            let h2 = d.r * d.r - off * off;
            if h2 < 0.0 {
                continue;
            }
            let h = h2.sqrt();
            for s in [-h, h] {
                let p = if fixed_x { (c, d.y + s) } else { (d.x + s, c) };
                vertices.push(p);
            }
        }
    }
    for (i, a) in disks.iter().enumerate() {
        for b in &disks[i + 1..] {
            let (dx, dy) = (b.x - a.x, b.y - a.y);
            let d2 = dx * dx + dy * dy;
            let d = d2.sqrt();
            if d == 0.0 || d > a.r + b.r || d < (a.r - b.r).abs() {
                continue;
            }
            let along = (a.r * a.r - b.r * b.r + d2) / (2.0 * d);
            let h = (a.r * a.r - along * along).max(0.0).sqrt();
            let (ux, uy) = (dx / d, dy / d);
            let (mx, my) = (a.x + along * ux, a.y + along * uy);
            vertices.push((mx - h * uy, my + h * ux));
            vertices.push((mx + h * uy, my - h * ux));
        }
    }
    // A vertex within rounding of the cell is tested too: the test only
    // errs towards "not covered".
    let near = |(x, y): (f64, f64)| {
        x >= x0 - MARGIN && x <= x1 + MARGIN && y >= y0 - MARGIN && y <= y1 + MARGIN
    };
    vertices
        .into_iter()
        .filter(|&v| near(v))
        .all(|v| strictly_covered(disks, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_big_disk_covers_and_a_gap_is_found() {
        let cell = (0.0, 0.0, 1.0, 1.0);
        let big = Disk {
            x: 0.5,
            y: 0.5,
            r: 2.0,
        };
        assert!(covers(&[big], cell));
        // Two disks that leave a sliver between them uncovered.
        let left = Disk {
            x: -1.0,
            y: 0.5,
            r: 1.49,
        };
        let right = Disk {
            x: 2.0,
            y: 0.5,
            r: 1.49,
        };
        assert!(!covers(&[left, right], cell));
        // Overlapping enough, they cover the cell together but neither alone.
        let left = Disk {
            x: -0.6,
            y: 0.5,
            r: 1.3,
        };
        let right = Disk {
            x: 1.6,
            y: 0.5,
            r: 1.3,
        };
        assert!(covers(&[left, right], cell));
        assert!(!covers(&[left], cell) && !covers(&[right], cell));
    }
}
