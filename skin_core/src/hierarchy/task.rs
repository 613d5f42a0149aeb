//! One level of the task hierarchy: a Jacobian block and what the level asks for.

use nalgebra::{DMatrixSlice, Dim, Matrix, Storage};

use super::error::HierarchyError;

/// What a level asks for: a task-space acceleration (interactive-force-control paper eq. 9, 10, 12) or a task-space
/// force (intentional-contact paper eq. 3-6). Borrowed: [`TaskLevel::push`] copies it into the level's storage.
#[derive(Clone, Copy, Debug)]
pub enum Reference<'a> {
    /// Reference acceleration `ẍ*` and the drift `J̇ q̇` of the same rows; the level's torque
    /// realizes `ẍ* − J̇ q̇ − a_k` (interactive-force-control paper eq. 20).
    Acceleration {
        /// Reference task acceleration `ẍ*_k` (one entry per row).
        xdd_star: &'a [f64],
        /// `J̇_k q̇` (one entry per row), e.g. from `model::point_jacobian_dot_qdot`.
        jdot_qdot: &'a [f64],
    },
    /// Task-space force `F_k` (one entry per row); the level's torque is `N_{k−1} J_kᵀ F_k`.
    Force {
        /// Force (N, or N m for rotational rows).
        f: &'a [f64],
    },
}

/// Kind of a level's reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceKind {
    /// Task-space acceleration (interactive-force-control paper).
    Acceleration,
    /// Task-space force (intentional-contact paper).
    Force,
}

/// One priority level: `rows` active rows of a Jacobian `J_k` (rows × nv) and their reference.
///
/// Storage is allocated once by [`TaskLevel::new`] for at most `max_rows` rows; each cycle the
/// owner calls [`TaskLevel::clear`] and pushes the currently active rows (e.g. one row per active
/// skin cell), which never allocates. A level with zero rows, or whose Jacobian vanishes,
/// contributes no torque and leaves the null space unchanged. All rows of a level share one
/// [`ReferenceKind`], set by the first push after a clear.
///
/// A force level may instead be filled with *activated* rows
/// ([`TaskLevel::push_row_activated`]): each row carries an activation `a_i ∈ [0, 1]`
/// that weights its share of the null-space projector (continuous null-space projection after
/// Dietrich et al. 2012, `docs/hierarchy.md`), so a skin row entering or leaving the sensing
/// range fades in and out of the projector instead of switching it.
#[derive(Clone, Debug)]
pub struct TaskLevel {
    name: String,
    nv: usize,
    max_rows: usize,
    rows: usize,
    kind: ReferenceKind,
    /// `J_kᵀ`, nv × max_rows column-major: task row r is the contiguous column r.
    jt: Vec<f64>,
    /// `ẍ*` or `F`.
    target: Vec<f64>,
    /// `J̇ q̇` (zeros for force levels).
    jdot_qdot: Vec<f64>,
    /// Per-row activation `a_i` (1 for rows pushed without one).
    activation: Vec<f64>,
    /// Rows were pushed with activations: the solver projects them row by row, weighted.
    activated: bool,
}

impl TaskLevel {
    /// A level named `name` (used in error messages) for `nv` joints with room for `max_rows`
    /// rows; starts empty, of kind acceleration.
    pub fn new(name: &str, nv: usize, max_rows: usize) -> Self {
        Self {
            name: name.to_string(),
            nv,
            max_rows,
            rows: 0,
            kind: ReferenceKind::Acceleration,
            jt: vec![0.0; nv * max_rows],
            target: vec![0.0; max_rows],
            jdot_qdot: vec![0.0; max_rows],
            activation: vec![1.0; max_rows],
            activated: false,
        }
    }

    /// Name of the level.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of joints (Jacobian columns).
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// Row capacity fixed at construction.
    pub fn max_rows(&self) -> usize {
        self.max_rows
    }

    /// Number of active rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Kind of the reference of the active rows.
    pub fn kind(&self) -> ReferenceKind {
        self.kind
    }

    /// Removes all rows (the level then contributes nothing).
    pub fn clear(&mut self) {
        self.rows = 0;
        self.activated = false;
    }

    /// Replaces the level's content by `jacobian` and `reference` (clear + push).
    pub fn set<R: Dim, C: Dim, S: Storage<f64, R, C>>(
        &mut self,
        jacobian: &Matrix<f64, R, C, S>,
        reference: Reference<'_>,
    ) -> Result<(), HierarchyError> {
        self.clear();
        self.push(jacobian, reference)
    }

    /// Appends the rows of `jacobian` (any nalgebra matrix or view, nv columns) with their
    /// reference (one entry per row). Stacked rows may be identical or dependent: the solver's
    /// inverse is rank-aware.
    pub fn push<R: Dim, C: Dim, S: Storage<f64, R, C>>(
        &mut self,
        jacobian: &Matrix<f64, R, C, S>,
        reference: Reference<'_>,
    ) -> Result<(), HierarchyError> {
        let k = jacobian.nrows();
        if jacobian.ncols() != self.nv {
            return Err(self.input_error(format!("Jacobian has {} columns, expected {}", jacobian.ncols(), self.nv)));
        }
        let r0 = self.begin_rows(k, &reference)?;
        for r in 0..k {
            let col = &mut self.jt[(r0 + r) * self.nv..(r0 + r + 1) * self.nv];
            for (c, x) in col.iter_mut().enumerate() {
                *x = jacobian[(r, c)];
            }
        }
        self.store_reference(r0, k, &reference);
        Ok(())
    }

    /// Appends the single row `dᵀ J` (e.g. a skin cell's normal times its point Jacobian's
    /// linear rows) with a one-entry reference, without forming `dᵀ J` on the heap.
    pub fn push_directional<R: Dim, C: Dim, S: Storage<f64, R, C>>(
        &mut self,
        direction: &[f64],
        jacobian: &Matrix<f64, R, C, S>,
        reference: Reference<'_>,
    ) -> Result<(), HierarchyError> {
        if jacobian.ncols() != self.nv || direction.len() != jacobian.nrows() {
            return Err(self.input_error(format!(
                "direction of length {} for a {}x{} Jacobian, expected {} columns",
                direction.len(),
                jacobian.nrows(),
                jacobian.ncols(),
                self.nv
            )));
        }
        let r0 = self.begin_rows(1, &reference)?;
        let col = &mut self.jt[r0 * self.nv..(r0 + 1) * self.nv];
        for (x, jc) in col.iter_mut().zip(jacobian.column_iter()) {
            *x = direction.iter().zip(jc.iter()).map(|(d, j)| d * j).sum();
        }
        self.store_reference(r0, 1, &reference);
        Ok(())
    }

    /// Appends the Jacobian row `row` (length nv, e.g. a skin cell's `dᵀ J_v` from
    /// [`crate::model::point_jacobian_along`]) as a force row `f` with activation `a ∈ [0, 1]`:
    /// the row's torque is `N_{k−1} J_iᵀ f` as always, but it takes only the fraction `a` of its
    /// direction out of the null space left to lower levels (`a = 0`: as if the row were absent,
    /// `a = 1`: strict priority). Plain force rows in the same level count as `a = 1`.
    pub fn push_row_activated(&mut self, row: &[f64], f: f64, a: f64) -> Result<(), HierarchyError> {
        if !(0.0..=1.0).contains(&a) {
            return Err(self.input_error(format!("activation {a} is not in [0, 1]")));
        }
        if row.len() != self.nv {
            return Err(self.input_error(format!("row of length {}, expected {}", row.len(), self.nv)));
        }
        let reference = Reference::Force { f: &[f] };
        let r0 = self.begin_rows(1, &reference)?;
        self.jt[r0 * self.nv..(r0 + 1) * self.nv].copy_from_slice(row);
        self.store_reference(r0, 1, &reference);
        self.activated = true;
        self.activation[r0] = a;
        Ok(())
    }

    /// Whether the rows carry activations ([`TaskLevel::push_row_activated`]).
    pub fn is_activated(&self) -> bool {
        self.activated
    }

    /// Activations `a_i` of the active rows (all 1 for a level of plain rows).
    pub fn activation(&self) -> &[f64] {
        &self.activation[..self.rows]
    }

    /// `J_kᵀ` of the active rows (nv × rows view, no copy).
    pub fn jacobian_transpose(&self) -> DMatrixSlice<'_, f64> {
        DMatrixSlice::from_slice(&self.jt[..self.nv * self.rows], self.nv, self.rows)
    }

    /// Row `r` of `J_k` (length nv).
    pub fn jacobian_row(&self, r: usize) -> &[f64] {
        &self.jt[r * self.nv..(r + 1) * self.nv]
    }

    /// `ẍ*` (acceleration levels) or `F` (force levels) of the active rows.
    pub fn target(&self) -> &[f64] {
        &self.target[..self.rows]
    }

    /// `J̇ q̇` of the active rows (zeros for force levels).
    pub fn jdot_qdot(&self) -> &[f64] {
        &self.jdot_qdot[..self.rows]
    }

    /// `J_kᵀ` storage of the active rows (nv × rows, column-major), for the solver.
    /// Zeroes the Jacobian columns of the joints marked in `locked` (length `nv`): a locked joint
    /// (e.g. a base that is switched off) does not move, so no task can use it.
    pub fn lock_joints(&mut self, locked: &[bool]) {
        let n = self.nv;
        for row in self.jt[..n * self.rows].chunks_exact_mut(n) {
            for (x, &l) in row.iter_mut().zip(locked) {
                if l {
                    *x = 0.0;
                }
            }
        }
    }

    pub(crate) fn jt_slice(&self) -> &[f64] {
        &self.jt[..self.nv * self.rows]
    }

    fn input_error(&self, message: String) -> HierarchyError {
        HierarchyError::LevelInput { name: self.name.clone(), message }
    }

    /// Checks that `k` rows of this reference fit; sets the kind on the first push; returns the
    /// first new row. Inlined: with the row count known at the call (one skin row each push,
    /// many per cycle) the checks and copies below reduce to single stores, not library calls.
    #[inline(always)]
    fn begin_rows(&mut self, k: usize, reference: &Reference<'_>) -> Result<usize, HierarchyError> {
        let (kind, lens) = match reference {
            Reference::Acceleration { xdd_star, jdot_qdot } => {
                (ReferenceKind::Acceleration, [xdd_star.len(), jdot_qdot.len()])
            }
            Reference::Force { f } => (ReferenceKind::Force, [f.len(), f.len()]),
        };
        if lens.iter().any(|&l| l != k) {
            return Err(self.input_error(format!("reference lengths {lens:?} do not match the {k} Jacobian rows")));
        }
        if self.rows > 0 && kind != self.kind {
            return Err(self.input_error(format!("cannot push {kind:?} rows into a {:?} level", self.kind)));
        }
        if self.rows + k > self.max_rows {
            return Err(HierarchyError::Capacity {
                what: format!("rows of level `{}`", self.name),
                got: self.rows + k,
                capacity: self.max_rows,
            });
        }
        self.kind = kind;
        Ok(self.rows)
    }

    #[inline(always)]
    fn store_reference(&mut self, r0: usize, k: usize, reference: &Reference<'_>) {
        self.activation[r0..r0 + k].fill(1.0);
        match reference {
            Reference::Acceleration { xdd_star, jdot_qdot } => {
                self.target[r0..r0 + k].copy_from_slice(xdd_star);
                self.jdot_qdot[r0..r0 + k].copy_from_slice(jdot_qdot);
            }
            Reference::Force { f } => {
                self.target[r0..r0 + k].copy_from_slice(f);
                self.jdot_qdot[r0..r0 + k].fill(0.0);
            }
        }
        self.rows = r0 + k;
    }
}
