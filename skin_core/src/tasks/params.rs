//! Parameters of every task (`config/tasks.yaml`), typed and validated; errors name the file and
//! the dotted key.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::declare_params;
use crate::param_file::declare::{Declared, Range};
use crate::param_file::{load_validated, parse_validated, InvalidParam, ParamsError};

declare_params! {
    /// Intentional-contact paper eq. (7)-(9): goal task gains and speed limit (used for position and
    /// orientation; the orientation's units are per radian).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct GoalParams {
        /// Position gain `k_p` (N m/rad for the orientation).
        pub kp_n_per_m: f64 => { unit: "N/m", range: Range::positive(1e5), live: false },
        /// Velocity gain `k_v` (N m s/rad for the orientation).
        pub kv_n_s_per_m: f64 => { unit: "N s/m", range: Range::positive(1e4), live: false },
        /// Speed limit `V_max` of eq. (9) (rad/s for the orientation).
        pub v_max_m_per_s: f64 => { unit: "m/s", range: Range::positive(2.0), live: false },
    }
}

declare_params! {
    /// Intentional-contact paper eq. (3): proximity avoidance `F_di = K (d_range - d_i)`.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct AvoidanceParams {
        /// `K`.
        pub gain_n_per_m: f64 => { unit: "N/m", range: Range::positive(1e5), live: false },
        /// Nominal `d_range`; the supervisor may pass a smaller one per cycle.
        pub range_m: f64 => { unit: "m", range: Range::closed(0.0, 1.0), live: false },
        /// Width of the outer band of the range over which a cell's row fades into the null-space
        /// projector (activation 0 at `d_range`, 1 from `d_range − band` inward; capped by the
        /// current range). 0: rows switch on at once (the projector then jumps at the boundary).
        pub activation_band_m: f64 => { unit: "m", range: Range::closed(0.0, 1.0), live: false },
    }
}

declare_params! {
    /// Intentional-contact paper eq. (6): contact reaction `F_ci = gain F_i` along the inward normal.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ContactReactionParams {
        /// Gain on the measured cell force of eq. (6).
        pub gain: f64 => { unit: "", range: Range::closed(0.0, 100.0), live: false },
        /// Measured cell force at which a contact row is fully active in the null-space projector
        /// (activation rises smoothly from 0 at no force). 0: rows switch on at once.
        pub activation_force_n: f64 => { unit: "N", range: Range::closed(0.0, 100.0), live: false },
    }
}

declare_params! {
    /// Interactive-force-control paper eq. (9): hand force / distance control on one row.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct HandForceParams {
        /// Desired inertia `Λ_1`.
        pub lambda_kg: f64 => { unit: "kg", range: Range::positive(1e3), live: false },
        /// `K_1` in force mode (force error in newtons, read by the pressed hand cells, to task
        /// force).
        pub k_force_n_per_n: f64 => { unit: "N/N", range: Range::closed(0.0, 1e3), live: false },
        /// `K_1` in distance mode.
        pub k_distance_n_per_m: f64 => { unit: "N/m", range: Range::closed(0.0, 1e4), live: false },
        /// `D_1`.
        pub d_n_s_per_m: f64 => { unit: "N s/m", range: Range::closed(0.0, 1e4), live: false },
        /// Desired contact force `f_c,d` (contact phase, Table 1) until a reference is given,
        /// regulated against the pressed hand cells' newtons (`skin::measured`).
        pub force_desired_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
        /// Desired distance `d_p,d` (approach phase, Table 1).
        pub distance_desired_m: f64 => { unit: "m", range: Range::closed(0.0, 1.0), live: false },
        /// Approach speed bound: the hand may close on a sensed surface at most at
        /// `approach_speed_min_mps + d / approach_time_s`, `d` the distance its proximity reads
        /// (`tasks::hand_force::approach_speed_limit`).
        pub approach_time_s: f64 => { unit: "s", range: Range::positive(100.0), live: false },
        /// Closing speed still allowed at `d = 0` (touching).
        pub approach_speed_min_mps: f64 => { unit: "m/s", range: Range::positive(1.0), live: false },
        /// Integral time `T_i` of the force error in contact (`tasks::hand_force`): eq. (9)'s
        /// error becomes `Δ + (1/T_i) ∫Δ dt` while the hand is pressed, so the force settles at
        /// the reference against the arm's velocity servo; 0: eq. (9) as printed.
        pub integral_time_s: f64 => { unit: "s", range: Range::closed(0.0, 1e3), live: false },
    }
}

declare_params! {
    /// Impedance of a 3-row acceleration task, interactive-force-control paper eq. (4)/(5):
    /// diagonals of `Λ`, `K`, `D`.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Impedance3 {
        /// Diagonal of `Λ` (kg m² for rotations).
        pub lambda: [f64; 3] => { unit: "kg", range: Range::positive(1e3), live: false },
        /// Diagonal of `K` (N m/rad, or N per signal unit on a skin signal).
        pub k: [f64; 3] => { unit: "N/m", range: Range::closed(0.0, 1e5), live: false },
        /// Diagonal of `D` (N m s/rad for rotations).
        pub d: [f64; 3] => { unit: "N s/m", range: Range::closed(0.0, 1e4), live: false },
    }
}

declare_params! {
    /// Interactive-force-control paper eq. (10): the compliant wrist,
    /// `ω̇* = Λ⁻¹(−K Γ − D ω)`, with the moment `Γ` of each sensing modality in its own units,
    /// weighted as eq. (6) weights the modalities (`tasks::wrist`).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct WristParams {
        /// Diagonal of `Λ_2`.
        pub lambda: [f64; 3] => { unit: "kg m²", range: Range::positive(1e3), live: false },
        /// Diagonal of `K_2` on the proximity signals' moment (eq. 8 of the proximity signals,
        /// the precontact phase's alignment before the touch).
        pub k: [f64; 3] => { unit: "N m per moment unit of the proximity signal", range: Range::closed(0.0, 1e5), live: false },
        /// Diagonal of `K_2` on the measured moment of the pressed cells' newtons (eq. 8 with
        /// `F_i = f⁻¹(s_i)`, `skin::measured`): the contact phase's alignment.
        pub k_force: [f64; 3] => { unit: "N m per N m", range: Range::closed(0.0, 1e5), live: false },
        /// Diagonal of `D_2`.
        pub d: [f64; 3] => { unit: "N m s/rad", range: Range::closed(0.0, 1e4), live: false },
    }
}

declare_params! {
    /// Interactive-force-control paper eq. (15)-(17): mobile-base collision avoidance from laser points.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct BaseAvoidanceParams {
        /// `f_max` of eq. (16).
        pub f_max_n: f64 => { unit: "N", range: Range::closed(0.0, 1e3), live: false },
        /// `α` of eq. (16).
        pub alpha_m: f64 => { unit: "m", range: Range::positive(10.0), live: false },
        /// Points farther than this from the footprint are ignored.
        pub range_m: f64 => { unit: "m", range: Range::closed(0.0, 30.0), live: false },
        /// Footprint rectangle in the base frame: `[x_min, x_max]`.
        pub footprint_x_m: [f64; 2] => { unit: "m", range: Range::closed(-10.0, 10.0), live: false },
        /// Footprint rectangle in the base frame: `[y_min, y_max]`.
        pub footprint_y_m: [f64; 2] => { unit: "m", range: Range::closed(-10.0, 10.0), live: false },
        /// Angular sectors (about the base origin); the closest point of each sector is one `o_i`.
        pub sectors: usize => { unit: "", range: Range::closed(1.0, 360.0), live: false },
    }
}

declare_params! {
    /// Interactive-force-control paper eq. (18): joint compliance / posture.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct PostureParams {
        /// `K_c` diagonal, one per joint or one value for all (N/m on prismatic joints).
        pub k_c: Vec<f64> => { unit: "N m/rad", range: Range::closed(0.0, 1e5), live: false },
        /// `D_c` diagonal, one per joint or one value for all (N s/m on prismatic joints).
        pub d_c: Vec<f64> => { unit: "N m s/rad", range: Range::closed(0.0, 1e4), live: false },
        /// Gain `k_skin` on the body skin torque `τ_skin` (eq. 14) inside `τ_s`.
        pub skin_gain: f64 => { unit: "N per signal unit", range: Range::closed(0.0, 1e3), live: false },
        /// `K_c`, `D_c` of the base joints (x, y, yaw) at rest, replacing `k_c`, `d_c` there (none:
        /// `k_c`, `d_c`): the base's virtual mass is far larger than an arm joint's inertia, so the
        /// arm's damping leaves it ringing after a touch.
        #[serde(default)]
        pub base: Option<BaseGains> => nested,
        /// `K_c`, `D_c` of the base joints while they track a commanded base motion
        /// (`tasks::BaseReference`); none: the base joints' gains at rest.
        #[serde(default)]
        pub base_tracking: Option<BaseGains> => nested,
    }
}

declare_params! {
    /// Gains of the base joints (world x, y, yaw) in the posture torque of eq. (18): at rest, or
    /// toward a commanded base motion (stiffer than the posture's, so that the lowest level follows
    /// the motion against the arm's own posture pull).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct BaseGains {
        /// Stiffness along x, y (N m/rad about yaw).
        pub k_c: [f64; 3] => { unit: "N/m", range: Range::closed(0.0, 1e5), live: false },
        /// Damping along x, y (N m s/rad about yaw).
        pub d_c: [f64; 3] => { unit: "N s/m", range: Range::closed(0.0, 1e4), live: false },
    }
}

declare_params! {
    /// Every task's parameters (`config/tasks.yaml`).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct TaskParams {
        /// End-effector position goal (intentional-contact paper eq. 7-9).
        pub goal: GoalParams => nested,
        /// End-effector orientation goal (same law, angular rows).
        pub goal_orientation: GoalParams => nested,
        /// Proximity avoidance (intentional-contact paper eq. 3).
        pub avoidance: AvoidanceParams => nested,
        /// Contact reaction (intentional-contact paper eq. 6).
        pub contact_reaction: ContactReactionParams => nested,
        /// Hand force/distance (interactive-force-control paper eq. 9).
        pub hand_force: HandForceParams => nested,
        /// Compliant wrist (interactive-force-control paper eq. 10).
        pub wrist: WristParams => nested,
        /// Tactile guidance (interactive-force-control paper eq. 11-12).
        pub tactile_guidance: Impedance3 => nested,
        /// Cartesian position hold (interactive-force-control paper eq. 4, Table 1).
        pub position_hold: Impedance3 => nested,
        /// Base collision avoidance (interactive-force-control paper eq. 15-17).
        pub base_avoidance: BaseAvoidanceParams => nested,
        /// Joint compliance / posture (interactive-force-control paper eq. 18).
        pub posture: PostureParams => nested,
    }
}

impl TaskParams {
    /// Checks every value: the declared ranges, then what relates two values; the error key is
    /// the dotted path in the file.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        self.check("")?;
        let b = &self.base_avoidance;
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
        for (name, v) in [("k_c", &self.posture.k_c), ("d_c", &self.posture.d_c)] {
            if v.is_empty() {
                let reason = "needs at least one value".into();
                return Err(InvalidParam { key: format!("posture.{name}"), value: 0.0, reason });
            }
        }
        Ok(())
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
