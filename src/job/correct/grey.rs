//! The grey drawing's correction: its sized dots resized toward the map's
//! ink, on the plan's [`Grid`].

use rayon::prelude::*;

use super::{ERROR_BLUR, Grid, Schedule, blur_sigmas, damping, momentum, step};
use crate::analyze::fidelity::Grey;
use crate::importance::{Prepared, ink};
use crate::sampler::Point;

use super::super::Stage;

/// The ink the map asks for at (`x`, `y`) (none past the white cutoff,
/// where no dot is drawn).
fn ink_at(map: &Prepared, x: f32, y: f32) -> f64 {
    ink_of(map, map.value_at(x, y))
}

/// The ink the map asks for where its value is `v`.
fn ink_of(map: &Prepared, v: f32) -> f64 {
    let v = v.clamp(0.0, 1.0);
    if map.cutoff().is_some_and(|c| v > c) {
        0.0
    } else {
        f64::from(1.0 - v)
    }
}

/// The grey drawing's correction on a grid: its target made once
/// ([`Self::new`], no dot needed, so the run makes it while the dots are
/// relaxed), then applied to the dots ([`Self::apply`]).
pub(crate) struct GreyCorrection<'a> {
    grid: Grid,
    map: &'a Prepared,
    /// The ink the map asks for at each render pixel's centre, averaged
    /// over the work grid's cells and blurred as the drawing is.
    target: Grey,
}

impl<'a> GreyCorrection<'a> {
    /// The correction toward `map`'s ink on `grid`.
    pub(crate) fn new(grid: Grid, map: &'a Prepared) -> Self {
        let (w, _) = grid.size;
        let inv = 1.0 / grid.scale;
        // The ink at each render pixel's centre: its domain pixel's, read
        // a row at a time ([`ink_at`]'s values).
        let columns: Vec<u32> = (0..w)
            .map(|x| map.pixel_at((x as f32 + 0.5) * inv, 0.0).0)
            .collect();
        let target = grid.cell_means_of_rows(|y, out| {
            let mut values = vec![0.0f32; columns.len()];
            let (_, py) = map.pixel_at(0.0, (y as f32 + 0.5) * inv);
            map.row_at(py, &columns, &mut values);
            for (o, &v) in out.iter_mut().zip(&values) {
                *o = ink_of(map, v);
            }
        });
        let sigmas = blur_sigmas(grid.px_per_spacing());
        let target = grid.blurred(target, sigmas);
        Self { grid, map, target }
    }

    /// Corrects `radii`, the sized dots of `points` sampled on the map at
    /// radius range `range` (a grey drawing), toward the map's ink, each
    /// kept within `limits` (the mapping's lightest and darkest dots:
    /// `--dot-mm` holds). The plan decides whether it runs and on which
    /// grid.
    pub(crate) fn apply(
        &self,
        points: &[Point],
        range: crate::importance::RadiusRange,
        radii: &mut [f32],
        limits: (f32, f32),
        stage: &mut dyn FnMut(Stage) -> crate::Result<()>,
    ) -> crate::Result<()> {
        let Self { grid, map, target } = self;
        let ink = |x: f32, y: f32| ink_at(map, x, y);
        let sigmas = blur_sigmas(grid.px_per_spacing());
        let damping = damping(grid.sigma);
        let ratios = super::super::density::Ratios::new(
            f64::from(range.min) * 0.5,
            f64::from(range.max) * 3.2,
        );
        // The ink each dot was sized for (the calibration's, at most K_MAX).
        let mut assumed: Vec<f64> = points
            .par_iter()
            .map(|p| ink(p.x, p.y).min(ink::K_MAX))
            .collect();
        // Each dot's work cell and its radius's place among the ratios'
        // rows: the same every round.
        let at: Vec<(u32, f64)> = points
            .par_iter()
            .map(|p| (grid.cell(p) as u32, ratios.place(f64::from(p.radius))))
            .collect();
        let schedule = Schedule::grey(grid.sigma);
        let of = schedule.rounds;
        // Each dot's last ink change (momentum, and the prediction).
        let mut change = vec![0f64; points.len()];
        let mut shown: Vec<f32> = Vec::new();
        for round in 1..=of {
            stage(Stage::Correct { round, of })?;
            if schedule.renders(round) {
                let paper = grid.render(points, radii, |_| true)?;
                let raw = paper.as_raw();
                shown = grid
                    .cell_means(|i| [1.0 - f64::from(raw[i]) / 255.0])
                    .into_iter()
                    .map(|[v]| v)
                    .collect();
            }
            let drawn = grid.blurred(shown.clone(), sigmas);
            let error = grid.blurred(
                target
                    .values
                    .iter()
                    .zip(&drawn.values)
                    .map(|(t, d)| t - d)
                    .collect(),
                ERROR_BLUR * sigmas,
            );
            let beta = momentum(round);
            // Each dot's own update: in parallel, the same values.
            radii
                .par_iter_mut()
                .zip(assumed.par_iter_mut())
                .zip(at.par_iter())
                .zip(change.par_iter_mut())
                .for_each(|(((r, assumed), &(g, place)), change)| {
                    let (before, last) = (*assumed, std::mem::take(change));
                    let e = f64::from(error.values[g as usize]);
                    let Some(s) = step(&ratios, place, before, damping * e, beta * last) else {
                        return;
                    };
                    let factor = s.factor as f32;
                    let to = (*r * factor).clamp(limits.0.min(*r), limits.1.max(*r));
                    // A dot held by a clamp did not put down the change:
                    // nothing of it is predicted or carried.
                    if !s.held && to == *r * factor {
                        *change = s.after - before;
                    }
                    *r = to;
                    *assumed = s.after;
                });
            // The next round, if it does not render, sees this one's
            // render changed by each dot's ink change over its area.
            if round < of && !schedule.renders(round + 1) {
                predict(grid, points, &change, &mut shown);
            }
        }
        Ok(())
    }
}

/// Adds to `shown` (a render's ink per work cell) each dot's ink change
/// `change` over its area, spread over the work cells around it
/// ([`Grid::spread`]): the dots' areas in proportion to their sample
/// radii squared, together the domain's.
fn predict(grid: &Grid, points: &[Point], change: &[f64], shown: &mut [f32]) {
    let r2: f64 = points.iter().map(|p| f64::from(p.radius).powi(2)).sum();
    if r2.is_nan() || r2 <= 0.0 {
        return;
    }
    let (w, h) = grid.size;
    let area = f64::from(w) * f64::from(h) / f64::from(grid.scale).powi(2);
    let per_r2 = area / r2;
    for (p, &c) in points.iter().zip(change) {
        if c != 0.0 {
            let ink = c * per_r2 * f64::from(p.radius).powi(2);
            grid.spread(p, |cell, share| {
                let mean = ink * share / grid.cell_area(cell);
                shown[cell] = (f64::from(shown[cell]) + mean) as f32;
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::GridSpec;
    use super::*;
    use crate::importance::{ImportanceMap, Mapping, RadiusRange};
    use crate::stipple::Dot;

    /// `n`×`n` points `step` apart from `first`, each of sample radius
    /// `radius`.
    fn lattice(n: u32, step: f32, first: (f32, f32), radius: f32) -> Vec<Point> {
        (0..n * n)
            .map(|i| Point {
                x: (i % n) as f32 * step + first.0,
                y: (i / n) as f32 * step + first.1,
                radius,
                class: 0,
            })
            .collect()
    }

    /// The mean ink of `dots` on a `size` domain, rendered at 4×.
    fn mean_ink(dots: &[Dot], size: (u32, u32)) -> f64 {
        let view = (f64::from(size.0), f64::from(size.1));
        let grey = crate::stipple::raster::render_mean(dots, view, size).unwrap();
        grey.iter().map(|&g| 1.0 - f64::from(g)).sum::<f64>() / grey.len() as f64
    }

    /// The target made a row at a time is the one made a render pixel at a
    /// time (each pixel's ink read where it lies), bit for bit, on a map
    /// stretched to a larger domain with a white cutoff.
    #[test]
    fn the_target_by_rows_is_the_target_by_pixels() {
        let (w, h) = (23u32, 17u32);
        let values = (0..w * h)
            .map(|i| ((i * 37) % 101) as f32 / 100.0)
            .collect();
        let map = ImportanceMap::from_values(w, h, values).unwrap();
        let range = RadiusRange::new(2.0, 8.0).unwrap();
        let domain = (157, 101);
        let prepared =
            Prepared::new(map, Mapping::ToneSized(0.3), range, Some(0.8)).stretched(domain);
        let grid = GridSpec {
            pixels: u64::MAX,
            ..GridSpec::grey(0.0)
        }
        .grid(domain, 100);
        assert!(grid.scale < 0.9, "{grid:?}");
        let made = GreyCorrection::new(grid, &prepared).target;
        let (rw, _) = grid.size;
        let inv = 1.0 / grid.scale;
        let by_pixels = grid.cell_means(|i| {
            let (x, y) = ((i as u32 % rw) as f32 + 0.5, (i as u32 / rw) as f32 + 0.5);
            [ink_at(&prepared, x * inv, y * inv)]
        });
        let sigmas = blur_sigmas(grid.px_per_spacing());
        let expected = grid.blurred(by_pixels.into_iter().map(|[v]| v).collect(), sigmas);
        assert_eq!(made.values.len(), expected.values.len());
        for (a, b) in made.values.iter().zip(&expected.values) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    /// A predicted round's render is the next render: dots on a lattice
    /// 16 px apart grown from radius 4 to 5 (no overlaps; the render at
    /// half the domain's scale), their ink change spread over the last
    /// render, give the render of the grown dots within 3% of its ink
    /// change in the mean (the render's pixels round the dots' edges), and
    /// within 4% of it in every cell of the blurred work grid.
    #[test]
    fn a_prediction_is_the_render_it_stands_for() {
        let (w, h) = (256u32, 256u32);
        let points = lattice(16, 16.0, (8.3, 7.9), 8.0);
        let grid = GridSpec::grey(0.0).grid((w, h), points.len());
        assert!((grid.scale - 0.5).abs() < 1e-6, "{grid:?}");
        let shown = |r: f32| -> Vec<f32> {
            let radii = vec![r; points.len()];
            let raw = grid.render(&points, &radii, |_| true).unwrap().into_raw();
            grid.cell_means(|i| [1.0 - f64::from(raw[i]) / 255.0])
                .into_iter()
                .map(|[v]| v)
                .collect()
        };
        let (before, after) = (shown(4.0), shown(5.0));
        // Each dot's ink is its coverage of its 16×16 px share.
        let change = vec![std::f64::consts::PI * (25.0 - 16.0) / 256.0; points.len()];
        let mut predicted = before.clone();
        predict(&grid, &points, &change, &mut predicted);
        let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
        let grown = mean(&after) - mean(&before);
        assert!(
            (mean(&predicted) - mean(&after)).abs() < 0.03 * grown,
            "predicted {} against {} (grown by {grown})",
            mean(&predicted),
            mean(&after)
        );
        let blur = |v: Vec<f32>| grid.blurred(v, 1.0).values;
        for (p, a) in blur(predicted).iter().zip(blur(after)) {
            assert!((p - a).abs() < (0.04 * grown) as f32, "{p} against {a}");
        }
    }

    /// On a flat grey whose render ends in a sliver of a work cell (one
    /// render pixel past the last whole block), the dots along that edge
    /// are sized as those inside: a sliver cell read only the outer edge of
    /// the last dots' disks, so that the correction grew them (a dark band
    /// down the right or bottom edge of some drawings, 20 grey levels).
    #[test]
    fn the_last_cells_are_corrected_as_the_others() {
        // A domain whose render's width is one pixel past whole blocks.
        let (n, h) = (32u32, 256u32);
        let (w, grid) = (250..300)
            .map(|w| (w, GridSpec::grey(0.0).grid((w, h), (n * n) as usize)))
            .find(|(_, g)| g.block >= 3 && g.size.0 % g.block == 1)
            .expect("a width whose render ends in a sliver");
        let map = ImportanceMap::from_values(w, h, vec![0.6; (w * h) as usize]).unwrap();
        let range = RadiusRange::new(4.0, 16.0).unwrap();
        let prepared = Prepared::new(map, Mapping::ToneSized(0.3), range, None);
        // Dots on a lattice that fills the domain to its edges.
        let step = (w as f32 / n as f32, h as f32 / n as f32);
        let points: Vec<Point> = (0..n * n)
            .map(|i| Point {
                x: (i % n) as f32 * step.0 + step.0 / 2.0,
                y: (i / n) as f32 * step.1 + step.1 / 2.0,
                radius: 5.0,
                class: 0,
            })
            .collect();
        let mut radii = vec![3.0f32; points.len()];
        GreyCorrection::new(grid, &prepared)
            .apply(&points, range, &mut radii, (0.5, 8.0), &mut |_| Ok(()))
            .unwrap();
        let mean = |dot: &dyn Fn(u32, u32) -> bool| {
            let r: Vec<f32> = (0..n * n)
                .filter(|i| dot(i % n, i / n))
                .map(|i| radii[i as usize])
                .collect();
            r.iter().sum::<f32>() / r.len() as f32
        };
        let inside = mean(&|c, r| (4..n - 4).contains(&c) && (4..n - 4).contains(&r));
        let (column, row) = (mean(&|c, _| c == n - 1), mean(&|_, r| r == n - 1));
        for (edge, last) in [("column", column), ("row", row)] {
            assert!(
                (last / inside - 1.0).abs() < 0.03,
                "the last {edge}'s dots {last:.3} against {inside:.3} inside ({grid:?})"
            );
        }
    }

    /// On a flat grey, dots drawn far too large (or too small) are brought
    /// most of the way to the grey's ink, as a fine render measures it (the
    /// rounds' steps are scaled for calibrated dots, near their ink: from
    /// this far the five rounds, two of them rendered, close at least four
    /// fifths of the gap).
    #[test]
    fn the_correction_brings_a_flat_grey_to_its_ink() {
        let (w, h) = (256u32, 256u32);
        let map = ImportanceMap::from_values(w, h, vec![0.6; (w * h) as usize]).unwrap();
        let range = RadiusRange::new(4.0, 16.0).unwrap();
        let prepared = Prepared::new(map, Mapping::ToneSized(0.3), range, None);
        // A lattice 8 px apart, every dot the same: its ink is π r² / 64.
        let points = lattice(32, 8.0, (4.0, 4.0), 5.0);
        let drawn = |radii: &[f32]| {
            let dots: Vec<Dot> = points
                .iter()
                .zip(radii)
                .map(|(p, &radius)| Dot {
                    x: p.x,
                    y: p.y,
                    radius,
                })
                .collect();
            mean_ink(&dots, (w, h))
        };
        for start in [3.8f32, 2.0] {
            let mut radii = vec![start; points.len()];
            let before = drawn(&radii);
            let mut stages = Vec::new();
            let spec = GridSpec {
                pixels: u64::MAX,
                ..GridSpec::grey(0.0)
            };
            let grid = spec.grid((w, h), points.len());
            GreyCorrection::new(grid, &prepared)
                .apply(&points, range, &mut radii, (0.5, 8.0), &mut |s| {
                    stages.push(s);
                    Ok(())
                })
                .unwrap();
            let after = drawn(&radii);
            println!("from radius {start}: ink {before:.3} before, {after:.3} after");
            assert!(
                (after - 0.4).abs() < (before - 0.4).abs() / 5.0 && (before - 0.4).abs() > 0.2,
                "from radius {start}: ink {before:.3} before, {after:.3} after, 0.4 asked"
            );
            assert_eq!(stages.len(), 5, "five rounds, each reported");
        }
    }
}
