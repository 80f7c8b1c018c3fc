//! Post-processing (paper §3.3, step PP) on the CPU: order-preserving stream
//! compaction of the empty-pixel list by the coverage map.
//!
//! WGSL mirror: `shaders/compact.wgsl` (a prefix-sum scan and scatter).
//!
//! The list is held in pieces, one per band of [`BAND_ROWS`] rows. A pixel's
//! band never changes, so each piece is compacted in place by its own thread
//! and nothing is copied; read in band order, the pieces are the one ordered
//! list that the semantics define.

use rayon::prelude::*;

use crate::sampler::coverage::{BAND_ROWS, is_covered};

/// The pixels still empty, in ascending order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmptyList {
    /// The domain's pixel count.
    pixels: u32,
    /// Pixels per band.
    band: u32,
    /// `None` while every pixel is empty: the first iteration's list is never
    /// stored (paper §3.3, "Optimizations for an Empty Domain").
    pieces: Option<Vec<Vec<u32>>>,
    /// `starts[b]` is the list index of the first pixel of band `b`; the last
    /// entry is the length.
    starts: Vec<u32>,
}

impl EmptyList {
    /// Every pixel of a `width`-wide domain of `pixels` pixels.
    #[must_use]
    pub fn all(pixels: u32, width: u32) -> Self {
        Self {
            pixels,
            band: BAND_ROWS.saturating_mul(width).max(1),
            pieces: None,
            starts: Vec::new(),
        }
    }

    /// The number of empty pixels.
    #[inline]
    #[must_use]
    pub fn len(&self) -> u32 {
        match self.pieces {
            None => self.pixels,
            Some(_) => self.starts.last().copied().unwrap_or(0),
        }
    }

    /// The `i`-th empty pixel.
    #[inline]
    #[must_use]
    pub fn get(&self, i: u32) -> u32 {
        self.stored(i).map_or(i, |p| *p)
    }

    /// Asks the cache for the line holding the `i`-th empty pixel: a hint
    /// that changes no result.
    #[inline]
    pub fn prefetch(&self, i: u32) {
        if let Some(p) = self.stored(i) {
            super::prefetch(p);
        }
    }

    /// Where the list holds its `i`-th empty pixel; `None` while every
    /// pixel is empty and the list is not stored.
    #[inline]
    fn stored(&self, i: u32) -> Option<&u32> {
        let pieces = self.pieces.as_ref()?;
        // The last band starting at or before i: the one holding it.
        let b = self.starts.partition_point(|&s| s <= i) - 1;
        Some(&pieces[b][(i - self.starts[b]) as usize])
    }

    /// Removes the pixels that the coverage map ([`crate::sampler::coverage::new_map`])
    /// marks, keeping the order.
    pub fn compact(&mut self, coverage: &[u64]) {
        let band = self.band as usize;
        match &mut self.pieces {
            None => {
                let mut pieces = vec![Vec::new(); (self.pixels as usize).div_ceil(band)];
                pieces
                    .par_iter_mut()
                    .zip(coverage.par_chunks(band / 64))
                    .enumerate()
                    .for_each(|(b, (piece, cov))| uncovered_of(piece, (b * band) as u32, cov));
                self.pieces = Some(pieces);
            }
            Some(pieces) => pieces
                .par_iter_mut()
                .for_each(|piece| retain_uncovered(piece, coverage)),
        }
        let pieces = self.pieces.as_deref().unwrap_or_default();
        self.starts.clear();
        self.starts.push(0);
        let mut total = 0u32;
        for piece in pieces {
            total += piece.len() as u32;
            self.starts.push(total);
        }
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        let pieces = self.pieces.as_deref().unwrap_or_default();
        pieces.iter().map(|p| 4 * p.capacity()).sum::<usize>() + 4 * self.starts.capacity()
    }
}

/// Sets `piece` to the empty pixels of the coverage words `cov`, whose
/// first pixel is `base`: a word's zero bits, visited by their index. A first
/// pass counts them so that `piece` holds no more than it keeps.
fn uncovered_of(piece: &mut Vec<u32>, base: u32, cov: &[u64]) {
    let count: u32 = cov.iter().map(|w| w.count_zeros()).sum();
    piece.clear();
    piece.resize(count as usize, 0);
    let mut n = 0;
    for (word, &bits) in (base..).step_by(64).zip(cov) {
        let mut empty = !bits;
        while empty != 0 {
            piece[n] = word + empty.trailing_zeros();
            n += 1;
            empty &= empty - 1;
        }
    }
}

/// Keeps the pixels of `piece` that the coverage map leaves empty, in order,
/// in place. Branchless: every pixel is written and the length advances only
/// past the uncovered ones, since a data-dependent branch would mispredict
/// about as often as coverage changes along the list.
fn retain_uncovered(piece: &mut Vec<u32>, coverage: &[u64]) {
    let mut n = 0;
    for i in 0..piece.len() {
        let p = piece[i];
        piece[n] = p;
        n += usize::from(!is_covered(coverage, p));
    }
    piece.truncate(n);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The list equals a plain filter of all pixels after each compaction,
    /// and `get` reads it in order across empty and full bands.
    #[test]
    fn compaction_matches_a_plain_filter() {
        let (w, h) = (7u32, 3 * BAND_ROWS + 5);
        let n = w * h;
        let mut list = EmptyList::all(n, w);
        let mut coverage = crate::sampler::coverage::new_map(n);
        let mut want: Vec<u32> = (0..n).collect();
        for round in 0..4u32 {
            for p in 0..n {
                // Round 1 covers a whole band; the others scatter.
                let band = p / (BAND_ROWS * w);
                if (round == 1 && band == 1)
                    || crate::sampler::fixed::mix(p ^ (round << 20)).is_multiple_of(3)
                {
                    coverage[(p / 64) as usize] |= 1 << (p % 64);
                }
            }
            list.compact(&coverage);
            want.retain(|&p| !is_covered(&coverage, p));
            assert_eq!(list.len() as usize, want.len(), "round {round}");
            for (i, &p) in want.iter().enumerate() {
                assert_eq!(list.get(i as u32), p, "round {round} index {i}");
            }
        }
    }
}
