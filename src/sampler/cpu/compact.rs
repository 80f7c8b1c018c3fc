//! Post-processing (paper §3.3, step PP) on the CPU: order-preserving stream
//! compaction of the empty-pixel list by the coverage map.
//!
//! WGSL mirror: `shaders/compact.wgsl` (a prefix-sum scan and scatter).

use rayon::prelude::*;

/// The pixels still empty, in ascending order of first listing.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EmptyList {
    /// Every pixel `0..n`: the first iteration's list, never stored (paper
    /// §3.3, "Optimizations for an Empty Domain").
    All(u32),
    /// An explicit list of pixel indices.
    List(Vec<u32>),
}

impl EmptyList {
    /// The number of empty pixels.
    #[inline]
    #[must_use]
    pub fn len(&self) -> u32 {
        match self {
            Self::All(n) => *n,
            Self::List(v) => v.len() as u32,
        }
    }

    /// Whether no pixel is empty.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `i`-th empty pixel.
    #[inline]
    #[must_use]
    pub fn get(&self, i: u32) -> u32 {
        match self {
            Self::All(_) => i,
            Self::List(v) => v[i as usize],
        }
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        match self {
            Self::All(_) => 0,
            Self::List(v) => 4 * v.capacity(),
        }
    }
}

/// Compacts the empty-pixel list by the coverage map. Holds one buffer per
/// band of [`super::cover::BAND_ROWS`] rows, reused between iterations
/// (fresh memory costs page faults).
#[derive(Default)]
pub struct Compactor {
    pieces: Vec<Vec<u32>>,
}

impl Compactor {
    /// Writes into `out` the list without the pixels the coverage map marks,
    /// in the same order: the list is cut at band boundaries, the pieces are
    /// filtered in parallel and joined in band order.
    pub fn compact(&mut self, empty: &EmptyList, coverage: &[u8], width: u32, out: &mut Vec<u32>) {
        let band = super::cover::BAND_ROWS * width;
        let n_bands = (coverage.len() as u32).div_ceil(band);
        let uncovered = |p: &u32| coverage[*p as usize] == 0;
        self.pieces.resize_with(n_bands as usize, Vec::new);
        match empty {
            EmptyList::All(n) => {
                self.pieces
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(b, piece)| {
                        let b = b as u32;
                        piece.clear();
                        piece.extend((b * band..((b + 1) * band).min(*n)).filter(uncovered));
                    });
            }
            EmptyList::List(v) => {
                let cut = |b: u32| v.partition_point(|&p| p < b.saturating_mul(band));
                self.pieces
                    .par_iter_mut()
                    .enumerate()
                    .for_each(|(b, piece)| {
                        let b = b as u32;
                        piece.clear();
                        piece.extend(v[cut(b)..cut(b + 1)].iter().copied().filter(uncovered));
                    });
            }
        }
        out.clear();
        out.reserve(self.pieces.iter().map(Vec::len).sum());
        for piece in &self.pieces {
            out.extend_from_slice(piece);
        }
    }

    /// Bytes held.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.pieces.iter().map(|p| 4 * p.capacity()).sum()
    }
}
