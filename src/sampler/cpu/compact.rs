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

/// Writes into `out` the list without the pixels the coverage map marks, in
/// the same order. The list is cut at band boundaries
/// ([`super::cover::BAND_ROWS`] rows); the pieces are counted, then written in
/// parallel straight to their place (the scan and scatter of paper §3.3).
/// `out` is reused between iterations: fresh memory costs page faults.
pub fn compact(empty: &EmptyList, coverage: &[u8], width: u32, out: &mut Vec<u32>) {
    let band = super::cover::BAND_ROWS * width;
    let n_bands = (coverage.len() as u32).div_ceil(band);
    let uncovered = |p: &u32| coverage[*p as usize] == 0;
    match empty {
        EmptyList::All(n) => {
            let pieces: Vec<_> = (0..n_bands)
                .map(|b| b * band..((b + 1) * band).min(*n))
                .collect();
            scatter(&pieces, |r| r.clone().filter(uncovered), out);
        }
        EmptyList::List(v) => {
            let cut = |b: u32| v.partition_point(|&p| p < b.saturating_mul(band));
            let pieces: Vec<_> = (0..n_bands).map(|b| cut(b)..cut(b + 1)).collect();
            scatter(
                &pieces,
                |r| v[r.clone()].iter().copied().filter(uncovered),
                out,
            );
        }
    }
}

/// Counts each piece's items, then writes them in parallel into their place
/// in `out`.
fn scatter<R: Sync, I: Iterator<Item = u32>>(
    pieces: &[R],
    items: impl Fn(&R) -> I + Sync,
    out: &mut Vec<u32>,
) {
    let counts: Vec<usize> = pieces.par_iter().map(|p| items(p).count()).collect();
    out.clear();
    out.resize(counts.iter().sum(), 0);
    let mut slots = Vec::with_capacity(counts.len());
    let mut rest = out.as_mut_slice();
    for &c in &counts {
        let (head, tail) = rest.split_at_mut(c);
        slots.push(head);
        rest = tail;
    }
    slots
        .into_par_iter()
        .zip(pieces.par_iter())
        .for_each(|(slot, p)| {
            for (dst, src) in slot.iter_mut().zip(items(p)) {
                *dst = src;
            }
        });
}
