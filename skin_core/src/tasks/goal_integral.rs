//! The goal error's integral while the arm pushes (intentional-contact paper Table I (b)).
//!
//! At rest against an obstacle, eq. (8) pushes with `F_g = k_v ν ẋ_d = k_p e` (eq. 7): a
//! proportional law against Coulomb friction, so the push stalls where `k_p e = μ m g`, short of
//! the goal by `μ m g / k_p` (1.2-2 cm for 3-5 N with `k_p` 250 N/m, the tolerance 1 cm). In
//! intentional contact the error of eq. (7) is therefore
//!
//! `e_I = e + (1/T_i) ∫ e dt`,  `ẋ_d = (k_p / k_v) e_I`  (`integral_time_s` `T_i`; 0: eq. 7 as printed),
//!
//! which raises the push at rest until the obstacle slides, and lets it settle on the goal.
//! The integral
//! - grows only in Table I (b), the one arrangement that pushes, and is zero in every other one
//!   (each (b) starts from zero: nothing wound up in (a) or in the hard contact (c) is carried
//!   into a push) and on a new goal;
//! - keeps within what the error leaves before eq. (9) saturates, `‖(1/T_i) ∫ e dt‖ ≤
//!   V_max k_v / k_p − ‖e‖` (scaled back to it, not frozen: a component along a blocked direction
//!   does not stop the others from settling; zero far from the goal): `‖ẋ_d‖ ≤ V_max`, so the push
//!   at rest, `k_v ‖ẋ_d‖`, never exceeds eq. (9)'s saturated push `k_v V_max`, which
//!   `config/tasks.yaml` keeps below `ε_c` (Sec. III: light objects are pushed below `ε_c`). The
//!   integral is a force bounded like the push it adds to, not a new source of force.

use nalgebra::Vector3;

use super::params::GoalParams;

/// `∫ e dt` of the goal error in intentional contact \[m s\] (or rad s on the angular rows).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GoalIntegral {
    sum: Vector3<f64>,
    /// The goal `sum` was integrated toward.
    goal: Vector3<f64>,
}

impl GoalIntegral {
    /// The error eq. (7) is given this cycle: `e + (1/T_i) ∫ e dt` (`e` alone with `T_i` = 0).
    pub fn error(&self, params: &GoalParams, e: &Vector3<f64>) -> Vector3<f64> {
        if params.integral_time_s > 0.0 {
            e + self.sum / params.integral_time_s
        } else {
            *e
        }
    }

    /// Integrates the error `e` toward `goal` over a cycle of `dt_s` while `pushing` (Table I
    /// (b)), within what `e` leaves before eq. (9) saturates (module doc); back to zero when not
    /// pushing, with `T_i` = 0, or on a new goal.
    pub fn integrate(&mut self, params: &GoalParams, e: &Vector3<f64>, goal: &Vector3<f64>, dt_s: f64, pushing: bool) {
        let t_i = params.integral_time_s;
        let active = pushing && t_i > 0.0;
        if !active || *goal != self.goal {
            *self = Self { sum: Vector3::zeros(), goal: *goal };
        }
        if !active {
            return;
        }
        // eq. (9) saturates at ‖e + (1/T_i) ∫e‖ = V_max k_v / k_p: the integral keeps to what
        // the error leaves of it (nothing far from the goal), scaled back rather than frozen, so
        // its free components still settle when one is blocked.
        let room = (params.v_max_m_per_s * params.kv_n_s_per_m / params.kp_n_per_m - e.norm()).max(0.0);
        let sum = self.sum + e * dt_s;
        let term = sum.norm() / t_i;
        self.sum = if term > room { sum * (room / term) } else { sum };
    }
}
