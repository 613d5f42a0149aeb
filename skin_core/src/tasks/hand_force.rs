//! Interactive-force-control paper eq. (9), Table 1: hand force / distance control on one acceleration row.
//!
//! Frame `{h}`: the hand frame, its z axis along the palm's outward normal, i.e. into the surface
//! to be touched. The row is the third row of the hand body Jacobian, `z_hᵀ J_v(o_h)` (world
//! `z_h` from the frame pose), and
//! `ẍ* = (K_1 Δ − D_1 ż_h) / Λ_1` (eq. 9) with
//! - force mode (contact phase): `Δ = f_c,d − f_c` on the fused hand-patch signal `f_c`, the
//!   reference `f_c,d` the force in newtons read through the characteristic with the contact's
//!   measured distribution over the cells (`skin::measured`);
//! - distance mode (approach phase): `Δ = d_p − d_p,d` with `d_p` from the proximity signal
//!   through the inverse characteristic.
//!
//! Either way a positive `Δ` (too little force, too far away) accelerates the hand along `+z_h`,
//! into the surface. The drift is `J̇q̇ = z_h·a_lin + (ω × z_h)·v`.
//!
//! No impact at the first touch: eq. (9) alone lets the hand reach the surface with whatever
//! speed the force error built up on the way (a 6 N reference peaked at 18 N). The closing speed
//! `ż_h` is therefore bounded by the distance the hand's proximity senses,
//! `ż_h ≤ v_0 + d / T_a` ([`approach_speed_limit`]): the hand slows down as the surface comes
//! near and touches it at most at `v_0`. The bound acts as a braking acceleration
//! `(v_lim − ż_h) / T_b` that replaces eq. (9)'s when it is lower; it never pushes, so it changes
//! nothing while the hand is slower than the bound (in contact and holding a force, `ż_h ≈ 0`).

use nalgebra::Vector3;

use super::params::HandForceParams;
use super::point_rows::{PointRows, ANGULAR, LINEAR};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use super::TaskError;
use crate::hierarchy::{Reference, TaskLevel};
use crate::model::{ModelData, RobotModel};
use crate::skin::characteristic::ProximityCharacteristic;

/// What the hand task regulates this cycle (interactive-force-control paper Table 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HandMeasurement {
    /// Contact phase: the fused hand-patch signal `f_c` (z of the hand-frame patch force).
    Force {
        /// `f_c` in signal units \[0, 1\].
        fused_signal: f64,
    },
    /// Approach phase: the hand's proximity signal (largest over the hand patch).
    Distance {
        /// Proximity signal \[0, 1\].
        proximity_signal: f64,
    },
}

/// Time constant of the braking toward the approach bound \[s\] (a few control cycles).
pub const APPROACH_BRAKE_S: f64 = 0.02;

/// The largest closing speed toward a surface sensed `distance_m` ahead \[m/s\]:
/// `v_0 + d / T_a` (a surface out of the proximity range reads as the range).
pub fn approach_speed_limit(params: &HandForceParams, distance_m: f64) -> f64 {
    params.approach_speed_min_mps + distance_m.max(0.0) / params.approach_time_s
}

/// Hand force/distance task.
#[derive(Debug, Clone)]
pub struct HandForce {
    /// Hand frame `{h}` (z into the surface).
    pub frame: usize,
    /// Gains and set points.
    pub params: HandForceParams,
    /// `f_c,d` of eq. (9) in signal units (the cycle's [`crate::tasks::HandSignals::force_reference`]).
    pub force_signal_desired: f64,
    rows: PointRows,
}

impl HandForce {
    /// The task for `frame` on a model with `nv` joints; its level needs 1 row.
    pub fn new(nv: usize, frame: usize, params: HandForceParams) -> Self {
        Self { frame, params, force_signal_desired: 0.0, rows: PointRows::new(nv) }
    }

    /// The error `Δ` of eq. (9) for a measurement (positive: push along `+z_h`).
    pub fn error(&self, measurement: HandMeasurement, proximity: &ProximityCharacteristic) -> f64 {
        match measurement {
            HandMeasurement::Force { fused_signal } => {
                self.params.k_force_n_per_signal * (self.force_signal_desired - fused_signal)
            }
            HandMeasurement::Distance { proximity_signal } => {
                self.params.k_distance_n_per_m
                    * (proximity.distance_m(proximity_signal) - self.params.distance_desired_m)
            }
        }
    }

    /// Fills `level` (1 acceleration row); returns `ẍ*`. `proximity_signal` is the hand's
    /// proximity (largest over the hand patch): it bounds the closing speed in either mode.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        measurement: HandMeasurement,
        proximity_signal: f64,
        proximity: &ProximityCharacteristic,
        level: &mut TaskLevel,
    ) -> Result<f64, TaskError> {
        self.rows.update(model, data, self.frame, &Vector3::zeros())?;
        let z = data.frame_pose(self.frame).rotation * Vector3::z();
        let v = self.rows.velocity(LINEAR, data.qd());
        let w = self.rows.velocity(ANGULAR, data.qd());
        let a = self.rows.drift(LINEAR);
        let jdot_qdot = z.dot(&a) + w.cross(&z).dot(&v);
        let closing = z.dot(&v);
        let eq9 = (self.error(measurement, proximity) - self.params.d_n_s_per_m * closing) / self.params.lambda_kg;
        let limit = approach_speed_limit(&self.params, proximity.distance_m(proximity_signal));
        let xdd = eq9.min((limit - closing) / APPROACH_BRAKE_S);
        level.clear();
        level.push_directional(
            z.as_slice(),
            &self.rows.jac.fixed_rows::<3>(LINEAR),
            Reference::Acceleration { xdd_star: &[xdd], jdot_qdot: &[jdot_qdot] },
        )?;
        Ok(xdd)
    }
}

impl Task for HandForce {
    fn name() -> &'static str {
        "hand_force"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(1))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.end_effector, s.params.hand_force))
    }

    /// Eq. (9) on the fused hand signal toward the reference of this cycle.
    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.force_signal_desired = cx.hand.force_reference;
        let m = HandMeasurement::Force { fused_signal: cx.hand.fused_force };
        self.update(cx.model, cx.data, m, cx.hand.proximity, &cx.skin.proximity, level).map(drop)
    }
}

/// `hand_distance`: the hand task of eq. (9) on the hand's proximity (the approach).
#[derive(Debug, Clone)]
pub struct HandDistance(pub HandForce);

impl Task for HandDistance {
    fn name() -> &'static str {
        "hand_distance"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(1))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        HandForce::build(s).map(HandDistance)
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        let m = HandMeasurement::Distance { proximity_signal: cx.hand.proximity };
        self.0.update(cx.model, cx.data, m, cx.hand.proximity, &cx.skin.proximity, level).map(drop)
    }
}
