//! Resolver parameters (`config/resolver.yaml`): the virtual arm and base dynamics of interactive-force-control paper
//! eq. (26), the inner velocity loop and the last-stage limits, loaded and validated with errors
//! naming the file and the key.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::param_file::{load_validated, parse_validated, InvalidParam, ParamsError};

/// All resolver parameters (one YAML file, sections as the fields).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResolverParams {
    /// Arm joints: `M_a q̈_a + C_a q̇_a + g = τ_a*` (interactive-force-control paper eq. (26), upper row).
    pub arm: ArmParams,
    /// Holonomic base: `M_b ẍ_b + D_b ẋ_b = τ_b*` (interactive-force-control paper eq. (26), lower row).
    pub base: BaseParams,
}

/// Virtual dynamics and limits of the arm joints (every moving joint that is not a base joint).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmParams {
    /// Nominal command rate \[Hz\], in \[1, 100000\] (TOMM's UR5s: 125). Each update integrates
    /// over the `dt` it is given; a `dt` above two nominal periods is capped at two periods.
    pub rate_hz: f64,
    /// Diagonal entry of `M_a` for every arm joint \[kg m² (revolute) or kg (prismatic)\], > 0.
    pub inertia: f64,
    /// Diagonal entry of `C_a` for every arm joint \[N m s/rad or N s/m\], >= 0.
    /// `inertia / damping` is the time constant of the virtual joint (s).
    pub damping: f64,
    /// Per-joint overrides, keyed by joint name (must be arm joints of the model).
    #[serde(default)]
    pub joints: BTreeMap<String, JointOverride>,
    /// `k` of the inner velocity loop \[1/s\], >= 0: before each step the virtual velocity moves
    /// towards the measured one by the fraction `1 − exp(−k dt)` (0: no synchronization).
    pub sync_gain_per_s: f64,
    /// Whether `g` of eq. (26) is subtracted from the given torque (`true` for a `τ*` that
    /// contains the bias `g` of eq. (19); `false` for a task-only torque).
    pub subtract_gravity: bool,
    /// Fraction of each joint's URDF velocity limit that may be commanded, in (0, 1].
    pub velocity_limit_scale: f64,
    /// Acceleration limit of every arm joint command \[rad/s² or m/s²\], > 0.
    pub max_acceleration: f64,
}

/// Optional per-joint values replacing the arm-wide ones (same units and bounds).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointOverride {
    /// Replaces [`ArmParams::inertia`].
    #[serde(default)]
    pub inertia: Option<f64>,
    /// Replaces [`ArmParams::damping`].
    #[serde(default)]
    pub damping: Option<f64>,
    /// Replaces [`ArmParams::max_acceleration`].
    #[serde(default)]
    pub max_acceleration: Option<f64>,
}

/// Virtual dynamics and limits of the holonomic base. Index order is (x, y, yaw); x and y are
/// the base frame's forward and left axes (the virtual inertia is attached to the base).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseParams {
    /// Nominal command rate \[Hz\], in \[1, 100000\] (TOMM's base: 1000).
    pub rate_hz: f64,
    /// Diagonal of `M_b`: \[kg, kg, kg m²\], each > 0.
    pub inertia: [f64; 3],
    /// Diagonal of `D_b`: \[N s/m, N s/m, N m s/rad\], each >= 0.
    pub damping: [f64; 3],
    /// `k` of the inner velocity loop \[1/s\], >= 0 (as [`ArmParams::sync_gain_per_s`]).
    pub sync_gain_per_s: f64,
    /// Limit of the planar speed `|(vx, vy)|` \[m/s\], > 0.
    pub max_linear_m_s: f64,
    /// Limit of `|wz|` \[rad/s\], > 0.
    pub max_angular_rad_s: f64,
    /// Limit of the planar acceleration `|(ax, ay)|` \[m/s²\], > 0.
    pub max_linear_accel_m_s2: f64,
    /// Limit of the yaw acceleration \[rad/s²\], > 0.
    pub max_angular_accel_rad_s2: f64,
}

const RATE_MIN_HZ: f64 = 1.0;
const RATE_MAX_HZ: f64 = 100_000.0;

fn non_negative(prefix: &str, name: &str, value: f64) -> Result<(), InvalidParam> {
    InvalidParam::in_range(prefix, name, value, 0.0, f64::MAX, "must be finite and >= 0")
}

fn rate(prefix: &str, value: f64) -> Result<(), InvalidParam> {
    InvalidParam::in_range(prefix, "rate_hz", value, RATE_MIN_HZ, RATE_MAX_HZ, "must be in [1, 100000] Hz")
}

impl JointOverride {
    fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        if let Some(m) = self.inertia {
            InvalidParam::positive_finite(prefix, "inertia", m)?;
        }
        if let Some(c) = self.damping {
            non_negative(prefix, "damping", c)?;
        }
        if let Some(a) = self.max_acceleration {
            InvalidParam::positive_finite(prefix, "max_acceleration", a)?;
        }
        Ok(())
    }
}

impl ArmParams {
    /// Checks every value; `prefix` (e.g. `arm.`) starts the error's key.
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        rate(prefix, self.rate_hz)?;
        InvalidParam::positive_finite(prefix, "inertia", self.inertia)?;
        non_negative(prefix, "damping", self.damping)?;
        non_negative(prefix, "sync_gain_per_s", self.sync_gain_per_s)?;
        InvalidParam::in_range(
            prefix,
            "velocity_limit_scale",
            self.velocity_limit_scale,
            f64::MIN_POSITIVE,
            1.0,
            "must be in (0, 1]",
        )?;
        InvalidParam::positive_finite(prefix, "max_acceleration", self.max_acceleration)?;
        for (name, o) in &self.joints {
            o.validate(&format!("{prefix}joints.{name}."))?;
        }
        Ok(())
    }
}

impl BaseParams {
    /// Checks every value; `prefix` (e.g. `base.`) starts the error's key.
    pub fn validate(&self, prefix: &str) -> Result<(), InvalidParam> {
        const AXES: [&str; 3] = ["0", "1", "2"];
        rate(prefix, self.rate_hz)?;
        for (k, axis) in AXES.iter().enumerate() {
            InvalidParam::positive_finite(prefix, &format!("inertia[{axis}]"), self.inertia[k])?;
            non_negative(prefix, &format!("damping[{axis}]"), self.damping[k])?;
        }
        non_negative(prefix, "sync_gain_per_s", self.sync_gain_per_s)?;
        InvalidParam::positive_finite(prefix, "max_linear_m_s", self.max_linear_m_s)?;
        InvalidParam::positive_finite(prefix, "max_angular_rad_s", self.max_angular_rad_s)?;
        InvalidParam::positive_finite(prefix, "max_linear_accel_m_s2", self.max_linear_accel_m_s2)?;
        InvalidParam::positive_finite(prefix, "max_angular_accel_rad_s2", self.max_angular_accel_rad_s2)
    }
}

impl ResolverParams {
    /// Checks every section; the error's key is the dotted path in the file.
    pub fn validate(&self) -> Result<(), InvalidParam> {
        self.arm.validate("arm.")?;
        self.base.validate("base.")
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
        }
    }
}
