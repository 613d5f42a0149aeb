//! Interactive-force-control paper eq. (9), Table 1: hand force / distance control on one acceleration row.
//!
//! Frame `{h}`: the hand frame, its z axis along the palm's outward normal, i.e. into the surface
//! to be touched. The row is the third row of the hand body Jacobian, `z_hᵀ J_v(o_h)` (world
//! `z_h` from the frame pose), and
//! `ẍ* = (K_1 Δ − D_1 ż_h) / Λ_1` (eq. 9) with
//! - force mode (contact phase): `Δ = f_c,d − f_c` in newtons, `f_c = Σ_i c_i f⁻¹(s_i)` the
//!   pressed hand cells' newtons along `z_h` (`skin::measured`: the summed signal of the paper
//!   reads an edge or a corner of the palm low, saturated cells barely at all, so the hand
//!   pushed on; in newtons the gain is the same whatever the distribution);
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
//!
//! Making contact (the paper's "this causes the robot to make contact with the object"): before
//! the touch the force error is the whole reference, and eq. (9) closes the gap at
//! `K_1 f_c,d / D_1`, 3.7 mm/s for a 2.3 N reference (8.5 s for the 3 cm the approach phase left).
//! So in force mode, untouched and with a surface in proximity range, the hand closes at the
//! approach bound itself: the touch comes at the same time and speed whatever the reference.
//!
//! Tracking a moving reference: the loop of eq. (9) through the velocity servo and the contact
//! lags the reference by about its time constant, so the force error is taken against the led
//! reference `f_c,d + T_l ḟ_c,d` (`reference_lead_s`; 0: as printed).
//!
//! No offset in contact: the arm is velocity-servoed, and holding a force against a surface needs
//! a commanded velocity above the measured one, which eq. (9)'s proportional law only gives with a
//! lasting error (the force settled 0.1 N under a 6 N reference; a moving base pressed the hand
//! 0.4 N off). While the hand is pressed, the error is `Δ + (1/T_i) ∫Δ dt`
//! (`integral_time_s`; 0: eq. 9 as printed): the integral starts at zero at every touch and
//! arrangement switch, does not grow while the approach bound brakes, and its term stays within
//! a share of the reference: a small one during the rise ([`RISE_INTEGRAL_SHARE`], the rise is
//! the proportional law's), a large one once the force has settled ([`INTEGRAL_SHARE`]).

use nalgebra::Vector3;

use super::error::TaskError;
use super::params::HandForceParams;
use super::point_rows::{PointRows, ANGULAR, LINEAR};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use crate::hierarchy::{Reference, TaskLevel};
use crate::model::{ModelData, RobotModel};
use crate::skin::characteristic::ProximityCharacteristic;

/// What the hand task regulates this cycle (interactive-force-control paper Table 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HandMeasurement {
    /// Contact phase: the hand's force `f_c` along `z_h`.
    Force {
        /// `f_c` \[N\] (the pressed hand cells' newtons, `skin::measured`).
        force_n: f64,
    },
    /// Approach phase: the hand's proximity signal (largest over the hand patch).
    Distance {
        /// Proximity signal \[0, 1\].
        proximity_signal: f64,
    },
}

/// Time constant of the braking toward the approach bound \[s\] (a few control cycles).
pub const APPROACH_BRAKE_S: f64 = 0.02;

/// The integral term of the force error stays within this share of the reference once the
/// force has settled (come within [`INTEGRAL_BAND`] of it since the touch). It makes up what the
/// proportional law leaves: the velocity servo's offset, and a moving base pressing the hand
/// (the campaign's force family, its base scenes of radius 0.26-0.30 m: RMS w/ 0.38-0.49 N with
/// 0.1, 0.21-0.27 N with 0.5 and `integral_time_s` 0.5 s).
pub const INTEGRAL_SHARE: f64 = 0.5;

/// The share during the rise, before the force has settled: a small one, so that the force
/// reaches its reference without creeping and without overshooting it (force family, seeds
/// 1 + 2, Table 3 met / rises over 2 s: none 96 / 5 of 100 scenes, 0.05 96 / 1, 0.1 92 / 0).
pub const RISE_INTEGRAL_SHARE: f64 = 0.05;

/// The force has settled once it comes within this share of its reference since the touch.
pub const INTEGRAL_BAND: f64 = 0.05;

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
    /// `f_c,d` of eq. (9) \[N\] (the cycle's [`crate::tasks::HandSignals::force_reference_n`]).
    pub force_desired_n: f64,
    /// `∫Δ dt` of the force error since the touch \[N s\].
    integral: f64,
    /// The approach bound braked in the last update.
    braking: bool,
    /// The force came within [`INTEGRAL_BAND`] of its reference since the touch.
    settled: bool,
    /// The last cycle's reference, for its rate \[N\].
    previous_reference_n: Option<f64>,
    /// `Ḟ_c,d` \[N/s\].
    reference_rate: f64,
    rows: PointRows,
}

impl HandForce {
    /// The task for `frame` on a model with `nv` joints; its level needs 1 row.
    pub fn new(nv: usize, frame: usize, params: HandForceParams) -> Self {
        Self {
            frame,
            params,
            force_desired_n: 0.0,
            integral: 0.0,
            braking: false,
            settled: false,
            previous_reference_n: None,
            reference_rate: 0.0,
            rows: PointRows::new(nv),
        }
    }

    /// Sets this cycle's reference `f_c,d`, a cycle of `dt_s` after the last one (its rate:
    /// zero on the first cycle after a switch).
    pub fn set_reference(&mut self, reference_n: f64, dt_s: f64) {
        self.force_desired_n = reference_n;
        self.reference_rate = self.previous_reference_n.map_or(0.0, |f| (reference_n - f) / dt_s);
        self.previous_reference_n = Some(reference_n);
    }

    /// Integrates the force error of a cycle of `dt_s` (module doc): only while the hand is
    /// pressed (`force_n > 0`, else back to zero), not upward while the approach bound brakes,
    /// its term within [`RISE_INTEGRAL_SHARE`] of `f_c,d` until the force has settled, then
    /// within [`INTEGRAL_SHARE`].
    pub fn integrate(&mut self, force_n: f64, dt_s: f64) {
        let t_i = self.params.integral_time_s;
        if t_i <= 0.0 || force_n <= 0.0 {
            self.integral = 0.0;
            self.settled = false;
            return;
        }
        let e = self.force_desired_n - force_n;
        self.settled |= e <= INTEGRAL_BAND * self.force_desired_n.abs();
        if self.braking && e > 0.0 {
            return;
        }
        let share = if self.settled { INTEGRAL_SHARE } else { RISE_INTEGRAL_SHARE };
        let limit = share * t_i * self.force_desired_n.abs();
        self.integral = (self.integral + e * dt_s).clamp(-limit, limit);
    }

    /// The error `Δ` of eq. (9) for a measurement (positive: push along `+z_h`); in force mode
    /// against the led reference `f_c,d + T_l ḟ_c,d` and with the integral term (module doc).
    pub fn error(&self, measurement: HandMeasurement, proximity: &ProximityCharacteristic) -> f64 {
        match measurement {
            HandMeasurement::Force { force_n } => {
                let t_i = self.params.integral_time_s;
                let integral = if t_i > 0.0 { self.integral / t_i } else { 0.0 };
                let led = self.force_desired_n + self.params.reference_lead_s * self.reference_rate;
                self.params.k_force_n_per_n * (led - force_n + integral)
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
        // Not yet touching a sensed surface: close at the approach bound (module doc).
        let untouched = matches!(measurement, HandMeasurement::Force { force_n } if force_n <= 0.0);
        let eq9 = if untouched && proximity_signal > 0.0 {
            f64::INFINITY
        } else {
            (self.error(measurement, proximity) - self.params.d_n_s_per_m * closing) / self.params.lambda_kg
        };
        let limit = approach_speed_limit(&self.params, proximity.distance_m(proximity_signal));
        let brake = (limit - closing) / APPROACH_BRAKE_S;
        self.braking = brake < eq9;
        let xdd = eq9.min(brake);
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

    /// Eq. (9) on the hand's newtons toward the reference of this cycle.
    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.set_reference(cx.hand.force_reference_n, cx.dt_s);
        self.integrate(cx.hand.force_n, cx.dt_s);
        let m = HandMeasurement::Force { force_n: cx.hand.force_n };
        self.update(cx.model, cx.data, m, cx.hand.proximity, &cx.skin.proximity, level).map(drop)
    }

    fn on_switch(&mut self, _data: &ModelData) {
        self.integral = 0.0;
        self.settled = false;
        self.previous_reference_n = None;
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
