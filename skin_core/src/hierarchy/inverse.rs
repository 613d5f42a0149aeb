//! The two inverses of the hierarchy, both in place in preallocated buffers:
//!
//! - `M⁻¹` of the SPD joint-space mass matrix: Cholesky `M = L Lᵀ`, then `M⁻¹ = L⁻ᵀ L⁻¹`
//!   (our own in-place code: nalgebra's `Cholesky` takes and returns owned matrices, which
//!   allocates for dynamic sizes). About n³ flops; n = 15 for TOMM.
//! - the damped, rank-aware inverse `Λ̄ = (J̄ M⁻¹ J̄ᵀ)⁻¹` of interactive-force-control paper eq. (23): the matrix is
//!   symmetric positive semidefinite, so it is diagonalized in place (Householder tridiagonal
//!   reduction + implicit QL; nalgebra's `SymmetricEigen` does the same but allocates) and every
//!   eigenvalue is inverted by the filter [`InverseParams::filter`].

use super::dense::sub_outer_padded_kernel;
use super::error::HierarchyError;

/// Parameters of the damped, rank-aware inverse of `A = J̄ M⁻¹ J̄ᵀ` (interactive-force-control paper eq. 23, 25).
///
/// Eigenvalues `e` of `A` are "task-space inverse masses" (1/kg for translational rows,
/// 1/(kg m²) for rotational rows). With `e_max` the largest eigenvalue of the level:
/// - `e ≤ max(rank_threshold_rel · e_max, rank_threshold_abs)`: the direction is not controllable
///   (duplicated rows, a row dependent on a higher level, a vanished Jacobian): inverse 0, not
///   counted in the rank;
/// - `e ≥ damping`: exact inverse `1/e`, so the hierarchy is the paper's strict one;
/// - in between (`x = e/damping < 1`): `x (3 − 2x) / damping`. The achieved fraction of the
///   reference in that direction, `e · f(e) = x²(3 − 2x)`, is a smoothstep from 0 (singular) to
///   1 (band edge) with zero slope at the edge, so torques fade smoothly when a direction is lost
///   instead of growing like `1/√e` (the jerks and "extremely high speeds" near singularities).
///
/// Bounds that follow (documented in `docs/hierarchy.md`): `‖Λ̄‖ ≤ 1.125/damping`, and the level
/// torque satisfies `‖τ̄‖ ≤ 1.03 √(λ_max(M)/damping) ‖r‖` for the reference `r` it is given.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct InverseParams {
    /// Eigenvalues below this fraction of the level's largest one are treated as zero
    /// (dimensionless, in `[0, 1)`). Default `1e-12` (singular-value ratio 1e-6): well above
    /// round-off (~1e-16), well below any direction the damping band still uses.
    pub rank_threshold_rel: f64,
    /// Eigenvalues below this are treated as zero (task-space inverse mass, ≥ 0). Default `1e-12`:
    /// a Jacobian that vanishes (no active skin cell) contributes nothing.
    pub rank_threshold_abs: f64,
    /// Width of the damping band (task-space inverse mass, ≥ 0; 0 = plain thresholded
    /// pseudo-inverse). Default `1e-3` (1/kg): damping starts when the effective task mass in a
    /// direction exceeds 1000 kg, which on planar7 and TOMM happens only within a few degrees of
    /// a singularity. Raise it to damp earlier (smaller torques, less tracking near singularities).
    pub damping: f64,
}

impl Default for InverseParams {
    fn default() -> Self {
        Self { rank_threshold_rel: 1e-12, rank_threshold_abs: 1e-12, damping: 1e-3 }
    }
}

impl InverseParams {
    /// Checks ranges: `rank_threshold_rel ∈ [0, 1)`, `rank_threshold_abs ≥ 0`, `damping ≥ 0`,
    /// all finite.
    pub fn validate(&self) -> Result<(), HierarchyError> {
        let check = |name, value: f64, ok: bool, reason| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(HierarchyError::InvalidParameter { name, value, reason })
            }
        };
        check(
            "rank_threshold_rel",
            self.rank_threshold_rel,
            (0.0..1.0).contains(&self.rank_threshold_rel),
            "must be in [0, 1)",
        )?;
        check(
            "rank_threshold_abs",
            self.rank_threshold_abs,
            self.rank_threshold_abs >= 0.0,
            "must be finite and >= 0",
        )?;
        check("damping", self.damping, self.damping >= 0.0, "must be finite and >= 0")
    }

    /// Rank threshold for a level whose largest eigenvalue is `e_max`.
    pub fn threshold(&self, e_max: f64) -> f64 {
        (self.rank_threshold_rel * e_max).max(self.rank_threshold_abs)
    }

    /// Filtered inverse `f(e)` of one eigenvalue given the rank threshold `thr`
    /// (see the type's documentation). Returns 0 for `e ≤ thr`.
    pub fn filter(&self, e: f64, thr: f64) -> f64 {
        if e <= thr {
            0.0
        } else if e >= self.damping {
            1.0 / e
        } else {
            let x = e / self.damping;
            x * (3.0 - 2.0 * x) / self.damping
        }
    }
}

/// Result of one damped inverse: how many directions were kept and how many were damped.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct InverseInfo {
    pub(crate) rank: usize,
    pub(crate) damped: usize,
    pub(crate) min_kept: f64,
}

avx2_dispatch! {
    /// Cholesky `M = L Lᵀ` of the SPD `m` (n × n, column-major, lower triangle read) into `l`
    /// (ld × n, ld ≥ n: lower triangle written, upper and rows n.. zeroed). Fails on a pivot that is
    /// not clearly positive.
    ///
    /// Right-looking: once column k is final, `L[i, c] −= L[c, k] L[i, k]` (i ≥ c) in every later
    /// column c. Each entry gets `M[i, c] − Σ_{k<c} L[c, k] L[i, k]` subtracted in the order of k, as
    /// a left-looking column-by-column pass would, but the later columns' updates are independent of
    /// each other instead of one dependent chain per column.
    cholesky => cholesky_kernel(m: &[f64], l: &mut [f64], n: usize, ld: usize) -> Result<(), HierarchyError>
}

#[inline(always)]
fn cholesky_kernel(m: &[f64], l: &mut [f64], n: usize, ld: usize) -> Result<(), HierarchyError> {
    with_const_ld!(ld, { cholesky_columns(m, l, n, ld) })
}

#[inline(always)]
fn cholesky_columns(m: &[f64], l: &mut [f64], n: usize, ld: usize) -> Result<(), HierarchyError> {
    super::dense::pad(m, l, n, ld, n);
    for k in 0..n {
        let (done, later) = l[..ld * n].split_at_mut((k + 1) * ld);
        let col = &mut done[k * ld..];
        let d = col[k];
        // relative guard: a pivot at round-off level means M is singular to working precision
        // (NaN fails `>`, hence the explicit finiteness check)
        if !d.is_finite() || d <= f64::EPSILON * m[k * n + k].abs() {
            return Err(HierarchyError::NotPositiveDefinite { index: k, pivot: d });
        }
        // rows above k: the other columns' updates (never read), now zero
        col[..k].fill(0.0);
        let inv = 1.0 / d.sqrt();
        for x in col.iter_mut() {
            *x *= inv;
        }
        // whole columns: rows below c as described, rows up to c (zeroed at their turn) too
        sub_outer_padded_kernel(later, col, &col[k + 1..n], ld, n - k - 1);
    }
    Ok(())
}

/// `M⁻¹ = L⁻ᵀ L⁻¹` from the Cholesky factor `l` (n × n); `linv` receives `L⁻¹`, `minv` the
/// result (full symmetric matrix).
pub(crate) fn spd_inverse_from_cholesky(l: &[f64], linv: &mut [f64], minv: &mut [f64], n: usize) {
    lower_inverse_rows(l, n, minv, n, n); // minv: scratch for the rows
    transpose(minv, linv, n);
    // (L⁻ᵀ L⁻¹)_ij = Σ_{k ≥ max(i,j)} L⁻¹_ki L⁻¹_kj: a dot product of two column tails
    for j in 0..n {
        for i in 0..=j {
            let s = super::dense::dot(&linv[i * n + j..(i + 1) * n], &linv[j * n + j..(j + 1) * n]);
            minv[j * n + i] = s;
            minv[i * n + j] = s;
        }
    }
}

avx2_dispatch! {
    /// [`spd_inverse_from_cholesky`] from the padded factor `l` (ld × n) into the padded `minv`
    /// (ld × n, `dense::padded_len`): the same sums `Σ_k L⁻¹_ki L⁻¹_kj` in the same order, as
    /// rank-one updates with the rows `r_k` of `L⁻¹` (nonzero up to column k) down padded columns
    /// instead of n² short dot products. `rows` (ld × n) receives the rows as padded columns.
    spd_inverse_padded => spd_inverse_padded_kernel(l: &[f64], rows: &mut [f64], minv: &mut [f64], n: usize, ld: usize)
}

/// `L⁻¹` (n × n, into `linv`) from the padded factor `l` (ld × n) of [`cholesky`], the same
/// numbers as [`spd_inverse_from_cholesky`] gives; `rows` (ld × n) is scratch.
pub(crate) fn lower_inverse_padded(l: &[f64], rows: &mut [f64], linv: &mut [f64], n: usize, ld: usize) {
    lower_inverse_rows(l, ld, rows, n, ld);
    for (k, rk) in rows[..ld * n].chunks_exact(ld).enumerate() {
        for (j, x) in rk[..n].iter().enumerate() {
            linv[j * n + k] = *x;
        }
    }
}

#[inline(always)]
fn spd_inverse_padded_kernel(l: &[f64], rows: &mut [f64], minv: &mut [f64], n: usize, ld: usize) {
    with_const_ld!(ld, { spd_inverse_columns(l, rows, minv, n, ld) })
}

#[inline(always)]
fn spd_inverse_columns(l: &[f64], rows: &mut [f64], minv: &mut [f64], n: usize, ld: usize) {
    lower_inverse_rows(l, ld, rows, n, ld);
    // −M⁻¹ = −Σ_k r_k r_kᵀ (the columns j ≤ k that r_k reaches), then negated: exact
    minv[..ld * n].fill(0.0);
    for (k, rk) in rows[..ld * n].chunks_exact(ld).enumerate() {
        sub_outer_padded_kernel(&mut minv[..ld * (k + 1)], rk, &rk[..=k], ld, k + 1);
    }
    for x in &mut minv[..ld * n] {
        *x = -*x;
    }
}

/// The rows of `L⁻¹` (lower triangular `l`, n × n with leading dimension `ldl`) as the columns
/// of `rows` (ld × n, zero below row k in column k and below row n): forward substitution
/// `L x = e_j` for all j at once, row k of `L⁻¹` final at step k:
///
/// ```text
/// r_k ← r_k / L[k, k],   r_i ← r_i − L[i, k] r_k  (i > k)
/// ```
///
/// Every entry sees the same operations, in the same order, as a substitution column by column
/// (plus subtractions of `L[i, k] · 0` that change nothing), but the k-th step's updates are
/// independent of each other (no chain of divisions per column), and run down whole columns.
#[inline(always)]
fn lower_inverse_rows(l: &[f64], ldl: usize, rows: &mut [f64], n: usize, ld: usize) {
    super::dense::set_identity_padded(rows, n, ld);
    for k in 0..n {
        let lk = &l[k * ldl..k * ldl + n];
        let (done, later) = rows[..ld * n].split_at_mut((k + 1) * ld);
        // whole columns: the entries past k are 0 in r_k and stay as they are in r_i
        let rk = &mut done[k * ld..];
        for x in rk.iter_mut() {
            *x /= lk[k];
        }
        sub_outer_padded_kernel(later, rk, &lk[k + 1..], ld, n - k - 1);
    }
}

/// `dst = srcᵀ` (n × n).
fn transpose(src: &[f64], dst: &mut [f64], n: usize) {
    for (j, col) in src[..n * n].chunks_exact(n).enumerate() {
        for (i, x) in col.iter().enumerate() {
            dst[i * n + j] = *x;
        }
    }
}

/// Eigen decomposition of the symmetric `a` (m × m, column-major, overwritten: its diagonal ends
/// up holding the eigenvalues, the rest zero); `v` receives the orthonormal eigenvectors as
/// columns. Householder reduction to tridiagonal form, then the implicit QL iteration with
/// Wilkinson shifts (EISPACK `tred2`/`tql2`, as in the public-domain JAMA): about `9 m³` flops,
/// a few times cheaper than cyclic Jacobi sweeps for the 10-20 stacked skin rows of a level,
/// with eigenvalues accurate to `ε ‖A‖` (the rank threshold is `1e-12 e_max`, far above that).
/// A 2 × 2 matrix takes one Jacobi rotation instead ([`symmetric_eigen_2x2`]).
pub(crate) fn symmetric_eigen(a: &mut [f64], v: &mut [f64], m: usize) {
    if m <= 1 {
        v[..m].fill(1.0);
        return;
    }
    if m == 2 {
        symmetric_eigen_2x2(a, v);
        return;
    }
    v[..m * m].copy_from_slice(&a[..m * m]);
    // d and e (diagonal and sub-diagonal) live in the first two columns of `a`
    let (d, rest) = a.split_at_mut(m);
    let e = &mut rest[..m];
    tridiagonalize(v, d, e, m);
    tridiagonal_ql(v, d, e, m);
    // d is a[..m]; spread it onto the diagonal (back to front: a[i*m+i] >= i, no overlap issue
    // except i = 0, which is already in place)
    for i in (1..m).rev() {
        a[i * m + i] = a[i];
    }
    for c in 0..m {
        for r in 0..m {
            if r != c {
                a[c * m + r] = 0.0;
            }
        }
    }
}

/// [`symmetric_eigen`] of a 2 × 2 matrix: the Jacobi rotation `J = [c s; −s c]` that makes
/// `Jᵀ A J` diagonal (Golub & Van Loan, Algorithm 8.5.1 `symSchur2`): with
/// `τ = (a₁₁ − a₀₀) / (2 a₁₀)` and `t = sign(τ) / (|τ| + √(1 + τ²))` (the smaller rotation), the
/// eigenvalues are `a₀₀ − t a₁₀` and `a₁₁ + t a₁₀`, exact to rounding, and the columns of `J`
/// the eigenvectors. A quarter of the flops of the general path's reduction alone.
fn symmetric_eigen_2x2(a: &mut [f64], v: &mut [f64]) {
    let (a00, a10, a11) = (a[0], a[1], a[3]);
    let (c, s, t) = if a10 == 0.0 {
        (1.0, 0.0, 0.0)
    } else {
        let tau = (a11 - a00) / (2.0 * a10);
        let t = 1.0f64.copysign(tau) / (tau.abs() + hypot(tau, 1.0));
        let c = 1.0 / hypot(t, 1.0);
        (c, t * c, t)
    };
    a[..4].copy_from_slice(&[a00 - t * a10, 0.0, 0.0, a11 + t * a10]);
    v[..4].copy_from_slice(&[c, -s, s, c]);
}

/// Householder reduction of the symmetric matrix in `v` (column-major, `V(i, j) = v[j m + i]`)
/// to tridiagonal form: `d` the diagonal, `e[1..]` the sub-diagonal; `v` becomes the orthogonal
/// transformation. EISPACK `tred2`.
fn tridiagonalize(v: &mut [f64], d: &mut [f64], e: &mut [f64], n: usize) {
    let ix = |i: usize, j: usize| j * n + i;
    for j in 0..n {
        d[j] = v[ix(n - 1, j)];
    }
    for i in (1..n).rev() {
        let scale: f64 = d[..i].iter().map(|x| x.abs()).sum();
        let mut h = 0.0;
        if scale == 0.0 {
            e[i] = d[i - 1];
            for j in 0..i {
                d[j] = v[ix(i - 1, j)];
                v[ix(i, j)] = 0.0;
                v[ix(j, i)] = 0.0;
            }
        } else {
            for dk in &mut d[..i] {
                *dk /= scale;
                h += *dk * *dk;
            }
            let f = d[i - 1];
            let g = if f > 0.0 { -h.sqrt() } else { h.sqrt() };
            e[i] = scale * g;
            h -= f * g;
            d[i - 1] = f - g;
            e[..i].fill(0.0);
            for j in 0..i {
                let f = d[j];
                v[ix(j, i)] = f;
                let mut g = e[j] + v[ix(j, j)] * f;
                for k in j + 1..i {
                    g += v[ix(k, j)] * d[k];
                    e[k] += v[ix(k, j)] * f;
                }
                e[j] = g;
            }
            let mut f = 0.0;
            for j in 0..i {
                e[j] /= h;
                f += e[j] * d[j];
            }
            let hh = f / (h + h);
            for j in 0..i {
                e[j] -= hh * d[j];
            }
            for j in 0..i {
                let (f, g) = (d[j], e[j]);
                for k in j..i {
                    v[ix(k, j)] -= f * e[k] + g * d[k];
                }
                d[j] = v[ix(i - 1, j)];
                v[ix(i, j)] = 0.0;
            }
        }
        d[i] = h;
    }
    // accumulate the transformations
    for i in 0..n - 1 {
        v[ix(n - 1, i)] = v[ix(i, i)];
        v[ix(i, i)] = 1.0;
        let h = d[i + 1];
        if h != 0.0 {
            for k in 0..=i {
                d[k] = v[ix(k, i + 1)] / h;
            }
            for j in 0..=i {
                let g: f64 = (0..=i).map(|k| v[ix(k, i + 1)] * v[ix(k, j)]).sum();
                for k in 0..=i {
                    v[ix(k, j)] -= g * d[k];
                }
            }
        }
        for k in 0..=i {
            v[ix(k, i + 1)] = 0.0;
        }
    }
    for j in 0..n {
        d[j] = v[ix(n - 1, j)];
        v[ix(n - 1, j)] = 0.0;
    }
    v[ix(n - 1, n - 1)] = 1.0;
    e[0] = 0.0;
}

/// `√(a² + b²)` without overflow or underflow, cheaper than libm's correctly rounded `hypot`
/// (which dominated the QL iteration's cost).
#[inline]
fn hypot(a: f64, b: f64) -> f64 {
    let (a, b) = (a.abs(), b.abs());
    let (big, small) = if a > b { (a, b) } else { (b, a) };
    if big < 1e150 && small > 1e-150 {
        (a * a + b * b).sqrt()
    } else if big == 0.0 {
        0.0
    } else {
        let r = small / big;
        big * (1.0 + r * r).sqrt()
    }
}

/// Eigenvalues (into `d`) and eigenvectors (accumulated into `v`) of the symmetric tridiagonal
/// matrix (`d`, `e[1..]`) by the implicit QL method. EISPACK `tql2`, with an iteration cap so
/// that no input can loop forever (30 iterations per eigenvalue; 2-3 are typical).
fn tridiagonal_ql(v: &mut [f64], d: &mut [f64], e: &mut [f64], n: usize) {
    for i in 1..n {
        e[i - 1] = e[i];
    }
    e[n - 1] = 0.0;
    let (mut f, mut tst1) = (0.0f64, 0.0f64);
    for l in 0..n {
        tst1 = tst1.max(d[l].abs() + e[l].abs());
        let mut m = l;
        while m < n - 1 && e[m].abs() > f64::EPSILON * tst1 {
            m += 1;
        }
        if m > l {
            for _ in 0..30 {
                // Wilkinson shift
                let g = d[l];
                let mut p = (d[l + 1] - g) / (2.0 * e[l]);
                let mut r = hypot(p, 1.0);
                if p < 0.0 {
                    r = -r;
                }
                d[l] = e[l] / (p + r);
                d[l + 1] = e[l] * (p + r);
                let dl1 = d[l + 1];
                let mut h = g - d[l];
                for di in &mut d[l + 2..n] {
                    *di -= h;
                }
                f += h;
                // implicit QL transformation
                p = d[m];
                let (mut c, mut c2, mut c3) = (1.0, 1.0, 1.0);
                let el1 = e[l + 1];
                let (mut s, mut s2) = (0.0, 0.0);
                for i in (l..m).rev() {
                    c3 = c2;
                    c2 = c;
                    s2 = s;
                    let g = c * e[i];
                    h = c * p;
                    r = hypot(p, e[i]);
                    e[i + 1] = s * r;
                    s = e[i] / r;
                    c = p / r;
                    p = c * d[i] - s * g;
                    d[i + 1] = h + s * (c * g + s * d[i]);
                    let (ci, ci1) = v[i * n..(i + 2) * n].split_at_mut(n);
                    for (vk, vk1) in ci.iter_mut().zip(ci1.iter_mut()) {
                        let h = *vk1;
                        *vk1 = s * *vk + c * h;
                        *vk = c * *vk - s * h;
                    }
                }
                p = -s * s2 * c3 * el1 * e[l] / dl1;
                e[l] = s * p;
                d[l] = c * p;
                if e[l].abs() <= f64::EPSILON * tst1 {
                    break;
                }
            }
        }
        d[l] += f;
        e[l] = 0.0;
    }
}

/// Damped, rank-aware inverse of the symmetric PSD `a` (m × m, destroyed): `out = V f(E) Vᵀ`
/// with the filter of [`InverseParams`]. `v` and `w` are scratch (m × m).
///
/// Rows (and columns) of `a` that are exactly zero come from task rows no joint moves (the
/// out-of-plane row of a planar arm's position task, a row a higher level took whole): each is an
/// eigenvalue 0 with a unit eigenvector, so its row and column of `out` are 0 and the other rows
/// are inverted on their own, which usually takes a cheaper path of [`damped_inverse_full`] (the
/// Cholesky fast path, or the closed form for one or two rows) instead of the general eigen
/// decomposition. Levels of more than 64 rows are inverted whole.
pub(crate) fn damped_inverse(
    a: &mut [f64],
    v: &mut [f64],
    w: &mut [f64],
    out: &mut [f64],
    m: usize,
    params: &InverseParams,
) -> InverseInfo {
    let zero = if m <= 64 { zero_rows(a, m) } else { 0 };
    if zero == 0 {
        return damped_inverse_full(a, v, w, out, m, params);
    }
    let kept = m - zero.count_ones() as usize;
    compact(a, m, zero);
    let info = if kept == 0 { InverseInfo::default() } else { damped_inverse_full(a, v, w, out, kept, params) };
    expand(out, m, kept, zero);
    info
}

/// Bit i set: row i of the symmetric `a` (m × m, m ≤ 64) is exactly zero.
fn zero_rows(a: &[f64], m: usize) -> u64 {
    a[..m * m]
        .chunks_exact(m)
        .enumerate()
        .filter(|(_, col)| col.iter().all(|&x| x == 0.0))
        .fold(0, |z, (i, _)| z | 1 << i)
}

/// Moves the rows and columns of `a` (m × m) that are not in `zero` to the front, as a
/// kept × kept matrix (in place: every entry moves to a lower index, in increasing order).
fn compact(a: &mut [f64], m: usize, zero: u64) {
    let mut d = 0;
    for c in (0..m).filter(|c| zero >> c & 1 == 0) {
        for r in (0..m).filter(|r| zero >> r & 1 == 0) {
            a[d] = a[c * m + r];
            d += 1;
        }
    }
}

/// The inverse of [`compact`] for `out`: the kept × kept matrix at the front of `out` spread to
/// m × m with zero rows and columns at `zero` (in place, from the back).
fn expand(out: &mut [f64], m: usize, kept: usize, zero: u64) {
    let below = |i: usize| i - (zero & ((1u64 << i) - 1)).count_ones() as usize;
    for c in (0..m).rev() {
        for r in (0..m).rev() {
            let keep = zero >> c & 1 == 0 && zero >> r & 1 == 0;
            out[c * m + r] = if keep { out[below(c) * kept + below(r)] } else { 0.0 };
        }
    }
}

/// [`damped_inverse`] without looking for zero rows.
///
/// Fast path first (m > 2): a Cholesky inverse `A⁻¹`; if `1/‖A⁻¹‖_F` (a lower bound of the
/// smallest eigenvalue) is above both the damping band and the rank threshold, every eigenvalue
/// gets `f(e) = 1/e`, so `A⁻¹` *is* the filtered inverse and the eigen decomposition (the most
/// expensive step) is skipped. Otherwise the eigen decomposition and the filter; for m ≤ 2 it is
/// closed-form and cheaper than the Cholesky inverse, so it is taken directly.
fn damped_inverse_full(
    a: &mut [f64],
    v: &mut [f64],
    w: &mut [f64],
    out: &mut [f64],
    m: usize,
    params: &InverseParams,
) -> InverseInfo {
    let trace: f64 = (0..m).map(|i| a[i * m + i]).sum();
    if m > 2 && trace > 0.0 && cholesky(a, v, m, m).is_ok() {
        spd_inverse_from_cholesky(v, w, out, m);
        let e_min_bound = 1.0 / super::dense::norm(&out[..m * m]);
        // e_max ≤ trace bounds the relative threshold from above
        if e_min_bound >= params.damping && e_min_bound > params.threshold(trace) {
            return InverseInfo { rank: m, damped: 0, min_kept: e_min_bound };
        }
    }
    symmetric_eigen(a, v, m);
    let e_max = (0..m).map(|i| a[i * m + i]).fold(0.0, f64::max);
    let thr = params.threshold(e_max);
    let mut info = InverseInfo { rank: 0, damped: 0, min_kept: 0.0 };
    out[..m * m].fill(0.0);
    for i in 0..m {
        let e = a[i * m + i];
        let f = params.filter(e, thr);
        if f == 0.0 {
            continue;
        }
        info.min_kept = if info.rank == 0 { e } else { info.min_kept.min(e) };
        info.rank += 1;
        if e < params.damping {
            info.damped += 1;
        }
        let vi = &v[i * m..(i + 1) * m];
        for c in 0..m {
            let fc = f * vi[c];
            for r in 0..m {
                out[c * m + r] += vi[r] * fc;
            }
        }
    }
    info
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn random_spd(n: usize, seed: u64) -> DMatrix<f64> {
        let mut s = seed;
        let b = DMatrix::from_fn(n, n, |_, _| {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        });
        &b * b.transpose() + DMatrix::identity(n, n) * 0.1
    }

    #[test]
    fn cholesky_inverse_matches_nalgebra() {
        for n in [1, 2, 7, 15, 20] {
            let m = random_spd(n, n as u64);
            let (mut l, mut li, mut mi) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
            cholesky(m.as_slice(), &mut l, n, n).unwrap();
            spd_inverse_from_cholesky(&l, &mut li, &mut mi, n);
            let mi = DMatrix::from_column_slice(n, n, &mi);
            let err = (&m * &mi - DMatrix::identity(n, n)).norm();
            assert!(err < 1e-10, "n = {n}: |M M⁻¹ − I| = {err}");
        }
    }

    #[test]
    fn padded_inverse_is_the_plain_one() {
        for n in [1, 7, 15, 17] {
            let m = random_spd(n, 50 + n as u64);
            let ld = crate::hierarchy::dense::padded_len(n);
            let (mut l, mut li, mut mi) = (vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]);
            let (mut rows, mut mp, mut back) = (vec![0.0; ld * n], vec![1.0; ld * n], vec![0.0; n * n]);
            let (mut lp, mut lip) = (vec![1.0; ld * n], vec![0.0; n * n]);
            cholesky(m.as_slice(), &mut l, n, n).unwrap();
            spd_inverse_from_cholesky(&l, &mut li, &mut mi, n);
            cholesky(m.as_slice(), &mut lp, n, ld).unwrap();
            crate::hierarchy::dense::unpad(&lp, &mut back, n, ld, n);
            assert_eq!(back, l, "n = {n}: padded factor");
            spd_inverse_padded(&lp, &mut rows, &mut mp, n, ld);
            lower_inverse_padded(&lp, &mut rows, &mut lip, n, ld);
            assert_eq!(lip, li, "n = {n}: L⁻¹");
            crate::hierarchy::dense::unpad(&mp, &mut back, n, ld, n);
            assert_eq!(back, mi, "n = {n}");
            assert!(mp.chunks_exact(ld).all(|c| c[n..].iter().all(|&x| x == 0.0)), "padding stays zero");
        }
    }

    #[test]
    fn cholesky_rejects_indefinite() {
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
        let mut l = vec![0.0; 4];
        assert!(matches!(
            cholesky(m.as_slice(), &mut l, 2, 2),
            Err(HierarchyError::NotPositiveDefinite { index: 1, .. })
        ));
    }

    #[test]
    fn eigen_reconstructs_and_is_orthonormal() {
        for m in [1, 2, 3, 6, 13, 40] {
            let a0 = random_spd(m, 100 + m as u64);
            let mut a = a0.as_slice().to_vec();
            let mut v = vec![0.0; m * m];
            symmetric_eigen(&mut a, &mut v, m);
            let vm = DMatrix::from_column_slice(m, m, &v);
            let e = DMatrix::from_diagonal(&DMatrix::from_column_slice(m, m, &a).diagonal());
            assert!((&vm * e * vm.transpose() - &a0).norm() < 1e-12 * a0.norm().max(1.0));
            assert!((vm.transpose() * &vm - DMatrix::identity(m, m)).norm() < 1e-12);
        }
    }

    #[test]
    fn damped_inverse_exact_above_band_and_bounded_below() {
        let p = InverseParams::default();
        p.validate().unwrap();
        // well conditioned: exact inverse
        let a0 = random_spd(4, 7);
        let (mut a, mut v, mut w, mut out) = (a0.as_slice().to_vec(), vec![0.0; 16], vec![0.0; 16], vec![0.0; 16]);
        let info = damped_inverse(&mut a, &mut v, &mut w, &mut out, 4, &p);
        assert_eq!((info.rank, info.damped), (4, 0));
        let inv = DMatrix::from_column_slice(4, 4, &out);
        assert!((&a0 * inv - DMatrix::identity(4, 4)).norm() < 1e-10);
        // rank one (duplicated rows): rank 1, bounded
        let a0 = DMatrix::from_element(3, 3, 2.0);
        let (mut a, mut v, mut w, mut out) = (a0.as_slice().to_vec(), vec![0.0; 9], vec![0.0; 9], vec![0.0; 9]);
        let info = damped_inverse(&mut a, &mut v, &mut w, &mut out, 3, &p);
        assert_eq!(info.rank, 1);
        let inv = DMatrix::from_column_slice(3, 3, &out);
        assert!((&a0 * &inv * &a0 - &a0).norm() < 1e-12, "pseudo-inverse property");
        // the filter is continuous at the band edge and bounded by 1.125/damping
        let d = p.damping;
        assert!((p.filter(d * (1.0 - 1e-9), 0.0) - 1.0 / d).abs() < 1e-5 / d);
        let max = (1..1000).map(|i| p.filter(d * i as f64 / 1000.0, 0.0)).fold(0.0, f64::max);
        assert!(max <= 1.125 / d + 1e-9);
    }

    #[test]
    fn fast_path_equals_filtered_eigen_inverse() {
        let p = InverseParams::default();
        for m in [1, 3, 6] {
            let a0 = random_spd(m, 40 + m as u64);
            let (mut a, mut v, mut w, mut fast) =
                (a0.as_slice().to_vec(), vec![0.0; m * m], vec![0.0; m * m], vec![0.0; m * m]);
            damped_inverse(&mut a, &mut v, &mut w, &mut fast, m, &p);
            // the eigen path on the same matrix
            let mut a = a0.as_slice().to_vec();
            symmetric_eigen(&mut a, &mut v, m);
            let vm = DMatrix::from_column_slice(m, m, &v);
            let thr = p.threshold(a0.norm());
            let f = DMatrix::from_fn(m, m, |r, c| if r == c { p.filter(a[r * m + r], thr) } else { 0.0 });
            let slow = &vm * f * vm.transpose();
            assert!((DMatrix::from_column_slice(m, m, &fast) - &slow).norm() < 1e-10 * slow.norm());
        }
    }

    #[test]
    fn eigen_2x2_handles_the_edge_cases() {
        // diagonal, rank one, equal diagonal, a coupling far below the diagonal's scale, and one far above
        for [a00, a10, a11] in
            [[2.0, 0.0, 3.0], [1.0, 2.0, 4.0], [5.0, 1e-3, 5.0], [1.0, 1e-200, 2.0], [1e-9, 1e9, 0.0]]
        {
            let a0 = DMatrix::from_column_slice(2, 2, &[a00, a10, a10, a11]);
            let (mut a, mut v) = (a0.as_slice().to_vec(), vec![0.0; 4]);
            symmetric_eigen(&mut a, &mut v, 2);
            assert_eq!((a[1], a[2]), (0.0, 0.0));
            let vm = DMatrix::from_column_slice(2, 2, &v);
            let e = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![a[0], a[3]]));
            assert!((&vm * e * vm.transpose() - &a0).norm() <= 1e-15 * a0.norm(), "{a0}");
            assert!((vm.transpose() * &vm - DMatrix::identity(2, 2)).norm() < 1e-15);
        }
    }

    #[test]
    fn zero_rows_are_split_off_and_get_zero_inverse() {
        let p = InverseParams::default();
        let inner = random_spd(3, 9);
        // the 3 × 3 matrix spread over rows/columns 0, 2, 4 of a 5 × 5 one
        let at = [0, 2, 4];
        let a0 =
            DMatrix::from_fn(5, 5, |r, c| match (at.iter().position(|&i| i == r), at.iter().position(|&i| i == c)) {
                (Some(i), Some(j)) => inner[(i, j)],
                _ => 0.0,
            });
        let run = |split: bool| {
            let (mut a, mut v, mut w, mut out) = (a0.as_slice().to_vec(), vec![0.0; 25], vec![0.0; 25], vec![7.0; 25]);
            let info = if split {
                damped_inverse(&mut a, &mut v, &mut w, &mut out, 5, &p)
            } else {
                damped_inverse_full(&mut a, &mut v, &mut w, &mut out, 5, &p)
            };
            (info, DMatrix::from_column_slice(5, 5, &out))
        };
        let ((info, split), (whole_info, whole)) = (run(true), run(false));
        assert_eq!((info.rank, info.damped), (3, 0));
        assert_eq!((whole_info.rank, whole_info.damped), (3, 0), "the eigen path agrees on the rank");
        assert!((&split - &whole).norm() < 1e-10 * whole.norm(), "{split} vs {whole}");
        for i in [1, 3] {
            assert!(split.row(i).iter().chain(split.column(i).iter()).all(|&x| x == 0.0));
        }
        let inv = inner.try_inverse().unwrap();
        for (i, &r) in at.iter().enumerate() {
            for (j, &c) in at.iter().enumerate() {
                assert!((split[(r, c)] - inv[(i, j)]).abs() < 1e-10 * inv.norm());
            }
        }
        // nothing left: rank 0, all zero
        let (mut a, mut v, mut w, mut out) = (vec![0.0; 9], vec![0.0; 9], vec![0.0; 9], vec![1.0; 9]);
        assert_eq!(damped_inverse(&mut a, &mut v, &mut w, &mut out, 3, &p).rank, 0);
        assert!(out.iter().all(|&x| x == 0.0));
    }

    #[test]
    fn params_validation_names_the_key() {
        let bad = InverseParams { damping: f64::NAN, ..Default::default() };
        assert!(matches!(bad.validate(), Err(HierarchyError::InvalidParameter { name: "damping", .. })));
        let bad = InverseParams { rank_threshold_rel: 1.0, ..Default::default() };
        assert!(matches!(bad.validate(), Err(HierarchyError::InvalidParameter { name: "rank_threshold_rel", .. })));
    }
}
