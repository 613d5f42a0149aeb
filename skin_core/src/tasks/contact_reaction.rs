//! Intentional-contact paper eq. (6): contact reaction as a force level, one directional row per contact cell.
//!
//! Sign choice: the touching object is outside the link, along the cell's outward normal `+n_i`;
//! the measured contact force on the robot points inward (`−n_i`). The reaction yields to the
//! contact: its task force `F_ci = gain · F_i`, the measured cell force as eq. (6) prints it times a
//! documented gain (no cap: a harder contact is met with a harder reaction), acts along `−n_i`,
//! i.e. the row is
//! `(−n_i)ᵀ J_v(p_i)` with a positive force, so the touched point accelerates away from the object
//! (`n_iᵀ J_v M⁻¹ τ < 0` at rest), relieving the contact. `F_i` \[N\] comes from the inverse force
//! characteristic of the cell's force signal, for cells above the activity threshold. A row's
//! activation in the null-space projector rises smoothly with `F_i` (`activation_force_n`).

use nalgebra::Vector3;

use super::error::TaskError;
use super::params::ContactReactionParams;
use super::point_rows::{push_inward_cell_row, row_activation};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};
use crate::skin::aggregate::{FusionParams, LengthMismatch};
use crate::skin::characteristic::{ForceCharacteristic, PreparedForce};
use crate::skin::layout::{ResolvedCell, ResolvedLayout};
use crate::skin::live::LiveCells;

/// Contact reaction over all cells of a layout.
#[derive(Debug, Clone)]
pub struct ContactReaction {
    /// Gain and row activation.
    pub params: ContactReactionParams,
    /// The cells' force characteristic (signal to newtons), prepared once.
    force: PreparedForce,
    /// Scratch: one cell's Jacobian row.
    row: Vec<f64>,
    /// Scratch per model frame: its cells' measured forces, summed.
    link_press: Vec<LinkPress>,
}

/// One link's contact this cycle (link frame): its cells' measured forces `F_i` along their
/// outward normals `n_i`, summed, and the point where they press.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinkContact {
    /// The link's model frame.
    pub frame: usize,
    /// `Σ F_i n_i` \[N\]: its norm is the link's contact force, its direction the way the link
    /// presses into what it touches.
    pub force: Vector3<f64>,
    /// `Σ F_i p_i / Σ F_i`, the force-weighted mean of the pressed cells' positions \[m\].
    pub point: Vector3<f64>,
}

/// Sums of one link's pressed cells.
#[derive(Debug, Clone, Copy, Default)]
struct LinkPress {
    /// `Σ F_i n_i`.
    force: Vector3<f64>,
    /// `Σ F_i p_i`.
    weighted_points: Vector3<f64>,
    /// `Σ F_i`.
    total_n: f64,
}

/// Summary of one contact-reaction update, for the supervisor.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactSummary {
    /// Rows pushed (contact cells).
    pub rows: usize,
    /// Largest task force `F_ci = gain · F_i` \[N\].
    pub max_force_n: f64,
    /// The link pressed hardest (the largest `‖Σ F_i n_i‖`), if any cell is in contact.
    pub pressed: Option<LinkContact>,
}

impl ContactReaction {
    /// The task for a model with `nv` joints and `nframes` frames and cells with the force
    /// characteristic `force`; its level needs `layout.num_cells()` rows.
    pub fn new(nv: usize, nframes: usize, params: ContactReactionParams, force: &ForceCharacteristic) -> Self {
        Self { params, force: force.prepared(), row: vec![0.0; nv], link_press: vec![LinkPress::default(); nframes] }
    }

    /// Fills `level` (force rows) from the non-silent cells of this cycle's readings.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        fusion: &FusionParams,
        level: &mut TaskLevel,
    ) -> Result<ContactSummary, TaskError> {
        level.clear();
        let row = &mut self.row;
        self.params.contact_cells(layout, cells, &self.force, fusion, &mut self.link_press, |cell, fa| {
            push_inward_cell_row(model, data, cell, fa, row, level)
        })
    }

    /// The summary [`Self::update`] would return, without the rows (no Jacobians).
    pub fn summarize(
        &mut self,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        fusion: &FusionParams,
    ) -> Result<ContactSummary, TaskError> {
        self.params.contact_cells(layout, cells, &self.force, fusion, &mut self.link_press, |_, _| Ok(()))
    }
}

impl ContactReactionParams {
    /// Calls `row(cell, (F_ci, a_i))` for every cell in contact (eq. 6) and sums them up; `a_i`
    /// rises with the measured force up to `activation_force_n`. Only the non-silent cells can
    /// be in contact (a silent cell's force signal is 0). `links` (one per model frame) is
    /// scratch for the links' sums, in the same pass.
    fn contact_cells(
        &self,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        force: &PreparedForce,
        fusion: &FusionParams,
        links: &mut [LinkPress],
        mut row: impl FnMut(&ResolvedCell, (f64, f64)) -> Result<(), TaskError>,
    ) -> Result<ContactSummary, TaskError> {
        LengthMismatch::check_count(layout, cells.num_cells())?;
        let mut s = ContactSummary::default();
        links.fill(LinkPress::default());
        for (i, reading) in cells.cells() {
            let Some(measured) = fusion.cell_force_n(reading, force) else {
                continue;
            };
            let cell = &layout.cells()[*i];
            let f = self.gain * measured;
            row(cell, (f, row_activation(measured, self.activation_force_n)))?;
            s.rows += 1;
            s.max_force_n = s.max_force_n.max(f);
            let link = &mut links[cell.frame];
            link.force += cell.normal_link * measured;
            link.weighted_points += cell.position_link * measured;
            link.total_n += measured;
        }
        for (frame, link) in links.iter().enumerate().filter(|(_, l)| l.total_n > 0.0) {
            if link.force.norm() > s.pressed.map_or(0.0, |p| p.force.norm()) {
                s.pressed = Some(LinkContact { frame, force: link.force, point: link.weighted_points / link.total_n });
            }
        }
        Ok(s)
    }
}

impl Task for ContactReaction {
    fn name() -> &'static str {
        "contact_reaction"
    }

    fn role() -> Role {
        Role::Level(Rows::PerCell)
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.model.nframes(), s.params.contact_reaction, &s.skin.force))
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.update(cx.model, cx.data, cx.layout, cx.cells, &cx.skin.fusion, level).map(drop)
    }
}
