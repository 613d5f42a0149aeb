//! Safety of a run, one definition for every scene (issue 17): a run is unsafe when it has a
//! non-finite command, a safe-stop cycle, an arm joint over its velocity limit, a contact force
//! above `ε_c` for more than [`CONTACT_EVENT_LIMIT_S`] in one event, or chatter (one
//! arrangement switch, the same `from → to`, more than [`CHATTER_MAX_REPEATS`] times within
//! [`CHATTER_WINDOW_S`]).
//! [`violations`] is the one function that says so.

use serde::Serialize;
use skin_core::supervisor::Mode;

use crate::outputs::record::{CycleRecord, RunRecord};

/// Longest a contact force may stay above its limit in one event \[s\] (issue 17: the robot must
/// relieve a hard contact within 0.5 s, whatever caused it).
pub const CONTACT_EVENT_LIMIT_S: f64 = 0.5;
/// Window of the chatter test \[s\].
pub const CHATTER_WINDOW_S: f64 = 10.0;
/// Most times one switch (the same `from → to`) may happen within [`CHATTER_WINDOW_S`]: a
/// reaction and one more (a second external hit, a retry); a third within 10 s is a limit
/// cycle, not a decision (the (b) ↔ (c) cycle against a fixed obstacle repeats (b) → (c)
/// every 0.5-1 s). Different switches in a row are no cycle: a whole Table I episode
/// (a) → (b) → (c) → (b) → (a) repeats none.
pub const CHATTER_MAX_REPEATS: usize = 2;
/// In the contact phase of a force scene the hand presses on purpose: a contact counts as over
/// its limit there only above the force reference plus this much \[N\] (the first-touch
/// overshoot bound of `outcome`).
pub const CONTACT_PHASE_MARGIN_N: f64 = 2.0;

/// The safety figures of a run (flattened into `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SafetyMetrics {
    /// Cycles with a non-finite joint or base velocity command.
    pub non_finite_command_cycles: usize,
    /// Cycles in which a measured arm joint speed exceeded its URDF velocity limit.
    pub joint_speed_over_limit_cycles: usize,
    /// Longest contact event over its limit: the longest run of consecutive cycles with the
    /// largest link contact force at or over `ε_c` (in the contact phase of a force scene: over
    /// the reference + [`CONTACT_PHASE_MARGIN_N`] when that is larger), pushes included (the
    /// robot must relieve a hard contact, whatever caused it) \[s\].
    pub longest_contact_over_eps_c_s: f64,
    /// The most times one arrangement switch (the same `from → to`) happened within any
    /// [`CHATTER_WINDOW_S`] window of the run.
    pub max_switch_repeats_in_window: usize,
    /// The most touches within [`TOUCH_WINDOW_S`] (see [`touch_times`]): a link bouncing on a surface, a
    /// contact vibration that stays mostly under `ε_c` and so escapes the figures above. Reported,
    /// not (yet) judged: docs/supervisor.md, "A hard contact that must last".
    pub max_touches_per_s: usize,
}

/// A touch starts when a link force that had fallen to [`TOUCH_LOW`] `ε_c` rises to
/// [`TOUCH_HIGH`] `ε_c`: from hardly touching to a real press.
pub const TOUCH_LOW: f64 = 0.1;
/// See [`TOUCH_LOW`].
pub const TOUCH_HIGH: f64 = 0.5;
/// The window of `max_touches_per_s` \[s\].
pub const TOUCH_WINDOW_S: f64 = 1.0;

/// What limits the safety figures compare with.
#[derive(Debug, Clone, PartialEq)]
pub struct SafetyLimits {
    /// `ε_c` \[N\].
    pub eps_c_n: f64,
    /// `(model joint index, URDF velocity limit)` of every arm joint \[rad/s or m/s\].
    pub joint_speed_limits: Vec<(usize, f64)>,
}

/// The contact force limit of cycle `c`: `ε_c`, or the reference + margin while a force scene's
/// hand presses on purpose.
fn contact_limit(c: &CycleRecord, eps_c_n: f64) -> f64 {
    if c.mode == Mode::Contact && c.force_reference_n.is_finite() {
        eps_c_n.max(c.force_reference_n + CONTACT_PHASE_MARGIN_N)
    } else {
        eps_c_n
    }
}

/// The longest run of consecutive cycles whose link contact force is at or over `limit(cycle)`
/// \[s\] (from the first such cycle to the first one below; a run still going at the end counts
/// to the last cycle).
pub fn longest_over(cycles: &[CycleRecord], limit: impl Fn(&CycleRecord) -> f64) -> f64 {
    let (mut longest, mut since) = (0.0_f64, None);
    for c in cycles {
        match (c.link_force_n >= limit(c), since) {
            (true, None) => since = Some(c.t_s),
            (false, Some(t0)) => {
                longest = longest.max(c.t_s - t0);
                since = None;
            }
            _ => {}
        }
    }
    if let (Some(t0), Some(last)) = (since, cycles.last()) {
        longest = longest.max(last.t_s - t0);
    }
    longest
}

/// The most switch times `times_s` (ascending) within any window of `window_s`.
pub fn max_in_window(times_s: &[f64], window_s: f64) -> usize {
    let mut start = 0;
    let mut most = 0;
    for (end, &t) in times_s.iter().enumerate() {
        while t - times_s[start] >= window_s {
            start += 1;
        }
        most = most.max(end + 1 - start);
    }
    most
}

/// The times at which a touch starts: the largest link force reaches `TOUCH_HIGH · ε_c` after
/// having been at most `TOUCH_LOW · ε_c` (the run starts released).
pub fn touch_times(cycles: &[CycleRecord], eps_c_n: f64) -> Vec<f64> {
    let mut released = true;
    let mut times = Vec::new();
    for c in cycles {
        if c.link_force_n <= TOUCH_LOW * eps_c_n {
            released = true;
        } else if released && c.link_force_n >= TOUCH_HIGH * eps_c_n {
            released = false;
            times.push(c.t_s);
        }
    }
    times
}

/// The safety figures of `record`.
pub fn compute(record: &RunRecord, limits: &SafetyLimits) -> SafetyMetrics {
    let cycles = &record.cycles;
    let finite = |c: &CycleRecord| c.joint_velocities.iter().chain(&c.base_twist).all(|v| v.is_finite());
    let over_speed = |c: &CycleRecord| {
        limits.joint_speed_limits.iter().any(|&(j, vmax)| c.qd.get(j).is_some_and(|v| v.abs() > vmax))
    };
    let repeats = |from: Mode, to: Mode| {
        let times: Vec<f64> = record.switches.iter().filter(|s| (s.from, s.to) == (from, to)).map(|s| s.t_s).collect();
        max_in_window(&times, CHATTER_WINDOW_S)
    };
    let pairs = Mode::ALL.iter().flat_map(|&a| Mode::ALL.iter().map(move |&b| (a, b)));
    SafetyMetrics {
        non_finite_command_cycles: cycles.iter().filter(|c| !finite(c)).count(),
        joint_speed_over_limit_cycles: cycles.iter().filter(|c| over_speed(c)).count(),
        longest_contact_over_eps_c_s: longest_over(cycles, |c| contact_limit(c, limits.eps_c_n)),
        max_switch_repeats_in_window: pairs.map(|(a, b)| repeats(a, b)).max().unwrap_or(0),
        max_touches_per_s: max_in_window(&touch_times(cycles, limits.eps_c_n), TOUCH_WINDOW_S),
    }
}

/// Every safety violation of a run (empty: safe), each a readable line: `safety` its figures,
/// `safe_stop_cycles` the controller's faulted cycles. A non-finite figure is a violation (a
/// figure that could not be measured proves nothing).
pub fn violations(safety: &SafetyMetrics, safe_stop_cycles: usize) -> Vec<String> {
    let mut out = Vec::new();
    if safety.non_finite_command_cycles > 0 {
        out.push(format!("{} cycles with a non-finite command", safety.non_finite_command_cycles));
    }
    if safe_stop_cycles > 0 {
        out.push(format!("{safe_stop_cycles} safe-stop cycles"));
    }
    if safety.joint_speed_over_limit_cycles > 0 {
        out.push(format!("{} cycles with a joint over its velocity limit", safety.joint_speed_over_limit_cycles));
    }
    let longest = safety.longest_contact_over_eps_c_s;
    if longest.is_nan() || longest > CONTACT_EVENT_LIMIT_S {
        out.push(format!("contact over eps_c for {longest:.3} s in one event (limit {CONTACT_EVENT_LIMIT_S} s)"));
    }
    if safety.max_switch_repeats_in_window > CHATTER_MAX_REPEATS {
        out.push(format!(
            "chatter: one arrangement switch {} times within {CHATTER_WINDOW_S} s (at most {CHATTER_MAX_REPEATS})",
            safety.max_switch_repeats_in_window
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_in_a_window() {
        // (b) -> (c) against the fixed obstacle (before issue 17's blocked hold): 3 in 2 s.
        assert_eq!(max_in_window(&[9.75, 10.66, 11.72], CHATTER_WINDOW_S), 3);
        assert_eq!(max_in_window(&[0.0, 9.9, 10.0, 19.95], CHATTER_WINDOW_S), 2);
        // Switches 10 s apart or more are in different windows.
        assert_eq!(max_in_window(&[0.0, 10.0, 20.0, 30.0, 40.0], CHATTER_WINDOW_S), 1);
        assert_eq!(max_in_window(&[], CHATTER_WINDOW_S), 0);
    }

    #[test]
    fn a_touch_is_a_rise_from_hardly_touching_to_a_press() {
        // eps_c 5 N: a touch from <= 0.5 N to >= 2.5 N; a press that only wavers above 0.5 N is
        // one touch, and a rise that stays under 2.5 N (2.4 N at 0.8 s) none
        let forces = [0.0, 3.0, 1.0, 4.0, 0.4, 2.6, 2.0, 0.5, 2.4, 0.0, 6.0];
        let cycles: Vec<CycleRecord> =
            forces.iter().enumerate().map(|(i, &f)| CycleRecord::at_rest(i as f64 * 0.1, f)).collect();
        let times = touch_times(&cycles, 5.0);
        assert_eq!(times.len(), 3, "{times:?}");
        assert!((times[1] - 0.5).abs() < 1e-12 && (times[2] - 1.0).abs() < 1e-12, "{times:?}");
        assert_eq!(max_in_window(&times, 1.0), 3, "0.1, 0.5 and 1.0 s: within one second");
        assert_eq!(max_in_window(&times[..2], 0.3), 1, "0.4 s apart");
    }

    #[test]
    fn every_kind_of_violation_is_reported_and_nan_is_one() {
        let safe = SafetyMetrics {
            non_finite_command_cycles: 0,
            joint_speed_over_limit_cycles: 0,
            longest_contact_over_eps_c_s: 0.5,
            max_switch_repeats_in_window: CHATTER_MAX_REPEATS,
            max_touches_per_s: 50,
        };
        assert!(violations(&safe, 0).is_empty());
        assert_eq!(violations(&safe, 1).len(), 1);
        for unsafe_ in [
            SafetyMetrics { non_finite_command_cycles: 1, ..safe.clone() },
            SafetyMetrics { joint_speed_over_limit_cycles: 3, ..safe.clone() },
            SafetyMetrics { longest_contact_over_eps_c_s: 0.51, ..safe.clone() },
            SafetyMetrics { longest_contact_over_eps_c_s: f64::NAN, ..safe.clone() },
            SafetyMetrics { max_switch_repeats_in_window: CHATTER_MAX_REPEATS + 1, ..safe.clone() },
        ] {
            assert_eq!(violations(&unsafe_, 0).len(), 1, "{unsafe_:?}");
        }
    }
}
