//! Exact mode's rules that both backends follow, written once: the wrap
//! periods, the darts an iteration throws, when a level refines, how a
//! sample becomes a point, and the typed handover of a GPU run to the CPU's
//! at the finest level ([`Handover`], for [`super::ExactStepper::resume`]).

use super::super::fixed::{self, MAX_BATCH};
use super::super::{Plan, Point};
use super::REFINE_BELOW;

/// The wrap periods in 1/2^`frac` px (0 when the domain is not periodic).
#[must_use]
pub(crate) fn periods(plan: &Plan, frac: u32) -> (u32, u32) {
    if plan.periodic {
        (plan.width << frac, plan.height << frac)
    } else {
        (0, 0)
    }
}

/// The darts an iteration throws with `empty` pixels or cells active: the
/// plan's batch, at most one per active pixel or cell and [`MAX_BATCH`].
#[must_use]
pub(crate) fn darts_for(plan: &Plan, empty: u64) -> u32 {
    u64::from(plan.batch).min(empty).min(u64::from(MAX_BATCH)) as u32
}

/// Whether an iteration at `level` that accepted `accepted` of `darts`
/// goes one level down: above the finest level `frac`, when fewer than one
/// dart in [`REFINE_BELOW`] was accepted.
#[must_use]
pub(crate) fn refines(level: u32, frac: u32, accepted: usize, darts: usize) -> bool {
    level < frac && accepted * REFINE_BELOW < darts
}

/// A sample placed at (x, y) in 1/2^F px in pixel `pixel`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Placed {
    /// x in 1/2^F px.
    pub x: u32,
    /// y in 1/2^F px.
    pub y: u32,
    /// The index of its pixel.
    pub pixel: u32,
}

impl Placed {
    /// The point of this sample: its position in pixels (exact in `f32`)
    /// and the radius of its pixel.
    #[must_use]
    pub(crate) fn point(self, plan: &Plan, frac: u32) -> Point {
        let one = (1u32 << frac) as f32;
        Point {
            x: self.x as f32 / one,
            y: self.y as f32 / one,
            radius: fixed::fx_to_radius(plan.radius_at(self.pixel)),
            class: 0,
        }
    }
}

/// A run handed over at a level: the samples in acceptance order, the
/// pixels one of them holds whole (bit p % 64 of word p / 64, set beyond
/// the last pixel), the level, and above level 0 its active cells in order
/// (x, y in cell units).
#[cfg(feature = "gpu")]
#[derive(Clone, Debug, Default)]
pub(crate) struct Handover {
    /// The accepted samples, in acceptance order.
    pub samples: Vec<Placed>,
    /// The level-0 coverage bitmap.
    pub coverage: Vec<u64>,
    /// The level the run is at.
    pub level: u32,
    /// The level's active cells.
    pub cells: Vec<[u32; 2]>,
}
