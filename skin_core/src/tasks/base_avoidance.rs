//! Interactive-force-control paper eq. (15)-(17): mobile-base collision avoidance from 2D laser points.
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

use super::error::TaskError;
use super::params::BaseAvoidanceParams;
use super::task::{Cycle, Role, Task, TaskSetup};

/// A pseudo-angle of the direction `(x, y)` in `[0, 4)`: 0 along +x, 1 along +y, 2 along −x, 3
/// along −y, strictly increasing with the angle in `[0, 2π)`; four divisions, no `atan2`.
fn diamond_angle(y: f64, x: f64) -> f64 {
    let s = x.abs() + y.abs();
    if s == 0.0 {
        return 0.0;
    }
    match (y >= 0.0, x >= 0.0) {
        (true, true) => y / s,
        (true, false) => 1.0 - x / s,
        (false, false) => 2.0 - y / s,
        (false, true) => 3.0 + x / s,
    }
}

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
    /// Per sector: squared footprint distance, the point, its closest footprint point.
    best: Vec<(f64, Vector2<f64>, Vector2<f64>)>,
    /// Pseudo-angles of the inner sector bounds `2π k/n`, k = 1..n.
    bounds: Vec<f64>,
    /// Unit directions of the sector bounds `2π k/n`, k = 0..=n.
    edges: Vec<Vector2<f64>>,
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
        let n = params.sectors;
        let bounds = (1..n)
            .map(|k| {
                let (s, c) = (std::f64::consts::TAU * k as f64 / n as f64).sin_cos();
                diamond_angle(s, c)
            })
            .collect();
        let edges = (0..=n)
            .map(|k| {
                let (s, c) = (std::f64::consts::TAU * k as f64 / n as f64).sin_cos();
                Vector2::new(c, s)
            })
            .collect();
        Ok(Self {
            params,
            joints,
            best: vec![(f64::INFINITY, Vector2::zeros(), Vector2::zeros()); n],
            bounds,
            edges,
            tau: DVector::zeros(nv),
        })
    }

    /// The sector of `p`: sector `s` spans the angles `atan2(y, x) + π ∈ [2π s/n, 2π (s+1)/n)`.
    /// Compared in the pseudo-angle of [`diamond_angle`] (monotone in the angle, no `atan2`)
    /// against the sector bounds precomputed in it. The bounds increase, so the sector is the
    /// number of bounds at or below the angle, counted without a branch per bound (the sector
    /// of consecutive scan points varies, which a loop's exit would mispredict).
    fn sector(&self, p: &Vector2<f64>) -> usize {
        let a = diamond_angle(-p.y, -p.x);
        self.bounds.iter().map(|&b| usize::from(a >= b)).sum()
    }

    /// [`Self::sector`] when `p` is likely in sector `hint` (a scan runs around in angle, so
    /// most points fall in the sector of the one before): two cross products with the hinted
    /// sector's bound directions instead of a division, accepted only with a margin (far above
    /// the rounding of either test), so the result is [`Self::sector`]'s in every case.
    fn sector_near(&self, p: &Vector2<f64>, hint: usize) -> usize {
        let d = -p;
        let margin = 1e-9 * (d.x.abs() + d.y.abs());
        if self.edges[hint].perp(&d) > margin && d.perp(&self.edges[hint + 1]) > margin {
            return hint;
        }
        self.sector(p)
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
        let (fx, fy) = (self.params.footprint_x_m, self.params.footprint_y_m);
        let range_sq = self.params.range_m * self.params.range_m;
        // squared distances in the scan loop (a scan has hundreds of points); the square root
        // and the sector's angle only for points in range
        let mut last = 0;
        for p in points {
            if !(p.x.is_finite() && p.y.is_finite()) {
                continue;
            }
            let c = Vector2::new(p.x.clamp(fx[0], fx[1]), p.y.clamp(fy[0], fy[1]));
            let d_sq = (p - c).norm_squared();
            if d_sq <= 0.0 || d_sq > range_sq {
                continue;
            }
            let s = self.sector_near(p, last);
            last = s;
            if d_sq < self.best[s].0 {
                self.best[s] = (d_sq, *p, c);
            }
        }
        let mut sum = BaseAvoidanceSummary { min_distance_m: f64::INFINITY, ..Default::default() };
        for &(d_sq, p, c) in &self.best {
            if !d_sq.is_finite() {
                continue;
            }
            let d = d_sq.sqrt();
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

/// `base_avoidance` in an arrangement: eq. (15)-(17) on the robot's mobile base from this cycle's
/// LIDAR points, a term of `τ_s`; nothing on a robot without a mobile base.
#[derive(Debug, Clone)]
pub struct MobileBaseAvoidance(pub Option<BaseAvoidance>);

impl Task for MobileBaseAvoidance {
    fn name() -> &'static str {
        "base_avoidance"
    }

    fn role() -> Role {
        Role::PostureTerm
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        let base = s.base_joints.map(|joints| BaseAvoidance::new(s.model.nv(), joints, s.params.base_avoidance));
        Ok(MobileBaseAvoidance(base.transpose()?))
    }

    fn torque(&mut self, cx: &Cycle, tau_s: &mut DVector<f64>) -> Result<(), TaskError> {
        if let Some(base) = &mut self.0 {
            base.update(cx.data.q(), cx.scan)?;
            *tau_s += base.torque();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tasks::params::BaseAvoidanceParams;

    fn with_sectors(n: usize) -> BaseAvoidance {
        let params = BaseAvoidanceParams {
            f_max_n: 1.0,
            alpha_m: 0.1,
            range_m: 1.0,
            footprint_x_m: [-0.1, 0.1],
            footprint_y_m: [-0.1, 0.1],
            sectors: n,
        };
        BaseAvoidance::new(3, [0, 1, 2], params).unwrap()
    }

    /// The pseudo-angle binning equals the `atan2` definition of the sectors, with or without a
    /// hint.
    #[test]
    fn sectors_match_atan2() {
        for n in [1, 2, 3, 8, 13] {
            let b = with_sectors(n);
            for k in 0..3600 {
                let a = (k as f64 + 0.37) * std::f64::consts::TAU / 3600.0;
                let p = Vector2::new(a.cos(), a.sin()) * (0.5 + (k % 7) as f64);
                let angle = p.y.atan2(p.x) + std::f64::consts::PI;
                let want = ((angle / std::f64::consts::TAU * n as f64) as usize).min(n - 1);
                assert_eq!(b.sector(&p), want, "n = {n}, angle {a}");
                for hint in 0..n {
                    assert_eq!(b.sector_near(&p, hint), want, "n = {n}, angle {a}, hint {hint}");
                }
            }
        }
    }

    /// On and next to the sector bounds (where the tests' rounding could disagree) the hint
    /// never changes the sector.
    #[test]
    fn hint_agrees_on_bounds() {
        for n in [2, 4, 8, 13, 360] {
            let b = with_sectors(n);
            for k in 0..n {
                for da in [-1e-15, -1e-12, 0.0, 1e-12, 1e-15] {
                    let (s, c) = (std::f64::consts::TAU * k as f64 / n as f64 + da).sin_cos();
                    for p in [-Vector2::new(c, s), -Vector2::new(c, s) * 3.7] {
                        for hint in [0, k.saturating_sub(1), k, (k + 1) % n] {
                            assert_eq!(b.sector_near(&p, hint), b.sector(&p), "n = {n}, bound {k} {da}, hint {hint}");
                        }
                    }
                }
            }
        }
    }
}
