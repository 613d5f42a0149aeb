//! The skin's approach bound (`docs/resolver.md`): for every cell that senses a surface, the
//! speed at which its point closes on it, `nᵀ J_v(p) q̇`, limited to the bound at the sensed
//! distance and force, as a limit the resolver meets. A link that pushes something that gives
//! way pushes faster than it touches, and holds its force under `ε_c`.

use super::press::Press;
use crate::model::{point_jacobian_along, ModelData, ModelError, RobotModel};
use crate::resolver::{ApproachParams, ClosingBounds};
use crate::skin::contacts::LinkForce;
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
    /// A push holds its link's force at this (`ε_c` − `push_margin_n`).
    pub(crate) push_n: f64,
    /// `ε_c`: no cell is pushed into it.
    pub(crate) limit_n: f64,
}

impl ContactLevels {
    /// The levels of the supervisor's thresholds.
    pub(crate) fn of(th: &Thresholds) -> Self {
        Self { zero_n: th.contact_zero_n, push_n: th.contact_force_n - th.push_margin_n, limit_n: th.contact_force_n }
    }
}

/// The rule of the limits, one per cell within the proximity range.
#[derive(Debug, Clone)]
pub(crate) struct ApproachBound {
    params: ApproachParams,
    levels: ContactLevels,
    /// Per model frame: the link's push.
    pushes: Vec<LinkPush>,
    /// Number of cells of the layout: at most one limit each.
    cells: usize,
    /// Scratch: one cell's row.
    row: Vec<f64>,
}

impl ApproachBound {
    /// The bound on a model with `nv` joints and `nframes` frames and the skin `layout`, at the
    /// contact `levels`.
    pub(crate) fn new(
        params: ApproachParams,
        levels: ContactLevels,
        nv: usize,
        nframes: usize,
        layout: &ResolvedLayout,
    ) -> Self {
        Self {
            params,
            levels,
            pushes: vec![LinkPush::at(params.speed_min_mps); nframes],
            cells: layout.num_cells(),
            row: vec![0.0; nv],
        }
    }

    /// Room for the limits of every cell of the layout.
    pub(crate) fn limits(&self) -> ClosingBounds {
        let rows = if self.params.enabled { self.cells } else { 0 };
        ClosingBounds::with_capacity(self.row.len(), rows)
    }

    /// Sets `bounds` to the limits for the live `cells` and their `press` at the state of the last
    /// kinematics update, `dt_s` after the last: the outward normal's row (closing is positive) and
    /// `v_c + d / time` for distance `d`. The speed at contact `v_c` of a link's cells is
    /// - 0 for a cell pressed at `ε_c` or more, and in a hard contact and the hold after a push
    ///   given up ([`ContactIntent::Release`]): nothing drives the body back into a contact the
    ///   reaction relieves (the goal below the reaction did, a limit cycle of touches for the rest
    ///   of the run);
    /// - in a push ([`ContactIntent::Push`]), regulated by the link's force `F`, the sum over its
    ///   contacts of their `‖Σ F_i n_i‖` ([`Press`]; the supervisor's `‖F_c‖` is the largest
    ///   link's), about its push force `F_p = ε_c − push_margin_n`:
    ///   under it, growing by `push_force_gain_mps2_per_n · (F_p − F)` per second, at most
    ///   `push_accel_mps2`, up to `push_speed_max_mps`: it pushes something that slides (a push
    ///   at the touch speed would take 10 s for 20 cm); over it, falling by the gain times the
    ///   excess, down to 0, and at once at most the touch speed unless the excess is a
    ///   stick-slip peak (over `F_p` for at most `push_peak_s`, and under `ε_c`): a link that
    ///   pushes what does not give way holds `F_p`, under `ε_c` by the margin a skin that reads
    ///   low needs, and a push that slides keeps going (`docs/resolver.md`). Falling back to the
    ///   touch speed when the pushed thing slid ahead out of contact (its cells' forces sum to no
    ///   contact);
    /// - otherwise the touch speed `speed_min_mps`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn update(
        &mut self,
        model: &RobotModel,
        data: &ModelData,
        layout: &ResolvedLayout,
        cells: &LiveCells,
        press: &Press,
        intent: ContactIntent,
        dt_s: f64,
        bounds: &mut ClosingBounds,
    ) -> Result<(), ModelError> {
        bounds.clear();
        if !self.params.enabled {
            return Ok(());
        }
        let (p, levels) = (&self.params, self.levels);
        let dt = if dt_s.is_finite() { dt_s.max(0.0) } else { 0.0 };
        if intent == ContactIntent::Push {
            for (push, link) in self.pushes.iter_mut().zip(press.links()) {
                push.regulate(*link, p, &levels, dt);
            }
        } else {
            self.pushes.fill(LinkPush::at(p.speed_min_mps));
        }
        let range = cells.proximity_range_m();
        // a cell without proximity signal is at the range: it senses nothing
        for (((i, _), &d), &f) in cells.cells().iter().zip(cells.distances()).zip(press.cell_forces_n()) {
            if d >= range {
                continue;
            }
            let cell = &layout.cells()[*i];
            let at_limit = f >= levels.limit_n;
            let contact =
                if intent == ContactIntent::Release || at_limit { 0.0 } else { self.pushes[cell.frame].speed_mps };
            let outward = data.frame_pose(cell.frame).rotation * cell.normal_link;
            point_jacobian_along(model, data, cell.frame, &cell.position_link, &outward, &mut self.row)?;
            bounds.push(&self.row, contact + d / p.time_s);
        }
        Ok(())
    }
}

/// One link's push regulator (the speed at contact of [`ApproachBound::update`]).
#[derive(Debug, Clone, Copy)]
struct LinkPush {
    /// The speed at contact of the link's cells \[m/s\]: 0 up to `push_speed_max_mps`.
    speed_mps: f64,
    /// How long the link's force has been over its push force \[s\].
    over_s: f64,
}

impl LinkPush {
    /// At `speed_mps`, out of contact.
    fn at(speed_mps: f64) -> Self {
        Self { speed_mps, over_s: 0.0 }
    }

    /// One cycle of the push with the link's force `link`, `dt_s` after the last.
    fn regulate(&mut self, link: LinkForce, p: &ApproachParams, levels: &ContactLevels, dt_s: f64) {
        let (f, v) = (link.contact_n, self.speed_mps);
        self.over_s = if f > levels.push_n { self.over_s + dt_s } else { 0.0 };
        self.speed_mps = if link.pressed_n <= levels.zero_n {
            (v - p.push_accel_mps2 * dt_s).max(p.speed_min_mps) // a pushed object that slid ahead: the push goes on
        } else if f <= levels.push_n {
            (v + dt_s * p.push_accel_mps2.min(p.push_force_gain_mps2_per_n * (levels.push_n - f)))
                .min(p.push_speed_max_mps)
        } else {
            // a stick-slip peak is brief and under eps_c; a stop lasts, a strike reaches eps_c
            let peak = self.over_s <= p.push_peak_s && f < levels.limit_n;
            let from = if peak { v } else { v.min(p.speed_min_mps) };
            (from - dt_s * p.push_force_gain_mps2_per_n * (f - levels.push_n)).max(0.0)
        };
    }
}
