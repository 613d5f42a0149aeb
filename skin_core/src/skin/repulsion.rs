//! Repulsive force laws: intentional-contact paper eq. (3) (linear, per skin cell) and interactive-force-control paper eq. (16)
//! (exponential).

use serde::{Deserialize, Serialize};

use crate::param_file::InvalidParam;

/// Parameters of the repulsive force laws.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RepulsionParams {
    /// `K` of intentional-contact paper eq. (3) \[N/m\].
    pub gain_n_per_m: f64,
    /// `d_range` of intentional-contact paper eq. (3) \[m\]: no repulsion at or beyond it.
    pub range_m: f64,
    /// `f_max` of interactive-force-control paper eq. (16) \[N\]: the force at distance 0.
    pub max_force_n: f64,
    /// `alpha` of interactive-force-control paper eq. (16) \[m\]: decay length.
    pub decay_m: f64,
}

impl RepulsionParams {
    /// Checks that every parameter is finite and positive.
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        InvalidParam::positive_finite(prefix, "gain_n_per_m", self.gain_n_per_m)?;
        InvalidParam::positive_finite(prefix, "range_m", self.range_m)?;
        InvalidParam::positive_finite(prefix, "max_force_n", self.max_force_n)?;
        InvalidParam::positive_finite(prefix, "decay_m", self.decay_m)
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
