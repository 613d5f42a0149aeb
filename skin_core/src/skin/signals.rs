//! Raw per-cell readings and their reduction to one force and one proximity signal.

use serde::{Deserialize, Serialize};

use super::characteristic::sanitize_signal;

/// How the three force sensors of a cell are reduced to one force signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForceReduction {
    /// Mean of the three sensors: tracks the total normal load on the cell (default).
    #[default]
    Mean,
    /// Maximum of the three sensors: most sensitive to a touch near one sensor (cell edge).
    Max,
}

/// One cell's normalized readings, all nominally in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CellReading {
    /// The three capacitive force sensors of the cell (interactive-force-control paper Sec. 4.1.2).
    pub force: [f64; 3],
    /// The optical proximity sensor: 1 at contact, 0 when nothing is within range.
    pub proximity: f64,
}

impl CellReading {
    /// A reading with all three force sensors at `force` and the given proximity.
    pub const fn uniform(force: f64, proximity: f64) -> Self {
        CellReading { force: [force; 3], proximity }
    }

    /// The cell's force signal `f_{s_i}` in [0, 1]: each sensor sanitized
    /// ([`sanitize_signal`]: NaN -> 0, clamp to [0, 1]) then reduced by `reduction`.
    #[inline]
    pub fn force_signal(&self, reduction: ForceReduction) -> f64 {
        let [a, b, c] = self.force.map(sanitize_signal);
        match reduction {
            ForceReduction::Mean => (a + b + c) * (1.0 / 3.0),
            ForceReduction::Max => a.max(b).max(c),
        }
    }

    /// The cell's proximity signal `p_{s_i}` in [0, 1], sanitized (NaN -> 0, clamp to [0, 1]).
    #[inline]
    pub fn proximity_signal(&self) -> f64 {
        sanitize_signal(self.proximity)
    }

    /// No raw value above 0 (so every sanitized signal is 0, NaN included): the cell adds
    /// nothing to a wrench, a signal maximum or a skin task's rows, whatever the fusion weight
    /// and thresholds are. Most cells of a skin are silent, and this test is cheaper than the
    /// sanitizing.
    #[inline]
    pub fn is_silent(&self) -> bool {
        // `|`, not `||`: one branch for the cell, not one per value
        !((self.force[0] > 0.0) | (self.force[1] > 0.0) | (self.force[2] > 0.0) | (self.proximity > 0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reductions_and_sanitizing() {
        let r = CellReading { force: [0.3, f64::NAN, 1.5], proximity: -0.2 };
        assert!((r.force_signal(ForceReduction::Mean) - 1.3 / 3.0).abs() < 1e-15);
        assert_eq!(r.force_signal(ForceReduction::Max), 1.0);
        assert_eq!(r.proximity_signal(), 0.0);
        assert_eq!(CellReading::uniform(0.4, f64::NAN).proximity_signal(), 0.0);
        assert!((CellReading::uniform(0.4, 0.0).force_signal(ForceReduction::Mean) - 0.4).abs() < 1e-15);
    }
}
