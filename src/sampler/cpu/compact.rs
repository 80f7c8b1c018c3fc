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
            Self::List(v) => 4 * v.len(),
        }
    }
}

/// The list without the pixels the coverage map marks, in the same order.
/// The list is cut at band boundaries ([`super::cover::BAND_ROWS`] rows), the
/// pieces are filtered in parallel and joined in band order.
#[must_use]
pub fn compact(empty: &EmptyList, coverage: &[u8], width: u32) -> EmptyList {
    let band = super::cover::BAND_ROWS * width;
    let n_bands = (coverage.len() as u32).div_ceil(band);
    let uncovered = |p: &u32| coverage[*p as usize] == 0;
    let pieces: Vec<Vec<u32>> = match empty {
        EmptyList::All(n) => (0..n_bands)
            .into_par_iter()
            .map(|b| {
                (b * band..((b + 1) * band).min(*n))
                    .filter(uncovered)
                    .collect()
            })
            .collect(),
        EmptyList::List(v) => {
            let cuts: Vec<usize> = (0..=n_bands)
                .map(|b| v.partition_point(|&p| p < b.saturating_mul(band)))
                .collect();
            cuts.par_windows(2)
                .map(|c| v[c[0]..c[1]].iter().copied().filter(uncovered).collect())
                .collect()
        }
    };
    EmptyList::List(pieces.concat())
}
