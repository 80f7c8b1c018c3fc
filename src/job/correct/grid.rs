//! The grids a correction works on: the drawing rendered at a few pixels
//! between dots ([`GridSpec`], decided by the plan), and that render in
//! blocks (the work grid) a few to the blur's σ.

use rayon::prelude::*;

use crate::analyze::fidelity::{Grey, blur};
use crate::sampler::Point;
use crate::stipple::Dot;

/// The render pixels of work cell `c` of `n` along a side of `len`
/// pixels in blocks of `block`: the last cell takes what is left over.
fn span(c: u32, n: u32, block: u32, len: u32) -> std::ops::Range<u32> {
    let end = if c + 1 >= n { len } else { (c + 1) * block };
    c * block..end.min(len)
}

/// Render pixels between neighbouring dots in a grey drawing's
/// correction: dots a few pixels wide, so that the render sees their
/// overlaps (4096 px squares at 10K–1M dots, measured against renders of
/// the whole drawing at 4×: 5 px 0.4–0.9 dB short of 8, 12 no better).
/// With the exact union render (session 50) 6 px measured as 8 on five
/// photos at 20K (seeds 0–1, 48.98 / 34.95 dB against 48.73 / 34.92) but
/// leaves the flat-grey tests' edges 4% off: kept at 8.
pub(crate) const GREY_PX_PER_SPACING: f64 = 8.0;
/// Grey correction: render pixels at most, unless the plan asks for a
/// finer render (2048² px: 207K dots at 4.5 px between them).
pub(crate) const GREY_PIXELS: u64 = 2048 * 2048;
/// Render pixels between neighbouring dots in a colour drawing's
/// correction (fewer where [`COLOUR_SIDE`] caps it): the same colours
/// within ΔE00 0.02 as a finer render on five photos at 20K dots, at a
/// quarter of its pixels.
pub(crate) const COLOUR_PX_PER_SPACING: f64 = 5.0;
/// The colour render grid's longer side, at most.
pub(crate) const COLOUR_SIDE: u32 = 1024;
/// The work grid's cells are blocks of render pixels at most σ / this wide.
const CELLS_PER_SIGMA: f64 = 2.0;

/// How a correction's render is sized for the dots a run has: render
/// pixels between dots (at most one render pixel per domain pixel), at
/// most `side` on the longer side and `pixels` in all, but at least
/// `floor_px` between dots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct GridSpec {
    pub px_per_spacing: f64,
    pub side: u32,
    pub pixels: u64,
    pub floor_px: f64,
}

impl GridSpec {
    /// The grey correction's render: [`GREY_PX_PER_SPACING`] within
    /// [`GREY_PIXELS`], at least `floor` px between dots.
    pub(crate) fn grey(floor: f64) -> Self {
        Self {
            px_per_spacing: GREY_PX_PER_SPACING,
            side: u32::MAX,
            pixels: GREY_PIXELS,
            floor_px: floor,
        }
    }

    /// The colour correction's render: [`COLOUR_PX_PER_SPACING`] within
    /// [`COLOUR_SIDE`].
    pub(crate) fn colour() -> Self {
        Self {
            px_per_spacing: COLOUR_PX_PER_SPACING,
            side: COLOUR_SIDE,
            pixels: u64::MAX,
            floor_px: 0.0,
        }
    }

    /// The grid for `dots` dots on `domain`.
    pub(crate) fn grid(&self, domain: (u32, u32), dots: usize) -> Grid {
        Grid::new(domain, dots, self)
    }
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
    /// Render-grid pixels per side of a work-grid cell (the last column
    /// and row of cells take what is left over too: no cell is a sliver).
    pub block: u32,
    /// The work grid's size: the render grid in whole blocks.
    pub work: (u32, u32),
    /// The blur's σ (the mean dot spacing) in work-grid cells.
    pub sigma: f64,
}

impl Grid {
    /// The grids for `dots` dots on a `domain`, rendered as `spec` asks.
    pub(crate) fn new(domain: (u32, u32), dots: usize, spec: &GridSpec) -> Self {
        let GridSpec {
            px_per_spacing,
            side,
            pixels,
            floor_px,
        } = *spec;
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
            work: ((size.0 / block).max(1), (size.1 / block).max(1)),
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
    /// render pixels, drawn as their union's exact coverage
    /// ([`crate::stipple::raster::render_union`]): 255 paper, 0 ink.
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
        Ok(crate::stipple::raster::render_union(&dots, self.size)?)
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
                let (xs, ys) = (span(cx, ww, block, w), span(cy, wh, block, h));
                for y in ys {
                    for x in xs.clone() {
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

    /// [`Self::cell_means`] of one value a render pixel, made a render
    /// row at a time: `row(y, out)` writes the values of render row `y`
    /// (the render's width of them) into `out`. The same sums in the same
    /// order, so the same means.
    pub(crate) fn cell_means_of_rows(&self, row: impl Fn(u32, &mut [f64]) + Sync) -> Vec<f32> {
        let (w, h) = self.size;
        let (ww, wh) = self.work;
        let block = self.block as usize;
        let mut means = vec![0f32; ww as usize * wh as usize];
        let columns: Vec<std::ops::Range<usize>> = (0..ww)
            .map(|cx| {
                let r = span(cx, ww, block as u32, w);
                r.start as usize..r.end as usize
            })
            .collect();
        means.par_chunks_mut(ww as usize).enumerate().for_each_init(
            || (vec![0f64; w as usize], vec![0f64; ww as usize]),
            |(values, sums), (cy, out)| {
                sums.iter_mut().for_each(|s| *s = 0.0);
                let ys = span(cy as u32, wh, block as u32, h);
                let (y0, y1) = (ys.start as usize, ys.end as usize);
                for y in y0..y1 {
                    row(y as u32, values);
                    for (s, xs) in sums.iter_mut().zip(&columns) {
                        for &v in &values[xs.clone()] {
                            *s += v;
                        }
                    }
                }
                for ((o, s), xs) in out.iter_mut().zip(sums.iter()).zip(&columns) {
                    let cols = xs.len();
                    // The count as `cell_means` makes it: 1.0 added once a pixel.
                    let n = (0..(y1 - y0) * cols).fold(0.0f64, |n, _| n + 1.0);
                    *o = (s / n) as f32;
                }
            },
        );
        means
    }

    /// Calls `add(cell, share)` for the four work cells around domain
    /// point `p`, shares bilinear by its place between their centres
    /// (summing to 1; clamped at the grid's edges): how a change at the
    /// point is spread over the work grid ([`super::Schedule::predicted`]).
    pub(crate) fn spread(&self, p: &Point, mut add: impl FnMut(usize, f64)) {
        let (ww, wh) = self.work;
        let at = |v: f32, n: u32| {
            (f64::from(v * self.scale) / f64::from(self.block) - 0.5).clamp(0.0, f64::from(n - 1))
        };
        let (fx, fy) = (at(p.x, ww), at(p.y, wh));
        if !(fx.is_finite() && fy.is_finite()) {
            return;
        }
        let (x0, y0) = (fx as usize, fy as usize);
        let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
        let (x1, y1) = ((x0 + 1).min(ww as usize - 1), (y0 + 1).min(wh as usize - 1));
        let w = ww as usize;
        add(y0 * w + x0, (1.0 - tx) * (1.0 - ty));
        add(y0 * w + x1, tx * (1.0 - ty));
        add(y1 * w + x0, (1.0 - tx) * ty);
        add(y1 * w + x1, tx * ty);
    }

    /// A work cell's area in domain pixels² (a whole block's; the last
    /// column's and row's take the render's leftover pixels too).
    pub(crate) fn cell_area(&self, cell: usize) -> f64 {
        let (ww, wh) = self.work;
        let (cx, cy) = (cell as u32 % ww, cell as u32 / ww);
        let xs = span(cx, ww, self.block, self.size.0);
        let ys = span(cy, wh, self.block, self.size.1);
        f64::from(xs.len() as u32 * ys.len() as u32) / f64::from(self.scale).powi(2)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Means made a row at a time are the means made a pixel at a time,
    /// bit for bit, on a render whose sides are not whole blocks.
    #[test]
    fn cell_means_by_rows_are_the_cell_means() {
        let grid = Grid::new((301, 197), 400, &GridSpec::grey(0.0));
        assert!(
            grid.block > 1 && !grid.size.0.is_multiple_of(grid.block),
            "{grid:?}"
        );
        let w = grid.size.0;
        let f = |x: u32, y: u32| ((x * 7919 + y * 104_729) % 1000) as f64 / 999.0;
        let whole = grid.cell_means(|i| [f(i as u32 % w, i as u32 / w)]);
        let by_rows = grid.cell_means_of_rows(|y, out| {
            for (x, o) in out.iter_mut().enumerate() {
                *o = f(x as u32, y);
            }
        });
        assert_eq!(whole.len(), by_rows.len());
        for (a, b) in whole.iter().zip(&by_rows) {
            assert_eq!(a[0].to_bits(), b.to_bits());
        }
    }

    /// The work cells tile the render, each a whole block, the last of a
    /// row or column with what is left over (less than another block): no
    /// cell is a sliver.
    #[test]
    fn the_work_cells_are_whole_blocks() {
        for (domain, dots) in [((301, 197), 400), ((1415, 941), 20035), ((250, 256), 1024)] {
            let grid = Grid::new(domain, dots, &GridSpec::grey(0.0));
            for (n, len) in [(grid.work.0, grid.size.0), (grid.work.1, grid.size.1)] {
                let spans: Vec<_> = (0..n).map(|c| span(c, n, grid.block, len)).collect();
                assert_eq!(spans[0].start, 0);
                assert_eq!(spans[n as usize - 1].end, len, "{grid:?}");
                for (c, s) in spans.iter().enumerate() {
                    let width = s.end - s.start;
                    assert!(
                        width >= grid.block.min(len) && width < 2 * grid.block,
                        "cell {c}: {s:?} ({grid:?})"
                    );
                    if c > 0 {
                        assert_eq!(spans[c - 1].end, s.start);
                    }
                }
            }
        }
    }

    /// A dot's change is spread over the four work cells around it: the
    /// shares sum to one, and their centre of mass is the dot's place in
    /// cell units (away from the edges; at an edge the share stays in the
    /// grid); a dot at a cell's centre gives that cell everything.
    #[test]
    fn a_change_spreads_around_its_dot() {
        let grid = Grid::new((301, 197), 400, &GridSpec::grey(0.0));
        let (ww, wh) = grid.work;
        let cell = f64::from(grid.block) / f64::from(grid.scale);
        let at = |x: f32, y: f32| Point {
            x,
            y,
            radius: 1.0,
            class: 0,
        };
        for p in [
            at(100.3, 57.9),
            at(12.0, 150.5),
            at(0.1, 0.2),
            at(300.9, 196.9),
        ] {
            let (mut total, mut mx, mut my) = (0.0, 0.0, 0.0);
            grid.spread(&p, |c, share| {
                assert!(c < (ww * wh) as usize && share >= 0.0);
                total += share;
                mx += share * ((c % ww as usize) as f64 + 0.5);
                my += share * ((c / ww as usize) as f64 + 0.5);
            });
            assert!((total - 1.0).abs() < 1e-12, "{p:?}: {total}");
            let (px, py) = (f64::from(p.x) / cell, f64::from(p.y) / cell);
            let inside = |v: f64, n: u32| v > 0.5 && v < f64::from(n) - 0.5;
            if inside(px, ww) && inside(py, wh) {
                assert!(
                    (mx - px).abs() < 1e-3 && (my - py).abs() < 1e-3,
                    "{p:?}: ({mx}, {my}) against ({px}, {py})"
                );
            }
        }
        let centre = at((2.5 * cell) as f32, (3.5 * cell) as f32);
        grid.spread(&centre, |c, share| {
            if c == 3 * ww as usize + 2 {
                assert!((share - 1.0).abs() < 1e-6, "{share}");
            } else {
                assert!(share < 1e-6, "cell {c}: {share}");
            }
        });
    }
}
