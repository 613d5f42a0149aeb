//! Small dense kernels on column-major slices (leading dimension = number of rows).
//!
//! Why not nalgebra's `gemm`: for dynamic matrices with all sides above 5 it calls
//! `matrixmultiply`, which allocates its packing buffer on every call; the control cycle must not
//! touch the heap. At the sizes of a task hierarchy (n ≤ ~20 joints, m ≤ a few tens of rows)
//! these plain loops are as fast. Every kernel runs its inner loop down a contiguous column.

/// `c (r × p) = a (r × q) · b (q × p)`.
pub(crate) fn mul(a: &[f64], b: &[f64], c: &mut [f64], r: usize, q: usize, p: usize) {
    // chunks_exact: no bounds checks in the inner loop, which then vectorizes
    for (cj, bj) in c[..r * p].chunks_exact_mut(r).zip(b[..q * p].chunks_exact(q)) {
        cj.fill(0.0);
        for (ak, &bkj) in a[..r * q].chunks_exact(r).zip(bj) {
            if bkj != 0.0 {
                axpy(bkj, ak, cj);
            }
        }
    }
}

/// `c (q × p) = aᵀ · b` with `a` (r × q) and `b` (r × p).
pub(crate) fn mul_tn(a: &[f64], b: &[f64], c: &mut [f64], r: usize, q: usize, p: usize) {
    for (cj, bj) in c[..q * p].chunks_exact_mut(q).zip(b[..r * p].chunks_exact(r)) {
        for (cij, ai) in cj.iter_mut().zip(a[..r * q].chunks_exact(r)) {
            *cij = dot(ai, bj);
        }
    }
}

/// `c (r × p) -= a (r × q) · bᵀ` with `b` (p × q).
pub(crate) fn sub_mul_nt(c: &mut [f64], a: &[f64], b: &[f64], r: usize, q: usize, p: usize) {
    let b = &b[..p * q];
    for (j, cj) in c[..r * p].chunks_exact_mut(r).enumerate() {
        for (k, ak) in a[..r * q].chunks_exact(r).enumerate() {
            let bjk = b[k * p + j];
            if bjk != 0.0 {
                axpy(-bjk, ak, cj);
            }
        }
    }
}

/// `y (r) = a (r × q) · x (q)`.
pub(crate) fn mul_vec(a: &[f64], x: &[f64], y: &mut [f64], r: usize, q: usize) {
    y[..r].fill(0.0);
    add_mul_vec(a, x, y, r, q);
}

/// `y (r) += a (r × q) · x (q)`.
pub(crate) fn add_mul_vec(a: &[f64], x: &[f64], y: &mut [f64], r: usize, q: usize) {
    let y = &mut y[..r];
    for (ak, &xk) in a[..r * q].chunks_exact(r).zip(&x[..q]) {
        if xk != 0.0 {
            axpy(xk, ak, y);
        }
    }
}

/// `y (q) = aᵀ · x` with `a` (r × q) and `x` (r).
pub(crate) fn mul_tr_vec(a: &[f64], x: &[f64], y: &mut [f64], r: usize, q: usize) {
    for (yi, ai) in y[..q].iter_mut().zip(a[..r * q].chunks_exact(r)) {
        *yi = dot(ai, &x[..r]);
    }
}

/// `y += alpha · x`.
pub(crate) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

/// `xᵀ y`.
pub(crate) fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// Euclidean norm.
pub(crate) fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}
