//! Repulsive force laws: intentional-contact paper eq. (3) (linear, per skin cell) and interactive-force-control paper eq. (16)
//! (exponential).

use crate::declare_params;
use crate::param_file::declare::{Declared, Range};
use serde::{Deserialize, Serialize};

use crate::param_file::InvalidParam;

declare_params! {
    /// Parameters of the repulsive force laws.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct RepulsionParams {
        /// `K` of intentional-contact paper eq. (3).
        pub gain_n_per_m: f64 => { unit: "N/m", range: Range::positive(1e5), live: true },
        /// `d_range` of intentional-contact paper eq. (3): no repulsion at or beyond it
        /// (at most `proximity.range_m`).
        pub range_m: f64 => { unit: "m", range: Range::positive(1.0), live: true },
        /// `f_max` of interactive-force-control paper eq. (16): the force at distance 0.
        pub max_force_n: f64 => { unit: "N", range: Range::positive(1e3), live: true },
        /// `alpha` of interactive-force-control paper eq. (16): decay length.
        pub decay_m: f64 => { unit: "m", range: Range::positive(10.0), live: true },
    }
}

impl RepulsionParams {
    /// Checks the declared ranges.
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        self.check(prefix)
    }

    /// Intentional-contact paper eq. (3) with these parameters, see [`linear_repulsion`].
    #[inline]
    pub fn linear_n(&self, distance_m: f64) -> f64 {
        linear_repulsion(self.gain_n_per_m, self.range_m, distance_m)
    }

    /// Interactive-force-control paper eq. (16) with these parameters, see [`exponential_repulsion`].
    #[inline]
    pub fn exponential_n(&self, distance_m: f64) -> f64 {
        exponential_repulsion(self.max_force_n, self.decay_m, distance_m)
    }
}

/// Intentional-contact paper eq. (3): repulsive force magnitude \[N\] `K (d_range - d)` for `d < d_range`, else 0.
/// Negative distances count as 0 (contact); NaN gives 0 (nothing measured).
#[inline]
pub fn linear_repulsion(gain_n_per_m: f64, range_m: f64, distance_m: f64) -> f64 {
    if distance_m.is_nan() || distance_m >= range_m {
        0.0
    } else {
        gain_n_per_m * (range_m - distance_m.max(0.0))
    }
}

/// Interactive-force-control paper eq. (16): `f_rep(d) = f_max exp(-d / alpha)` \[N\]. Negative distances count as 0
/// (giving `f_max`); NaN and +Inf give 0.
#[inline]
pub fn exponential_repulsion(max_force_n: f64, decay_m: f64, distance_m: f64) -> f64 {
    if distance_m.is_nan() {
        return 0.0;
    }
    max_force_n * (-distance_m.max(0.0) / decay_m).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_law() {
        assert_eq!(linear_repulsion(100.0, 0.1, 0.0), 10.0);
        assert!((linear_repulsion(100.0, 0.1, 0.04) - 6.0).abs() < 1e-12);
        assert_eq!(linear_repulsion(100.0, 0.1, 0.1), 0.0);
        assert_eq!(linear_repulsion(100.0, 0.1, 0.5), 0.0);
        assert_eq!(linear_repulsion(100.0, 0.1, -1.0), 10.0);
        assert_eq!(linear_repulsion(100.0, 0.1, f64::NAN), 0.0);
    }

    #[test]
    fn exponential_law() {
        assert_eq!(exponential_repulsion(20.0, 0.05, 0.0), 20.0);
        assert!((exponential_repulsion(20.0, 0.05, 0.05) - 20.0 / std::f64::consts::E).abs() < 1e-12);
        assert_eq!(exponential_repulsion(20.0, 0.05, f64::INFINITY), 0.0);
        assert_eq!(exponential_repulsion(20.0, 0.05, f64::NAN), 0.0);
        assert_eq!(exponential_repulsion(20.0, 0.05, -3.0), 20.0);
    }
}
