//! Resolver parameters (`config/resolver.yaml`): the virtual arm and base dynamics of interactive-force-control paper
//! eq. (26), the inner velocity loop and the last-stage limits, loaded and validated with errors
//! naming the file and the key.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::declare_params;
use crate::param_file::declare::{Declared, Range};
use crate::param_file::{load_validated, parse_validated, InvalidParam, ParamsError};

declare_params! {
    /// All resolver parameters (one YAML file, sections as the fields).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ResolverParams {
        /// Arm joints: `M_a q̈_a + C_a q̇_a + g = τ_a*` (interactive-force-control paper eq. (26), upper row).
        pub arm: ArmParams => nested,
        /// Holonomic base: `M_b ẍ_b + D_b ẋ_b = τ_b*` (interactive-force-control paper eq. (26), lower row).
        pub base: BaseParams => nested,
        /// The skin's approach bound on the arm command (`docs/resolver.md`).
        #[serde(default)]
        pub approach: ApproachParams => nested,
    }
}

declare_params! {
    /// No skin point closes on a surface its cell senses faster than `speed_min_mps + d / time_s`
    /// (`d` the cell's proximity distance): the body slows down as a surface comes near and
    /// touches it, or comes back to it after a contact, at most at `speed_min_mps` (0 for a cell
    /// pressed at `ε_c` and in a hard contact that ends a push, `docs/resolver.md`).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ApproachParams {
        /// Whether the bound is applied.
        pub enabled: bool => { choices: "true | false", live: false },
        /// Closing speed allowed at contact (`d = 0`): the touch, and the start of a push.
        pub speed_min_mps: f64 => { unit: "m/s", range: Range::positive(10.0), live: false },
        /// Time in which the allowed closing speed would cover the sensed distance.
        pub time_s: f64 => { unit: "s", range: Range::positive(100.0), live: false },
        /// In a push, a link pressed under its push force (`ε_c −
        /// thresholds.push_margin_n`) pushes something that gives way: its speed at contact
        /// grows from `speed_min_mps` by at most this much per second.
        #[serde(default = "default_push_accel")]
        pub push_accel_mps2: f64 => { unit: "m/s²", range: Range::closed(0.0, 100.0), live: false },
        /// The fastest push into a surface that gives way.
        #[serde(default = "default_push_speed_max")]
        pub push_speed_max_mps: f64 => { unit: "m/s", range: Range::positive(10.0), live: false },
        /// The push force's regulator: the speed at contact changes by this much per second per
        /// newton of the link's force under (up to `push_accel_mps2`) or over its push force.
        #[serde(default = "default_push_force_gain")]
        pub push_force_gain_mps2_per_n: f64 => { unit: "m/s² per N", range: Range::closed(0.0, 100.0), live: false },
        /// A link's force over its push force for at most this long, and under `ε_c`, is a
        /// stick-slip peak of what it pushes: the regulator slows the push by its gain instead
        /// of setting it back to the touch speed.
        #[serde(default = "default_push_peak")]
        pub push_peak_s: f64 => { unit: "s", range: Range::closed(0.0, 10.0), live: false },
    }
}

fn default_push_accel() -> f64 {
    ApproachParams::default().push_accel_mps2
}

fn default_push_speed_max() -> f64 {
    ApproachParams::default().push_speed_max_mps
}

fn default_push_force_gain() -> f64 {
    ApproachParams::default().push_force_gain_mps2_per_n
}

fn default_push_peak() -> f64 {
    ApproachParams::default().push_peak_s
}

impl Default for ApproachParams {
    /// The shipped values (`config/resolver.yaml`).
    fn default() -> Self {
        Self {
            enabled: true,
            speed_min_mps: 0.02,
            time_s: 0.5,
            push_accel_mps2: 0.1,
            push_speed_max_mps: 0.1,
            push_force_gain_mps2_per_n: 0.1,
            push_peak_s: 0.02,
        }
    }
}

declare_params! {
    /// Virtual dynamics and limits of the arm joints (every moving joint that is not a base joint).
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct ArmParams {
        /// Nominal command rate (TOMM's UR5s: 125). Each update integrates over the `dt` it is
        /// given; a `dt` above two nominal periods is capped at two periods.
        pub rate_hz: f64 => { unit: "Hz", range: RATE_HZ, live: false },
        /// Diagonal entry of `M_a` for every arm joint (kg for a prismatic joint).
        pub inertia: f64 => { unit: "kg m²", range: Range::positive(1e4), live: false },
        /// Diagonal entry of `C_a` for every arm joint (N s/m for a prismatic joint);
        /// `inertia / damping` is the time constant of the virtual joint.
        pub damping: f64 => { unit: "N m s/rad", range: Range::closed(0.0, 1e5), live: false },
        /// Per-joint overrides, keyed by joint name (must be arm joints of the model).
        #[serde(default)]
        pub joints: BTreeMap<String, JointOverride> => nested,
        /// `k` of the inner velocity loop: before each step the virtual velocity moves towards
        /// the measured one by the fraction `1 − exp(−k dt)` (0: no synchronization).
        pub sync_gain_per_s: f64 => { unit: "1/s", range: Range::closed(0.0, 1e4), live: false },
        /// Whether `g` of eq. (26) is subtracted from the given torque (`true` for a `τ*` that
        /// contains the bias `g` of eq. (19); `false` for a task-only torque).
        pub subtract_gravity: bool => { choices: "true | false", live: false },
        /// Fraction of each joint's URDF velocity limit that may be commanded.
        pub velocity_limit_scale: f64 => { unit: "", range: Range::positive(1.0), live: false },
        /// Acceleration limit of every arm joint command (m/s² for a prismatic joint).
        pub max_acceleration: f64 => { unit: "rad/s²", range: Range::positive(1e6), live: false },
    }
}

declare_params! {
    /// Optional per-joint values replacing the arm-wide ones (same units and bounds).
    #[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct JointOverride {
        /// Replaces `arm.inertia` for this joint.
        #[serde(default)]
        pub inertia: Option<f64> => { unit: "kg m²", range: Range::positive(1e4), live: false },
        /// Replaces `arm.damping` for this joint.
        #[serde(default)]
        pub damping: Option<f64> => { unit: "N m s/rad", range: Range::closed(0.0, 1e5), live: false },
        /// Replaces `arm.max_acceleration` for this joint.
        #[serde(default)]
        pub max_acceleration: Option<f64> => { unit: "rad/s²", range: Range::positive(1e6), live: false },
    }
}

declare_params! {
    /// Virtual dynamics and limits of the holonomic base. Index order is (x, y, yaw); x and y are
    /// the base frame's forward and left axes (the virtual inertia is attached to the base).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct BaseParams {
        /// Nominal command rate (TOMM's base: 1000).
        pub rate_hz: f64 => { unit: "Hz", range: RATE_HZ, live: false },
        /// Diagonal of `M_b`.
        pub inertia: [f64; 3] => { unit: "kg, kg, kg m²", range: Range::positive(1e4), live: false },
        /// Diagonal of `D_b`.
        pub damping: [f64; 3] => { unit: "N s/m, N s/m, N m s/rad", range: Range::closed(0.0, 1e5), live: false },
        /// `k` of the inner velocity loop (as `arm.sync_gain_per_s`).
        pub sync_gain_per_s: f64 => { unit: "1/s", range: Range::closed(0.0, 1e4), live: false },
        /// Limit of the planar speed `|(vx, vy)|`.
        pub max_linear_m_s: f64 => { unit: "m/s", range: Range::positive(10.0), live: false },
        /// Limit of `|wz|`.
        pub max_angular_rad_s: f64 => { unit: "rad/s", range: Range::positive(10.0), live: false },
        /// Limit of the planar acceleration `|(ax, ay)|`.
        pub max_linear_accel_m_s2: f64 => { unit: "m/s²", range: Range::positive(1e4), live: false },
        /// Limit of the yaw acceleration.
        pub max_angular_accel_rad_s2: f64 => { unit: "rad/s²", range: Range::positive(1e4), live: false },
    }
}

/// Command rates a resolver accepts.
const RATE_HZ: Range = Range::closed(1.0, 100_000.0);

impl ResolverParams {
    /// Checks every section; the error's key is the dotted path in the file.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        self.check("")?;
        let a = &self.approach;
        if a.push_speed_max_mps < a.speed_min_mps {
            return Err(InvalidParam {
                key: "approach.push_speed_max_mps".into(),
                value: a.push_speed_max_mps,
                reason: "must be >= speed_min_mps (a push is never slower than a touch)".into(),
            });
        }
        Ok(())
    }

    /// Parses and validates YAML text; `source` names the file in errors.
    pub fn from_yaml_str(text: &str, source: &str) -> Result<Self, ParamsError> {
        parse_validated(text, source, Self::validate)
    }

    /// Reads, parses and validates the file at `path`.
    pub fn load(path: &Path) -> Result<Self, ParamsError> {
        load_validated(path, Self::validate)
    }
}

impl Default for ResolverParams {
    /// The values of the shipped `config/resolver.yaml` (TOMM), without per-joint overrides.
    fn default() -> Self {
        Self {
            arm: ArmParams {
                rate_hz: 125.0,
                inertia: 0.5,
                damping: 10.0,
                joints: BTreeMap::new(),
                sync_gain_per_s: 5.0,
                subtract_gravity: true,
                velocity_limit_scale: 0.5,
                max_acceleration: 3.0,
            },
            base: BaseParams {
                rate_hz: 1000.0,
                inertia: [40.0, 40.0, 10.0],
                damping: [100.0, 100.0, 25.0],
                sync_gain_per_s: 5.0,
                max_linear_m_s: 0.5,
                max_angular_rad_s: 0.8,
                max_linear_accel_m_s2: 1.0,
                max_angular_accel_rad_s2: 2.0,
            },
            approach: ApproachParams::default(),
        }
    }
}
