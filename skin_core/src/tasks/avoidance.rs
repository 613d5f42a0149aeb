//! Intentional-contact paper eq. (3)-(4): proximity avoidance as a force level, one directional row per cell.
//!
//! For every cell `i` whose proximity signal gives a distance `d_i < d_range` (inverse proximity
//! characteristic), the row is `(−n_i)ᵀ J_v(p_i)` (world inward normal, cell position) and its
//! force `F_di = K (d_range − d_i) ≥ 0`, so the level's torque is `Σ J_v(p_i)ᵀ (−n_i) F_di`
//! (eq. 4): the link is pushed away from the obstacle, which is outside along `+n_i`.
//! `d_range` is given per cycle: the supervisor shrinks it (0 disables the task).
//!
//! A row enters the null-space projector with an activation that rises smoothly over the outer
//! `activation_band_m` of the range (`docs/tasks.md`): a cell entering the range changes neither
//! the torque (`F_di = 0` there) nor the projector of the lower levels by a step.

use super::error::TaskError;
use super::params::AvoidanceParams;
use super::point_rows::{push_inward_cell_row, row_activation};
use super::task::{Cycle, Role, Rows, Task, TaskSetup};
use crate::hierarchy::TaskLevel;
use crate::model::{ModelData, RobotModel};
use crate::skin::aggregate::LengthMismatch;
use crate::skin::layout::{ResolvedCell, ResolvedLayout};
use crate::skin::live::LiveCells;
use crate::skin::repulsion::linear_repulsion;

/// Proximity avoidance over all cells of a layout.
#[derive(Debug, Clone)]
pub struct ProximityAvoidance {
    /// `K` and the nominal `d_range`.
    pub params: AvoidanceParams,
    /// Scratch: one cell's Jacobian row.
    row: Vec<f64>,
}

/// Summary of one avoidance update, for the supervisor.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AvoidanceSummary {
    /// Rows pushed (cells within range).
    pub rows: usize,
    /// `‖F_d‖`: Euclidean norm of the per-cell forces \[N\].
    pub force_norm_n: f64,
    /// Largest single `F_di` \[N\].
    pub max_force_n: f64,
    /// Smallest distance seen \[m\] (`f64::INFINITY` if none within range).
    pub min_distance_m: f64,
}

impl ProximityAvoidance {
    /// The task for a model with `nv` joints; its level needs `layout.num_cells()` rows.
    pub fn new(nv: usize, params: AvoidanceParams) -> Self {
        Self { params, row: vec![0.0; nv] }
    }

    /// Fills `level` (force rows) from the non-silent cells of this cycle's readings (with their
    /// distances) with the sensing range `range_m` of this cycle, capped by the proximity
    /// characteristic's range.
    pub fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        range_m: f64,
        level: &mut TaskLevel,
    ) -> Result<AvoidanceSummary, TaskError> {
        level.clear();
        let row = &mut self.row;
        self.params
            .cells_in_range(layout, cells, range_m, |cell, fa| push_inward_cell_row(model, data, cell, fa, row, level))
    }

    /// The summary [`Self::update`] would return, without the rows (no Jacobians): what the
    /// supervisor needs when the task is not in the active arrangement.
    pub fn summarize(
        &self,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        range_m: f64,
    ) -> Result<AvoidanceSummary, TaskError> {
        self.params.cells_in_range(layout, cells, range_m, |_, _| Ok(()))
    }
}

impl AvoidanceParams {
    /// Calls `row(cell, (F_di, a_i))` for every cell within the range (eq. 3) and sums them up;
    /// `a_i` is the row's activation over the outer `activation_band_m` of the range. Only the
    /// non-silent cells can be in range (a silent cell's proximity signal is 0); their distances
    /// `d_i` come with them ([`LiveCells::distances`]).
    fn cells_in_range(
        &self,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        range_m: f64,
        mut row: impl FnMut(&ResolvedCell, (f64, f64)) -> Result<(), TaskError>,
    ) -> Result<AvoidanceSummary, TaskError> {
        LengthMismatch::check_count(layout, cells.num_cells())?;
        let mut s = AvoidanceSummary { min_distance_m: f64::INFINITY, ..Default::default() };
        let range = range_m.min(cells.proximity_range_m());
        if range.is_nan() || range <= 0.0 {
            return Ok(s);
        }
        let band = self.activation_band_m.min(range);
        let mut sum_sq = 0.0;
        // a cell without proximity signal is at `range_m`, out of range
        for ((i, _), &d) in cells.cells().iter().zip(cells.distances()) {
            if d >= range {
                continue;
            }
            let f = linear_repulsion(self.gain_n_per_m, range, d);
            row(&layout.cells()[*i], (f, row_activation(range - d, band)))?;
            s.rows += 1;
            sum_sq += f * f;
            s.max_force_n = s.max_force_n.max(f);
            s.min_distance_m = s.min_distance_m.min(d);
        }
        s.force_norm_n = sum_sq.sqrt();
        Ok(s)
    }
}

impl Task for ProximityAvoidance {
    fn name() -> &'static str {
        "avoidance"
    }

    fn role() -> Role {
        Role::Level(Rows::PerCell)
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(Self::new(s.model.nv(), s.params.avoidance))
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        self.update(cx.model, cx.data, cx.layout, cx.cells, cx.sensing_range_m, level).map(drop)
    }
}
