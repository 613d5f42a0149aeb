//! Paper 003 eq. (15)-(17): mobile-base collision avoidance from 2D laser points.
//!
//! Laser points are given in the base frame `{b}`. For each angular sector about the base origin
//! the point `o_i` closest to the footprint rectangle is kept (so a dense wall counts once per
//! sector, not once per beam). With `x̄_oi` the closest footprint point, `d_oi = ‖o_i − x̄_oi‖`,
//! `n_oi = (o_i − x̄_oi)/d_oi` (from the robot TOWARD the obstacle) and
//! `f_rep = f_max exp(−d_oi/α)` (eq. 16), the base-frame generalized force is
//! `ᵇτ = Σ_i ᵇJ_oiᵀ n_oi f_rep` (eq. 15) with `ᵇJ_oi = [1 0 −x̄_y; 0 1 x̄_x]` (eq. 17).
//! Its force part is rotated to world by the base yaw (the `base_x`/`base_y` joints are
//! world-aligned prismatic joints), the moment goes to `base_yaw`. The result is `τ_oca`, a part
//! of `τ_s` that eq. (18) SUBTRACTS: `−τ_oca` pushes the base away from the obstacles.
//! Points inside the footprint or beyond `range_m` are ignored.

use nalgebra::{DVector, Vector2, Vector3};

use super::params::BaseAvoidanceParams;
use super::TaskError;

/// Summary of one base-avoidance update.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaseAvoidanceSummary {
    /// Obstacle points used (`n_o`).
    pub obstacles: usize,
    /// Smallest footprint distance \[m\] (`f64::INFINITY` if none).
    pub min_distance_m: f64,
    /// `ᵇτ` of eq. (15) in the base frame: `[f_x, f_y, m_z]` (toward the obstacles).
    pub base_frame: Vector3<f64>,
}

/// Base collision avoidance producing `τ_oca` on the base joints.
#[derive(Debug, Clone)]
pub struct BaseAvoidance {
    /// Footprint, range and repulsion parameters.
    pub params: BaseAvoidanceParams,
    joints: [usize; 3],
    best: Vec<(f64, Vector2<f64>, Vector2<f64>)>,
    tau: DVector<f64>,
}

impl BaseAvoidance {
    /// The task for a model with `nv` joints; `joints` are the indices of `base_x`, `base_y`,
    /// `base_yaw` (e.g. from `RobotModel::joint_index`).
    pub fn new(nv: usize, joints: [usize; 3], params: BaseAvoidanceParams) -> Result<Self, TaskError> {
        if let Some(&j) = joints.iter().find(|&&j| j >= nv) {
            return Err(TaskError::Length { what: "base joint index (must be < nv)", expected: nv, got: j });
        }
        if params.sectors == 0 {
            return Err(TaskError::Length { what: "base_avoidance.sectors (must be >= 1)", expected: 1, got: 0 });
        }
        Ok(Self { params, joints, best: vec![(f64::INFINITY, Vector2::zeros(), Vector2::zeros()); params.sectors], tau: DVector::zeros(nv) })
    }

    /// Closest footprint point to `p` (base frame) and its distance (0 inside).
    pub fn closest_footprint_point(&self, p: &Vector2<f64>) -> (Vector2<f64>, f64) {
        let (fx, fy) = (self.params.footprint_x_m, self.params.footprint_y_m);
        let c = Vector2::new(p.x.clamp(fx[0], fx[1]), p.y.clamp(fy[0], fy[1]));
        (c, (p - c).norm())
    }

    /// Computes `τ_oca` (length nv, zero outside the base joints) from the laser points `points`
    /// (base frame, \[m\]) and the joint positions `q`; read it with [`BaseAvoidance::torque`].
    pub fn update(&mut self, q: &[f64], points: &[Vector2<f64>]) -> Result<BaseAvoidanceSummary, TaskError> {
        if q.len() != self.tau.len() {
            return Err(TaskError::Length { what: "q", expected: self.tau.len(), got: q.len() });
        }
        self.tau.fill(0.0);
        for b in self.best.iter_mut() {
            b.0 = f64::INFINITY;
        }
        let n = self.best.len();
        for p in points {
            if !(p.x.is_finite() && p.y.is_finite()) {
                continue;
            }
            let (c, d) = self.closest_footprint_point(p);
            if d <= 0.0 || d > self.params.range_m {
                continue;
            }
            let angle = p.y.atan2(p.x) + std::f64::consts::PI; // [0, 2π]
            let s = ((angle / std::f64::consts::TAU * n as f64) as usize).min(n - 1);
            if d < self.best[s].0 {
                self.best[s] = (d, *p, c);
            }
        }
        let mut sum = BaseAvoidanceSummary { min_distance_m: f64::INFINITY, ..Default::default() };
        for &(d, p, c) in &self.best {
            if !d.is_finite() {
                continue;
            }
            let nrm = (p - c) / d;
            let f = self.params.f_max_n * (-d / self.params.alpha_m).exp();
            // eq. (17)ᵀ n f: [n_x, n_y, −x̄_y n_x + x̄_x n_y] f
            sum.base_frame += Vector3::new(nrm.x, nrm.y, -c.y * nrm.x + c.x * nrm.y) * f;
            sum.obstacles += 1;
            sum.min_distance_m = sum.min_distance_m.min(d);
        }
        let (s, co) = q[self.joints[2]].sin_cos();
        let b = sum.base_frame;
        self.tau[self.joints[0]] = co * b.x - s * b.y;
        self.tau[self.joints[1]] = s * b.x + co * b.y;
        self.tau[self.joints[2]] = b.z;
        Ok(sum)
    }

    /// `τ_oca` of the last update (toward the obstacles; eq. 18 subtracts it).
    pub fn torque(&self) -> &DVector<f64> {
        &self.tau
    }
}
