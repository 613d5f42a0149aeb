//! The skin's approach bound (`docs/resolver.md`): for every cell that senses a surface, the
//! speed at which its point closes on it, `nᵀ J_v(p) q̇`, limited to the bound at the sensed
//! distance and force, as a limit the resolver meets. A link that pushes something that gives
//! way pushes faster than it touches.

use crate::model::{point_jacobian_along, ModelData, ModelError, RobotModel};
use crate::resolver::{ApproachParams, ClosingBounds};
use crate::skin::aggregate::FusionParams;
use crate::skin::characteristic::PreparedForce;
use crate::skin::layout::ResolvedLayout;
use crate::skin::live::LiveCells;
use crate::supervisor::Thresholds;

/// What the active arrangement asks of the skin's contacts (intentional-contact paper Table I).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ContactIntent {
    /// (b): push what gives way.
    Push,
    /// (a) and the interactive-force-control paper phases: touch at most at the touch speed.
    Touch,
    /// (c) and the hold after a push given up ([`crate::supervisor::Supervisor::releasing`]):
    /// press nothing.
    Release,
}

/// Contact force levels of intentional-contact paper Table I that the bound reads \[N\].
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactLevels {
    /// No contact at or below this (Table I (a): `‖F_c‖ = 0`).
    pub(crate) zero_n: f64,
    /// A hard contact is released below this (`ε_c` − band): a push under it gives way.
    pub(crate) release_n: f64,
    /// `ε_c`: no cell is pushed into it.
    pub(crate) limit_n: f64,
}

impl ContactLevels {
    /// The levels of the supervisor's thresholds.
    pub(crate) fn of(th: &Thresholds) -> Self {
        Self {
            zero_n: th.contact_zero_n,
            release_n: th.contact_force_n - th.contact_band_n,
            limit_n: th.contact_force_n,
        }
    }
}

/// The rule of the limits, one per cell within the proximity range.
#[derive(Debug, Clone)]
pub(crate) struct ApproachBound {
    params: ApproachParams,
    levels: ContactLevels,
    force: PreparedForce,
    /// Per model frame: the speed at contact of the link's cells \[m/s\] (`speed_min_mps` up to
    /// `push_speed_max_mps` while the link pushes something that gives way).
    push_mps: Vec<f64>,
    /// Scratch per model frame: the force on the link's cells this cycle \[N\].
    pressed_n: Vec<f64>,
    /// Scratch per model frame: the largest force on one of the link's cells this cycle \[N\].
    hardest_n: Vec<f64>,
    /// Scratch per live cell: its measured force this cycle \[N\] (0 below the threshold).
    forces_n: Vec<f64>,
    /// Scratch: one cell's row.
    row: Vec<f64>,
}

impl ApproachBound {
    /// The bound on a model with `nv` joints and `nframes` frames and a layout of `cells` cells;
    /// the contact `levels` are read through `force`.
    pub(crate) fn new(
        params: ApproachParams,
        levels: ContactLevels,
        force: PreparedForce,
        nv: usize,
        nframes: usize,
        cells: usize,
    ) -> Self {
        Self {
            params,
            levels,
            force,
            push_mps: vec![params.speed_min_mps; nframes],
            pressed_n: vec![0.0; nframes],
            hardest_n: vec![0.0; nframes],
            forces_n: Vec::with_capacity(cells),
            row: vec![0.0; nv],
        }
    }

    /// Room for the limits of every cell of the layout.
    pub(crate) fn limits(&self) -> ClosingBounds {
        let rows = if self.params.enabled { self.forces_n.capacity() } else { 0 };
        ClosingBounds::with_capacity(self.row.len(), rows)
    }

    /// Sets `bounds` to the limits for the cells' readings at the state of the last kinematics
    /// update, `dt_s` after the last: the outward normal's row (closing is positive) and
    /// `v_c + d / time` for distance `d`. The speed at contact `v_c` of a link's cells is
    /// - 0 for a cell pressed at `ε_c` or more, and in a hard contact and the hold after a push
    ///   given up ([`ContactIntent::Release`]): nothing drives the body back into a contact the
    ///   reaction relieves (the goal below the reaction did, a limit cycle of touches for the rest
    ///   of the run);
    /// - in a push ([`ContactIntent::Push`]), growing by `push_accel_mps2` up to
    ///   `push_speed_max_mps` while the link is in contact (its cells' forces sum above no
    ///   contact) and none of its cells is pressed at the release level of a hard contact (a
    ///   level of the supervisor's; compared per cell, not with the link's force `‖F_c‖`, which
    ///   sums a spread contact past it and stopped pushes, `docs/resolver.md`): it pushes something that
    ///   slides (a push at the touch speed would take 10 s for 20 cm); falling back as fast when
    ///   the pushed thing slid ahead out of contact, and at once to the touch speed when a cell
    ///   is pressed at that level;
    /// - otherwise the touch speed `speed_min_mps`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        fusion: &FusionParams,
        intent: ContactIntent,
        dt_s: f64,
        bounds: &mut ClosingBounds,
    ) -> Result<(), ModelError> {
        bounds.clear();
        if !self.params.enabled {
            return Ok(());
        }
        let (p, levels) = (&self.params, self.levels);
        self.pressed_n.fill(0.0);
        self.hardest_n.fill(0.0);
        self.forces_n.clear(); // within capacity: one per layout cell at most
        for (i, reading) in cells.cells() {
            let f = fusion.cell_force_n(reading, &self.force).unwrap_or(0.0);
            let frame = layout.cells()[*i].frame;
            self.pressed_n[frame] += f;
            self.hardest_n[frame] = self.hardest_n[frame].max(f);
            self.forces_n.push(f);
        }
        let dt = if dt_s.is_finite() { dt_s.max(0.0) } else { 0.0 };
        let (touch, fastest, dv) = (p.speed_min_mps, p.push_speed_max_mps, p.push_accel_mps2 * dt);
        for ((v, &f), &hardest) in self.push_mps.iter_mut().zip(&self.pressed_n).zip(&self.hardest_n) {
            *v = if intent != ContactIntent::Push {
                touch
            } else if f > levels.zero_n && hardest < levels.release_n {
                (*v + dv).min(fastest)
            } else if f <= levels.zero_n {
                (*v - dv).max(touch) // a pushed object that slid ahead: the push goes on
            } else {
                touch // NaN too
            };
        }
        let range = cells.proximity_range_m();
        // a cell without proximity signal is at the range: it senses nothing
        for (((i, _), &d), &f) in cells.cells().iter().zip(cells.distances()).zip(&self.forces_n) {
            if d >= range {
                continue;
            }
            let cell = &layout.cells()[*i];
            let at_limit = f >= levels.limit_n;
            let contact = if intent == ContactIntent::Release || at_limit { 0.0 } else { self.push_mps[cell.frame] };
            let outward = data.frame_pose(cell.frame).rotation * cell.normal_link;
            point_jacobian_along(model, data, cell.frame, &cell.position_link, &outward, &mut self.row)?;
            bounds.push(&self.row, contact + d / p.time_s);
        }
        Ok(())
    }
}
