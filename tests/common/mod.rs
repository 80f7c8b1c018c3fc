//! Brute-force checkers shared by the integration tests, and the binary's
//! runner. They use nothing of
//! the sampler but its output and the policy's definition.
#![allow(dead_code, reason = "each test binary uses a subset")]

use pixelpie::sampler::{Point, Policy};

/// Runs the `pixelpie` binary with `args`.
pub fn pixelpie(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_pixelpie"))
        .args(args)
        .output()
        .expect("run pixelpie")
}

/// The path of bundled asset `name`.
pub fn asset(name: &str) -> String {
    format!("{}/assets/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// The policy's separation f(r_earlier, r_later) in pixels.
pub fn separation(policy: Policy, earlier: f64, later: f64) -> f64 {
    match policy {
        Policy::Prior => earlier,
        Policy::Current => later,
        Policy::Bigger => earlier.max(later),
        Policy::Smaller => earlier.min(later),
    }
}

fn delta(a: f64, b: f64, period: Option<f64>) -> f64 {
    let d = (a - b).abs();
    period.map_or(d, |p| d.min(p - d))
}

/// The worst violation of the minimum distance over all pairs (earlier, later)
/// in acceptance order: max(f - distance), or -inf when there are no pairs.
pub fn worst_violation(points: &[Point], policy: Policy, wrap: Option<(f64, f64)>) -> f64 {
    let mut worst = f64::NEG_INFINITY;
    for (j, b) in points.iter().enumerate() {
        for a in &points[..j] {
            let dx = delta(f64::from(a.x), f64::from(b.x), wrap.map(|w| w.0));
            let dy = delta(f64::from(a.y), f64::from(b.y), wrap.map(|w| w.1));
            let f = separation(policy, f64::from(a.radius), f64::from(b.radius));
            worst = worst.max(f - (dx * dx + dy * dy).sqrt());
        }
    }
    worst
}

/// Pixel centres that no point covers under the policy's coverage rule,
/// |p - c_i| < f(r_i, r_p), with `radius_at(x, y)` the map's radius.
pub fn uncovered_pixels(
    points: &[Point],
    width: u32,
    height: u32,
    policy: Policy,
    wrap: bool,
    radius_at: impl Fn(u32, u32) -> f64,
) -> Vec<(u32, u32)> {
    let period = wrap.then_some((f64::from(width), f64::from(height)));
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            let rp = radius_at(x, y);
            let covered = points.iter().any(|c| {
                let f = match policy {
                    Policy::Prior => f64::from(c.radius),
                    Policy::Current => rp,
                    Policy::Bigger => f64::from(c.radius).max(rp),
                    Policy::Smaller => f64::from(c.radius).min(rp),
                };
                let dx = delta(px, f64::from(c.x), period.map(|p| p.0));
                let dy = delta(py, f64::from(c.y), period.map(|p| p.1));
                dx * dx + dy * dy < f * f
            });
            if !covered {
                out.push((x, y));
            }
        }
    }
    out
}

/// A radius map with sharp steps: 2.5 px on the left, 6 px on the right, and a
/// 9 px block in the lower middle.
pub fn step_radii(width: u32, height: u32) -> Vec<f32> {
    let mut r = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let block = y > height / 2 && (width / 3..2 * width / 3).contains(&x);
            r.push(if block {
                9.0
            } else if x < width / 2 {
                2.5
            } else {
                6.0
            });
        }
    }
    r
}

/// A smooth radius map: a quadratic ramp from 2 px (left) to 8 px (right).
pub fn smooth_radii(width: u32, height: u32) -> Vec<f32> {
    let mut r = Vec::with_capacity((width * height) as usize);
    for _ in 0..height {
        for x in 0..width {
            let t = x as f32 / (width - 1) as f32;
            r.push(2.0 + 6.0 * t * t);
        }
    }
    r
}
