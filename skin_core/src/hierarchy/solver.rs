//! The multi-priority torque solver of interactive-force-control paper eq. (19)-(25), with intentional-contact paper's force levels in
//! the same pass.

use nalgebra::{DMatrix, DVector};

use crate::model::{bias_forces, crba, ModelData, RobotModel};

use super::dense::{
    add_mul_vec, add_mul_vec_padded, axpy, dot, mul, mul_padded, mul_tn, mul_tr_vec, mul_vec, mul_vec2_padded,
    mul_vec_padded, norm, pad, padded_len, set_identity_padded, sub_mul_nt, sub_mul_nt_padded,
    sub_outer_mul_vec_padded, sub_outer_padded, unpad,
};
use super::error::HierarchyError;
use super::inverse::{
    cholesky, damped_inverse, lower_inverse_padded, spd_inverse_padded, symmetric_eigen, InverseParams,
};
use super::task::{ReferenceKind, TaskLevel};

/// What one level did in the last solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelDiagnostics {
    /// Kind of the level's reference.
    pub kind: ReferenceKind,
    /// Active rows `m_k`.
    pub rows: usize,
    /// Rank used: eigenvalues of `J̄_k M⁻¹ J̄_kᵀ` above the rank threshold.
    pub rank: usize,
    /// Of these, directions inside the damping band (inverse faded: near a singularity or a
    /// conflict with a higher level).
    pub damped: usize,
    /// Smallest eigenvalue kept (task-space inverse mass; 0 if rank 0). When every direction is
    /// well above the damping band the eigen decomposition is skipped and this is the lower
    /// bound `1/‖Λ̄‖_F` instead.
    pub min_eigenvalue: f64,
    /// `‖τ̄_k‖`, the projected torque of the level (N m).
    pub torque_norm: f64,
    /// Acceleration levels: `‖J_k q̈ + J̇_k q̇ − ẍ*_k‖` with the model-predicted
    /// `q̈ = M⁻¹(Σ τ̄ + N_L τ_c*)` (what the bias term does not cancel is not included); `None`
    /// for force levels.
    pub task_error: Option<f64>,
}

impl LevelDiagnostics {
    fn empty(kind: ReferenceKind) -> Self {
        Self { kind, rows: 0, rank: 0, damped: 0, min_eigenvalue: 0.0, torque_norm: 0.0, task_error: None }
    }
}

/// Preallocated workspace and parameters of the hierarchy; [`HierarchySolver::solve`] is the one
/// function (mass matrix, ordered levels, posture torque, bias) → torque.
///
/// ```text
/// τ* = Σ_k τ̄_k + N_L τ_c* + (C q̇ + g)                              interactive-force-control paper eq. (19)
/// τ̄_k = J̄_kᵀ Λ̄_k (ẍ*_k − J̇_k q̇ − a_k)        acceleration level, eq. (20)
/// τ̄_k = J̄_kᵀ F_k = N_{k−1} J_kᵀ F_k             force level (intentional-contact paper, augmented projection)
/// a_k = J_k M⁻¹ Σ_{i<k} τ̄_i                                          eq. (21)
/// J̄_k = J_k N_{k−1}ᵀ                                                 eq. (22)
/// Λ̄_k = (J̄_k M⁻¹ J̄_kᵀ)⁻¹   damped, rank-aware (InverseParams)        eq. (23)
/// N_k = N_{k−1} (I − J̄_kᵀ Λ̄_k J̄_k M⁻¹),  N_0 = I                   eq. (24), (25)
/// ```
/// After [`HierarchySolver::new`] no call allocates.
#[derive(Clone, Debug)]
pub struct HierarchySolver {
    nv: usize,
    max_levels: usize,
    max_rows: usize,
    params: InverseParams,
    /// `L` of `M = L Lᵀ` (padded: `chol_pad`) and, for the levels that need them
    /// ([`Self::wide_level`]), `L` and `L⁻¹` n × n.
    chol: Vec<f64>,
    chol_pad: Vec<f64>,
    linv: Vec<f64>,
    /// `chol` and `linv` hold this solve's `L` and `L⁻¹` (set by the first wide level).
    lower_ready: bool,
    /// `M⁻¹` and N_{k−1} (during the pass) with padded columns (`dense::padded_len`), so that
    /// the products with them run without remainder loops.
    minv_pad: Vec<f64>,
    nproj_pad: Vec<f64>,
    /// n × max_rows: J̄ᵀ, M⁻¹J̄ᵀ, N J̄ᵀ (`z`: padded, ld × max(max_rows, n), also the scratch of
    /// the other padded products), M⁻¹J̄ᵀΛ̄.
    jbt: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    wt: Vec<f64>,
    /// max_rows²: A, eigenvectors (or the Cholesky factor of A), scratch, Λ̄.
    a: Vec<f64>,
    v: Vec<f64>,
    w: Vec<f64>,
    lam: Vec<f64>,
    /// max_rows: task-space residual and Λ̄ r.
    r: Vec<f64>,
    s: Vec<f64>,
    /// n: Σ τ̄, predicted q̈; padded (ld): τ̄_k, M⁻¹ Σ τ̄, N_L τ_c*.
    tau_sum: Vec<f64>,
    tau_bar: Vec<f64>,
    u_sum: Vec<f64>,
    posture_proj: Vec<f64>,
    /// n: `J_kᵀ F_k` of an activated level, before its projection.
    force_torque: Vec<f64>,
    qdd: DVector<f64>,
    diagnostics: Vec<LevelDiagnostics>,
    /// M and C q̇ + g for [`HierarchySolver::solve_model`].
    m_model: DMatrix<f64>,
    bias_model: DVector<f64>,
    /// Joints held still ([`HierarchySolver::set_locked_joints`]).
    locked: Vec<bool>,
    /// Activated levels, row by row: the row's `j̄ᵀ`, `M⁻¹ j̄ᵀ`, `N j̄ᵀ` (padded).
    row_pad: [Vec<f64>; 3],
}

impl HierarchySolver {
    /// Workspace for `nv` joints, at most `max_levels` levels of at most `max_rows` rows each.
    pub fn new(nv: usize, max_levels: usize, max_rows: usize, params: InverseParams) -> Result<Self, HierarchyError> {
        params.validate()?;
        let (n, m, ld) = (nv, max_rows, padded_len(nv));
        Ok(Self {
            nv,
            max_levels,
            max_rows,
            params,
            chol: vec![0.0; n * n],
            chol_pad: vec![0.0; ld * n],
            linv: vec![0.0; n * n],
            lower_ready: false,
            jbt: vec![0.0; n * m],
            y: vec![0.0; n * m],
            z: vec![0.0; ld * m.max(n)],
            wt: vec![0.0; n * m],
            a: vec![0.0; m * m],
            v: vec![0.0; m * m],
            w: vec![0.0; m * m],
            lam: vec![0.0; m * m],
            r: vec![0.0; m],
            s: vec![0.0; m],
            tau_sum: vec![0.0; n],
            tau_bar: vec![0.0; ld],
            u_sum: vec![0.0; ld],
            posture_proj: vec![0.0; ld],
            force_torque: vec![0.0; n],
            qdd: DVector::zeros(n),
            diagnostics: Vec::with_capacity(max_levels),
            m_model: DMatrix::zeros(n, n),
            bias_model: DVector::zeros(n),
            locked: vec![false; n],
            minv_pad: vec![0.0; ld * n],
            nproj_pad: vec![0.0; ld * n],
            row_pad: std::array::from_fn(|_| vec![0.0; ld]),
        })
    }

    /// Number of joints.
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// Inverse parameters in use.
    pub fn params(&self) -> &InverseParams {
        &self.params
    }

    /// Replaces the inverse parameters (validated first; the old ones stay on error).
    pub fn set_params(&mut self, params: InverseParams) -> Result<(), HierarchyError> {
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// Per-level diagnostics of the last solve, in priority order (after an error: the levels
    /// processed before it).
    pub fn diagnostics(&self) -> &[LevelDiagnostics] {
        &self.diagnostics
    }

    /// `M⁻¹` of the last solve (a copy: for tests and diagnostics, the cycle does not need it
    /// unpadded).
    pub fn mass_inverse(&self) -> DMatrix<f64> {
        self.unpadded(&self.minv_pad)
    }

    /// The null-space projector `N_L` of the last solve (eq. 24 after the last level; after an
    /// error, after the levels processed before it). A copy, like [`Self::mass_inverse`].
    pub fn null_space(&self) -> DMatrix<f64> {
        self.unpadded(&self.nproj_pad)
    }

    fn unpadded(&self, padded: &[f64]) -> DMatrix<f64> {
        let n = self.nv;
        let mut m = DMatrix::zeros(n, n);
        unpad(padded, m.as_mut_slice(), n, padded_len(n), n);
        m
    }

    /// Model-predicted acceleration of the last successful solve, `M⁻¹ (Σ τ̄_k + N_L τ_c*)`, i.e. `q̈` when
    /// the bias term exactly cancels `C q̇ + g`.
    pub fn predicted_acceleration(&self) -> &DVector<f64> {
        &self.qdd
    }

    /// Computes interactive-force-control paper eq. (19)-(25) into `tau_out`.
    ///
    /// - `mass_matrix`: `M(q)` (nv × nv, symmetric positive definite; the lower triangle is read),
    ///   e.g. from `model::crba`. Factorized here every call.
    /// - `levels`: the task levels, highest priority first (any iterator of `&TaskLevel` that can
    ///   be cloned, e.g. `levels.iter()` or `order.iter().map(|&i| &levels[i])`, so an arrangement
    ///   is just an order). Empty levels are skipped.
    /// - `posture`: `τ_c*` of eq. (18), projected into the null space of all levels (`None`: 0).
    /// - `bias`: `C q̇ + g` (e.g. `model::bias_forces`) added at the end; `None` leaves it out (the
    ///   admittance resolver of interactive-force-control paper eq. (26) adds g itself).
    ///
    /// Inputs are checked first (sizes, finiteness); on error `tau_out` is untouched.
    pub fn solve<'a, I>(
        &mut self,
        mass_matrix: &DMatrix<f64>,
        levels: I,
        posture: Option<&[f64]>,
        bias: Option<&[f64]>,
        tau_out: &mut DVector<f64>,
    ) -> Result<(), HierarchyError>
    where
        I: IntoIterator<Item = &'a TaskLevel>,
        I::IntoIter: Clone,
    {
        let (n, ld) = (self.nv, padded_len(self.nv));
        self.check_inputs(mass_matrix, posture, bias, tau_out)?;
        let levels = levels.into_iter();

        cholesky(mass_matrix.as_slice(), &mut self.chol_pad, n, ld)?;
        spd_inverse_padded(&self.chol_pad, &mut self.z, &mut self.minv_pad, n, ld);
        self.lower_ready = false;
        set_identity_padded(&mut self.nproj_pad, n, ld);
        self.tau_sum.fill(0.0);
        self.u_sum.fill(0.0);
        self.diagnostics.clear();
        let mut first = true; // N_{k−1} = I: skip the products with it

        for (k, level) in levels.clone().enumerate() {
            self.check_level(k, level)?;
            let m = level.rows();
            let mut diag = LevelDiagnostics::empty(level.kind());
            if m == 0 {
                self.diagnostics.push(diag);
                continue;
            }
            if level.is_activated() {
                // skin rows with activations: weighted, row by row (any m)
                self.activated_level(k, level, &mut diag, &mut first)?;
                self.diagnostics.push(diag);
                continue;
            }
            let (nm, mm) = (n * m, m * m);
            let jt = level.jt_slice();
            // J̄_kᵀ = N_{k−1} J_kᵀ (eq. 22)
            if first {
                self.jbt[..nm].copy_from_slice(jt);
            } else {
                mul_padded(&self.nproj_pad, jt, &mut self.z, ld, n, m);
                unpad(&self.z, &mut self.jbt, n, ld, m);
            }
            if m > n {
                // more rows than joints (stacked skin cells): the same level in joint space
                self.wide_level(k, level, &mut diag, &mut first)?;
                self.diagnostics.push(diag);
                continue;
            }
            // Y = M⁻¹ J̄ᵀ, A = J̄ M⁻¹ J̄ᵀ (symmetrized against round-off), Λ̄ (eq. 23)
            mul_padded(&self.minv_pad, &self.jbt[..nm], &mut self.z, ld, n, m);
            unpad(&self.z, &mut self.y, n, ld, m);
            mul_tn(&self.jbt[..nm], &self.y[..nm], &mut self.a[..mm], n, m, m);
            for c in 0..m {
                for r in 0..c {
                    let s = 0.5 * (self.a[c * m + r] + self.a[r * m + c]);
                    self.a[c * m + r] = s;
                    self.a[r * m + c] = s;
                }
            }
            let info = damped_inverse(
                &mut self.a[..mm],
                &mut self.v[..mm],
                &mut self.w[..mm],
                &mut self.lam[..mm],
                m,
                &self.params,
            );
            diag.rows = m;
            diag.rank = info.rank;
            diag.damped = info.damped;
            diag.min_eigenvalue = info.min_kept;

            // the level's task-space command: Λ̄ (ẍ* − J̇q̇ − a_k) or F
            match level.kind() {
                ReferenceKind::Acceleration => {
                    // a_k = J_k M⁻¹ Σ_{i<k} τ̄_i (eq. 21), M⁻¹ Σ τ̄ kept up to date below
                    mul_tr_vec(jt, &self.u_sum, &mut self.r[..m], n, m);
                    for ((ri, x), d) in self.r[..m].iter_mut().zip(level.target()).zip(level.jdot_qdot()) {
                        *ri = x - d - *ri;
                    }
                    mul_vec(&self.lam[..mm], &self.r[..m], &mut self.s[..m], m, m);
                }
                ReferenceKind::Force => self.s[..m].copy_from_slice(level.target()),
            }
            // τ̄_k = J̄_kᵀ s (eq. 20); M⁻¹ τ̄_k = Y s
            mul_vec(&self.jbt[..nm], &self.s[..m], &mut self.tau_bar, n, m);
            axpy(1.0, &self.tau_bar[..n], &mut self.tau_sum);
            add_mul_vec(&self.y[..nm], &self.s[..m], &mut self.u_sum, n, m);
            diag.torque_norm = norm(&self.tau_bar);
            if !self.tau_sum.iter().all(|t| t.is_finite()) {
                return Err(HierarchyError::Overflow { level: k });
            }

            // N_k = N_{k−1} − (N_{k−1} J̄ᵀ)(M⁻¹ J̄ᵀ Λ̄)ᵀ (eq. 24 with (J̄^{#M})ᵀ = Λ̄ J̄ M⁻¹, eq. 25)
            if info.rank > 0 {
                mul(&self.y[..nm], &self.lam[..mm], &mut self.wt[..nm], n, m, m);
                if first {
                    pad(&self.jbt, &mut self.z, n, ld, m);
                } else {
                    mul_padded(&self.nproj_pad, &self.jbt[..nm], &mut self.z, ld, n, m);
                }
                sub_mul_nt_padded(&mut self.nproj_pad, &self.z, &self.wt[..nm], ld, m, n);
                first = false;
            }
            self.diagnostics.push(diag);
        }

        // N_L τ_c* (eq. 19) and the predicted acceleration
        let nlevels = self.diagnostics.len();
        if let Some(tc) = posture {
            mul_vec_padded(&self.nproj_pad, tc, &mut self.posture_proj, ld, n);
            axpy(1.0, &self.posture_proj[..n], &mut self.tau_sum);
            add_mul_vec_padded(&self.minv_pad, &self.posture_proj, &mut self.u_sum, ld, n);
        }
        self.qdd.as_mut_slice().copy_from_slice(&self.u_sum[..n]);
        for (k, level) in levels.enumerate() {
            if level.kind() == ReferenceKind::Acceleration && level.rows() > 0 {
                let mut e2 = 0.0;
                for r in 0..level.rows() {
                    let e = dot(level.jacobian_row(r), &self.u_sum) + level.jdot_qdot()[r] - level.target()[r];
                    e2 += e * e;
                }
                self.diagnostics[k].task_error = Some(e2.sqrt());
            }
        }
        if let Some(b) = bias {
            axpy(1.0, b, &mut self.tau_sum);
        }
        if !self.tau_sum.iter().all(|t| t.is_finite()) {
            return Err(HierarchyError::Overflow { level: nlevels });
        }
        tau_out.as_mut_slice().copy_from_slice(&self.tau_sum);
        Ok(())
    }

    /// One level with more rows `m` than joints `n` (J̄ᵀ already in `jbt`), computed with n × n
    /// matrices only: the m × m `A = J̄ M⁻¹ J̄ᵀ` has rank ≤ n and, with `M = L Lᵀ` and
    /// `G = J̄ L⁻ᵀ`, the same nonzero eigenvalues `e` as `C = Gᵀ G = L⁻¹ (J̄ᵀ J̄) L⁻ᵀ = V E Vᵀ`.
    /// With the filter `f` of [`InverseParams`] (so exactly what the m × m path computes):
    ///
    /// ```text
    /// J̄ᵀ Λ̄ J̄ M⁻¹ = L V diag(e f(e)) Vᵀ L⁻¹         (the projector of eq. 24)
    /// J̄ᵀ Λ̄ r     = L V diag(f(e)) Vᵀ L⁻¹ J̄ᵀ r      (eq. 20)
    /// ```
    ///
    /// Cost `m n² + O(n³)` instead of `O(m³)`: 50 active cells on one level stay cheap.
    fn wide_level(
        &mut self,
        k: usize,
        level: &TaskLevel,
        diag: &mut LevelDiagnostics,
        first: &mut bool,
    ) -> Result<(), HierarchyError> {
        let (n, m, ld) = (self.nv, level.rows(), padded_len(self.nv));
        let (nm, nn) = (n * m, n * n);
        if !self.lower_ready {
            // once per solve, whatever the number of wide levels (z is free: J̄ᵀ is in jbt)
            unpad(&self.chol_pad, &mut self.chol, n, ld, n);
            lower_inverse_padded(&self.chol_pad, &mut self.z, &mut self.linv, n, ld);
            self.lower_ready = true;
        }
        // C = L⁻¹ (J̄ᵀ J̄) L⁻ᵀ, symmetrized; its eigen decomposition
        self.w[..nn].fill(0.0);
        sub_mul_nt(&mut self.w[..nn], &self.jbt[..nm], &self.jbt[..nm], n, m, n);
        mul(&self.linv, &self.w[..nn], &mut self.lam[..nn], n, n, n);
        self.a[..nn].fill(0.0);
        sub_mul_nt(&mut self.a[..nn], &self.lam[..nn], &self.linv, n, n, n);
        for c in 0..n {
            for r in 0..c {
                // w = −J̄ᵀJ̄, lam = −L⁻¹J̄ᵀJ̄, a = 0 − lam L⁻ᵀ = C
                let s = 0.5 * (self.a[c * n + r] + self.a[r * n + c]);
                self.a[c * n + r] = s;
                self.a[r * n + c] = s;
            }
        }
        symmetric_eigen(&mut self.a[..nn], &mut self.v[..nn], n);
        let e_max = (0..n).map(|i| self.a[i * n + i]).fold(0.0, f64::max);
        let thr = self.params.threshold(e_max);
        // f(e) into r, e f(e) into s
        for i in 0..n {
            let e = self.a[i * n + i];
            let f = self.params.filter(e, thr);
            self.r[i] = f;
            self.s[i] = e * f;
            if f > 0.0 {
                diag.min_eigenvalue = if diag.rank == 0 { e } else { diag.min_eigenvalue.min(e) };
                diag.rank += 1;
                diag.damped += usize::from(e < self.params.damping);
            }
        }
        diag.rows = m;

        // τ̄_k: force level J̄ᵀ F; acceleration level L V f Vᵀ L⁻¹ J̄ᵀ (ẍ* − J̇q̇ − a_k)
        match level.kind() {
            ReferenceKind::Force => mul_vec(&self.jbt[..nm], level.target(), &mut self.tau_bar, n, m),
            ReferenceKind::Acceleration => {
                let res = &mut self.y[..m];
                mul_tr_vec(level.jt_slice(), &self.u_sum, res, n, m);
                for ((ri, x), d) in res.iter_mut().zip(level.target()).zip(level.jdot_qdot()) {
                    *ri = x - d - *ri;
                }
                let (g, rest) = self.z.split_at_mut(n);
                let (h, p) = rest.split_at_mut(n);
                mul_vec(&self.jbt[..nm], res, g, n, m);
                mul_vec(&self.linv, g, h, n, n);
                mul_tr_vec(&self.v[..nn], h, &mut p[..n], n, n);
                for (pi, fi) in p[..n].iter_mut().zip(&self.r[..n]) {
                    *pi *= fi;
                }
                mul_vec(&self.v[..nn], &p[..n], g, n, n);
                mul_vec(&self.chol, g, &mut self.tau_bar, n, n);
            }
        }
        self.add_level_torque(k, diag)?;

        // N_k = N_{k−1} − (N_{k−1} L V) (L⁻ᵀ V diag(e f))ᵀ
        if diag.rank > 0 {
            mul(&self.chol, &self.v[..nn], &mut self.w[..nn], n, n, n);
            mul_tn(&self.linv, &self.v[..nn], &mut self.lam[..nn], n, n, n);
            for (col, s) in self.lam[..nn].chunks_exact_mut(n).zip(&self.s[..n]) {
                for x in col {
                    *x *= s;
                }
            }
            if *first {
                pad(&self.w, &mut self.z, n, ld, n);
            } else {
                mul_padded(&self.nproj_pad, &self.w[..nn], &mut self.z, ld, n, n);
            }
            sub_mul_nt_padded(&mut self.nproj_pad, &self.z, &self.lam[..nn], ld, n, n);
            *first = false;
        }
        Ok(())
    }

    /// A force level of activated rows: the torque is the usual `τ̄_k = N_{k−1} (J_kᵀ F_k)` (one
    /// product with `N_{k−1}`, not one per row); the projector takes the rows one at a time, each
    /// weighted by its activation `a_i` (continuous null-space projection, Dietrich et al. 2012):
    ///
    /// ```text
    /// j̄_i = j_i Nᵀ,  e_i = j̄_i M⁻¹ j̄_iᵀ,  N ← N − a_i f(e_i) (N j̄_iᵀ)(M⁻¹ j̄_iᵀ)ᵀ
    /// ```
    ///
    /// with `N` starting at `N_{k−1}` and including the rows before `i`. With every `a_i = 1` this
    /// is the augmented projector of the whole level (successive rank-one projections span the
    /// same space; the damping band `f` of [`InverseParams`] fades dependent rows); a row with
    /// `a_i = 0` leaves `N` as if it were absent, and `N` is continuous in every `a_i` (in the
    /// M-metric each factor has eigenvalues `1` and `1 − a_i e_i f(e_i) ∈ [0, 1]`).
    fn activated_level(
        &mut self,
        k: usize,
        level: &TaskLevel,
        diag: &mut LevelDiagnostics,
        first: &mut bool,
    ) -> Result<(), HierarchyError> {
        let (n, m) = (self.nv, level.rows());
        if *first {
            mul_vec(level.jt_slice(), level.target(), &mut self.tau_bar, n, m);
        } else {
            mul_vec(level.jt_slice(), level.target(), &mut self.force_torque, n, m);
            mul_vec_padded(&self.nproj_pad, &self.force_torque, &mut self.tau_bar, padded_len(n), n);
        }
        diag.rows = m;
        self.add_level_torque(k, diag)?;
        self.project_activated_rows(level, diag, first);
        Ok(())
    }

    /// Adds the level torque `τ̄_k` (in `tau_bar`) to `Σ τ̄` and `M⁻¹ τ̄_k` to `M⁻¹ Σ τ̄`; its norm
    /// into the diagnostics. Fails if the sum overflows.
    fn add_level_torque(&mut self, k: usize, diag: &mut LevelDiagnostics) -> Result<(), HierarchyError> {
        let (n, ld) = (self.nv, padded_len(self.nv));
        axpy(1.0, &self.tau_bar[..n], &mut self.tau_sum);
        add_mul_vec_padded(&self.minv_pad, &self.tau_bar, &mut self.u_sum, ld, n);
        diag.torque_norm = norm(&self.tau_bar);
        if !self.tau_sum.iter().all(|t| t.is_finite()) {
            return Err(HierarchyError::Overflow { level: k });
        }
        Ok(())
    }

    /// The row-by-row projector update of [`Self::activated_level`] on the padded `N` and `M⁻¹`:
    /// `4 n²` per row, the level's main cost (the torque costs `n m`). The next row's `N j_iᵀ`
    /// is summed in the pass that updates `N` (the same sums as after it).
    fn project_activated_rows(&mut self, level: &TaskLevel, diag: &mut LevelDiagnostics, first: &mut bool) {
        let (n, ld) = (self.nv, padded_len(self.nv));
        let [jb, mj, nj] = &mut self.row_pad;
        let row = |i: usize| level.jt_slice().get(i * n..(i + 1) * n);
        jb.fill(0.0);
        // j̄ᵀ = N j_iᵀ (jb), M⁻¹ j̄ᵀ (mj), N j̄ᵀ (nj)
        if let Some(r) = row(0) {
            project_row(&self.nproj_pad, r, jb, *first, ld);
        }
        for (i, &a) in level.activation().iter().enumerate() {
            if *first {
                mul_vec_padded(&self.minv_pad, jb, mj, ld, n);
                nj.copy_from_slice(jb);
            } else {
                mul_vec2_padded(&self.minv_pad, &self.nproj_pad, jb, mj, nj, ld, n);
            }
            let e = dot(&jb[..n], &mj[..n]);
            let f = self.params.filter(e, self.params.threshold(e));
            if f > 0.0 {
                diag.min_eigenvalue = if diag.rank == 0 { e } else { diag.min_eigenvalue.min(e) };
                diag.rank += 1;
                diag.damped += usize::from(e < self.params.damping);
            }
            let next = row(i + 1);
            if f > 0.0 && a > 0.0 {
                for x in mj[..n].iter_mut() {
                    *x *= a * f;
                }
                // N ← N − (N j̄ᵀ)(a f M⁻¹ j̄ᵀ)ᵀ, and the next row's N j_{i+1}ᵀ in the same pass
                match next {
                    Some(r) => sub_outer_mul_vec_padded(&mut self.nproj_pad, nj, mj, r, jb, ld, n),
                    None => sub_outer_padded(&mut self.nproj_pad, nj, mj, ld, n),
                }
                *first = false;
            } else if let Some(r) = next {
                project_row(&self.nproj_pad, r, jb, *first, ld);
            }
        }
    }

    /// Marks joints as locked for [`HierarchySolver::solve_model`] (length `nv`): their rows and
    /// columns of `M` are replaced by the identity's and their bias by 0, so the hierarchy is
    /// solved on the free joints' dynamics `M_ff` exactly (the levels' Jacobian columns of locked
    /// joints must be zero too: [`TaskLevel::lock_joints`]); their torque comes out 0.
    pub fn set_locked_joints(&mut self, locked: &[bool]) -> Result<(), HierarchyError> {
        if locked.len() != self.nv {
            return Err(HierarchyError::Dimension { what: "locked joints", expected: self.nv, got: locked.len() });
        }
        self.locked.copy_from_slice(locked);
        Ok(())
    }

    /// [`HierarchySolver::solve`] with `M` and `C q̇ + g` computed from the model at the state of
    /// the last `model::update_kinematics` on `data` (CRBA and RNEA into the solver's own
    /// buffers); `include_bias = false` leaves the bias out. The same as
    /// [`HierarchySolver::model_dynamics`] followed by [`HierarchySolver::solve_with_model`].
    pub fn solve_model<'a, I>(
        &mut self,
        model: &RobotModel,
        data: &mut ModelData,
        levels: I,
        posture: Option<&[f64]>,
        include_bias: bool,
        tau_out: &mut DVector<f64>,
    ) -> Result<(), HierarchyError>
    where
        I: IntoIterator<Item = &'a TaskLevel>,
        I::IntoIter: Clone,
    {
        self.model_dynamics(model, data, include_bias)?;
        self.solve_with_model(levels, posture, include_bias, tau_out)
    }

    /// The first half of [`HierarchySolver::solve_model`]: `M` (CRBA) and, with `include_bias`,
    /// `C q̇ + g` (RNEA) at the state of the last `model::update_kinematics` on `data`, into the
    /// solver's own buffers, locked joints decoupled ([`HierarchySolver::set_locked_joints`]).
    pub fn model_dynamics(
        &mut self,
        model: &RobotModel,
        data: &mut ModelData,
        include_bias: bool,
    ) -> Result<(), HierarchyError> {
        let model_error = |e: crate::model::ModelError| HierarchyError::Model { message: e.to_string() };
        crba(model, data, &mut self.m_model).map_err(model_error)?;
        if include_bias {
            bias_forces(model, data, &mut self.bias_model).map_err(model_error)?;
        }
        for (j, _) in self.locked.iter().enumerate().filter(|(_, &l)| l) {
            self.m_model.row_mut(j).fill(0.0);
            self.m_model.column_mut(j).fill(0.0);
            self.m_model[(j, j)] = 1.0;
            self.bias_model[j] = 0.0;
        }
        Ok(())
    }

    /// The second half of [`HierarchySolver::solve_model`]: [`HierarchySolver::solve`] with the
    /// `M` and `C q̇ + g` of the last [`HierarchySolver::model_dynamics`] (`include_bias` as
    /// there).
    pub fn solve_with_model<'a, I>(
        &mut self,
        levels: I,
        posture: Option<&[f64]>,
        include_bias: bool,
        tau_out: &mut DVector<f64>,
    ) -> Result<(), HierarchyError>
    where
        I: IntoIterator<Item = &'a TaskLevel>,
        I::IntoIter: Clone,
    {
        // moved out for the call (self.solve borrows self mutably); empty matrices do not allocate
        let m = std::mem::replace(&mut self.m_model, DMatrix::zeros(0, 0));
        let bias = std::mem::replace(&mut self.bias_model, DVector::zeros(0));
        let result = self.solve(&m, levels, posture, include_bias.then_some(bias.as_slice()), tau_out);
        self.m_model = m;
        self.bias_model = bias;
        result
    }

    fn check_inputs(
        &self,
        mass_matrix: &DMatrix<f64>,
        posture: Option<&[f64]>,
        bias: Option<&[f64]>,
        tau_out: &DVector<f64>,
    ) -> Result<(), HierarchyError> {
        let n = self.nv;
        let dim = |what, got: usize| {
            if got == n {
                Ok(())
            } else {
                Err(HierarchyError::Dimension { what, expected: n, got })
            }
        };
        dim("mass matrix rows", mass_matrix.nrows())?;
        dim("mass matrix columns", mass_matrix.ncols())?;
        dim("torque output", tau_out.len())?;
        for c in 0..n {
            for r in 0..n {
                let value = mass_matrix[(r, c)];
                if !value.is_finite() {
                    return Err(HierarchyError::NonFiniteMassMatrix { row: r, col: c, value });
                }
            }
        }
        for (what, v) in [("posture torque", posture), ("bias", bias)] {
            if let Some(v) = v {
                dim(what, v.len())?;
                if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                    return Err(HierarchyError::NonFinite { what, index, value });
                }
            }
        }
        Ok(())
    }

    fn check_level(&self, k: usize, level: &TaskLevel) -> Result<(), HierarchyError> {
        if k >= self.max_levels {
            return Err(HierarchyError::Capacity { what: "levels".to_string(), got: k + 1, capacity: self.max_levels });
        }
        if level.nv() != self.nv {
            return Err(HierarchyError::LevelColumns {
                level: k,
                name: level.name().to_string(),
                expected: self.nv,
                got: level.nv(),
            });
        }
        if level.rows() > self.max_rows {
            return Err(HierarchyError::Capacity {
                what: format!("rows of level {k} (`{}`)", level.name()),
                got: level.rows(),
                capacity: self.max_rows,
            });
        }
        let bad = |what, index: usize, value: f64| HierarchyError::NonFiniteLevel {
            level: k,
            name: level.name().to_string(),
            what,
            index,
            value,
        };
        if let Some(i) = first_non_finite(level.jt_slice()) {
            // storage is Jᵀ column-major, so i = row · nv + column of J
            return Err(bad("jacobian", i, level.jt_slice()[i]));
        }
        let (target_name, drift) = match level.kind() {
            ReferenceKind::Acceleration => ("xdd_star", true),
            ReferenceKind::Force => ("force", false),
        };
        if let Some(i) = first_non_finite(level.target()) {
            return Err(bad(target_name, i, level.target()[i]));
        }
        if drift {
            if let Some(i) = first_non_finite(level.jdot_qdot()) {
                return Err(bad("jdot_qdot", i, level.jdot_qdot()[i]));
            }
        }
        Ok(())
    }
}

/// `jb = N rowᵀ` (padded; `N = I` while `identity`).
fn project_row(nproj_pad: &[f64], row: &[f64], jb: &mut [f64], identity: bool, ld: usize) {
    if identity {
        jb[..row.len()].copy_from_slice(row);
    } else {
        mul_vec_padded(nproj_pad, row, jb, ld, row.len());
    }
}

/// Index of the first NaN or infinite entry of `x`. The usual all-finite case is one pass without
/// a branch per entry (the levels' Jacobians are checked every solve): `v − v` is 0 for a finite
/// `v` and NaN otherwise, summed in eight independent lanes (vectorized).
fn first_non_finite(x: &[f64]) -> Option<usize> {
    let mut acc = [0.0; 8];
    let blocks = x.chunks_exact(8);
    let tail = blocks.remainder();
    for b in blocks {
        for (a, v) in acc.iter_mut().zip(b) {
            #[allow(clippy::eq_op)] // NaN for NaN and ±∞: the point
            {
                *a += v - v;
            }
        }
    }
    if acc.iter().all(|&a| a == 0.0) && tail.iter().all(|v| v.is_finite()) {
        return None;
    }
    x.iter().position(|v| !v.is_finite())
}
