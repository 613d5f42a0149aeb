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

/// Rows per register block of the padded kernels below: their matrices have columns of a length
/// `ld` that is a multiple of it ([`padded_len`]), zero below row n, so no loop has a remainder.
pub(crate) const BLOCK: usize = 8;

/// Column length of a padded matrix of `n` rows.
pub(crate) fn padded_len(n: usize) -> usize {
    n.div_ceil(BLOCK) * BLOCK
}

/// Defines `pub(crate) fn $name` calling `$kernel` compiled for AVX2 when the CPU has it (4
/// doubles per instruction instead of SSE2's 2; the same operations in the same order, so the
/// same results: Rust never fuses a multiply and an add by itself), else as compiled.
macro_rules! avx2_dispatch {
    ($(#[$doc:meta])* $name:ident => $kernel:ident($($arg:ident: $ty:ty),*)) => {
        $(#[$doc])*
        pub(crate) fn $name($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                #[target_feature(enable = "avx2")]
                unsafe fn avx2($($arg: $ty),*) {
                    $kernel($($arg),*)
                }
                // SAFETY: the CPU supports AVX2 (checked above).
                return unsafe { avx2($($arg),*) };
            }
            $kernel($($arg),*)
        }
    };
}

avx2_dispatch! {
    /// `y (ld) = a (ld × q) · x (q)`, `a` padded: each block of `BLOCK` rows is summed in
    /// registers over all columns (the same sum, in the same order, as [`mul_vec`]).
    mul_vec_padded => mul_vec_padded_kernel(a: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize)
}

#[inline(always)]
fn mul_vec_padded_kernel(a: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize) {
    for (b, yb) in y[..ld].chunks_exact_mut(BLOCK).enumerate() {
        let mut acc = [0.0; BLOCK];
        for (col, &xk) in a[..ld * q].chunks_exact(ld).zip(&x[..q]) {
            let ab: &[f64; BLOCK] = col[b * BLOCK..(b + 1) * BLOCK].try_into().unwrap();
            for (s, aik) in acc.iter_mut().zip(ab) {
                *s += aik * xk;
            }
        }
        yb.copy_from_slice(&acc);
    }
}

avx2_dispatch! {
    /// `a (ld × q) -= u (ld) · vᵀ (q)`, `a` and `u` padded (the rank-one case of [`sub_mul_nt`]).
    sub_outer_padded => sub_outer_padded_kernel(a: &mut [f64], u: &[f64], v: &[f64], ld: usize, q: usize)
}

#[inline(always)]
fn sub_outer_padded_kernel(a: &mut [f64], u: &[f64], v: &[f64], ld: usize, q: usize) {
    let u = &u[..ld];
    for (col, &vk) in a[..ld * q].chunks_exact_mut(ld).zip(&v[..q]) {
        if vk != 0.0 {
            for (c, x) in col.iter_mut().zip(u) {
                *c -= vk * x;
            }
        }
    }
}

avx2_dispatch! {
    /// `c (ld × p) = a (ld × q) · b (q × p)`, `a` and `c` padded: [`mul_vec_padded`] per column.
    mul_padded => mul_padded_kernel(a: &[f64], b: &[f64], c: &mut [f64], ld: usize, q: usize, p: usize)
}

#[inline(always)]
fn mul_padded_kernel(a: &[f64], b: &[f64], c: &mut [f64], ld: usize, q: usize, p: usize) {
    for (cj, bj) in c[..ld * p].chunks_exact_mut(ld).zip(b[..q * p].chunks_exact(q)) {
        mul_vec_padded_kernel(a, bj, cj, ld, q);
    }
}

/// Copies the column-major `src` (n × p) into the padded `dst` (ld × p, zero below row n).
pub(crate) fn pad(src: &[f64], dst: &mut [f64], n: usize, ld: usize, p: usize) {
    for (d, s) in dst[..ld * p].chunks_exact_mut(ld).zip(src[..n * p].chunks_exact(n)) {
        d[..n].copy_from_slice(s);
        d[n..].fill(0.0);
    }
}

/// Copies the padded `src` (ld × p) into the column-major `dst` (n × p).
pub(crate) fn unpad(src: &[f64], dst: &mut [f64], n: usize, ld: usize, p: usize) {
    for (d, s) in dst[..n * p].chunks_exact_mut(n).zip(src[..ld * p].chunks_exact(ld)) {
        d.copy_from_slice(&s[..n]);
    }
}

/// Sets the padded `dst` (ld × n) to the n × n identity.
pub(crate) fn set_identity_padded(dst: &mut [f64], n: usize, ld: usize) {
    dst[..ld * n].fill(0.0);
    for (k, col) in dst[..ld * n].chunks_exact_mut(ld).enumerate() {
        col[k] = 1.0;
    }
}
