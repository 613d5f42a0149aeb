//! Smooth switching: the torque blend of intentional-contact paper eq. (10)-(11), with a corrected χ, and the
//! sigmoid fusion-weight shift of interactive-force-control paper Sec. 4.2.2.
//!
//! Intentional-contact paper eq. (11), `χ = (1 − tanh(δ_t (t − t_t)))/2`, gives `χ(t_t) = 1/2`: at the switch
//! instant the output jumps from `τ_{k-1}` to `(τ_{k-1} + τ_k)/2`, a step of half the torque
//! difference, which is what the blend is meant to avoid. We use
//!
//! ```text
//! χ(t) = 1 − tanh(δ_t (t − t_t))      (t ≥ t_t)
//! ```
//!
//! which is exactly 1 at `t_t` (no step: the first output is `τ_{k-1}`), decreases monotonically
//! to 0 with the same time constant `1/δ_t`, and has `|dχ/dt| = δ_t sech²(·) ≤ δ_t`.
//!
//! Per-cycle bound. With `τ(t) = τ_k(t) + χ(t) (τ_{k-1} − τ_k(t))` and a cycle `dt`:
//!
//! ```text
//! τ(t+dt) − τ(t) = (1 − χ(t+dt)) Δτ_k + (χ(t+dt) − χ(t)) (τ_{k-1} − τ_k(t))
//! ‖Δτ‖ ≤ ‖Δτ_k‖ + δ_t dt ‖τ_{k-1} − τ_k(t)‖
//! ```
//!
//! ([`step_bound`]): the blend adds at most `δ_t dt` times the torque gap per cycle to the change
//! the new arrangement itself makes.

/// `χ` of the corrected intentional-contact paper eq. (11) at `elapsed_s = t − t_t`: 1 for `elapsed ≤ 0`
/// (and NaN), then `1 − tanh(δ_t elapsed)`.
pub fn chi(smoothing_gain_per_s: f64, elapsed_s: f64) -> f64 {
    if elapsed_s > 0.0 {
        1.0 - (smoothing_gain_per_s * elapsed_s).tanh()
    } else {
        1.0
    }
}

/// The per-cycle bound on `‖τ(t+dt) − τ(t)‖` while blending (module docs): `‖Δτ_k‖ +
/// δ_t dt ‖τ_{k-1} − τ_k(t)‖`, any norm.
pub fn step_bound(smoothing_gain_per_s: f64, dt_s: f64, gap_norm: f64, dtau_k_norm: f64) -> f64 {
    dtau_k_norm + smoothing_gain_per_s * dt_s * gap_norm
}

/// Intentional-contact paper eq. (10): `τ = χ τ_{k-1} + (1 − χ) τ_k`, with `τ_{k-1}` the output torque held at
/// the switch. Storage is allocated once in [`TorqueBlender::new`].
#[derive(Debug, Clone)]
pub struct TorqueBlender {
    held: Vec<f64>,
    last: Vec<f64>,
    has_output: bool,
    blending: bool,
    switch_time_s: f64,
    gain_per_s: f64,
}

impl TorqueBlender {
    /// A blender for `n` joint torques; passes torques through until the first switch.
    pub fn new(n: usize) -> Self {
        TorqueBlender {
            held: vec![0.0; n],
            last: vec![0.0; n],
            has_output: false,
            blending: false,
            switch_time_s: f64::NAN,
            gain_per_s: 0.0,
        }
    }

    /// Number of torques.
    pub fn len(&self) -> usize {
        self.last.len()
    }

    /// `true` for a blender of zero torques.
    pub fn is_empty(&self) -> bool {
        self.last.is_empty()
    }

    /// Whether a blend is in progress.
    pub fn is_blending(&self) -> bool {
        self.blending
    }

    /// Starts a blend at `switch_time_s` (t_t) with gain δ_t: holds the last output as
    /// `τ_{k-1}` (the blended output, so a switch during a blend is continuous too). Before any
    /// output there is nothing to hold and no blend starts.
    pub fn start(&mut self, switch_time_s: f64, smoothing_gain_per_s: f64) {
        if !self.has_output {
            return;
        }
        self.held.copy_from_slice(&self.last);
        self.switch_time_s = switch_time_s;
        self.gain_per_s = smoothing_gain_per_s;
        self.blending = true;
    }

    /// Starts a blend when `arrangement`'s switch time differs from the current one (call once
    /// per cycle before [`Self::apply`]).
    pub fn sync(&mut self, arrangement: &super::types::Arrangement) {
        if arrangement.switch_time_s.to_bits() != self.switch_time_s.to_bits() {
            if self.has_output {
                self.start(arrangement.switch_time_s, arrangement.smoothing_gain_per_s);
            } else {
                self.switch_time_s = arrangement.switch_time_s;
            }
        }
    }

    /// Writes the blended torque for time `t_s` and the new arrangement's torque `tau_k` into
    /// `out`, and remembers it as the last output.
    ///
    /// # Panics
    /// When `tau_k` or `out` do not have [`Self::len`] elements.
    pub fn apply(&mut self, t_s: f64, tau_k: &[f64], out: &mut [f64]) {
        assert_eq!(tau_k.len(), self.last.len(), "tau_k length");
        assert_eq!(out.len(), self.last.len(), "out length");
        let c = if self.blending { chi(self.gain_per_s, t_s - self.switch_time_s) } else { 0.0 };
        if c <= f64::EPSILON {
            // Below one ulp of the held torque's weight the blend is over (snapping adds at
            // most EPSILON times the gap to one cycle's change).
            self.blending = false;
            out.copy_from_slice(tau_k);
        } else {
            for ((o, &h), &k) in out.iter_mut().zip(&self.held).zip(tau_k) {
                *o = c * h + (1.0 - c) * k;
            }
        }
        self.last.copy_from_slice(out);
        self.has_output = true;
    }
}

/// The interactive-force-control paper fusion weight shift: `w(t) = w_0 + (w_1 − w_0) s((t − t_t)/T)` with `s` a
/// logistic of steepness `gain` over `[0, 1]`, rescaled so that `s(0) = 0` and `s(1) = 1`
/// exactly (no step at either end) and monotonic in between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightShift {
    from: f64,
    to: f64,
    start_s: f64,
    duration_s: f64,
    gain: f64,
}

impl WeightShift {
    /// A weight resting at `w`.
    pub fn constant(w: f64) -> Self {
        WeightShift { from: w, to: w, start_s: 0.0, duration_s: 1.0, gain: 1.0 }
    }

    /// A shift from `from` to `to` starting at `start_s`, lasting `duration_s > 0`.
    pub fn new(from: f64, to: f64, start_s: f64, duration_s: f64, gain: f64) -> Self {
        WeightShift { from, to, start_s, duration_s, gain }
    }

    /// The target weight.
    pub fn target(&self) -> f64 {
        self.to
    }

    /// `w(t)`: `from` before the start, `to` after `start + duration`.
    pub fn at(&self, t_s: f64) -> f64 {
        let s = ((t_s - self.start_s) / self.duration_s).clamp(0.0, 1.0);
        if s.is_nan() || s <= 0.0 {
            return self.from;
        }
        if s >= 1.0 {
            return self.to;
        }
        let logistic = |x: f64| 1.0 / (1.0 + (-self.gain * (x - 0.5)).exp());
        let (l0, l1) = (logistic(0.0), logistic(1.0));
        let n = ((logistic(s) - l0) / (l1 - l0)).clamp(0.0, 1.0);
        self.from + (self.to - self.from) * n
    }
}
