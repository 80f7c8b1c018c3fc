//! Post-processing (paper §3.3, step PP) on the CPU: order-preserving stream
//! compaction of the empty-pixel list by the coverage map.
//!
//! WGSL mirror: `shaders/compact.wgsl` (a prefix-sum scan and scatter).

use std::sync::atomic::{AtomicU8, Ordering};

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
#[must_use]
pub fn compact(empty: &EmptyList, coverage: &[AtomicU8]) -> EmptyList {
    let uncovered = |p: &u32| coverage[*p as usize].load(Ordering::Relaxed) == 0;
    EmptyList::List(match empty {
        EmptyList::All(n) => (0..*n).into_par_iter().filter(uncovered).collect(),
        EmptyList::List(v) => v.par_iter().copied().filter(uncovered).collect(),
    })
}
