//! The size stage's closed loop: the drawing rendered, blurred by the mean
//! dot spacing (the measure's σ) and compared with its target, blurred
//! alike; each dot then resized by the ink curve to put down the ink its
//! neighbourhood lacks, in [`rounds`]. The calibration's curves hold for
//! maximal Poisson-disk sets on average; the loop corrects what they miss:
//! relaxed sets (evener, so their dots overlap less), edges, the policies'
//! spacing. Grey drawings use [`correct_grey`]; colour drawings the same
//! [`Grid`] with their render model (`super::colour`).

use rayon::prelude::*;

use crate::analyze::fidelity::{Grey, blur};
use crate::importance::{Prepared, ink};
use crate::sampler::Point;
use crate::stipple::Dot;

use super::Stage;

/// Render pixels between neighbouring dots in a grey drawing's
/// correction: dots a few pixels wide, so that the render sees their
/// overlaps (4096 px squares at 10K–1M dots, measured against renders of
/// the whole drawing at 4×: 5 px 0.4–0.9 dB short of 8, 12 no better).
pub(crate) const GREY_PX_PER_SPACING: f64 = 8.0;
/// Render pixels between neighbouring dots in a colour drawing's
/// correction (fewer where [`COLOUR_SIDE`] caps it): the same colours
/// within ΔE00 0.02 as a finer render on five photos at 20K dots, at a
/// quarter of its pixels.
pub(crate) const COLOUR_PX_PER_SPACING: f64 = 5.0;
/// The colour render grid's longer side, at most.
pub(crate) const COLOUR_SIDE: u32 = 1024;
/// The work grid's cells are blocks of render pixels at most σ / this wide.
const CELLS_PER_SIGMA: f64 = 2.0;
/// The error's own blur, in σ: corrections follow the local bias, not each
/// dot's own noise.
pub(crate) const ERROR_BLUR: f64 = 1.0;

/// The fraction of each round's ink change that is made, by the blur's σ
/// in work-grid cells: 1.15 (a little past the linear model's step, which
/// falls short) where σ spans 1.5 cells or more, 0.7 at one cell and less
/// (the work grid then finer than the dots' noise). Measured by `pixelpie
/// fidelity` on two photos at 20K, 100K, 300K and 1M dots (docs/colour.md).
pub(crate) fn damping(sigma_cells: f64) -> f64 {
    (0.7 + 0.9 * (sigma_cells - 1.0)).clamp(0.7, 1.15)
}

/// The rounds of a correction: three, or two where the blur's σ spans
/// less than 1.25 work-grid cells (dense drawings: there a third round
/// chases the dots' own noise, ΔE00 0.03–0.2 worse on two photos at 1M
/// dots). Each is reported as [`Stage::Correct`].
pub(crate) fn rounds(sigma_cells: f64) -> u8 {
    if sigma_cells < 1.25 { 2 } else { 3 }
}

/// The grids a correction works on: the drawing rendered at about
/// [`PX_PER_SPACING`] pixels between dots, and that render in blocks (the
/// work grid) a few to the blur's σ.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grid {
    /// The render grid's size (the drawing, at most [`SIDE`]).
    pub size: (u32, u32),
    /// Render-grid pixels per domain pixel.
    pub scale: f32,
    /// Render-grid pixels per side of a work-grid cell.
    pub block: u32,
    /// The work grid's size: the render grid in blocks.
    pub work: (u32, u32),
    /// The blur's σ (the mean dot spacing) in work-grid cells.
    pub sigma: f64,
}

impl Grid {
    /// The grids for `dots` dots on a `domain`, rendered at
    /// `px_per_spacing` pixels between dots (at most one render pixel per
    /// domain pixel), at most `side` on the longer side and `pixels` in
    /// all, but at least `floor_px` pixels between dots (a finer render
    /// where the plan needs it, [`super::plan`]).
    pub(crate) fn new(
        domain: (u32, u32),
        dots: usize,
        px_per_spacing: f64,
        side: u32,
        pixels: u64,
        floor_px: f64,
    ) -> Self {
        let long = domain.0.max(domain.1);
        let area = f64::from(domain.0) * f64::from(domain.1);
        let spacing = (area / dots.max(1) as f64).sqrt();
        let scale = (side as f32 / long as f32)
            .min((pixels as f64 / area).sqrt() as f32)
            .min(1.0)
            .min((px_per_spacing / spacing) as f32)
            .max((floor_px / spacing) as f32);
        let size = (
            ((domain.0 as f32 * scale).round() as u32).max(1),
            ((domain.1 as f32 * scale).round() as u32).max(1),
        );
        // σ in render pixels; the work grid resolves it with a few cells.
        let fine_sigma = spacing * f64::from(scale);
        let block = ((fine_sigma / CELLS_PER_SIGMA).floor() as u32).clamp(1, 8);
        Self {
            size,
            scale,
            block,
            work: (size.0.div_ceil(block), size.1.div_ceil(block)),
            sigma: fine_sigma / f64::from(block),
        }
    }

    /// Render pixels between neighbouring dots.
    pub(crate) fn px_per_spacing(&self) -> f64 {
        self.sigma * f64::from(self.block)
    }

    /// The work cell of domain point `p`.
    pub(crate) fn cell(&self, p: &Point) -> usize {
        let (ww, wh) = self.work;
        let gx = ((p.x * self.scale) as u32 / self.block).min(ww - 1);
        let gy = ((p.y * self.scale) as u32 / self.block).min(wh - 1);
        (gy * ww + gx) as usize
    }

    /// The dots of `points` with `radii` (those that `keep` passes), in
    /// render pixels, drawn: 255 paper, 0 ink.
    pub(crate) fn render(
        &self,
        points: &[Point],
        radii: &[f32],
        keep: impl Fn(&Point) -> bool,
    ) -> crate::Result<image::GrayImage> {
        let dots: Vec<Dot> = points
            .iter()
            .zip(radii)
            .filter(|(p, _)| keep(p))
            .map(|(p, &r)| Dot {
                x: p.x * self.scale,
                y: p.y * self.scale,
                radius: r * self.scale,
            })
            .collect();
        Ok(crate::stipple::raster::render(&dots, self.size, 1.0)?)
    }

    /// The mean of `f` over each work cell's render pixels (`f` of the
    /// render pixel's index).
    pub(crate) fn cell_means<const N: usize>(
        &self,
        f: impl Fn(usize) -> [f64; N] + Sync,
    ) -> Vec<[f32; N]> {
        let (w, h) = self.size;
        let (ww, wh) = self.work;
        let block = self.block;
        (0..(ww * wh) as usize)
            .into_par_iter()
            .map(|c| {
                let (cx, cy) = (c as u32 % ww, c as u32 / ww);
                let mut sum = [0f64; N];
                let mut n = 0.0;
                for y in cy * block..((cy + 1) * block).min(h) {
                    for x in cx * block..((cx + 1) * block).min(w) {
                        for (s, v) in sum.iter_mut().zip(f((y * w + x) as usize)) {
                            *s += v;
                        }
                        n += 1.0;
                    }
                }
                sum.map(|s| (s / n) as f32)
            })
            .collect()
    }

    /// `values` (one per work cell) blurred by `sigmas` σ.
    pub(crate) fn blurred(&self, values: Vec<f32>, sigmas: f64) -> Grey {
        blur(
            &Grey {
                width: self.work.0,
                height: self.work.1,
                values,
            },
            sigmas * self.sigma,
        )
    }
}

/// Corrects `radii`, the sized dots of `points` sampled on `map` at radius
/// range `range` (a grey drawing), toward the map's ink, each kept within
/// `limits` (the mapping's lightest and darkest dots: `--dot-mm` holds).
/// The plan decides whether it runs and on which `grid`.
pub(crate) fn correct_grey(
    grid: &Grid,
    map: &Prepared,
    points: &[Point],
    range: crate::importance::RadiusRange,
    radii: &mut [f32],
    limits: (f32, f32),
    stage: &mut dyn FnMut(Stage) -> crate::Result<()>,
) -> crate::Result<()> {
    // The ink the map asks for (none past the white cutoff, where no dot
    // is drawn).
    let ink = |x: f32, y: f32| {
        let v = map.value_at(x, y).clamp(0.0, 1.0);
        if map.cutoff.is_some_and(|c| v > c) {
            0.0
        } else {
            f64::from(1.0 - v)
        }
    };
    // The target: the ink at each render pixel's centre.
    let (w, _) = grid.size;
    let inv = 1.0 / grid.scale;
    let target = grid.cell_means(|i| {
        let (x, y) = ((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
        [ink(x * inv, y * inv)]
    });
    let target = grid.blurred(target.into_iter().map(|[v]| v).collect(), 1.0);
    let damping = damping(grid.sigma);
    let ratios =
        super::density::Ratios::new(f64::from(range.min) * 0.5, f64::from(range.max) * 3.2);
    // The ink each dot was sized for (the calibration's, at most K_MAX).
    let mut assumed: Vec<f64> = points
        .par_iter()
        .map(|p| ink(p.x, p.y).min(ink::K_MAX))
        .collect();
    let of = rounds(grid.sigma);
    for round in 1..=of {
        stage(Stage::Correct { round, of })?;
        let paper = grid.render(points, radii, |_| true)?;
        let raw = paper.as_raw();
        let shown = grid.cell_means(|i| [1.0 - f64::from(raw[i]) / 255.0]);
        let drawn = grid.blurred(shown.into_iter().map(|[v]| v).collect(), 1.0);
        let error = grid.blurred(
            target
                .values
                .iter()
                .zip(&drawn.values)
                .map(|(t, d)| t - d)
                .collect(),
            ERROR_BLUR,
        );
        // Each dot's own update: in parallel, the same values.
        points
            .par_iter()
            .zip(radii.par_iter_mut())
            .zip(assumed.par_iter_mut())
            .for_each(|((p, r), assumed)| {
                let before = *assumed;
                if before < 1e-3 {
                    return;
                }
                let e = f64::from(error.values[grid.cell(p)]);
                let after = (before + damping * e).clamp(0.5 * before, MAX_INK);
                let radius = f64::from(p.radius);
                let had = ratios.at(before, radius);
                if had <= 0.0 {
                    return;
                }
                let factor = (ratios.at(after, radius) / had).clamp(0.6, 1.6) as f32;
                *r = (*r * factor).clamp(limits.0.min(*r), limits.1.max(*r));
                *assumed = after;
            });
    }
    Ok(())
}

/// The most ink a correction asks of a dot: past [`ink::K_MAX`], where the
/// calibration stops, since overlaps with other pens' dots (colour) and
/// the holes of dark areas (grey) hide some of it.
pub(crate) const MAX_INK: f64 = 0.995;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::importance::{ImportanceMap, Mapping, RadiusRange};

    /// The mean ink of `dots` on a `size` domain, rendered at 4×.
    fn mean_ink(dots: &[Dot], size: (u32, u32)) -> f64 {
        let view = (f64::from(size.0), f64::from(size.1));
        let grey = crate::stipple::raster::render_mean(dots, view, size).unwrap();
        grey.iter().map(|&g| 1.0 - f64::from(g)).sum::<f64>() / grey.len() as f64
    }

    /// On a flat grey, dots drawn far too large (or too small) are brought
    /// most of the way to the grey's ink, as a fine render measures it (the
    /// rounds' steps are scaled for calibrated dots, near their ink: from
    /// this far the three rounds close at least four fifths of the gap).
    #[test]
    fn the_correction_brings_a_flat_grey_to_its_ink() {
        let (w, h) = (256u32, 256u32);
        let map = ImportanceMap::from_values(w, h, vec![0.6; (w * h) as usize]).unwrap();
        let range = RadiusRange::new(4.0, 16.0).unwrap();
        let prepared = Prepared::new(map, Mapping::ToneSized(0.3), range, None);
        // A lattice 8 px apart, every dot the same: its ink is π r² / 64.
        let points: Vec<Point> = (0..32 * 32)
            .map(|i| Point {
                x: (i % 32) as f32 * 8.0 + 4.0,
                y: (i / 32) as f32 * 8.0 + 4.0,
                radius: 5.0,
                class: 0,
            })
            .collect();
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
            let grid = Grid::new(
                (w, h),
                points.len(),
                GREY_PX_PER_SPACING,
                u32::MAX,
                u64::MAX,
                0.0,
            );
            correct_grey(
                &grid,
                &prepared,
                &points,
                range,
                &mut radii,
                (0.5, 8.0),
                &mut |s| {
                    stages.push(s);
                    Ok(())
                },
            )
            .unwrap();
            let after = drawn(&radii);
            println!("from radius {start}: ink {before:.3} before, {after:.3} after");
            assert!(
                (after - 0.4).abs() < (before - 0.4).abs() / 5.0 && (before - 0.4).abs() > 0.2,
                "from radius {start}: ink {before:.3} before, {after:.3} after, 0.4 asked"
            );
            assert_eq!(stages.len(), 3, "three rounds, each reported");
        }
    }
}
