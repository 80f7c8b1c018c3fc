//! The weights, cleaned (a negative or non-finite weight counts as zero),
//! with their pyramid of moments `[Σw, Σw·x, Σw·y]` over aligned square
//! blocks from 4×4 to 16×16 pixels, and the aligned blocks themselves
//! ([`Tile`]), which the Lloyd step walks and splits in four.

use rayon::prelude::*;
use std::borrow::Cow;

use super::Density;

/// The pyramid's finest level: blocks of 4×4 pixels, assigned pixel by pixel
/// when more than one point may own them.
pub(super) const LEAF_LEVEL: u32 = 2;
/// The coarsest level: the 16×16 tiles whose candidates come from the k-d tree.
pub(super) const TOP_LEVEL: u32 = 4;

/// The weights, checked, with their pyramid of block moments.
pub(super) struct Field<'a> {
    /// Width in pixels.
    pub(super) width: usize,
    /// Height in pixels.
    pub(super) height: usize,
    /// Row-major weights, all finite and >= 0.
    pub(super) weights: Cow<'a, [f32]>,
    /// Levels `LEAF_LEVEL..=TOP_LEVEL`, finest first.
    levels: Vec<Level>,
}

/// Moments `[Σw, Σw·x, Σw·y]` (pixel centres) of the aligned square blocks of
/// one size, clipped to the image.
struct Level {
    /// Blocks per row.
    cols: usize,
    /// Row-major block moments.
    sums: Vec<[f64; 3]>,
}

impl<'a> Field<'a> {
    /// `None` for a density with no pixels or the wrong number of weights.
    pub(super) fn new(density: &Density<'a>) -> Option<Field<'a>> {
        let (width, height) = (density.width as usize, density.height as usize);
        if width == 0 || height == 0 || density.weights.len() != width * height {
            return None;
        }
        let clean = |v: &f32| v.is_finite() && *v >= 0.0;
        let weights = if density.weights.iter().all(clean) {
            Cow::Borrowed(density.weights)
        } else {
            let fixed = density
                .weights
                .iter()
                .map(|v| if clean(v) { *v } else { 0.0 });
            Cow::Owned(fixed.collect())
        };
        let mut levels = vec![leaf_level(&weights, width, height)];
        for level in LEAF_LEVEL + 1..=TOP_LEVEL {
            let finer = levels.last()?;
            levels.push(coarser_level(finer, height.div_ceil(1 << level)));
        }
        Some(Field {
            width,
            height,
            weights,
            levels,
        })
    }

    /// The moments of an aligned tile of the pyramid.
    pub(super) fn moments(&self, tile: &Tile) -> [f64; 3] {
        let level = &self.levels[(tile.level - LEAF_LEVEL) as usize];
        let (bx, by) = (tile.x0 >> tile.level, tile.y0 >> tile.level);
        level.sums[by * level.cols + bx]
    }
}

/// The finest level of the pyramid, straight from the weights.
fn leaf_level(weights: &[f32], width: usize, height: usize) -> Level {
    let side = 1usize << LEAF_LEVEL;
    let (cols, rows) = (width.div_ceil(side), height.div_ceil(side));
    let block_row = |by: usize| {
        let mut out = vec![[0.0f64; 3]; cols];
        for y in by * side..((by + 1) * side).min(height) {
            let py = y as f64 + 0.5;
            for (x, &v) in weights[y * width..(y + 1) * width].iter().enumerate() {
                if v > 0.0 {
                    let (v, a) = (f64::from(v), &mut out[x >> LEAF_LEVEL]);
                    a[0] += v;
                    a[1] += v * (x as f64 + 0.5);
                    a[2] += v * py;
                }
            }
        }
        out
    };
    let parts: Vec<Vec<[f64; 3]>> = (0..rows).into_par_iter().map(block_row).collect();
    Level {
        cols,
        sums: parts.concat(),
    }
}

/// The next coarser level (blocks twice the side), `rows` blocks high.
fn coarser_level(finer: &Level, rows: usize) -> Level {
    let cols = finer.cols.div_ceil(2);
    let finer_rows = finer.sums.len() / finer.cols.max(1);
    let mut sums = vec![[0.0f64; 3]; cols * rows];
    for (i, out) in sums.iter_mut().enumerate() {
        let (bx, by) = (i % cols, i / cols);
        for fy in 2 * by..(2 * by + 2).min(finer_rows) {
            for fx in 2 * bx..(2 * bx + 2).min(finer.cols) {
                let m = finer.sums[fy * finer.cols + fx];
                (0..3).for_each(|k| out[k] += m[k]);
            }
        }
    }
    Level { cols, sums }
}

/// An aligned square block of pixels, `2^level` on a side, clipped to the image.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tile {
    /// log2 of the side.
    pub(super) level: u32,
    /// First column.
    pub(super) x0: usize,
    /// First row.
    pub(super) y0: usize,
    /// One past the last column.
    pub(super) x1: usize,
    /// One past the last row.
    pub(super) y1: usize,
}

impl Tile {
    /// The block at `(x0, y0)` (aligned to its side), or `None` if it lies outside.
    pub(super) fn new(level: u32, x0: usize, y0: usize, field: &Field<'_>) -> Option<Tile> {
        let side = 1usize << level;
        (x0 < field.width && y0 < field.height).then(|| Tile {
            level,
            x0,
            y0,
            x1: (x0 + side).min(field.width),
            y1: (y0 + side).min(field.height),
        })
    }

    /// The box spanned by the pixel centres: `[xmin, ymin, xmax, ymax]`.
    pub(super) fn hull(&self) -> [f64; 4] {
        [
            self.x0 as f64 + 0.5,
            self.y0 as f64 + 0.5,
            self.x1 as f64 - 0.5,
            self.y1 as f64 - 0.5,
        ]
    }

    /// The centre of the hull.
    pub(super) fn centre(&self) -> [f64; 2] {
        let [ax, ay, bx, by] = self.hull();
        [(ax + bx) * 0.5, (ay + by) * 0.5]
    }

    /// The four quarters that lie inside the image.
    pub(super) fn children(&self, field: &Field<'_>) -> impl Iterator<Item = Tile> {
        let (level, half) = (self.level - 1, 1usize << (self.level - 1));
        let (x0, y0) = (self.x0, self.y0);
        [(0, 0), (half, 0), (0, half), (half, half)]
            .into_iter()
            .filter_map(move |(dx, dy)| Tile::new(level, x0 + dx, y0 + dy, field))
    }
}
