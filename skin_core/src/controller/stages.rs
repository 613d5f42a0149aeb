//! Opt-in timing of the stages of [`super::Controller::update`]: where a cycle's time goes
//! (the scale benchmarks' shares, `docs/performance.md`). Off by default; when off a cycle pays
//! one branch per stage boundary, when on one clock read each (about 20 ns).

use std::time::Instant;

/// A stage of the control cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Skin processing: the scan for live cells, their distances, the supervisor's signals
    /// (avoidance and contact summaries) and arrangement, the patch wrenches and hand signals.
    Skin,
    /// Rigid-body dynamics: kinematics, gravity, `M(q)` (CRBA) and `C q̇ + g` (RNEA), or the
    /// resolver's virtual dynamics in [`super::HierarchyDynamics::Admittance`].
    Dynamics,
    /// The arrangement's tasks (rows, Jacobians, references) and the posture torque.
    Tasks,
    /// The hierarchy's projections (interactive-force-control paper eq. 19-25, with the
    /// Cholesky inverse of `M`) and the blend across switches.
    Hierarchy,
    /// The admittance resolver (interactive-force-control paper eq. 26) and the limits.
    Resolver,
}

impl Stage {
    /// Every stage, in cycle order.
    pub const ALL: [Stage; 5] = [Stage::Skin, Stage::Dynamics, Stage::Tasks, Stage::Hierarchy, Stage::Resolver];

    /// Short name (the benchmarks' keys).
    pub fn name(self) -> &'static str {
        match self {
            Stage::Skin => "skin",
            Stage::Dynamics => "dynamics",
            Stage::Tasks => "tasks",
            Stage::Hierarchy => "hierarchy",
            Stage::Resolver => "resolver",
        }
    }
}

/// Time spent in each stage, summed over the cycles since timing was switched on.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StageTimes {
    ns: [u64; 5],
    cycles: u64,
}

impl StageTimes {
    /// Nanoseconds spent in `stage` in all timed cycles.
    pub fn total_ns(&self, stage: Stage) -> u64 {
        self.ns[stage as usize]
    }

    /// Number of timed cycles that ran to the end (a faulted cycle's laps are kept, not counted).
    pub fn cycles(&self) -> u64 {
        self.cycles
    }

    /// Fraction of the timed total spent in `stage` (0 before any timed cycle).
    pub fn share(&self, stage: Stage) -> f64 {
        let total: u64 = self.ns.iter().sum();
        if total == 0 {
            0.0
        } else {
            self.ns[stage as usize] as f64 / total as f64
        }
    }
}

/// The clock of [`StageTimes`]: each lap charges the time since the previous one to a stage.
#[derive(Debug, Clone, Default)]
pub(crate) struct StageClock {
    on: bool,
    last: Option<Instant>,
    times: StageTimes,
}

impl StageClock {
    /// Switches timing on (from zero) or off.
    pub(crate) fn set(&mut self, on: bool) {
        *self = Self { on, ..Self::default() };
    }

    /// The times so far, `None` when timing is off.
    pub(crate) fn times(&self) -> Option<&StageTimes> {
        self.on.then_some(&self.times)
    }

    /// Starts a cycle.
    #[inline]
    pub(crate) fn start(&mut self) {
        if self.on {
            self.last = Some(Instant::now());
        }
    }

    /// Charges the time since the last lap (or the start) to `stage`.
    #[inline]
    pub(crate) fn lap(&mut self, stage: Stage) {
        if let (true, Some(last)) = (self.on, self.last) {
            let now = Instant::now();
            self.times.ns[stage as usize] += (now - last).as_nanos() as u64;
            self.last = Some(now);
        }
    }

    /// Ends a cycle that ran to the end.
    #[inline]
    pub(crate) fn finish(&mut self) {
        if self.on {
            self.times.cycles += 1;
        }
    }
}
