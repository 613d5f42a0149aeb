//! Normalized [0, 1] characteristics of the skin cells' proximity and force sensors and their
//! inverses.
//!
//! Interactive-force-control paper Sec. 2.3: both signals are normalized to [0, 1], the proximity signal is maximal when
//! the sensor touches a surface, and both sensors are nonlinear with the highest sensitivity at
//! short distances and low forces, saturating at larger magnitudes. Both characteristics here are
//! normalized, truncated exponentials:
//!
//! - proximity: `p(d) = (exp(-d/decay_m) - exp(-range_m/decay_m)) / (1 - exp(-range_m/decay_m))`
//!   for `0 <= d <= range_m`, `p = 1` at contact, `p = 0` from `range_m` on;
//! - force: `f(F) = (1 - exp(-F/scale_n)) / (1 - exp(-max_n/scale_n))` for `0 <= F <= max_n`,
//!   `f = 0` without load, `f = 1` from `max_n` on.
//!
//! Both are strictly monotonic on their domain, so the inverses are exact there; at the
//! saturated ends the inverses return the end of the domain (`range_m` for `p = 0`, `max_n` for
//! `f = 1`), never Inf or NaN.

use crate::declare_params;
use crate::param_file::declare::{Declared, Range};
use serde::{Deserialize, Serialize};

use crate::param_file::InvalidParam;

/// Largest allowed `range_m / decay_m` and `max_n / scale_n`: beyond it the exponential is so
/// flat at the far end (`exp(-20)` ≈ 2e-9) that signals there are indistinguishable and the
/// inverse loses its precision.
pub const MAX_SPAN_RATIO: f64 = 20.0;

/// Sanitizes a raw normalized signal: NaN becomes 0 (no signal), everything else is clamped to
/// [0, 1] (so +Inf becomes 1, -Inf becomes 0).
#[inline]
#[allow(clippy::manual_clamp)] // `clamp` keeps NaN; this maps it to 0
pub fn sanitize_signal(signal: f64) -> f64 {
    // `f64::max` returns the non-NaN operand, so NaN maps to 0 without a branch.
    signal.max(0.0).min(1.0)
}

declare_params! {
    /// Proximity characteristic: distance \[m\] to the normalized proximity signal [0, 1].
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ProximityCharacteristic {
        /// Sensing range: at and beyond this distance the signal is 0 (intentional-contact paper
        /// eq. 3 `d_range`).
        pub range_m: f64 => { unit: "m", range: Range::positive(1.0), live: true },
        /// Decay length of the exponential: smaller means more sensitive close to the surface.
        pub decay_m: f64 => { unit: "m", range: Range::positive(10.0), live: true },
    }
}

impl ProximityCharacteristic {
    /// Checks that both parameters are finite and positive and `range_m / decay_m <=`
    /// [`MAX_SPAN_RATIO`]. `prefix` is prepended to the key names in the error (e.g. `"proximity."`).
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        self.check(prefix)?;
        InvalidParam::in_range(
            prefix,
            "decay_m",
            self.decay_m,
            self.range_m / MAX_SPAN_RATIO,
            f64::INFINITY,
            "must be at least range_m / 20 (else the signal is numerically flat near range_m)",
        )
    }

    /// The characteristic with its constants precomputed, for evaluating many cells per cycle.
    #[inline]
    pub fn prepared(&self) -> PreparedProximity {
        let x = -self.range_m / self.decay_m;
        PreparedProximity { range_m: self.range_m, decay_m: self.decay_m, tail: x.exp(), norm: -x.exp_m1() }
    }

    /// Signal for a distance \[m\]; see [`PreparedProximity::signal`].
    #[inline]
    pub fn signal(&self, distance_m: f64) -> f64 {
        self.prepared().signal(distance_m)
    }

    /// Distance \[m\] for a signal; see [`PreparedProximity::distance_m`].
    #[inline]
    pub fn distance_m(&self, signal: f64) -> f64 {
        self.prepared().distance_m(signal)
    }
}

/// A [`ProximityCharacteristic`] with `exp(-range/decay)` and `1 - exp(-range/decay)`
/// precomputed (two transcendental functions fewer per evaluation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedProximity {
    range_m: f64,
    decay_m: f64,
    tail: f64,
    norm: f64,
}

impl PreparedProximity {
    /// Sensing range \[m\]: at and beyond this distance the signal is 0.
    #[inline]
    pub fn range_m(&self) -> f64 {
        self.range_m
    }

    /// Signal for a distance \[m\]. Negative distances count as contact (1), NaN counts as
    /// "nothing detected" (0), `+Inf` and anything at or beyond `range_m` gives 0.
    #[inline]
    pub fn signal(&self, distance_m: f64) -> f64 {
        if distance_m.is_nan() || distance_m >= self.range_m {
            return 0.0;
        }
        let d = distance_m.max(0.0);
        // exp(-d/a) - exp(-R/a) = exp(-R/a) * expm1((R-d)/a), normalized by 1 - exp(-R/a).
        sanitize_signal(self.tail * ((self.range_m - d) / self.decay_m).exp_m1() / self.norm)
    }

    /// Distance \[m\] for a signal; the inverse of [`Self::signal`] on (0, 1]. The signal is
    /// sanitized first ([`sanitize_signal`]): 0 and NaN give `range_m` (nothing within range),
    /// 1 gives 0 (contact). The result is always in `[0, range_m]`.
    #[inline]
    pub fn distance_m(&self, signal: f64) -> f64 {
        let p = sanitize_signal(signal);
        if p <= 0.0 {
            return self.range_m;
        }
        let d = -self.decay_m * (p * self.norm + self.tail).ln();
        d.clamp(0.0, self.range_m)
    }
}

declare_params! {
    /// Force characteristic: normal force \[N\] on a cell to the normalized force signal [0, 1].
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ForceCharacteristic {
        /// Force scale of the exponential: smaller means more sensitive at low forces.
        pub scale_n: f64 => { unit: "N", range: Range::positive(1e3), live: true },
        /// Saturation force: at and beyond it the signal is 1.
        pub max_n: f64 => { unit: "N", range: Range::positive(1e3), live: true },
    }
}

impl ForceCharacteristic {
    /// Checks that both parameters are finite and positive and `max_n / scale_n <=`
    /// [`MAX_SPAN_RATIO`]. `prefix` is prepended to the key names in the error (e.g. `"force."`).
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        self.check(prefix)?;
        InvalidParam::in_range(
            prefix,
            "scale_n",
            self.scale_n,
            self.max_n / MAX_SPAN_RATIO,
            f64::INFINITY,
            "must be at least max_n / 20 (else the signal is numerically flat near max_n)",
        )
    }

    /// The characteristic with its constant precomputed, for evaluating many cells per cycle.
    #[inline]
    pub fn prepared(&self) -> PreparedForce {
        PreparedForce { scale_n: self.scale_n, max_n: self.max_n, span: (-self.max_n / self.scale_n).exp_m1() }
    }

    /// Signal for a force \[N\]; see [`PreparedForce::signal`].
    #[inline]
    pub fn signal(&self, force_n: f64) -> f64 {
        self.prepared().signal(force_n)
    }

    /// Force \[N\] for a signal; see [`PreparedForce::force_n`].
    #[inline]
    pub fn force_n(&self, signal: f64) -> f64 {
        self.prepared().force_n(signal)
    }
}

/// A [`ForceCharacteristic`] with `exp(-max/scale) - 1` precomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedForce {
    scale_n: f64,
    max_n: f64,
    span: f64,
}

impl PreparedForce {
    /// Signal for a force \[N\]. Negative forces and NaN give 0, `max_n` and above (and +Inf) give 1.
    #[inline]
    pub fn signal(&self, force_n: f64) -> f64 {
        if force_n.is_nan() || force_n <= 0.0 {
            return 0.0;
        }
        if force_n >= self.max_n {
            return 1.0;
        }
        sanitize_signal((-force_n / self.scale_n).exp_m1() / self.span)
    }

    /// Force \[N\] for a signal; the inverse of [`Self::signal`] on [0, 1). The signal is
    /// sanitized first ([`sanitize_signal`]): NaN and 0 give 0 N, 1 gives `max_n`. The result is
    /// always in `[0, max_n]`.
    #[inline]
    pub fn force_n(&self, signal: f64) -> f64 {
        let f = sanitize_signal(signal);
        if f <= 0.0 {
            return 0.0;
        }
        if f >= 1.0 {
            return self.max_n;
        }
        let x = -self.scale_n * (f * self.span).ln_1p();
        x.clamp(0.0, self.max_n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const PROX: ProximityCharacteristic = ProximityCharacteristic { range_m: 0.15, decay_m: 0.03 };
    const FORCE: ForceCharacteristic = ForceCharacteristic { scale_n: 2.0, max_n: 10.0 };

    #[test]
    fn proximity_ends_and_inverse() {
        assert_eq!(PROX.signal(0.0), 1.0);
        assert_eq!(PROX.signal(PROX.range_m), 0.0);
        assert_eq!(PROX.signal(1.0), 0.0);
        for k in 0..=300 {
            let d = PROX.range_m * k as f64 / 300.0;
            let p = PROX.signal(d);
            assert!((0.0..=1.0).contains(&p));
            let back = PROX.distance_m(p);
            assert_relative_eq!(back, d, epsilon = 1e-9);
        }
    }

    #[test]
    fn proximity_monotonic_and_most_sensitive_near() {
        let mut last = f64::INFINITY;
        let mut last_slope = f64::INFINITY;
        let n = 200;
        for k in 0..=n {
            let d = PROX.range_m * k as f64 / n as f64;
            let p = PROX.signal(d);
            assert!(p < last || k == 0 || (p == 0.0 && last == 0.0), "not decreasing at {d}");
            if k > 0 {
                let slope = last - p;
                assert!(slope <= last_slope + 1e-15, "sensitivity grows with distance at {d}");
                last_slope = slope;
            }
            last = p;
        }
    }

    #[test]
    fn proximity_sanitized_inputs() {
        assert_eq!(PROX.signal(f64::NAN), 0.0);
        assert_eq!(PROX.signal(-0.5), 1.0);
        assert_eq!(PROX.signal(f64::INFINITY), 0.0);
        assert_eq!(PROX.signal(f64::NEG_INFINITY), 1.0);
        assert_eq!(PROX.distance_m(f64::NAN), PROX.range_m);
        assert_eq!(PROX.distance_m(0.0), PROX.range_m);
        assert_eq!(PROX.distance_m(-3.0), PROX.range_m);
        assert_eq!(PROX.distance_m(1.0), 0.0);
        assert_eq!(PROX.distance_m(7.0), 0.0);
        assert_eq!(PROX.distance_m(f64::INFINITY), 0.0);
        // Tiny positive signals stay finite and inside the range.
        let d = PROX.distance_m(f64::MIN_POSITIVE);
        assert!(d.is_finite() && d <= PROX.range_m);
    }

    #[test]
    fn force_ends_and_inverse() {
        assert_eq!(FORCE.signal(0.0), 0.0);
        assert_eq!(FORCE.signal(FORCE.max_n), 1.0);
        assert_eq!(FORCE.signal(1e6), 1.0);
        for k in 0..=300 {
            let f = FORCE.max_n * k as f64 / 300.0;
            let s = FORCE.signal(f);
            assert!((0.0..=1.0).contains(&s));
            assert_relative_eq!(FORCE.force_n(s), f, epsilon = 1e-9);
        }
    }

    #[test]
    fn force_monotonic_saturating() {
        let mut last = -1.0;
        let mut last_slope = f64::INFINITY;
        for k in 0..=200 {
            let f = FORCE.max_n * k as f64 / 200.0;
            let s = FORCE.signal(f);
            assert!(s > last, "not increasing at {f}");
            if k > 0 {
                let slope = s - last;
                assert!(slope <= last_slope + 1e-15, "sensitivity grows with force at {f}");
                last_slope = slope;
            }
            last = s;
        }
    }

    #[test]
    fn force_sanitized_inputs() {
        assert_eq!(FORCE.signal(f64::NAN), 0.0);
        assert_eq!(FORCE.signal(-1.0), 0.0);
        assert_eq!(FORCE.signal(f64::INFINITY), 1.0);
        assert_eq!(FORCE.force_n(f64::NAN), 0.0);
        assert_eq!(FORCE.force_n(-1.0), 0.0);
        assert_eq!(FORCE.force_n(1.0), FORCE.max_n);
        assert_eq!(FORCE.force_n(2.0), FORCE.max_n);
        let f = FORCE.force_n(1.0 - f64::EPSILON);
        assert!(f.is_finite() && f <= FORCE.max_n);
    }

    #[test]
    fn validation_names_the_key() {
        let bad = ProximityCharacteristic { range_m: 0.1, decay_m: 0.0 };
        let e = bad.validate("proximity.").unwrap_err();
        assert_eq!(e.key, "proximity.decay_m");
        let bad = ForceCharacteristic { scale_n: f64::NAN, max_n: 1.0 };
        let e = bad.validate("force.").unwrap_err();
        assert_eq!(e.key, "force.scale_n");
    }

    mod prop {
        use super::*;
        use proptest::prelude::*;

        fn any_f64() -> impl Strategy<Value = f64> {
            prop_oneof![
                -1.0e3..1.0e3f64,
                -2.0..2.0f64,
                Just(f64::NAN),
                Just(f64::INFINITY),
                Just(f64::NEG_INFINITY),
                Just(0.0),
                Just(1.0),
            ]
        }

        proptest! {
            #[test]
            fn outputs_always_bounded(x in any_f64(), range in 0.01..1.0f64, decay in 0.001..1.0f64,
                                      scale in 0.01..50.0f64, max in 0.1..100.0f64) {
                let p = ProximityCharacteristic { range_m: range, decay_m: decay };
                let f = ForceCharacteristic { scale_n: scale, max_n: max };
                let s = p.signal(x);
                prop_assert!((0.0..=1.0).contains(&s));
                let d = p.distance_m(x);
                prop_assert!((0.0..=range).contains(&d));
                let s = f.signal(x);
                prop_assert!((0.0..=1.0).contains(&s));
                let n = f.force_n(x);
                prop_assert!((0.0..=max).contains(&n));
            }

            #[test]
            fn inverse_round_trip(u in 0.0..1.0f64, range in 0.01..1.0f64, pr in 0.1..20.0f64,
                                  scale in 0.05..50.0f64, fr in 0.1..20.0f64) {
                let (decay, max) = (range / pr, scale * fr);
                let p = ProximityCharacteristic { range_m: range, decay_m: decay };
                prop_assert!(p.validate("").is_ok());
                let d = u * range;
                prop_assert!((p.distance_m(p.signal(d)) - d).abs() <= 1e-7 * range);
                let f = ForceCharacteristic { scale_n: scale, max_n: max };
                prop_assert!(f.validate("").is_ok());
                let x = u * max;
                prop_assert!((f.force_n(f.signal(x)) - x).abs() <= 1e-7 * max);
            }
        }
    }
}
