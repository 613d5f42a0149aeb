//! The skin's approach bound (`docs/resolver.md`): for every cell that senses a surface, the
//! speed at which its point closes on it, `nᵀ J_v(p) q̇`, limited to the bound at the sensed
//! distance and force, as a limit the resolver meets.

use crate::model::{point_jacobian_along, ModelData, ModelError, RobotModel};
use crate::resolver::{ApproachParams, ClosingBounds};
use crate::skin::aggregate::FusionParams;
use crate::skin::characteristic::PreparedForce;
use crate::skin::layout::ResolvedLayout;
use crate::skin::live::LiveCells;

/// The rule of the limits, one per cell within the proximity range.
#[derive(Debug, Clone)]
pub(crate) struct ApproachBound {
    params: ApproachParams,
    /// `ε_c` of intentional-contact paper Table I \[N\]: no cell is pushed into it.
    force_limit_n: f64,
    force: PreparedForce,
    /// Scratch: one cell's row.
    row: Vec<f64>,
}

impl ApproachBound {
    /// The bound on a model with `nv` joints; no cell is pushed into a force of `force_limit_n`
    /// (`ε_c`), read through `force`.
    pub(crate) fn new(params: ApproachParams, force_limit_n: f64, force: PreparedForce, nv: usize) -> Self {
        Self { params, force_limit_n, force, row: vec![0.0; nv] }
    }

    /// Room for the limits of a layout with `cells` cells.
    pub(crate) fn limits(&self, cells: usize) -> ClosingBounds {
        ClosingBounds::with_capacity(self.row.len(), if self.params.enabled { cells } else { 0 })
    }

    /// Sets `bounds` to the limits for the cells' readings at the state of the last kinematics
    /// update: the outward normal's row (closing is positive) and `v_t + d / time` for distance
    /// `d`. The touch speed `v_t` is `speed_min`, and 0 for a cell pressed at `ε_c` or more and in
    /// a hard contact that ends the push (`releasing`, [`crate::supervisor::Supervisor::releasing`]):
    /// nothing drives the body back into a contact the reaction relieves (the goal below the
    /// reaction did, a limit cycle of touches for the rest of the run).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        fusion: &FusionParams,
        releasing: bool,
        bounds: &mut ClosingBounds,
    ) -> Result<(), ModelError> {
        bounds.clear();
        if !self.params.enabled {
            return Ok(());
        }
        let p = &self.params;
        let range = cells.proximity_range_m();
        // a cell without proximity signal is at the range: it senses nothing
        for ((i, reading), &d) in cells.cells().iter().zip(cells.distances()) {
            if d >= range {
                continue;
            }
            let at_limit = fusion.cell_force_n(reading, &self.force).is_some_and(|f| f >= self.force_limit_n);
            let touch = if releasing || at_limit { 0.0 } else { p.speed_min_mps };
            let cell = &layout.cells()[*i];
            let outward = data.frame_pose(cell.frame).rotation * cell.normal_link;
            point_jacobian_along(model, data, cell.frame, &cell.position_link, &outward, &mut self.row)?;
            bounds.push(&self.row, touch + d / p.time_s);
        }
        Ok(())
    }
}
