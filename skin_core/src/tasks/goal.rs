//! Intentional-contact paper eq. (7)-(9): end-effector goal with speed saturation, as a force level.
//!
//! `ẋ_d = (k_p / k_v)(x_d − x)`, `ν = min(1, V_max / ‖ẋ_d‖)`, `F_g = −k_v (ẋ − ν ẋ_d)`.
//! [`GoalPosition`] uses the 3 linear rows of the point Jacobian (world axes; a planar robot
//! simply has a zero row out of its plane, which the rank-aware inverse tolerates).
//! [`GoalOrientation`] applies the same law to the 3 angular rows with the orientation error
//! `e = axis·angle(R_d Rᵀ)` (world axes) in place of `x_d − x`.

use nalgebra::{Matrix6xX, UnitQuaternion, Vector3};

use super::error::TaskError;
use super::params::GoalParams;
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use super::terms::rows_times_qd;
use crate::hierarchy::{Reference, TaskLevel};
use crate::model::{point_jacobian, ModelData, RobotModel};

/// Eq. (7)-(9) on a 3-vector error: returns `F_g` for the error `e = x_d − x` and velocity `v`.
pub fn saturated_goal_force(params: &GoalParams, error: &Vector3<f64>, velocity: &Vector3<f64>) -> Vector3<f64> {
    let xd_dot = error * (params.kp_n_per_m / params.kv_n_s_per_m);
    let norm = xd_dot.norm();
    let nu = if norm > params.v_max_m_per_s { params.v_max_m_per_s / norm } else { 1.0 };
    -(velocity - xd_dot * nu) * params.kv_n_s_per_m
}

/// End-effector position goal (intentional-contact paper eq. 7-9): 3 force rows at a point of a frame.
#[derive(Debug, Clone)]
pub struct GoalPosition {
    /// Frame (link) index of the end effector.
    pub frame: usize,
    /// Controlled point in the frame \[m\].
    pub point: Vector3<f64>,
    /// Gains and speed limit.
    pub params: GoalParams,
    jac: Matrix6xX<f64>,
    force: Vector3<f64>,
}

impl GoalPosition {
    /// A goal task for `point` of `frame` on a model with `nv` joints.
    pub fn new(nv: usize, frame: usize, point: Vector3<f64>, params: GoalParams) -> Self {
        Self { frame, point, params, jac: Matrix6xX::zeros(nv), force: Vector3::zeros() }
    }

    /// Fills `level` (3 rows, [`Reference::Force`]) for the goal `x_d` (world) at the state of the
    /// last `update_kinematics`. Returns `F_g`.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        x_d: &Vector3<f64>,
        level: &mut TaskLevel,
    ) -> Result<Vector3<f64>, TaskError> {
        point_jacobian(model, data, self.frame, &self.point, &mut self.jac)?;
        let x = data.frame_pose(self.frame) * nalgebra::Point3::from(self.point);
        let v = rows_times_qd(&self.jac, 0, data.qd());
        self.force = saturated_goal_force(&self.params, &(x_d - x.coords), &v);
        level.set(&self.jac.fixed_rows::<3>(0), Reference::Force { f: self.force.as_slice() })?;
        Ok(self.force)
    }
}

/// End-effector orientation goal: the law of intentional-contact paper eq. (7)-(9) on the angular rows.
#[derive(Debug, Clone)]
pub struct GoalOrientation {
    /// Frame (link) index of the end effector.
    pub frame: usize,
    /// Gains (N m/rad, N m s/rad) and angular speed limit (rad/s).
    pub params: GoalParams,
    jac: Matrix6xX<f64>,
    moment: Vector3<f64>,
}

impl GoalOrientation {
    /// An orientation goal task for `frame` on a model with `nv` joints.
    pub fn new(nv: usize, frame: usize, params: GoalParams) -> Self {
        Self { frame, params, jac: Matrix6xX::zeros(nv), moment: Vector3::zeros() }
    }

    /// Fills `level` (3 angular rows, [`Reference::Force`]) for the desired world orientation
    /// `r_d`; returns the task moment.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        r_d: &UnitQuaternion<f64>,
        level: &mut TaskLevel,
    ) -> Result<Vector3<f64>, TaskError> {
        point_jacobian(model, data, self.frame, &Vector3::zeros(), &mut self.jac)?;
        let r = data.frame_pose(self.frame).rotation;
        // R_d Rᵀ: the world-frame rotation that takes the current orientation to the goal.
        let error = (r_d * r.inverse()).scaled_axis();
        let w = rows_times_qd(&self.jac, 3, data.qd());
        self.moment = saturated_goal_force(&self.params, &error, &w);
        level.set(&self.jac.fixed_rows::<3>(3), Reference::Force { f: self.moment.as_slice() })?;
        Ok(self.moment)
    }
}

impl Task for GoalPosition {
    fn name() -> &'static str {
        "goal"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(3))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.end_effector, Vector3::zeros(), s.params.goal))
    }

    /// Empty without a goal.
    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        match cx.goal {
            Some(goal) => self.update(cx.model, cx.data, &goal.translation.vector, level).map(drop),
            None => Ok(()),
        }
    }
}

impl Task for GoalOrientation {
    fn name() -> &'static str {
        "goal_orientation"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(3))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.end_effector, s.params.goal_orientation))
    }

    /// Empty without a goal.
    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        match cx.goal {
            Some(goal) => self.update(cx.model, cx.data, &goal.rotation, level).map(drop),
            None => Ok(()),
        }
    }
}
