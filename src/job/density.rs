//! The local density of a drawing's dots against the density a maximal
//! set of their radii has: where the policy or an edge thins the dots out,
//! each dot is sized for the spacing it has.

use rayon::prelude::*;

use crate::importance::ink;
use crate::importance::{Prepared, RadiusRange};
use crate::sampler::Point;

/// The dots' local density against what a maximal set of their sample
/// radii has there: where an edge or the policy thins the dots out, each is
/// sized for the spacing it has ([`local_spacing`]).
///
/// Counts are taken in a square window of half-side [`WINDOW`] × the dot's
/// sample radius (about thirty neighbours), from summed-area tables of the
/// points and of the density a maximal set has at the map's sample radii
/// ([`ink::density`]).
pub(crate) struct Density {
    /// The grid's cells per row and column.
    cols: usize,
    rows: usize,
    /// Summed-area table of point counts, (cols+1)×(rows+1).
    counts: Vec<u32>,
    /// Summed-area table of the expected point count.
    expected: Vec<f64>,
}

/// Steps of [`Density`]'s table of the expected count over the map's value.
const DENSITY_STEPS: usize = 4096;

/// The counting window's half-side in sample radii.
const WINDOW: f32 = 3.0;
/// The side in px of the cells the counts are kept in (windows are tens of
/// pixels wide: the sample radii are).
const CELL: usize = 4;
/// The expected count reads every SUBSAMPLE-th pixel of every
/// SUBSAMPLE-th row (a divisor of [`CELL`]).
const SUBSAMPLE: usize = 2;

/// The summed-area table of `cols`×`rows` values `f(cell)`.
fn summed<T: Copy + Default + std::ops::Add<Output = T>>(
    cols: usize,
    rows: usize,
    f: impl Fn(usize) -> T,
) -> Vec<T> {
    let mut t = vec![T::default(); (cols + 1) * (rows + 1)];
    for y in 0..rows {
        let mut row = T::default();
        for x in 0..cols {
            row = row + f(y * cols + x);
            t[(y + 1) * (cols + 1) + x + 1] = t[y * (cols + 1) + x + 1] + row;
        }
    }
    t
}

impl Density {
    /// The density of `points`, sampled on `map` at radius range `range`,
    /// over the `(w, h)` domain.
    pub(crate) fn new(
        points: &[Point],
        map: &Prepared,
        range: RadiusRange,
        (w, h): (u32, u32),
    ) -> Self {
        let (w, h) = (w as usize, h as usize);
        let (cols, rows) = (w.div_ceil(CELL), h.div_ceil(CELL));
        // The expected count per pixel is a function of its value:
        // tabulated once, as the radii are.
        let radius = crate::importance::ImportanceMap::radius_fn(map.mapping, range);
        let per_px: Vec<f64> = (0..=DENSITY_STEPS)
            .map(|i| {
                let r = f64::from(radius(i as f32 / DENSITY_STEPS as f32));
                ink::density(r) * crate::sampler::RSA_DENSITY / (std::f64::consts::PI * r * r / 4.0)
            })
            .collect();
        // Cell rows in parallel, each summing in order every other pixel
        // of every other row, which stands for its 2×2 block (the pixels
        // of it in the domain): the windows hold hundreds of cells.
        let columns: Vec<u32> = (0..w as u32).step_by(SUBSAMPLE).collect();
        let mut per_cell = vec![0f64; cols * rows];
        per_cell.par_chunks_mut(cols).enumerate().for_each_init(
            || vec![0.0f32; columns.len()],
            |values, (cy, row)| {
                for y in (cy * CELL..((cy + 1) * CELL).min(h)).step_by(SUBSAMPLE) {
                    let tall = (h - y).min(SUBSAMPLE);
                    map.row_at(y as u32, &columns, values);
                    for (x, &v) in (0..w).step_by(SUBSAMPLE).zip(values.iter()) {
                        let t = v.clamp(0.0, 1.0) * DENSITY_STEPS as f32;
                        let j = (t as usize).min(DENSITY_STEPS - 1);
                        let f = f64::from(t - j as f32);
                        let block = (tall * (w - x).min(SUBSAMPLE)) as f64;
                        row[x / CELL] += block * (per_px[j] + f * (per_px[j + 1] - per_px[j]));
                    }
                }
            },
        );
        let mut n = vec![0u32; cols * rows];
        for p in points {
            let (x, y) = ((p.x as usize).min(w - 1), (p.y as usize).min(h - 1));
            n[(y / CELL) * cols + x / CELL] += 1;
        }
        Self {
            cols,
            rows,
            counts: summed(cols, rows, |c| n[c]),
            expected: summed(cols, rows, |c| per_cell[c]),
        }
    }

    /// The radius of the maximal set that has the local density around
    /// point `p`: its sample radius, or more where the dots are thinned out.
    pub(crate) fn effective_radius(&self, p: &Point) -> f64 {
        let half = WINDOW * p.radius;
        let cell = CELL as f32;
        let x0 = ((p.x - half).max(0.0) / cell) as usize;
        let y0 = ((p.y - half).max(0.0) / cell) as usize;
        let x1 = (((p.x + half).max(0.0) / cell) as usize + 1).min(self.cols);
        let y1 = (((p.y + half).max(0.0) / cell) as usize + 1).min(self.rows);
        let stride = self.cols + 1;
        let n = self.counts[y1 * stride + x1] + self.counts[y0 * stride + x0]
            - self.counts[y0 * stride + x1]
            - self.counts[y1 * stride + x0];
        let e = self.expected[y1 * stride + x1] + self.expected[y0 * stride + x0]
            - self.expected[y0 * stride + x1]
            - self.expected[y1 * stride + x0];
        let r = f64::from(p.radius);
        if n == 0 || e <= 0.0 {
            return r;
        }
        r / (f64::from(n) / e).clamp(0.1, 4.0).sqrt()
    }
}

/// `radii`, the calibrated dots of `points` sampled on `map` (sized dots),
/// each resized for the spacing the dots have around it ([`Density`]),
/// within the mapping's own sizes: the darkest dots keep their size
/// (`--dot-mm`), the lightest their ratio (`--dot-ratio`).
pub(crate) fn local_spacing(
    map: &Prepared,
    points: &[Point],
    range: RadiusRange,
    domain: (u32, u32),
    radii: &mut [f32],
) {
    let density = Density::new(points, map, range, domain);
    let (lo, hi) = (
        map.mapping.dot_radius(1.0, range),
        map.mapping.dot_radius(0.0, range),
    );
    // The effective radii lie within 1/√4 and 1/√0.1 of the sample radii.
    let ratios = Ratios::new(f64::from(range.min) * 0.5, f64::from(range.max) * 3.2);
    points
        .par_iter()
        .zip(radii.par_iter_mut())
        .for_each(|(p, r)| {
            let ink = f64::from(1.0 - map.value_at(p.x, p.y));
            let factor = ratios.factor(ink, f64::from(p.radius), density.effective_radius(p));
            *r = (*r * factor).clamp(lo.min(*r), hi.max(*r));
        });
}

/// [`ink::dot_ratio`] tabulated over the ink (in steps of its square root:
/// the ratio grows as √k from no ink) and the log of the radius, read
/// bilinearly: the sizing reads it twice per dot.
pub(crate) struct Ratios {
    /// ln of the smallest radius, and the step between radius rows.
    ln_r: f64,
    ln_step: f64,
    rows: usize,
    /// rows × (INK_STEPS + 1) values.
    values: Vec<f32>,
}

/// Steps of [`Ratios`] over √k.
const INK_STEPS: usize = 512;
/// Rows of [`Ratios`] over ln r.
const RADIUS_ROWS: usize = 64;

impl Ratios {
    /// The table over radii from `lo` to `hi` px.
    pub(crate) fn new(lo: f64, hi: f64) -> Self {
        let (lo, hi) = if lo.is_finite() && lo > 0.0 && hi.is_finite() {
            (lo, hi.max(lo))
        } else {
            (1.0, 1.0)
        };
        let (ln_r, span) = (lo.ln(), (hi / lo).ln());
        let rows = if span > 0.0 { RADIUS_ROWS } else { 1 };
        let ln_step = if rows > 1 {
            span / (rows - 1) as f64
        } else {
            1.0
        };
        let values = (0..rows * (INK_STEPS + 1))
            .into_par_iter()
            .map(|i| {
                let (row, u) = (i / (INK_STEPS + 1), i % (INK_STEPS + 1));
                let k = (u as f64 / INK_STEPS as f64).powi(2);
                ink::dot_ratio(k, (ln_r + row as f64 * ln_step).exp()) as f32
            })
            .collect();
        Self {
            ln_r,
            ln_step,
            rows,
            values,
        }
    }

    /// [`ink::dot_ratio`]`(k, r)`, interpolated (radii outside the table's
    /// read at its ends).
    pub(crate) fn at(&self, k: f64, r: f64) -> f64 {
        self.at_place(k, self.place(r))
    }

    /// Where radius `r` lies among the table's rows: found once for a
    /// radius read at many inks ([`Self::at_place`]).
    pub(crate) fn place(&self, r: f64) -> f64 {
        if self.rows == 1 {
            return 0.0;
        }
        ((r.ln() - self.ln_r) / self.ln_step).clamp(0.0, (self.rows - 1) as f64)
    }

    /// [`Self::at`] of the radius at `t` among the rows ([`Self::place`]).
    pub(crate) fn at_place(&self, k: f64, t: f64) -> f64 {
        if k.is_nan() || k <= 0.0 {
            return 0.0;
        }
        let u = k.min(1.0).sqrt() * INK_STEPS as f64;
        let ui = (u as usize).min(INK_STEPS - 1);
        let fu = u - ui as f64;
        let row = |ri: usize| {
            let v = &self.values[ri * (INK_STEPS + 1)..];
            f64::from(v[ui]) + fu * (f64::from(v[ui + 1]) - f64::from(v[ui]))
        };
        if self.rows == 1 {
            return row(0);
        }
        let ri = (t as usize).min(self.rows - 2);
        let a = row(ri);
        a + (t - ri as f64) * (row(ri + 1) - a)
    }

    /// The factor on a calibrated dot radius (for ink `ink` on a maximal
    /// set of radius `r`) that puts down the same ink at the spacing of a
    /// maximal set of radius `r_eff`.
    pub(crate) fn factor(&self, ink: f64, r: f64, r_eff: f64) -> f32 {
        let k = ink.clamp(0.0, ink::K_MAX);
        let had = self.at(k, r) * r;
        if had > 0.0 {
            (self.at(k, r_eff) * r_eff / had) as f32
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ratio_table_reads_as_the_ink_curve() {
        let t = Ratios::new(2.0, 40.0);
        for &r in &[2.0, 3.3, 7.0, 19.5, 40.0] {
            for &k in &[0.01, 0.1, 0.37, 0.6, 0.9] {
                let (a, b) = (t.at(k, r), ink::dot_ratio(k, r));
                assert!(
                    (a - b).abs() < 2e-3 * b.max(0.05),
                    "k {k}, r {r}: {a} against {b}"
                );
            }
        }
        assert_eq!(t.at(0.0, 5.0), 0.0);
    }
}
