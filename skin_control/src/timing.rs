//! Durations of a node's stages over a run, for its shutdown summary and `/diagnostics`.
use std::time::Duration;

/// Durations of one stage over many runs (mean and max), for summaries.
#[derive(Debug, Default, Clone, Copy)]
pub struct Timing {
    /// Number of runs.
    pub count: u64,
    /// Sum of durations.
    pub total: Duration,
    /// Longest.
    pub max: Duration,
}

impl Timing {
    /// Adds one run.
    pub fn add(&mut self, d: Duration) {
        self.count += 1;
        self.total += d;
        self.max = self.max.max(d);
    }
}

impl std::fmt::Display for Timing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mean = self.total.checked_div(self.count.max(1) as u32).unwrap_or_default();
        write!(f, "mean {mean:?}, max {:?}", self.max)
    }
}
