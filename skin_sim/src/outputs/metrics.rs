//! Numbers of a run (`metrics.json`): always the run's cost and the arrangement switches; goal and
//! contact-force figures for scenes with goals (intentional-contact paper); force-tracking figures for scenes
//! with force references (interactive-force-control paper Table 3).

use serde::Serialize;
use skin_core::model::is_base_joint_name;
use skin_core::supervisor::Mode;

use crate::outputs::record::{CycleRecord, RunRecord};
use crate::outputs::safety::{self, SafetyLimits, SafetyMetrics};
use crate::scene::Scene;

/// An interaction's effect on the force outlasts it: cycles this long after one count as "with
/// interaction" too \[s\].
pub const INTERACTION_TAIL_S: f64 = 2.0;
/// The force-tracking error is taken once the hand has been in contact this long in the contact
/// phase \[s\] (from its first touch, not from the phase switch: the approach in between is no
/// tracking).
pub const CONTACT_SETTLE_S: f64 = 3.0;
/// The hard-contact reaction must relieve a push within this time after it ends \[s\] (the
/// issue's outcome).
pub const RECOVERY_LIMIT_S: f64 = 0.5;
/// The hand force must reach its reference within this time after the first touch \[s\]: the
/// rise the from-reach RMS leaves out is bounded (measured 0.46-1.85 s with the approach bound).
pub const FORCE_RISE_LIMIT_S: f64 = 2.0;
/// An object tilted further than this from its start orientation toppled \[deg\].
pub const TOPPLED_DEG: f64 = 45.0;

/// A run's wall-clock time by part \[s\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopTime {
    /// In `mj_step`.
    pub physics_s: f64,
    /// In the simulated skin and LIDAR.
    pub sensors_s: f64,
    /// In `Controller::update` (a graph run: as the controller node reported it).
    pub controller_s: f64,
    /// The rest: the recording and the view (a graph run: also the wait for the controller).
    pub other_s: f64,
}

impl LoopTime {
    fn of(record: &RunRecord) -> LoopTime {
        let physics_s = record.busy.physics.as_secs_f64();
        let sensors_s = record.busy.sensors.as_secs_f64();
        let controller_s = record.cycles.iter().map(|c| c.compute_us).sum::<f64>() * 1e-6;
        let other_s = record.wall_time_s - physics_s - sensors_s - controller_s;
        LoopTime { physics_s, sensors_s, controller_s, other_s }
    }
}

/// One arrangement switch, as written to `metrics.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SwitchEntry {
    /// Time \[s\].
    pub t: f64,
    /// Mode before (`config/supervisor.yaml` arrangement name).
    pub from: &'static str,
    /// Mode after.
    pub to: &'static str,
}

/// `metrics.json`. Optional groups are present only for scenes they apply to; NaN is written as
/// `null` (e.g. no cycle in a window).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Metrics {
    /// Scenario (or scene) name.
    pub scenario: String,
    /// Simulated time / wall-clock time.
    pub realtime_factor: f64,
    /// Simulated time \[s\].
    pub sim_duration_s: f64,
    /// Largest measured arm joint speed \[rad/s\] (base joints excluded).
    pub max_joint_speed_rad_s: f64,
    /// Median wall-clock time of `Controller::update` \[µs\].
    pub control_cycle_us_p50: f64,
    /// Where the run's wall-clock time went.
    pub loop_time_s: LoopTime,
    /// The real-time factor the physics alone allows: simulated time / time in `mj_step`.
    pub realtime_factor_physics_bound: f64,
    /// Arrangement switches.
    pub arrangement_switches: Vec<SwitchEntry>,
    /// Cycles that were safe-stop steps (a fault of the controller or of its inputs).
    pub faulted_cycles: usize,
    /// Every scene: the figures of the shared safety definition (`crate::outputs::safety`).
    #[serde(flatten)]
    pub safety: SafetyMetrics,
    /// Intentional-contact paper figures (scenes with goals).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub goal: Option<GoalMetrics>,
    /// Interactive-force-control paper figures (scenes with force references).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub force: Option<ForceMetrics>,
    /// Scenes with neither goals nor force references (interactive-force-control paper Exp. 2's pre-contact approach
    /// and guidance): nothing of the robot may press on the environment.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub contact_free: Option<ContactFreeMetrics>,
}

/// A scene in which the robot should touch nothing (interactive-force-control paper Exp. 2): its largest contact
/// against `ε_c`, how well the hand keeps `d_p,d` ahead of the surface, and how far the user's
/// touches on the arm guide it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactFreeMetrics {
    /// Largest physical contact force of the environment on one robot link, whole run \[N\].
    pub max_link_contact_n: f64,
    /// `ε_c` of the supervisor \[N\].
    pub eps_c_n: f64,
    /// `d_p,d` of the hand distance task \[m\].
    pub hand_distance_desired_m: f64,
    /// RMS of the hand's distance to the surface ahead (MuJoCo) − `d_p,d`, from the first cycle
    /// within [`DISTANCE_SETTLED_M`] of it to the end \[m\] (null: never there); a cycle with
    /// nothing ahead counts with the sensing range as its distance.
    pub hand_distance_rms_error_m: f64,
    /// Largest displacement of the hand over one touch on the arm (from the touch's start to
    /// [`INTERACTION_TAIL_S`] after its end) \[m\] (null: no touch).
    pub hand_guided_m: f64,
}

/// The hand counts as arrived at `d_p,d` once it is this close to it \[m\].
pub const DISTANCE_SETTLED_M: f64 = 0.005;

/// Intentional-contact paper: the goal and the contact forces against `ε_c`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GoalMetrics {
    /// Final goal error within the supervisor's goal tolerance.
    pub goal_reached: bool,
    /// Goal error at the end of the run \[m\].
    pub goal_error_m: f64,
    /// Goal tolerance of the supervisor \[m\].
    pub goal_tolerance_m: f64,
    /// Goal error when the first push on an object starts \[m\] (null: no push): a goal reached
    /// only after it was reached through the push, not by the controller.
    pub goal_error_before_pushes_m: f64,
    /// Largest physical contact force on one link during intentional contact (Table I (b)),
    /// outside the pushes and their recovery allowance (a push starting in (b) is the push's) \[N\].
    pub max_contact_force_intentional_n: f64,
    /// Largest physical contact force on one link outside the pushes (and their recovery
    /// allowance) \[N\].
    pub max_contact_force_n: f64,
    /// `ε_c` of the supervisor \[N\].
    pub eps_c_n: f64,
    /// Per push on an object: time from the push's end until the contact force is below `ε_c`
    /// for good (0 if it already is) \[s\]; the largest over the pushes (null: no push).
    pub hard_contact_recovery_s: f64,
    /// How the run ended: `reached` (final goal error within the tolerance), `blocked` (the
    /// supervisor gave up a push that reached `ε_c` and holds the arm in (a): a fixed or too
    /// heavy obstacle) or `not_reached`.
    pub outcome: &'static str,
    /// When the supervisor first held the arm as blocked \[s\] (null: never).
    pub blocked_at_s: f64,
    /// Largest tilt of a movable object from its start orientation over the run \[deg\]: over
    /// [`TOPPLED_DEG`] an obstacle toppled, which a planar scene does not model.
    pub object_tilt_max_deg: f64,
}

impl GoalMetrics {
    /// Whether the goal was within the tolerance when the first push on an object started (true
    /// without pushes).
    pub fn reached_before_pushes(&self) -> bool {
        self.goal_error_before_pushes_m.is_nan() || self.goal_error_before_pushes_m <= self.goal_tolerance_m
    }
}

/// Interactive-force-control paper Table 3: force tracking in the contact phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForceMetrics {
    /// Mean measured hand force over the settled contact phase \[N\].
    pub force_mean_n: f64,
    /// RMS of measured − reference force without interaction, from [`CONTACT_SETTLE_S`] after
    /// the first touch (the settled figure; the checks use the from-touch one) \[N\].
    pub rms_force_error_n: f64,
    /// RMS of measured − reference force during interactions (and their tail), from
    /// [`CONTACT_SETTLE_S`] after the first touch \[N\] (null: none).
    pub rms_force_error_interaction_n: f64,
    /// RMS of measured − reference force over the whole contact phase from the hand's first
    /// touch, interactions (and their tail) excluded, no settle window: what interactive-force-control paper Table 3
    /// reports "throughout the experiment" \[N\].
    pub rms_force_error_from_touch_n: f64,
    /// RMS of measured − reference force without interaction from the first cycle at which the
    /// force reached its reference after the touch (the rise excluded, its overshoot and every
    /// cycle after it included) \[N\]: the Table 3 checks use this one (docs/scenarios.md).
    pub rms_force_error_from_reach_n: f64,
    /// Time from the first touch until the force first reaches its reference \[s\] (null:
    /// never).
    pub force_rise_s: f64,
    /// Largest measured hand force of the first touch's transient \[N\] (see
    /// [`first_contact_peak`]; null: no touch).
    pub first_contact_peak_force_n: f64,
    /// The force reference at that peak \[N\].
    pub first_contact_reference_n: f64,
    /// Cycles behind each settled RMS (without, with).
    pub rms_cycles: [usize; 2],
    /// Fraction of settled contact-phase cycles with the hand out of contact.
    pub contact_lost_fraction: f64,
}

/// Supervisor thresholds and robot limits the metrics compare with.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// `ε_c` \[N\].
    pub eps_c_n: f64,
    /// Goal tolerance \[m\].
    pub goal_tolerance_m: f64,
    /// `d_p,d` of the hand distance task \[m\].
    pub hand_distance_desired_m: f64,
    /// Arm joint velocity limits of the safety figures.
    pub safety: SafetyLimits,
}

fn rms(values: impl Iterator<Item = f64>) -> (f64, usize) {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    ((sum / n as f64).sqrt(), n)
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The metrics of `record`, a run of `scene`.
pub fn compute(record: &RunRecord, scene: &Scene, limits: &Limits) -> Metrics {
    let cycles = &record.cycles;
    let arm: Vec<usize> =
        (0..record.joint_names.len()).filter(|&j| !is_base_joint_name(&record.joint_names[j])).collect();
    let max_joint_speed = cycles.iter().flat_map(|c| arm.iter().map(move |&j| c.qd[j].abs())).fold(0.0, f64::max);
    let sim = record.sim_duration_s();
    Metrics {
        scenario: record.name.clone(),
        realtime_factor: sim / record.wall_time_s,
        sim_duration_s: sim,
        max_joint_speed_rad_s: max_joint_speed,
        control_cycle_us_p50: median(cycles.iter().map(|c| c.compute_us).collect()),
        loop_time_s: LoopTime::of(record),
        realtime_factor_physics_bound: sim / record.busy.physics.as_secs_f64(),
        arrangement_switches: record
            .switches
            .iter()
            .map(|s| SwitchEntry { t: s.t_s, from: s.from.name(), to: s.to.name() })
            .collect(),
        faulted_cycles: cycles.iter().filter(|c| c.fault.is_some()).count(),
        safety: safety::compute(record, &limits.safety),
        goal: (!scene.spec.goals.is_empty()).then(|| goal_metrics(cycles, &record.object_pushes, limits)),
        force: (!scene.spec.force_references.is_empty()).then(|| force_metrics(cycles)),
        contact_free: (scene.spec.goals.is_empty() && scene.spec.force_references.is_empty())
            .then(|| contact_free_metrics(cycles, scene, limits)),
    }
}

fn contact_free_metrics(cycles: &[CycleRecord], scene: &Scene, limits: &Limits) -> ContactFreeMetrics {
    let desired = limits.hand_distance_desired_m;
    let range = scene.skin.as_ref().map_or(f64::INFINITY, |s| s.params.proximity.range_m);
    let error = |c: &CycleRecord| c.hand_distance_m.min(range) - desired;
    let settled = cycles.iter().position(|c| error(c).abs() < DISTANCE_SETTLED_M);
    let (rms_error, _) = match settled {
        Some(k) => rms(cycles[k..].iter().map(error)),
        None => (f64::NAN, 0),
    };
    let at = |t: f64| cycles.iter().find(|c| c.t_s >= t).or(cycles.last()).map(|c| c.hand_position_m);
    let guided = scene
        .spec
        .pushes
        .iter()
        .filter(|p| p.link.is_some())
        .filter_map(|p| Some((at(p.start_s)?, at(p.end_s + INTERACTION_TAIL_S)?)))
        .map(|(a, b)| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt())
        .fold(f64::NAN, f64::max);
    ContactFreeMetrics {
        max_link_contact_n: max_link_force(cycles, |_| true),
        eps_c_n: limits.eps_c_n,
        hand_distance_desired_m: desired,
        hand_distance_rms_error_m: rms_error,
        hand_guided_m: guided,
    }
}

/// The largest physical contact force on one link over the cycles that `keep` selects \[N\].
fn max_link_force(cycles: &[CycleRecord], keep: impl Fn(&CycleRecord) -> bool) -> f64 {
    cycles.iter().filter(|c| keep(c)).map(|c| c.link_force_n).fold(0.0, f64::max)
}

/// `pushes`: the scene's pushes on objects, as the record keeps them.
fn goal_metrics(cycles: &[CycleRecord], pushes: &[(f64, f64)], limits: &Limits) -> GoalMetrics {
    let eps = limits.eps_c_n;
    let excused = |t: f64| pushes.iter().any(|&(a, b)| t >= a && t < b + RECOVERY_LIMIT_S);
    let recovery = pushes
        .iter()
        .map(|&(_, end)| {
            // The last cycle at or over eps_c after the push ended; recovered right after it.
            let last_over = cycles.iter().rev().find(|c| c.t_s >= end && c.link_force_n >= eps);
            last_over.map_or(0.0, |c| c.t_s - end)
        })
        .fold(f64::NAN, f64::max);
    let error = cycles.last().map_or(f64::NAN, |c| c.signals.goal_error_m);
    let first_push = pushes.iter().map(|&(a, _)| a).fold(f64::INFINITY, f64::min);
    let before_pushes = cycles.iter().take_while(|c| c.t_s < first_push).last();
    GoalMetrics {
        goal_reached: error <= limits.goal_tolerance_m,
        goal_error_m: error,
        goal_tolerance_m: limits.goal_tolerance_m,
        goal_error_before_pushes_m: match before_pushes {
            Some(c) if first_push.is_finite() => c.signals.goal_error_m,
            _ => f64::NAN,
        },
        max_contact_force_intentional_n: max_link_force(cycles, |c| {
            c.mode == Mode::IntentionalContact && !excused(c.t_s)
        }),
        max_contact_force_n: max_link_force(cycles, |c| !excused(c.t_s)),
        eps_c_n: eps,
        hard_contact_recovery_s: recovery,
        outcome: match cycles.last() {
            _ if error <= limits.goal_tolerance_m => "reached",
            Some(c) if c.blocked.is_some() => "blocked",
            _ => "not_reached",
        },
        blocked_at_s: cycles.iter().find(|c| c.blocked.is_some()).map_or(f64::NAN, |c| c.t_s),
        object_tilt_max_deg: cycles.iter().map(|c| c.object_tilt_deg).fold(0.0, f64::max),
    }
}

fn force_metrics(cycles: &[CycleRecord]) -> ForceMetrics {
    let touched = |c: &&CycleRecord| c.mode == Mode::Contact && c.hand_force_n > 0.0;
    let contact_from = cycles.iter().find(touched).map_or(f64::INFINITY, |c| c.t_s);
    // The contact phase from the first touch: (cycle, with interaction, settled); interaction
    // windows are extended by their tail.
    let mut last_interaction = f64::NEG_INFINITY;
    let mut phase = Vec::new();
    for c in cycles {
        if c.interaction {
            last_interaction = c.t_s;
        }
        if c.mode == Mode::Contact && c.t_s >= contact_from && c.force_reference_n.is_finite() {
            let with = c.t_s - last_interaction <= INTERACTION_TAIL_S;
            phase.push((c, with, c.t_s >= contact_from + CONTACT_SETTLE_S));
        }
    }
    let errors = |with: bool, settled_only: bool| {
        phase
            .iter()
            .filter(move |&&(_, w, s)| w == with && (s || !settled_only))
            .map(|(c, _, _)| c.hand_force_n - c.force_reference_n)
    };
    let (without, n0) = rms(errors(false, true));
    let (during, n1) = rms(errors(true, true));
    let (from_touch, _) = rms(errors(false, false));
    let reached = phase.iter().find(|p| p.0.hand_force_n >= p.0.force_reference_n).map_or(f64::NAN, |p| p.0.t_s);
    let (from_reach, _) =
        rms(phase.iter().filter(|p| !p.1 && p.0.t_s >= reached).map(|p| p.0.hand_force_n - p.0.force_reference_n));
    let settled: Vec<&CycleRecord> = phase.iter().filter(|p| p.2).map(|p| p.0).collect();
    let n = settled.len() as f64;
    let touch: Vec<&CycleRecord> = phase.iter().map(|p| p.0).collect();
    let (peak, peak_reference) = first_contact_peak(&touch);
    ForceMetrics {
        force_mean_n: settled.iter().map(|c| c.hand_force_n).sum::<f64>() / n,
        rms_force_error_n: without,
        rms_force_error_interaction_n: during,
        rms_force_error_from_touch_n: from_touch,
        rms_force_error_from_reach_n: from_reach,
        force_rise_s: reached - contact_from,
        first_contact_peak_force_n: peak,
        first_contact_reference_n: peak_reference,
        rms_cycles: [n0, n1],
        contact_lost_fraction: settled.iter().filter(|c| c.hand_force_n <= 0.0).count() as f64 / n,
    }
}

/// The peak of the first touch (`contact`: the contact-phase cycles from the first touch on):
/// the largest hand force, and the reference at it, from the first touch until the force has
/// reached its reference and come back to it while still touching (the end of the first
/// overshoot; a bounce off the surface keeps the transient going). A force that never reaches
/// its reference makes the whole contact phase the transient. `(NaN, NaN)`: no touch.
pub fn first_contact_peak(contact: &[&CycleRecord]) -> (f64, f64) {
    let mut peak = (f64::NAN, f64::NAN);
    let mut reached = false;
    for c in contact {
        if peak.0.is_nan() || c.hand_force_n > peak.0 {
            peak = (c.hand_force_n, c.force_reference_n);
        }
        let over = c.hand_force_n > c.force_reference_n;
        if reached && !over && c.hand_force_n > 0.0 {
            break;
        }
        reached |= over;
    }
    peak
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cycle(t_s: f64, force: f64, reference: f64, interaction: bool) -> CycleRecord {
        CycleRecord { force_reference_n: reference, interaction, ..CycleRecord::at_rest(t_s, force) }
    }

    /// An impact at the touch, then tracking: the peak is the impact's, the from-touch RMS sees
    /// it while the settled one (3 s after the touch) does not, and an interaction is left out.
    #[test]
    fn from_touch_figures_see_the_impact_the_settled_window_hides() {
        let mut cycles = vec![cycle(0.0, 0.0, 6.0, false), cycle(0.1, 0.0, 6.0, false)];
        // touch, impact to 18 N, back to the reference
        for (k, f) in [3.0, 10.0, 18.0, 12.0, 7.0, 5.9, 6.0].iter().enumerate() {
            cycles.push(cycle(0.2 + 0.1 * k as f64, *f, 6.0, false));
        }
        // a bounce later on is not the first touch's
        for k in 0..60 {
            let t = 1.0 + 0.1 * k as f64;
            let f = if k == 40 { 30.0 } else { 6.0 };
            cycles.push(cycle(t, f, 6.0, k == 40));
        }
        let m = force_metrics(&cycles);
        assert_eq!((m.first_contact_peak_force_n, m.first_contact_reference_n), (18.0, 6.0));
        assert!(m.rms_force_error_from_touch_n > 1.0, "{m:?}");
        assert!(m.rms_force_error_n < 1e-12, "the settled window starts after the impact: {m:?}");
        assert!((m.force_rise_s - 0.1).abs() < 1e-9, "touch (3 N) at 0.2 s, 10 N >= 6 N at 0.3 s: {m:?}");
        assert!(m.rms_force_error_from_reach_n > 1.0, "the overshoot counts from reaching: {m:?}");
        assert!(m.rms_force_error_interaction_n > 0.0);
    }

    #[test]
    fn longest_event_over_a_limit_spans_consecutive_cycles() {
        let forces = [0.0, 6.0, 6.0, 6.0, 1.0, 6.0, 0.0, 6.0, 6.0];
        let cycles: Vec<CycleRecord> =
            forces.iter().enumerate().map(|(k, &f)| cycle(0.1 * k as f64, f, 0.0, false)).collect();
        assert!((safety::longest_over(&cycles, |_| 5.0) - 0.3).abs() < 1e-9);
        assert_eq!(safety::longest_over(&cycles[..1], |_| 5.0), 0.0);
    }
}
