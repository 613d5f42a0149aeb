//! Parameters of every task (`config/tasks.yaml`), typed and validated; errors name the file and
//! the dotted key.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::param_file::{load_validated, parse_validated, InvalidParam, ParamsError};

/// Intentional-contact paper eq. (7)-(9): goal task gains and speed limit (used for position and orientation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GoalParams {
    /// Position gain `k_p` \[N/m\] (or N m/rad for orientation).
    pub kp_n_per_m: f64,
    /// Velocity gain `k_v` \[N s/m\] (or N m s/rad).
    pub kv_n_s_per_m: f64,
    /// Speed limit `V_max` \[m/s\] (or rad/s) of eq. (9).
    pub v_max_m_per_s: f64,
}

/// Intentional-contact paper eq. (3): proximity avoidance `F_di = K (d_range - d_i)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AvoidanceParams {
    /// `K` \[N/m\].
    pub gain_n_per_m: f64,
    /// Nominal `d_range` \[m\]; the supervisor may pass a smaller one per cycle.
    pub range_m: f64,
    /// Width of the outer band of the range over which a cell's row fades into the null-space
    /// projector \[m\] (activation 0 at `d_range`, 1 from `d_range − band` inward; capped by the
    /// current range). 0: rows switch on at once (the projector then jumps at the boundary).
    pub activation_band_m: f64,
}

/// Intentional-contact paper eq. (6): contact reaction `F_ci = gain F_i` along the inward normal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactReactionParams {
    /// Dimensionless gain on the measured cell force of eq. (6).
    pub gain: f64,
    /// Measured cell force at which a contact row is fully active in the null-space projector
    /// \[N\] (activation rises smoothly from 0 at no force). 0: rows switch on at once.
    pub activation_force_n: f64,
}

/// Interactive-force-control paper eq. (9): hand force / distance control on one row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandForceParams {
    /// Desired inertia `Λ_1` \[kg\].
    pub lambda_kg: f64,
    /// `K_1` in force mode \[1/signal · N\] (signal error to task force).
    pub k_force_n_per_signal: f64,
    /// `K_1` in distance mode \[N/m\].
    pub k_distance_n_per_m: f64,
    /// `D_1` \[N s/m\].
    pub d_n_s_per_m: f64,
    /// Desired fused contact signal `f_c,d` (contact phase, Table 1), ≥ 0: the hand patch's
    /// summed virtual force (eq. 7 sums the active cells' signals, so it can exceed 1).
    pub force_signal_desired: f64,
    /// Desired distance `d_p,d` \[m\] (approach phase, Table 1).
    pub distance_desired_m: f64,
    /// Approach speed bound: the hand may close on a sensed surface at most at
    /// `approach_speed_min_mps + d / approach_time_s`, `d` the distance its proximity reads
    /// (see [`super::hand_force::approach_speed_limit`]) \[s\].
    pub approach_time_s: f64,
    /// Closing speed still allowed at `d = 0` (touching) \[m/s\].
    pub approach_speed_min_mps: f64,
}

/// Impedance of a 3-row acceleration task, interactive-force-control paper eq. (4)/(5): diagonals of `Λ`, `K`, `D`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Impedance3 {
    /// Diagonal of `Λ` \[kg or kg m²\].
    pub lambda: [f64; 3],
    /// Diagonal of `K` \[N/m, N m/rad, or N per signal unit\].
    pub k: [f64; 3],
    /// Diagonal of `D` \[N s/m or N m s/rad\].
    pub d: [f64; 3],
}

/// Interactive-force-control paper eq. (15)-(17): mobile-base collision avoidance from laser points.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseAvoidanceParams {
    /// `f_max` of eq. (16) \[N\].
    pub f_max_n: f64,
    /// `α` of eq. (16) \[m\].
    pub alpha_m: f64,
    /// Points farther than this from the footprint are ignored \[m\].
    pub range_m: f64,
    /// Footprint rectangle in the base frame: `[x_min, x_max]` \[m\].
    pub footprint_x_m: [f64; 2],
    /// Footprint rectangle in the base frame: `[y_min, y_max]` \[m\].
    pub footprint_y_m: [f64; 2],
    /// Angular sectors (about the base origin); the closest point of each sector is one `o_i`.
    pub sectors: usize,
}

/// Interactive-force-control paper eq. (18): joint compliance / posture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PostureParams {
    /// `K_c` diagonal (one per joint, or one value for all) \[N m/rad or N/m\].
    pub k_c: Vec<f64>,
    /// `D_c` diagonal (one per joint, or one value for all) \[N m s/rad or N s/m\].
    pub d_c: Vec<f64>,
    /// Gain on the body skin torque `τ_skin` (eq. 14) inside `τ_s` \[N per signal unit\].
    pub skin_gain: f64,
    /// `K_c`, `D_c` of the base joints (x, y, yaw) at rest, replacing `k_c`, `d_c` there (none:
    /// `k_c`, `d_c`): the base's virtual mass is far larger than an arm joint's inertia, so the
    /// arm's damping leaves it ringing after a touch.
    #[serde(default)]
    pub base: Option<BaseGains>,
    /// `K_c`, `D_c` of the base joints while they track a commanded base motion
    /// ([`super::posture::BaseReference`]); none: the base joints' gains at rest.
    #[serde(default)]
    pub base_tracking: Option<BaseGains>,
}

/// Gains of the base joints (world x, y, yaw) in the posture torque of eq. (18): at rest, or
/// toward a commanded base motion (stiffer than the posture's, so that the lowest level follows
/// the motion against the arm's own posture pull).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseGains {
    /// Stiffness along x, y \[N/m\] and about yaw \[N m/rad\].
    pub k_c: [f64; 3],
    /// Damping along x, y \[N s/m\] and about yaw \[N m s/rad\].
    pub d_c: [f64; 3],
}

/// Every task's parameters (`config/tasks.yaml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskParams {
    /// End-effector position goal (intentional-contact paper eq. 7-9).
    pub goal: GoalParams,
    /// End-effector orientation goal (same law, angular rows).
    pub goal_orientation: GoalParams,
    /// Proximity avoidance (intentional-contact paper eq. 3).
    pub avoidance: AvoidanceParams,
    /// Contact reaction (intentional-contact paper eq. 6).
    pub contact_reaction: ContactReactionParams,
    /// Hand force/distance (interactive-force-control paper eq. 9).
    pub hand_force: HandForceParams,
    /// Compliant wrist (interactive-force-control paper eq. 10).
    pub wrist: Impedance3,
    /// Tactile guidance (interactive-force-control paper eq. 11-12).
    pub tactile_guidance: Impedance3,
    /// Cartesian position hold (interactive-force-control paper eq. 4, Table 1).
    pub position_hold: Impedance3,
    /// Base collision avoidance (interactive-force-control paper eq. 15-17).
    pub base_avoidance: BaseAvoidanceParams,
    /// Joint compliance / posture (interactive-force-control paper eq. 18).
    pub posture: PostureParams,
}

fn pos(prefix: &str, name: &str, v: f64) -> Result<(), InvalidParam> {
    InvalidParam::positive_finite(prefix, name, v)
}

fn nonneg(prefix: &str, name: &str, v: f64) -> Result<(), InvalidParam> {
    InvalidParam::in_range(prefix, name, v, 0.0, f64::INFINITY, "must be finite and >= 0")
}

impl GoalParams {
    /// Checks gains and speed limit (all > 0).
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        pos(prefix, "kp_n_per_m", self.kp_n_per_m)?;
        pos(prefix, "kv_n_s_per_m", self.kv_n_s_per_m)?;
        pos(prefix, "v_max_m_per_s", self.v_max_m_per_s)
    }
}

impl Impedance3 {
    /// Checks `Λ > 0`, `K >= 0`, `D >= 0`.
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        for i in 0..3 {
            pos(prefix, &format!("lambda[{i}]"), self.lambda[i])?;
            nonneg(prefix, &format!("k[{i}]"), self.k[i])?;
            nonneg(prefix, &format!("d[{i}]"), self.d[i])?;
        }
        Ok(())
    }
}

impl TaskParams {
    /// Checks every value; the error key is the dotted path in the file.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        self.goal.validate("goal.")?;
        self.goal_orientation.validate("goal_orientation.")?;
        pos("avoidance.", "gain_n_per_m", self.avoidance.gain_n_per_m)?;
        nonneg("avoidance.", "range_m", self.avoidance.range_m)?;
        nonneg("avoidance.", "activation_band_m", self.avoidance.activation_band_m)?;
        nonneg("contact_reaction.", "gain", self.contact_reaction.gain)?;
        nonneg("contact_reaction.", "activation_force_n", self.contact_reaction.activation_force_n)?;
        let h = &self.hand_force;
        pos("hand_force.", "lambda_kg", h.lambda_kg)?;
        nonneg("hand_force.", "k_force_n_per_signal", h.k_force_n_per_signal)?;
        nonneg("hand_force.", "k_distance_n_per_m", h.k_distance_n_per_m)?;
        nonneg("hand_force.", "d_n_s_per_m", h.d_n_s_per_m)?;
        InvalidParam::in_range(
            "hand_force.",
            "force_signal_desired",
            h.force_signal_desired,
            0.0,
            f64::MAX,
            "must be finite and >= 0",
        )?;
        nonneg("hand_force.", "distance_desired_m", h.distance_desired_m)?;
        pos("hand_force.", "approach_time_s", h.approach_time_s)?;
        pos("hand_force.", "approach_speed_min_mps", h.approach_speed_min_mps)?;
        self.wrist.validate("wrist.")?;
        self.tactile_guidance.validate("tactile_guidance.")?;
        self.position_hold.validate("position_hold.")?;
        let b = &self.base_avoidance;
        nonneg("base_avoidance.", "f_max_n", b.f_max_n)?;
        pos("base_avoidance.", "alpha_m", b.alpha_m)?;
        nonneg("base_avoidance.", "range_m", b.range_m)?;
        for (name, r) in [("footprint_x_m", b.footprint_x_m), ("footprint_y_m", b.footprint_y_m)] {
            InvalidParam::in_range(
                "base_avoidance.",
                &format!("{name}[1]"),
                r[1],
                r[0],
                f64::INFINITY,
                "must be finite and >= the minimum",
            )?;
        }
        InvalidParam::in_range("base_avoidance.", "sectors", b.sectors as f64, 1.0, 360.0, "must be in [1, 360]")?;
        let p = &self.posture;
        for (name, v) in [("k_c", &p.k_c), ("d_c", &p.d_c)] {
            if v.is_empty() {
                return Err(InvalidParam {
                    key: format!("posture.{name}"),
                    value: 0.0,
                    reason: "needs at least one value",
                });
            }
            for (i, x) in v.iter().enumerate() {
                nonneg("posture.", &format!("{name}[{i}]"), *x)?;
            }
        }
        for (prefix, gains) in [("posture.base.", &p.base), ("posture.base_tracking.", &p.base_tracking)] {
            if let Some(b) = gains {
                for (name, v) in [("k_c", b.k_c), ("d_c", b.d_c)] {
                    for (i, x) in v.iter().enumerate() {
                        nonneg(prefix, &format!("{name}[{i}]"), *x)?;
                    }
                }
            }
        }
        nonneg("posture.", "skin_gain", p.skin_gain)
    }

    /// Parses and validates `text`; `source` names the file in errors.
    pub fn from_yaml_str(text: &str, source: &str) -> Result<Self, ParamsError> {
        parse_validated(text, source, Self::validate)
    }

    /// Loads and validates the file at `path`.
    pub fn load(path: &Path) -> Result<Self, ParamsError> {
        load_validated(path, Self::validate)
    }
}
