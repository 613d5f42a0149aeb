//! Paper 000 eq. (6): contact reaction as a force level, one directional row per contact cell.
//!
//! Sign choice: the touching object is outside the link, along the cell's outward normal `+n_i`;
//! the measured contact force on the robot points inward (`−n_i`). The reaction yields to the
//! contact: its task force `F_ci = min(gain · F_i, F_max)` acts along `−n_i`, i.e. the row is
//! `(−n_i)ᵀ J_v(p_i)` with a positive force, so the touched point accelerates away from the object
//! (`n_iᵀ J_v M⁻¹ τ < 0` at rest), relieving the contact. `F_i` \[N\] comes from the inverse force
//! characteristic of the cell's force signal, for cells above the activity threshold.

use nalgebra::Matrix6xX;

use super::params::ContactReactionParams;
use super::point_rows::push_inward_cell_row;
use super::TaskError;
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};
use crate::skin::aggregate::{FusionParams, LengthMismatch};
use crate::skin::characteristic::ForceCharacteristic;
use crate::skin::layout::ResolvedLayout;
use crate::skin::signals::CellReading;

/// Contact reaction over all cells of a layout.
#[derive(Debug, Clone)]
pub struct ContactReaction {
    /// Gain and saturation.
    pub params: ContactReactionParams,
    jac: Matrix6xX<f64>,
}

/// Summary of one contact-reaction update, for the supervisor.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactSummary {
    /// Rows pushed (contact cells).
    pub rows: usize,
    /// Largest task force `F_ci` \[N\] (`‖F_c‖` max).
    pub max_force_n: f64,
    /// Largest measured cell force `F_i` \[N\].
    pub max_measured_n: f64,
}

impl ContactReaction {
    /// The task for a model with `nv` joints; its level needs `layout.num_cells()` rows.
    pub fn new(nv: usize, params: ContactReactionParams) -> Self {
        Self { params, jac: Matrix6xX::zeros(nv) }
    }

    /// Fills `level` (force rows) from `readings` (indexed like `layout.cells()`).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        readings: &[CellReading],
        force: &ForceCharacteristic,
        fusion: &FusionParams,
        level: &mut TaskLevel,
    ) -> Result<ContactSummary, TaskError> {
        LengthMismatch::check_readings(layout, readings)?;
        level.clear();
        let mut s = ContactSummary::default();
        let force = force.prepared();
        for (cell, reading) in layout.cells().iter().zip(readings) {
            let sig = reading.force_signal(fusion.force_reduction);
            if sig <= fusion.activity_threshold {
                continue;
            }
            let measured = force.force_n(sig);
            let f = (self.params.gain * measured).min(self.params.max_force_n);
            push_inward_cell_row(model, data, cell, f, &mut self.jac, level)?;
            s.rows += 1;
            s.max_force_n = s.max_force_n.max(f);
            s.max_measured_n = s.max_measured_n.max(measured);
        }
        Ok(s)
    }
}
