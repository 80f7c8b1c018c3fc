//! The angular distribution of nearest neighbours (paper §4.3, Figure 9).
//!
//! Neighbours are the Delaunay triangulation's edges (`delaunator`). Each
//! undirected edge p–q contributes **both** directions, the angle of q − p
//! and that of p − q, so the histogram is symmetric under a half turn and
//! holds 2E entries for E edges (about 6N). Angles are measured from the
//! +x axis counter-clockwise with y pointing up (the file's y, which points
//! down in image coordinates, is negated), in degrees in [0°, 360°). The
//! histogram has 360 bins of 1°; its standard deviation is the population
//! one, sqrt(Σ (c_k − c̄)² / 360). For points placed independently of
//! direction the counts are close to Poisson, so the std is near
//! sqrt(2E/360) (≈ 13 for 10K points), and axis-aligned bias adds spikes.

/// The angles, in degrees, of every Delaunay edge of `points` in both directions.
///
/// ```
/// let a = pixelpie::analyze::angles::delaunay_angles(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
/// let mut a: Vec<i64> = a.iter().map(|x| x.round() as i64).collect();
/// a.sort();
/// assert_eq!(a, vec![0, 45, 90, 180, 225, 270]);
/// ```
#[must_use]
pub fn delaunay_angles(points: &[[f64; 2]]) -> Vec<f64> {
    if points.len() < 3 {
        return Vec::new();
    }
    let pts: Vec<delaunator::Point> = points
        .iter()
        .map(|p| delaunator::Point { x: p[0], y: -p[1] })
        .collect();
    let t = delaunator::triangulate(&pts);
    let mut out = Vec::with_capacity(t.triangles.len());
    for e in 0..t.triangles.len() {
        let twin = t.halfedges[e];
        if twin != delaunator::EMPTY && twin < e {
            continue; // the twin already counted this edge
        }
        let a = &pts[t.triangles[e]];
        let b = &pts[t.triangles[delaunator::next_halfedge(e)]];
        let deg = (b.y - a.y).atan2(b.x - a.x).to_degrees();
        out.push(deg.rem_euclid(360.0));
        out.push((deg + 180.0).rem_euclid(360.0));
    }
    out
}

/// Counts `angles` (degrees) into `bins` equal bins over [0°, 360°).
///
/// ```
/// let h = pixelpie::analyze::angles::histogram(&[0.5, 359.9, 360.0, 90.0], 4);
/// assert_eq!(h, vec![2, 1, 0, 1]); // 360° is 0°
/// ```
#[must_use]
pub fn histogram(angles: &[f64], bins: usize) -> Vec<u64> {
    let mut h = vec![0u64; bins.max(1)];
    let width = 360.0 / h.len() as f64;
    for &a in angles {
        let k = ((a.rem_euclid(360.0) / width) as usize).min(h.len() - 1);
        h[k] += 1;
    }
    h
}

/// The population standard deviation of the bin counts.
///
/// ```
/// assert_eq!(pixelpie::analyze::angles::histogram_std(&[1, 3, 1, 3]), 1.0);
/// ```
#[must_use]
pub fn histogram_std(counts: &[u64]) -> f64 {
    if counts.is_empty() {
        return 0.0;
    }
    let n = counts.len() as f64;
    let mean = counts.iter().map(|&c| c as f64).sum::<f64>() / n;
    let var = counts
        .iter()
        .map(|&c| (c as f64 - mean).powi(2))
        .sum::<f64>()
        / n;
    var.sqrt()
}
