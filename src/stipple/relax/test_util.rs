//! Helpers shared by the relaxation's unit tests: random points and
//! weights, options, relaxation without a progress callback, and a
//! comparison of two point lists with a tolerance.

use super::start::unit;
use super::{Density, RelaxOptions, relax};

/// Random points uniform in `[0, w) × [0, h)`.
pub(super) fn uniform_points(n: usize, w: f64, h: f64, seed: u64) -> Vec<[f32; 2]> {
    let n = n as u64;
    (0..n)
        .map(|i| [(unit(seed, i) * w) as f32, (unit(seed, n + i) * h) as f32])
        .collect()
}

/// Random weights, about a third of them zero.
pub(super) fn random_weights(w: usize, h: usize, seed: u64) -> Vec<f32> {
    (0..(w * h) as u64)
        .map(|i| unit(seed, i) as f32 * 3.0 - 1.0)
        .map(|v| v.max(0.0))
        .collect()
}

pub(super) fn opts(iterations: u32, periodic: bool) -> RelaxOptions {
    RelaxOptions {
        iterations,
        periodic,
        cells: super::Cells::Pixels,
        over: 1.0,
    }
}

/// Both ways of taking the cells: pixels, and polygons integrated at 2 px.
pub(super) const BOTH: [super::Cells; 2] =
    [super::Cells::Pixels, super::Cells::Polygons { edge: 2.0 }];

/// [`opts`] with the cells taken as `cells`.
pub(super) fn opts_with(iterations: u32, periodic: bool, cells: super::Cells) -> RelaxOptions {
    RelaxOptions {
        cells,
        ..opts(iterations, periodic)
    }
}

pub(super) fn relax_all(
    points: &[[f32; 2]],
    density: &Density<'_>,
    options: RelaxOptions,
) -> Vec<[f32; 2]> {
    relax(points, density, options, |_| true)
}

pub(super) fn assert_close(a: &[[f32; 2]], b: &[[f32; 2]], tol: f32, what: &str) {
    assert_eq!(a.len(), b.len());
    for (i, (p, q)) in a.iter().zip(b).enumerate() {
        let ok = (0..2).all(|k| (p[k] - q[k]).abs() <= tol || (p[k].is_nan() && q[k].is_nan()));
        assert!(ok, "{what}: point {i}: {p:?} vs {q:?}");
    }
}
