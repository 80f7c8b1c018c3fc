//! Distance and coverage measures: d_min, ρ, uncovered pixels, density.
//!
//! Each runs in about linear time: d_min through a uniform grid, coverage by
//! rasterizing every point's disk into a bitmap of the domain (the cost is
//! the sum of the disks' areas, not points × pixels).

use super::{CoverRadius, Domain, Result};
use crate::sampler::Control;

/// The most pixels [`uncovered_pixels`] agrees to rasterize.
pub const MAX_PIXELS: f64 = (1u64 << 31) as f64;

fn delta(a: f64, b: f64, period: Option<f64>) -> f64 {
    let d = (a - b).abs();
    match period {
        Some(p) => {
            let d = d % p;
            d.min(p - d)
        }
        None => d,
    }
}

/// The distance between `a` and `b`, the short way round on a periodic domain.
#[must_use]
pub fn distance(a: [f64; 2], b: [f64; 2], domain: Domain) -> f64 {
    let (px, py) = if domain.periodic {
        (Some(domain.width), Some(domain.height))
    } else {
        (None, None)
    };
    delta(a[0], b[0], px).hypot(delta(a[1], b[1], py))
}

/// The smallest distance between two of `points` (`None` for fewer than two).
///
/// ```
/// use pixelpie::analyze::{Domain, metrics};
/// let d = Domain { width: 10.0, height: 10.0, periodic: false };
/// let pts = [[1.0, 1.0], [4.0, 5.0], [9.0, 1.0]];
/// assert_eq!(metrics::min_distance(&pts, d), Some(5.0));
/// let torus = Domain { periodic: true, ..d };
/// assert_eq!(metrics::min_distance(&pts, torus), Some(2.0));
/// ```
#[must_use]
pub fn min_distance(points: &[[f64; 2]], domain: Domain) -> Option<f64> {
    min_distance_with(points, domain, &Control::new())
        .ok()
        .flatten()
}

/// [`min_distance`], polling `ctl`'s cancel flag ([`super::report_with`]).
pub(crate) fn min_distance_with(
    points: &[[f64; 2]],
    domain: Domain,
    ctl: &Control<'_>,
) -> Result<Option<f64>> {
    let n = points.len();
    if n < 2 {
        return Ok(None);
    }
    // Cells of about two points each, over the points' bounding box (the
    // domain's box when periodic, so that cells wrap).
    let (lo, hi) = if domain.periodic {
        ([0.0, 0.0], [domain.width, domain.height])
    } else {
        let mut lo = [f64::MAX; 2];
        let mut hi = [f64::MIN; 2];
        for p in points {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    };
    let (w, h) = ((hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9));
    let side = (2.0 * w * h / n as f64).sqrt();
    let nx = ((w / side).ceil() as usize).clamp(1, 4096);
    let ny = ((h / side).ceil() as usize).clamp(1, 4096);
    let (cw, ch) = (w / nx as f64, h / ny as f64);
    let cell_of = |p: [f64; 2]| {
        let (mut u, mut v) = (p[0] - lo[0], p[1] - lo[1]);
        if domain.periodic {
            u = u.rem_euclid(w);
            v = v.rem_euclid(h);
        }
        let cx = (u / cw).max(0.0) as usize;
        let cy = (v / ch).max(0.0) as usize;
        (cx.min(nx - 1), cy.min(ny - 1))
    };
    let mut cells = vec![Vec::new(); nx * ny];
    for (i, p) in points.iter().enumerate() {
        let (cx, cy) = cell_of(*p);
        cells[cy * nx + cx].push(i);
    }
    let mut best = f64::INFINITY;
    let reach = nx.max(ny) as isize;
    for (i, p) in points.iter().enumerate() {
        if i % super::POLL_EVERY == 0 {
            super::heed(ctl)?;
        }
        let (cx, cy) = cell_of(*p);
        let (cx, cy) = (cx as isize, cy as isize);
        for r in 0..=reach {
            // Points beyond ring r are at least r cells away.
            if r > 0 && (r - 1) as f64 * cw.min(ch) >= best {
                break;
            }
            for y in cy - r..=cy + r {
                let edge = y == cy - r || y == cy + r;
                let step = if edge || r == 0 { 1 } else { 2 * r as usize };
                for x in (cx - r..=cx + r).step_by(step) {
                    let (gx, gy) = if domain.periodic {
                        (x.rem_euclid(nx as isize), y.rem_euclid(ny as isize))
                    } else if x < 0 || y < 0 || x >= nx as isize || y >= ny as isize {
                        continue;
                    } else {
                        (x, y)
                    };
                    // Each pair is measured once, from its lower index.
                    for &j in &cells[gy as usize * nx + gx as usize] {
                        if j > i {
                            best = best.min(distance(*p, points[j], domain));
                        }
                    }
                }
            }
        }
    }
    Ok(Some(best))
}

/// ρ = d_min / d_hex, d_hex = sqrt(2A / (√3 N)) the spacing of N points in a
/// hexagonal packing of area A (Lagae & Dutré 2008; PSA's "relative radius").
///
/// ```
/// // A hexagonal lattice has ρ = 1.
/// let d = 2.0_f64;
/// let area = 100.0 * (3f64.sqrt() / 2.0 * d * d);
/// assert!((pixelpie::analyze::metrics::rho(d, 100, area) - 1.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn rho(min_distance: f64, n: usize, area: f64) -> f64 {
    let d_hex = (2.0 * area / (3f64.sqrt() * n as f64)).sqrt();
    min_distance / d_hex
}

/// The coverage density Σ π (r_i/2)² / A: the fraction of the domain that
/// disks of radius r/2 (which cannot overlap) cover.
#[must_use]
pub fn density(n: usize, radius: CoverRadius<'_>, area: f64) -> f64 {
    let sum: f64 = (0..n)
        .map(|i| {
            let r = radius.of(i) / 2.0;
            std::f64::consts::PI * r * r
        })
        .sum();
    sum / area
}

/// The pixel centres (i + ½, j + ½) of the domain that no point covers, with
/// "covered" meaning |p − c_i| < r_i, the sampler's strict rule (paper Eq. 3).
///
/// ```
/// use pixelpie::analyze::{CoverRadius, Domain, metrics};
/// let d = Domain { width: 4.0, height: 1.0, periodic: false };
/// let n = metrics::uncovered_pixels(&[[0.5, 0.5]], CoverRadius::Uniform(1.5), d).unwrap();
/// assert_eq!(n, 2); // centres at 0.5 and 1.5 are covered, 2.5 and 3.5 are not
/// ```
pub fn uncovered_pixels(
    points: &[[f64; 2]],
    radius: CoverRadius<'_>,
    domain: Domain,
) -> Result<u64> {
    uncovered_pixels_with(points, radius, domain, &Control::new())
}

/// [`uncovered_pixels`], polling `ctl`'s cancel flag
/// ([`super::report_with`]).
pub(crate) fn uncovered_pixels_with(
    points: &[[f64; 2]],
    radius: CoverRadius<'_>,
    domain: Domain,
    ctl: &Control<'_>,
) -> Result<u64> {
    domain.validate()?;
    let (wf, hf) = (domain.width.ceil(), domain.height.ceil());
    if wf * hf > MAX_PIXELS {
        return Err(super::Error::InvalidParameter(format!(
            "a {wf}x{hf} domain is too large to rasterize"
        )));
    }
    let (w, h) = (wf as i64, hf as i64);
    let mut covered = vec![false; (w * h) as usize];
    for (i, p) in points.iter().enumerate() {
        if i % super::POLL_EVERY == 0 {
            super::heed(ctl)?;
        }
        let r = radius.of(i);
        if r.is_nan() || r <= 0.0 {
            continue;
        }
        let r2 = r * r;
        // Pixel j's centre is j + 0.5: the rows whose centre may be within r.
        let y0 = (p[1] - r - 0.5).floor() as i64;
        let y1 = (p[1] + r - 0.5).ceil() as i64;
        let x0 = (p[0] - r - 0.5).floor() as i64;
        let x1 = (p[0] + r - 0.5).ceil() as i64;
        for y in y0..=y1 {
            let gy = if domain.periodic {
                y.rem_euclid(h)
            } else if (0..h).contains(&y) {
                y
            } else {
                continue;
            };
            let dy = y as f64 + 0.5 - p[1];
            if dy * dy >= r2 {
                continue;
            }
            for x in x0..=x1 {
                let gx = if domain.periodic {
                    x.rem_euclid(w)
                } else if (0..w).contains(&x) {
                    x
                } else {
                    continue;
                };
                let dx = x as f64 + 0.5 - p[0];
                if dx * dx + dy * dy < r2 {
                    covered[(gy * w + gx) as usize] = true;
                }
            }
        }
    }
    Ok(covered.iter().filter(|&&c| !c).count() as u64)
}
