//! Interactive-force-control paper eq. (4), Table 1 (contact phase): Cartesian position hold of the hand at its
//! position when the phase began, `x_d = x_ef,init`: `ẍ* = Λ⁻¹(K Δx − D ẋ)`, `Δx = x_d − x`
//! (`ẍ_d = 0`, no external wrench term), 3 world-aligned linear rows.

use nalgebra::{Point3, Vector3};

use super::error::TaskError;
use super::params::Impedance3;
use super::point_rows::{PointRows, LINEAR};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use super::terms::impedance_acceleration;
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};

/// Cartesian position hold task.
#[derive(Debug, Clone)]
pub struct PositionHold {
    /// Frame whose point is held.
    pub frame: usize,
    /// Point in the frame \[m\].
    pub point: Vector3<f64>,
    /// `Λ`, `K`, `D` diagonals (world axes).
    pub params: Impedance3,
    /// Held position `x_d` (world) \[m\].
    pub target: Vector3<f64>,
    rows: PointRows,
}

impl PositionHold {
    /// The task for `point` of `frame` on a model with `nv` joints; its level needs 3 rows.
    /// The target starts at the origin: call [`PositionHold::capture`] when the phase begins.
    pub fn new(nv: usize, frame: usize, point: Vector3<f64>, params: Impedance3) -> Self {
        Self { frame, point, params, target: Vector3::zeros(), rows: PointRows::new(nv) }
    }

    /// Sets `x_d = x_ef,init`, the current world position of the point.
    pub fn capture(&mut self, data: &ModelData) {
        self.target = (data.frame_pose(self.frame) * Point3::from(self.point)).coords;
    }

    /// Fills `level` (3 acceleration rows); returns `ẍ*`.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        level: &mut TaskLevel,
    ) -> Result<Vector3<f64>, TaskError> {
        self.rows.update(model, data, self.frame, &self.point)?;
        let x = (data.frame_pose(self.frame) * Point3::from(self.point)).coords;
        let v = self.rows.velocity(LINEAR, data.qd());
        let xdd = impedance_acceleration(&self.params, &(self.target - x), &v);
        self.rows.set_acceleration(level, LINEAR, &xdd)?;
        Ok(xdd)
    }
}

impl Task for PositionHold {
    fn name() -> &'static str {
        "position_hold"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(3))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.end_effector, Vector3::zeros(), s.params.position_hold))
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.update(cx.model, cx.data, level).map(drop)
    }

    fn on_switch(&mut self, data: &ModelData) {
        self.capture(data);
    }
}
