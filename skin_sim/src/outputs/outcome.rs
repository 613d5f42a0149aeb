//! The outcome checks of a run (what the scenario must show): each a named pass/fail with the measured
//! number and its limit.

use crate::outputs::metrics::{Metrics, FORCE_RISE_LIMIT_S, RECOVERY_LIMIT_S};
use crate::outputs::safety;
use crate::scene::spec::ExpectSpec;

/// One check.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What is checked.
    pub name: &'static str,
    /// Measured value and limit, readable.
    pub detail: String,
    /// Whether it holds.
    pub passed: bool,
}

fn at_most(name: &'static str, value: f64, limit: f64, unit: &str) -> Check {
    Check {
        name,
        detail: format!("{value:.3} {unit} (limit {limit} {unit})"),
        // NaN (nothing measured) fails: a check must see data.
        passed: value <= limit,
    }
}

fn at_least(name: &'static str, value: f64, limit: f64, unit: &str) -> Check {
    Check { name, detail: format!("{value:.3} {unit} (at least {limit} {unit})"), passed: value >= limit }
}

/// Largest RMS error of the hand's distance to the surface against `d_p,d` in a guidance scene
/// \[m\] (a third of the paper's 3 cm).
pub const DISTANCE_RMS_LIMIT_M: f64 = 0.01;
/// Smallest hand displacement one touch on the arm must cause in a guidance scene \[m\]: the
/// paper's user moves the hand by tens of centimetres (Fig. 6c).
pub const GUIDED_MIN_M: f64 = 0.05;

/// Largest overshoot of the hand force over its reference at the first touch \[N\]: the
/// contact phase starts without an impact.
pub const FIRST_CONTACT_OVERSHOOT_N: f64 = 2.0;

/// The checks of a run. Every run: safe ([`safety::violations`]). What the scene declares
/// (`expect`; `None`: a scene with goals expects the supervisor's goal tolerance and `ε_c`):
/// the goal reached (and before the first push on an object, when there is one), every contact
/// at most `ε_c` outside the pushes and the pushes relieved within [`RECOVERY_LIMIT_S`], a peak
/// contact force, the RMS force errors of Table 3; with `safety`, a run that ends `blocked` (the
/// push could not succeed) passes on safety and the peak alone. Every scene of its kind:
/// force scenes the first touch, the rise and a finite from-touch RMS; scenes with neither goals
/// nor force references (interactive-force-control paper Exp. 2) no link contact above `ε_c`,
/// the hand at `d_p,d` (when it is not 0) and moved by the touches on the arm (when there are
/// some). A check whose figure is not finite fails.
pub fn checks(m: &Metrics, expect: Option<&ExpectSpec>) -> Vec<Check> {
    let violations = safety::violations(&m.safety, m.faulted_cycles);
    let mut out = vec![Check {
        name: "safe (no non-finite command, safe-stop, joint over its velocity limit, contact over eps_c > 0.5 s, chatter)",
        detail: if violations.is_empty() { "none".into() } else { violations.join("; ") },
        passed: violations.is_empty(),
    }];
    if let Some(g) = &m.goal {
        let defaults = ExpectSpec {
            goal_tolerance_m: Some(g.goal_tolerance_m),
            eps_c_n: Some(g.eps_c_n),
            ..ExpectSpec::default()
        };
        let expect = expect.unwrap_or(&defaults);
        let blocked = g.outcome == "blocked";
        if expect.safety {
            out.push(Check {
                name: "goal reached or blocked (the goal may be unreachable)",
                detail: g.outcome.to_string(),
                passed: g.outcome != "not_reached",
            });
        }
        if let Some(peak) = expect.max_contact_force_n {
            out.push(at_most("peak contact force (outside pushes)", g.max_contact_force_n, peak, "N"));
        }
        // A blocked run of a scene that may be blocked is judged on safety (and the peak) alone.
        if !(expect.safety && blocked) {
            if let Some(tol) = expect.goal_tolerance_m {
                out.push(at_most("goal reached", g.goal_error_m, tol, "m"));
                if !g.goal_error_before_pushes_m.is_nan() {
                    // by the controller, not by a push that moved the obstacle out of the way
                    out.push(at_most("goal reached before the first push", g.goal_error_before_pushes_m, tol, "m"));
                }
            }
            if let Some(eps) = expect.eps_c_n {
                out.push(at_most("contact force <= eps_c (outside pushes)", g.max_contact_force_n, eps, "N"));
                if !g.hard_contact_recovery_s.is_nan() {
                    out.push(at_most("hard push relieved", g.hard_contact_recovery_s, RECOVERY_LIMIT_S, "s"));
                }
            }
        }
    }
    if let Some(c) = &m.contact_free {
        out.push(at_most("no link presses on anything (<= eps_c)", c.max_link_contact_n, c.eps_c_n, "N"));
        if c.hand_distance_desired_m > 0.0 {
            out.push(at_most("hand keeps d_p,d (RMS error)", c.hand_distance_rms_error_m, DISTANCE_RMS_LIMIT_M, "m"));
        }
        if !c.hand_guided_m.is_nan() {
            out.push(at_least("touches on the arm guide the hand", c.hand_guided_m, GUIDED_MIN_M, "m"));
        }
    }
    if let Some(f) = &m.force {
        out.push(at_most(
            "first touch without impact (peak - reference)",
            f.first_contact_peak_force_n - f.first_contact_reference_n,
            FIRST_CONTACT_OVERSHOOT_N,
            "N",
        ));
        out.push(at_most("force reaches its reference after the touch", f.force_rise_s, FORCE_RISE_LIMIT_S, "s"));
        // Any force scene, targets or not: tracking must have been measured (NaN: never touched).
        out.push(Check {
            name: "force tracked from the touch (finite RMS)",
            detail: format!("{:.3} N", f.rms_force_error_from_touch_n),
            passed: f.rms_force_error_from_touch_n.is_finite(),
        });
    }
    if let (Some(f), Some(t)) = (&m.force, expect.and_then(|e| e.force_targets)) {
        out.push(at_most(
            "RMS force error w/o interaction (from reaching the reference)",
            f.rms_force_error_from_reach_n,
            t.rms_without_n,
            "N",
        ));
        out.push(at_most("RMS force error w/ interaction", f.rms_force_error_interaction_n, t.rms_with_n, "N"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outputs::metrics::{GoalMetrics, LoopTime};
    use crate::outputs::safety::SafetyMetrics;

    fn goal_run(outcome: &'static str, error_m: f64, peak_n: f64) -> Metrics {
        Metrics {
            scenario: "x".into(),
            realtime_factor: 1.0,
            sim_duration_s: 20.0,
            max_joint_speed_rad_s: 0.1,
            control_cycle_us_p50: 4.0,
            loop_time_s: LoopTime { physics_s: 0.1, sensors_s: 0.05, controller_s: 0.02, other_s: 0.03 },
            realtime_factor_physics_bound: 200.0,
            arrangement_switches: vec![],
            faulted_cycles: 0,
            safety: SafetyMetrics {
                non_finite_command_cycles: 0,
                joint_speed_over_limit_cycles: 0,
                longest_contact_over_eps_c_s: 0.01,
                max_switch_repeats_in_window: 1,
                max_touches_per_s: 1,
            },
            goal: Some(GoalMetrics {
                goal_reached: outcome == "reached",
                goal_error_m: error_m,
                goal_tolerance_m: 0.01,
                goal_error_before_pushes_m: f64::NAN,
                max_contact_force_intentional_n: 3.0,
                max_contact_force_n: peak_n,
                eps_c_n: 5.0,
                hard_contact_recovery_s: f64::NAN,
                outcome,
                blocked_at_s: f64::NAN,
                object_tilt_max_deg: 0.0,
            }),
            force: None,
            contact_free: None,
        }
    }

    fn failed(m: &Metrics, e: Option<&ExpectSpec>) -> Vec<&'static str> {
        checks(m, e).into_iter().filter(|c| !c.passed).map(|c| c.name).collect()
    }

    /// `safety: true` lets a blocked run pass on safety and the declared peak, never a run that
    /// simply did not get there; without it a blocked run fails its goal.
    #[test]
    fn an_unreachable_goal_passes_blocked_and_safe_only() {
        let declared = ExpectSpec { goal_tolerance_m: Some(0.01), eps_c_n: Some(5.0), ..ExpectSpec::default() };
        let unreachable = ExpectSpec { safety: true, max_contact_force_n: Some(15.0), ..declared };
        let blocked = goal_run("blocked", 0.19, 8.1);
        assert!(failed(&blocked, Some(&unreachable)).is_empty());
        assert_eq!(failed(&blocked, Some(&declared)), ["goal reached", "contact force <= eps_c (outside pushes)"]);
        assert_eq!(failed(&blocked, None), failed(&blocked, Some(&declared)), "the defaults are the supervisor's");
        let stopped = goal_run("not_reached", 0.19, 3.0);
        assert_eq!(
            failed(&stopped, Some(&unreachable)),
            ["goal reached or blocked (the goal may be unreachable)", "goal reached"]
        );
        assert_eq!(
            failed(&goal_run("blocked", 0.19, 46.6), Some(&unreachable)),
            ["peak contact force (outside pushes)"]
        );
        let mut chattering = goal_run("blocked", 0.19, 8.1);
        chattering.safety.max_switch_repeats_in_window = 3;
        assert_eq!(failed(&chattering, Some(&unreachable)).len(), 1);
        assert!(failed(&goal_run("reached", f64::NAN, 1.0), Some(&declared)).contains(&"goal reached"), "NaN fails");
    }

    /// A goal that a push on the obstacle cleared the way to fails; one reached before it, or in
    /// a scene without pushes, passes.
    #[test]
    fn a_goal_reached_only_after_the_push_fails() {
        let mut run = goal_run("reached", 0.0, 1.0);
        assert!(failed(&run, None).is_empty(), "no push: nothing to check");
        for (before_m, fails) in [(0.005, false), (0.09, true)] {
            run.goal.as_mut().unwrap().goal_error_before_pushes_m = before_m;
            assert_eq!(failed(&run, None).contains(&"goal reached before the first push"), fails, "{before_m} m");
        }
    }
}
