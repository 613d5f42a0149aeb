//! Numbers of a run (`metrics.json`): always the run's cost and the arrangement switches; goal and
//! contact-force figures for scenes with goals (paper 000); force-tracking figures for scenes
//! with force references (paper 003 Table 3).

use serde::Serialize;
use skin_core::resolver::BASE_JOINTS;
use skin_core::supervisor::Mode;

use crate::record::{mode_name, CycleRecord, RunRecord};
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
    /// Arrangement switches.
    pub arrangement_switches: Vec<SwitchEntry>,
    /// Cycles that were safe-stop steps (a fault of the controller or of its inputs).
    pub faulted_cycles: usize,
    /// Paper 000 figures (scenes with goals).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub goal: Option<GoalMetrics>,
    /// Paper 003 figures (scenes with force references).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub force: Option<ForceMetrics>,
    /// Scenes with neither goals nor force references (paper 003 Exp. 2's pre-contact approach
    /// and guidance): nothing of the robot may press on the environment.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub contact_free: Option<ContactFreeMetrics>,
}

/// A scene in which the robot should touch nothing (paper 003 Exp. 2): its largest contact
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

/// Paper 000: the goal and the contact forces against `ε_c`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GoalMetrics {
    /// Final goal error within the supervisor's goal tolerance.
    pub goal_reached: bool,
    /// Goal error at the end of the run \[m\].
    pub goal_error_m: f64,
    /// Goal tolerance of the supervisor \[m\].
    pub goal_tolerance_m: f64,
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
}

/// Paper 003 Table 3: force tracking in the contact phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ForceMetrics {
    /// Mean measured hand force over the settled contact phase \[N\].
    pub force_mean_n: f64,
    /// RMS of measured − reference force without interaction \[N\].
    pub rms_force_error_n: f64,
    /// RMS of measured − reference force during interactions \[N\] (null: none).
    pub rms_force_error_interaction_n: f64,
    /// Cycles behind each RMS (without, with).
    pub rms_cycles: [usize; 2],
    /// Fraction of settled contact-phase cycles with the hand out of contact.
    pub contact_lost_fraction: f64,
}

/// Supervisor thresholds the metrics compare with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// `ε_c` \[N\].
    pub eps_c_n: f64,
    /// Goal tolerance \[m\].
    pub goal_tolerance_m: f64,
    /// `d_p,d` of the hand distance task \[m\].
    pub hand_distance_desired_m: f64,
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
pub fn compute(record: &RunRecord, scene: &Scene, limits: Limits) -> Metrics {
    let cycles = &record.cycles;
    let arm: Vec<usize> = (0..record.joint_names.len())
        .filter(|&j| !BASE_JOINTS.contains(&record.joint_names[j].as_str()))
        .collect();
    let max_joint_speed = cycles
        .iter()
        .flat_map(|c| arm.iter().map(move |&j| c.qd[j].abs()))
        .fold(0.0, f64::max);
    let sim = record.sim_duration_s();
    Metrics {
        scenario: record.name.clone(),
        realtime_factor: sim / record.wall_time_s,
        sim_duration_s: sim,
        max_joint_speed_rad_s: max_joint_speed,
        control_cycle_us_p50: median(cycles.iter().map(|c| c.compute_us).collect()),
        arrangement_switches: record
            .switches
            .iter()
            .map(|s| SwitchEntry {
                t: s.t_s,
                from: mode_name(s.from),
                to: mode_name(s.to),
            })
            .collect(),
        faulted_cycles: cycles.iter().filter(|c| c.fault.is_some()).count(),
        goal: (!scene.spec.goals.is_empty()).then(|| goal_metrics(cycles, scene, limits)),
        force: (!scene.spec.force_references.is_empty()).then(|| force_metrics(cycles)),
        contact_free: (scene.spec.goals.is_empty() && scene.spec.force_references.is_empty())
            .then(|| contact_free_metrics(cycles, scene, limits)),
    }
}

fn contact_free_metrics(cycles: &[CycleRecord], scene: &Scene, limits: Limits) -> ContactFreeMetrics {
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

fn goal_metrics(cycles: &[CycleRecord], scene: &Scene, limits: Limits) -> GoalMetrics {
    let eps = limits.eps_c_n;
    let pushes: Vec<(f64, f64)> = scene
        .spec
        .pushes
        .iter()
        .filter(|p| p.object.is_some())
        .map(|p| (p.start_s, p.end_s))
        .collect();
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
    GoalMetrics {
        goal_reached: error <= limits.goal_tolerance_m,
        goal_error_m: error,
        goal_tolerance_m: limits.goal_tolerance_m,
        max_contact_force_intentional_n: max_link_force(cycles, |c| c.mode == Mode::IntentionalContact && !excused(c.t_s)),
        max_contact_force_n: max_link_force(cycles, |c| !excused(c.t_s)),
        eps_c_n: eps,
        hard_contact_recovery_s: recovery,
    }
}

fn force_metrics(cycles: &[CycleRecord]) -> ForceMetrics {
    let touched = |c: &&CycleRecord| c.mode == Mode::Contact && c.hand_force_n > 0.0;
    let contact_from = cycles.iter().find(touched).map_or(f64::INFINITY, |c| c.t_s);
    // Interaction windows, extended by their tail.
    let mut last_interaction = f64::NEG_INFINITY;
    let mut settled = Vec::new(); // (cycle, with interaction)
    for c in cycles {
        if c.interaction {
            last_interaction = c.t_s;
        }
        if c.mode == Mode::Contact && c.t_s >= contact_from + CONTACT_SETTLE_S && c.force_reference_n.is_finite() {
            settled.push((c, c.t_s - last_interaction <= INTERACTION_TAIL_S));
        }
    }
    let errors = |with: bool| {
        settled
            .iter()
            .filter(move |&&(_, w)| w == with)
            .map(|(c, _)| c.hand_force_n - c.force_reference_n)
    };
    let (without, n0) = rms(errors(false));
    let (during, n1) = rms(errors(true));
    let n = settled.len() as f64;
    ForceMetrics {
        force_mean_n: settled.iter().map(|(c, _)| c.hand_force_n).sum::<f64>() / n,
        rms_force_error_n: without,
        rms_force_error_interaction_n: during,
        rms_cycles: [n0, n1],
        contact_lost_fraction: settled.iter().filter(|(c, _)| c.hand_force_n <= 0.0).count() as f64 / n,
    }
}
