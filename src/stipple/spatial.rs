//! Where points lie, for the stages that look near a point or walk the
//! page: the Hilbert curve (the drawing's dot order from the sampler on,
//! the Lloyd cells' order, the pen assignment's walk and the tour's start)
//! and the bucket grid of points by cell (neighbour queries in the tour
//! and the pen assignment).

/// Point indices bucketed by cell, in a counting sort: cell `c`'s points
/// are `items[start[c]..start[c + 1]]`, each cell's in the points' order.
pub(crate) struct Buckets {
    /// Where each cell's points begin in `items` (cells + 1 offsets).
    pub start: Vec<u32>,
    /// The points' indices, cell by cell.
    pub items: Vec<u32>,
}

impl Buckets {
    /// The points whose cells `cell_of` gives, among `cells` cells.
    pub fn new<T>(points: &[T], cells: usize, cell_of: impl Fn(&T) -> usize) -> Self {
        let mut start = vec![0u32; cells + 1];
        for p in points {
            start[cell_of(p) + 1] += 1;
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; points.len()];
        for (i, p) in points.iter().enumerate() {
            let c = cell_of(p);
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        Self { start, items }
    }

    /// The points of cells `from..=to` (consecutive cells: a row's run).
    #[must_use]
    pub fn span(&self, from: usize, to: usize) -> &[u32] {
        &self.items[self.start[from] as usize..self.start[to + 1] as usize]
    }
}

/// The points along a Hilbert curve over their bounding square.
pub(crate) fn hilbert_path(points: &[[f64; 2]]) -> Vec<usize> {
    use rayon::prelude::*;
    const ORDER: u32 = 16;
    let side = 1u32 << ORDER;
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
    let cell = |v: f64, o: f64| (((v - o) / span) * f64::from(side - 1)).round() as u32;
    let mut keyed: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            (
                hilbert(
                    u64::from(cell(p[0], lo[0])),
                    u64::from(cell(p[1], lo[1])),
                    ORDER,
                ),
                i as u32,
            )
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i as usize).collect()
}

/// The place of pixel (`x`, `y`) along the Hilbert curve through a 2^16-px
/// square, in cells of 2^`shift` px: the order of a drawing's dots
/// (`shift` 0, `job::plan`) and of its Lloyd cells (`shift` 3). The cells'
/// curve is the pixels' coarsened (its key the pixels' shifted right by
/// 2·`shift`), so dots in the one order are in the other too.
pub(crate) fn pixel_key(x: f32, y: f32, shift: u32) -> u64 {
    let order = 16 - shift;
    let cell = |v: f32| (v.max(0.0) as u64 >> shift).min((1 << order) - 1);
    hilbert(cell(x), cell(y), order)
}

/// The index of cell (`x`, `y`) along the Hilbert curve through a
/// 2^`order`-cell square (the tour's start, and the pens' assignment in
/// `job::assign`).
pub(crate) fn hilbert(mut x: u64, mut y: u64, order: u32) -> u64 {
    let n = 1u64 << order;
    let mut d = 0u64;
    let mut s = n / 2;
    while s > 0 {
        let rx = u64::from(x & s > 0);
        let ry = u64::from(y & s > 0);
        d += s * s * ((3 * rx) ^ ry);
        // Rotate the quadrant.
        if ry == 0 {
            if rx == 1 {
                x = n - 1 - x;
                y = n - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s /= 2;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buckets_hold_each_point_once_in_its_cell_in_order() {
        let cells = [3usize, 0, 3, 1, 0, 2];
        let b = Buckets::new(&cells, 5, |&c| c);
        assert_eq!(b.start, vec![0, 2, 3, 4, 6, 6]);
        assert_eq!(b.items, vec![1, 4, 3, 5, 0, 2]);
        assert_eq!(b.span(1, 3), &[3, 5, 0, 2]);
        assert!(b.span(4, 4).is_empty());
    }

    /// The Lloyd cells' curve is the dots' coarsened: a cell's key is each
    /// of its pixels' shifted right by 6, so sorted dots stay sorted; a
    /// place off the domain's low side reads as its corner.
    #[test]
    fn the_cells_curve_coarsens_the_pixels_curve() {
        use rand::{RngExt, SeedableRng, rngs::StdRng};
        let mut rng = StdRng::seed_from_u64(0x1234_5678);
        for _ in 0..20_000 {
            let (x, y): (f32, f32) = (
                rng.random_range(-2.0..70_000.0),
                rng.random_range(-2.0..70_000.0),
            );
            assert_eq!(pixel_key(x, y, 0) >> 6, pixel_key(x, y, 3), "({x}, {y})");
        }
        assert_eq!(pixel_key(-3.0, f32::NAN, 0), pixel_key(0.0, 0.0, 0));
    }
}
