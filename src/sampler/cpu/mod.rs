//! The CPU reference backend: the paper's loop (Figure 3) with one module per
//! stage, [`throw`] (S1), [`cull`] and [`cover`] (S2), [`compact`] (PP), each
//! the mirror of the WGSL shader of the same name. Parallel with rayon and
//! deterministic for any number of threads.
//!
//! [`CpuStepper`] runs one iteration; the loop itself is
//! [`crate::sampler::run::run`], shared with the GPU backend.

pub(crate) mod compact;
pub(crate) mod cover;
pub(crate) mod cull;
pub(crate) mod throw;

use std::time::Instant;

use compact::EmptyList;

use super::run::{self, StageTimes, Step, Stepper};
use super::{Control, Dart, Params, Plan, Result, SampleSet, Stats, coverage};

pub(crate) use super::coverage::prefetch;

/// Runs the sampler on the CPU (the exact mode's refinement included).
///
/// ```
/// use pixelpie::sampler::{Params, Control, cpu};
/// let set = cpu::sample(&Params::new(64, 64).with_radius(4.0).with_seed(1), Control::default()).unwrap();
/// assert!(set.maximal() && !set.points.is_empty());
/// ```
pub fn sample(params: &Params, ctl: Control<'_>) -> Result<SampleSet> {
    ctl.check()?;
    let plan = params.plan()?;
    ctl.check()?;
    let stats = Stats {
        backend: crate::sampler::BackendKind::Cpu,
        device: format!("{} threads", rayon::current_num_threads()),
        ..Stats::default()
    };
    if plan.exact {
        let mut stepper = super::exact::ExactStepper::new(&plan).with_control(ctl);
        return run::run(&plan, &mut stepper, stats, ctl);
    }
    let mut stepper = CpuStepper::new(&plan).with_control(ctl);
    // Before the first iteration, after the maps the run needs (a large
    // domain's take a while).
    ctl.check()?;
    run::run(&plan, &mut stepper, stats, ctl)
}

/// The pixel pass on the CPU: the state between iterations and the buffers
/// that every iteration reuses (fresh memory costs page faults).
pub struct CpuStepper<'p> {
    plan: &'p Plan,
    coverage: Vec<u64>,
    empty: EmptyList,
    darts: Vec<Dart>,
    survivors: Vec<Dart>,
    grid: throw::DartGrid,
    culler: cull::Culler,
    /// The radius map's blocks, for coverage under a policy that reads it.
    blocks: Option<coverage::Blocks>,
    peak_bytes: usize,
    /// Polled between the stages of an iteration ([`Self::with_control`]).
    ctl: Control<'p>,
}

impl<'p> CpuStepper<'p> {
    /// A run of `plan` with every pixel empty.
    #[must_use]
    pub fn new(plan: &'p Plan) -> Self {
        let slots = plan.slots();
        let (coverage, empty) = initial(plan);
        debug_assert_eq!(coverage.len(), slots.div_ceil(64) as usize);
        Self {
            plan,
            coverage,
            empty,
            darts: Vec::new(),
            survivors: Vec::new(),
            grid: throw::DartGrid::default(),
            culler: cull::Culler::default(),
            blocks: coverage::Blocks::new(plan),
            peak_bytes: 0,
            ctl: Control::new(),
        }
    }

    /// The run heeds `ctl`'s cancel between the stages of an iteration as
    /// well as before it (an iteration of a large batch takes a second on
    /// two cores): a cancelled step ends with
    /// [`crate::sampler::Error::Cancelled`], and a run not cancelled is the
    /// same.
    #[must_use]
    pub fn with_control(mut self, ctl: Control<'p>) -> Self {
        self.ctl = ctl;
        self
    }
}

/// The coverage map and the empty list before the first iteration: every
/// slot empty, but for the slots of a class with no radius at their pixel.
pub(crate) fn initial(plan: &Plan) -> (Vec<u64>, EmptyList) {
    let slots = plan.slots();
    let mut coverage = coverage::new_map(slots);
    let mut empty = EmptyList::all(slots, plan.width);
    if plan.holes
        && let Some(map) = &plan.map
    {
        for (s, _) in map.radii_fx().iter().enumerate().filter(|(_, r)| **r == 0) {
            coverage[s / 64] |= 1 << (s % 64);
        }
        empty.compact(&coverage);
    }
    (coverage, empty)
}

impl Stepper for CpuStepper<'_> {
    fn empty(&self) -> u64 {
        u64::from(self.empty.len())
    }

    fn step(&mut self, iteration: u32, darts: u32) -> Result<Step> {
        let plan = self.plan;
        let t0 = Instant::now();
        // Each stage polls the cancel inside too: a cancelled stage leaves
        // its work unfinished, and the step ends here with the error.
        let ctl = &self.ctl;
        throw::throw(plan, iteration, darts, &self.empty, &mut self.darts, ctl);
        ctl.check()?;
        self.grid.rebuild(plan, &self.darts, ctl);
        ctl.check()?;
        let t1 = Instant::now();
        self.culler
            .survivors(plan, &self.darts, &self.grid, &mut self.survivors, ctl);
        ctl.check()?;
        cover::cover(
            plan,
            self.blocks.as_ref(),
            &self.survivors,
            &mut self.coverage,
            ctl,
        );
        ctl.check()?;
        let t2 = Instant::now();
        self.empty.compact(&self.coverage);
        let t3 = Instant::now();
        self.peak_bytes = self.peak_bytes.max(
            self.empty.bytes()
                + self.grid.bytes()
                + self.culler.bytes()
                + 16 * (self.darts.capacity() + self.survivors.capacity()),
        );
        let mut stages = StageTimes::default();
        stages.add("throw", (t1 - t0).as_secs_f64());
        stages.add("cull", (t2 - t1).as_secs_f64());
        stages.add("compact", (t3 - t2).as_secs_f64());
        Ok(Step {
            empty: u64::from(self.empty.len()),
            accepted: self.survivors.iter().map(|d| plan.point(d)).collect(),
            stages,
            finished: false,
            removed: Vec::new(),
            held: 0,
        })
    }

    fn bytes(&self) -> usize {
        let map_bytes = self.plan.map.as_ref().map_or(0, |m| 4 * m.radii_fx().len());
        let blocks = self.blocks.as_ref().map_or(0, coverage::Blocks::bytes);
        8 * self.coverage.len() + map_bytes + blocks + self.peak_bytes
    }
}
