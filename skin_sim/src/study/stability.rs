//! When a run went unstable, measured on its record. The first cycle that meets any criterion
//! marks the run unstable at that time:
//!
//! - **fault**: a safe-stop cycle of the controller (it refused its inputs or its own output) or
//!   a non-finite joint state;
//! - **state jump**: a joint moved more in one control period than [`JUMP_FACTOR`] times its
//!   velocity limit allows (MuJoCo's divergence reset, or an integrator blow-up);
//! - **speed at limit**: an arm joint at [`SPEED_FRACTION`] of its velocity limit or more for
//!   [`SPEED_HOLD_S`] on end (the servo saturated: the loop no longer controls the joint);
//! - **chatter**: an arm joint's command reversing direction, by more than [`CHATTER_STEP`] of its
//!   velocity limit, in at least [`CHATTER_FRACTION`] of the cycles of a [`CHATTER_WINDOW_S`]
//!   window (the period-2 oscillation of a sampled loop whose gain is too high for its rate);
//! - **force blow-up**: a contact force on one link above [`FORCE_BLOWUP_N`].
//!
//! Energy growth is not used: the velocity servos inject and remove energy by design.

use serde::{Deserialize, Serialize};

use crate::outputs::record::RunRecord;

/// A state jump: one period's motion above this multiple of what the velocity limit allows.
pub const JUMP_FACTOR: f64 = 3.0;
/// Speed at limit: this fraction of the joint's velocity limit…
pub const SPEED_FRACTION: f64 = 0.95;
/// …held this long \[s\].
pub const SPEED_HOLD_S: f64 = 0.25;
/// Chatter: a reversal counts when the command changes by this fraction of the velocity limit.
pub const CHATTER_STEP: f64 = 0.05;
/// Chatter: this fraction of a window's cycles are reversals…
pub const CHATTER_FRACTION: f64 = 0.5;
/// …in a window this long \[s\] (at least 8 cycles).
pub const CHATTER_WINDOW_S: f64 = 0.5;
/// Force blow-up threshold \[N\]: far above any intended contact (the papers stay below 20 N) and
/// above what the arm's effort limits press with at rest.
pub const FORCE_BLOWUP_N: f64 = 1000.0;

/// Which criterion fired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InstabilityKind {
    /// Safe-stop cycle or non-finite state.
    Fault,
    /// Joint position jump.
    StateJump,
    /// Sustained joint speed at the limit.
    SpeedAtLimit,
    /// Command chatter.
    Chatter,
    /// Contact force blow-up.
    ForceBlowup,
}

impl InstabilityKind {
    /// Name in the document.
    pub fn name(self) -> &'static str {
        match self {
            InstabilityKind::Fault => "fault",
            InstabilityKind::StateJump => "state jump",
            InstabilityKind::SpeedAtLimit => "speed at limit",
            InstabilityKind::Chatter => "chatter",
            InstabilityKind::ForceBlowup => "force blow-up",
        }
    }
}

/// The first sign of instability in a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Instability {
    /// Time it was detected (for the held criteria: when the hold began) \[s\].
    pub t_s: f64,
    /// Which criterion.
    pub kind: InstabilityKind,
    /// The joint or link and the value, readable.
    pub detail: String,
}

/// The first instability of `record`, or None. `speed_limits` are the velocity limits of the
/// model joints (model order, the order of `q` and `qd`).
pub fn detect(record: &RunRecord, speed_limits: &[f64]) -> Option<Instability> {
    let found = [
        fault(record),
        jump(record, speed_limits),
        speed(record, speed_limits),
        chatter(record, speed_limits),
        force(record),
    ];
    found.into_iter().flatten().min_by(|a, b| a.t_s.total_cmp(&b.t_s))
}

/// Model indices of the arm joints of the record (the order of `joint_velocities`).
fn arm_joints(record: &RunRecord) -> Vec<usize> {
    record.arm_joints.iter().filter_map(|a| record.joint_names.iter().position(|j| j == a)).collect()
}

fn at(t_s: f64, kind: InstabilityKind, detail: String) -> Instability {
    Instability { t_s, kind, detail }
}

fn fault(record: &RunRecord) -> Option<Instability> {
    record.cycles.iter().find_map(|c| {
        let finite = c.q.iter().chain(&c.qd).all(|v| v.is_finite());
        match (&c.fault, finite) {
            (Some(f), _) => Some(at(c.t_s, InstabilityKind::Fault, f.clone())),
            (None, false) => Some(at(c.t_s, InstabilityKind::Fault, "non-finite joint state".into())),
            _ => None,
        }
    })
}

fn jump(record: &RunRecord, limits: &[f64]) -> Option<Instability> {
    let period = 1.0 / record.control_rate_hz;
    record.cycles.windows(2).find_map(|w| {
        (0..limits.len()).find_map(|j| {
            let dq = (w[1].q[j] - w[0].q[j]).abs();
            (dq > JUMP_FACTOR * limits[j] * period).then(|| {
                let detail = format!("{} moved {dq:.3} in one period", record.joint_names[j]);
                at(w[1].t_s, InstabilityKind::StateJump, detail)
            })
        })
    })
}

fn speed(record: &RunRecord, limits: &[f64]) -> Option<Instability> {
    let arm = arm_joints(record);
    let mut since: Vec<Option<f64>> = vec![None; arm.len()];
    record.cycles.iter().find_map(|c| {
        arm.iter().zip(&mut since).find_map(|(&j, since)| {
            if c.qd[j].abs() < SPEED_FRACTION * limits[j] {
                *since = None;
                return None;
            }
            let start = *since.get_or_insert(c.t_s);
            (c.t_s - start >= SPEED_HOLD_S).then(|| {
                let detail = format!("{} at {:.2} rad/s (limit {})", record.joint_names[j], c.qd[j].abs(), limits[j]);
                at(start, InstabilityKind::SpeedAtLimit, detail)
            })
        })
    })
}

fn chatter(record: &RunRecord, limits: &[f64]) -> Option<Instability> {
    let window = ((CHATTER_WINDOW_S * record.control_rate_hz).round() as usize).max(8);
    let cycles = &record.cycles;
    arm_joints(record)
        .iter()
        .enumerate()
        .filter_map(|(a, &j)| {
            let step = CHATTER_STEP * limits[j];
            // reversal[k]: the command turned around at cycle k + 1, by more than `step` both ways
            let reversal: Vec<bool> = cycles
                .windows(3)
                .map(|w| {
                    let (d0, d1) = (
                        w[1].joint_velocities[a] - w[0].joint_velocities[a],
                        w[2].joint_velocities[a] - w[1].joint_velocities[a],
                    );
                    d0 * d1 < 0.0 && d0.abs() > step && d1.abs() > step
                })
                .collect();
            let mut count = 0;
            (0..reversal.len()).find_map(|k| {
                count += usize::from(reversal[k]);
                if k >= window {
                    count -= usize::from(reversal[k - window]);
                }
                let start = (k + 1).saturating_sub(window);
                (k + 1 >= window && count as f64 >= CHATTER_FRACTION * window as f64).then(|| {
                    let detail = format!("{}: {count} reversals in {window} cycles", record.joint_names[j]);
                    at(cycles[start + 1].t_s, InstabilityKind::Chatter, detail)
                })
            })
        })
        .min_by(|a, b| a.t_s.total_cmp(&b.t_s))
}

fn force(record: &RunRecord) -> Option<Instability> {
    record
        .cycles
        .iter()
        .find(|c| c.link_force_n > FORCE_BLOWUP_N)
        .map(|c| at(c.t_s, InstabilityKind::ForceBlowup, format!("{:.0} N on one link", c.link_force_n)))
}
