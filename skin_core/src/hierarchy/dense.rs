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
#[inline(always)]
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

/// `$body` with `$ld` a compile-time constant when it is one or two blocks (up to 16 joints):
/// in a kernel, this lets the compiler unroll the loops down a column and drop their index
/// checks (a macro, not a closure, so that each copy is surely compiled with its constant).
macro_rules! with_const_ld {
    ($ld:ident, $body:block) => {
        match $ld {
            $crate::hierarchy::dense::BLOCK => {
                let $ld = $crate::hierarchy::dense::BLOCK;
                $body
            }
            16 => {
                let $ld = 16;
                $body
            }
            _ => $body,
        }
    };
}

/// Column length of a padded matrix of `n` rows.
pub(crate) fn padded_len(n: usize) -> usize {
    n.div_ceil(BLOCK) * BLOCK
}

avx2_dispatch! {
    /// `y (ld) = a (ld × q) · x (q)`, `a` padded: each row is summed in registers over all
    /// columns (the same sum, in the same order, as [`mul_vec`]).
    mul_vec_padded => mul_vec_padded_kernel(a: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize)
}

#[inline(always)]
fn mul_vec_padded_kernel(a: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize) {
    mul_vec_streams::<1, false>([a], [x], [y], ld, q);
}

avx2_dispatch! {
    /// `y (ld) += a (ld × q) · x (q)`, `a` and `y` padded: [`mul_vec_padded`] that starts each
    /// sum from `y` (the sums of [`add_mul_vec`], in the same order).
    add_mul_vec_padded => add_mul_vec_padded_kernel(a: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize)
}

#[inline(always)]
fn add_mul_vec_padded_kernel(a: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize) {
    mul_vec_streams::<1, true>([a], [x], [y], ld, q);
}

avx2_dispatch! {
    /// The two products `y1 = a1 · x` and `y2 = a2 · x` (padded, ld × q) in one pass:
    /// [`mul_vec_padded`] twice, with twice the independent sums in flight.
    mul_vec2_padded => mul_vec2_padded_kernel(a1: &[f64], a2: &[f64], x: &[f64], y1: &mut [f64], y2: &mut [f64], ld: usize, q: usize)
}

#[inline(always)]
fn mul_vec2_padded_kernel(a1: &[f64], a2: &[f64], x: &[f64], y1: &mut [f64], y2: &mut [f64], ld: usize, q: usize) {
    mul_vec_streams::<2, false>([a1, a2], [x, x], [y1, y2], ld, q);
}

/// `y_s (ld) = a_s (ld × q) · x_s (q)` (`ADD`: `+=`) for `S` products at once, `PASS` blocks of
/// `BLOCK` rows per pass over the columns: every row's sum runs over the columns in order from 0 (as in
/// [`mul_vec`]), but `S · PASS · BLOCK / 4` independent sums share a pass, so the adds' latency
/// (a dependent chain of q adds per sum) overlaps instead of adding up.
#[inline(always)]
fn mul_vec_streams<const S: usize, const ADD: bool>(
    a: [&[f64]; S],
    x: [&[f64]; S],
    mut y: [&mut [f64]; S],
    ld: usize,
    q: usize,
) {
    const PASS: usize = 2;
    with_const_ld!(ld, {
        let blocks = ld / BLOCK;
        let mut b = 0;
        while b + PASS <= blocks {
            mul_vec_pass::<S, PASS, ADD>(&a, &x, &mut y, ld, q, b);
            b += PASS;
        }
        if b < blocks {
            mul_vec_pass::<S, 1, ADD>(&a, &x, &mut y, ld, q, b);
        }
    });
}

/// Rows `b0 · BLOCK ..< (b0 + G) · BLOCK` of [`mul_vec_streams`].
#[inline(always)]
fn mul_vec_pass<const S: usize, const G: usize, const ADD: bool>(
    a: &[&[f64]; S],
    x: &[&[f64]; S],
    y: &mut [&mut [f64]; S],
    ld: usize,
    q: usize,
    b0: usize,
) {
    let mut acc = [[[0.0; BLOCK]; G]; S];
    if ADD {
        for (accs, ys) in acc.iter_mut().zip(y.iter()) {
            for (g, acc) in accs.iter_mut().enumerate() {
                acc.copy_from_slice(&ys[(b0 + g) * BLOCK..(b0 + g + 1) * BLOCK]);
            }
        }
    }
    let (a, x): ([&[f64]; S], [&[f64]; S]) =
        (std::array::from_fn(|s| &a[s][..ld * q]), std::array::from_fn(|s| &x[s][..q]));
    for k in 0..q {
        for s in 0..S {
            let xk = x[s][k];
            let col = &a[s][k * ld + b0 * BLOCK..][..G * BLOCK];
            for (g, acc) in acc[s].iter_mut().enumerate() {
                let ab: &[f64; BLOCK] = col[g * BLOCK..(g + 1) * BLOCK].try_into().unwrap();
                for (t, aik) in acc.iter_mut().zip(ab) {
                    *t += aik * xk;
                }
            }
        }
    }
    for (ys, accs) in y.iter_mut().zip(&acc) {
        for (g, acc) in accs.iter().enumerate() {
            ys[(b0 + g) * BLOCK..(b0 + g + 1) * BLOCK].copy_from_slice(acc);
        }
    }
}

avx2_dispatch! {
    /// `a (ld × q) -= u (ld) · vᵀ (q)` (the rank-one case of [`sub_mul_nt`]; columns skipped
    /// where `v` is 0), usually on padded `a` and `u`.
    sub_outer_padded => sub_outer_padded_kernel(a: &mut [f64], u: &[f64], v: &[f64], ld: usize, q: usize)
}

#[inline(always)]
pub(crate) fn sub_outer_padded_kernel(a: &mut [f64], u: &[f64], v: &[f64], ld: usize, q: usize) {
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
    /// [`sub_outer_padded`], then `y (ld) = a · x (q)` with the updated `a`, in one pass over
    /// `a`: the same operations, in the same order, as the two calls one after the other.
    sub_outer_mul_vec_padded => sub_outer_mul_vec_padded_kernel(a: &mut [f64], u: &[f64], v: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize)
}

#[inline(always)]
fn sub_outer_mul_vec_padded_kernel(a: &mut [f64], u: &[f64], v: &[f64], x: &[f64], y: &mut [f64], ld: usize, q: usize) {
    const PASS: usize = 2;
    with_const_ld!(ld, {
        let blocks = ld / BLOCK;
        let mut b = 0;
        while b + PASS <= blocks {
            sub_outer_mul_vec_pass::<PASS>(a, u, v, x, y, ld, q, b);
            b += PASS;
        }
        if b < blocks {
            sub_outer_mul_vec_pass::<1>(a, u, v, x, y, ld, q, b);
        }
    });
}

/// Rows `b0 · BLOCK ..< (b0 + G) · BLOCK` of [`sub_outer_mul_vec_padded`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn sub_outer_mul_vec_pass<const G: usize>(
    a: &mut [f64],
    u: &[f64],
    v: &[f64],
    x: &[f64],
    y: &mut [f64],
    ld: usize,
    q: usize,
    b0: usize,
) {
    let mut acc = [[0.0; BLOCK]; G];
    let u = &u[b0 * BLOCK..(b0 + G) * BLOCK];
    for ((col, &vk), &xk) in a[..ld * q].chunks_exact_mut(ld).zip(&v[..q]).zip(&x[..q]) {
        let col = &mut col[b0 * BLOCK..(b0 + G) * BLOCK];
        for ((acc, cb), ub) in acc.iter_mut().zip(col.chunks_exact_mut(BLOCK)).zip(u.chunks_exact(BLOCK)) {
            if vk != 0.0 {
                for (c, x) in cb.iter_mut().zip(ub) {
                    *c -= vk * x;
                }
            }
            for (t, c) in acc.iter_mut().zip(cb.iter()) {
                *t += c * xk;
            }
        }
    }
    for (g, acc) in acc.iter().enumerate() {
        y[(b0 + g) * BLOCK..(b0 + g + 1) * BLOCK].copy_from_slice(acc);
    }
}

avx2_dispatch! {
    /// [`sub_mul_nt`] on padded `c` (ld × p) and `a` (ld × q): the same operations, the column
    /// length a constant where it can be.
    sub_mul_nt_padded => sub_mul_nt_padded_kernel(c: &mut [f64], a: &[f64], b: &[f64], ld: usize, q: usize, p: usize)
}

#[inline(always)]
fn sub_mul_nt_padded_kernel(c: &mut [f64], a: &[f64], b: &[f64], ld: usize, q: usize, p: usize) {
    with_const_ld!(ld, { sub_mul_nt(c, a, b, ld, q, p) });
}

avx2_dispatch! {
    /// `c (ld × p) = a (ld × q) · b (q × p)`, `a` and `c` padded: [`mul_vec_padded`] per column.
    mul_padded => mul_padded_kernel(a: &[f64], b: &[f64], c: &mut [f64], ld: usize, q: usize, p: usize)
}

#[inline(always)]
fn mul_padded_kernel(a: &[f64], b: &[f64], c: &mut [f64], ld: usize, q: usize, p: usize) {
    // two columns per pass (independent sums in flight), then the odd one
    let (c2, c1) = c[..ld * p].split_at_mut(ld * (p / 2 * 2));
    let (b2, b1) = b[..q * p].split_at(q * (p / 2 * 2));
    for (cj, bj) in c2.chunks_exact_mut(2 * ld).zip(b2.chunks_exact(2 * q)) {
        let (c0, c1) = cj.split_at_mut(ld);
        mul_vec_streams::<2, false>([a, a], [&bj[..q], &bj[q..]], [c0, c1], ld, q);
    }
    if !c1.is_empty() {
        mul_vec_streams::<1, false>([a], [b1], [c1], ld, q);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(len: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..len)
            .map(|_| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    /// The padded kernels give the plain kernels' numbers to the bit, for column lengths of one
    /// block, two blocks (the constant-length paths) and more (the general path).
    #[test]
    fn padded_kernels_are_the_plain_ones() {
        for n in [1, 7, 8, 15, 16, 17, 30] {
            let (ld, q) = (padded_len(n), n + 2);
            let plain = sample(n * q, n as u64);
            let mut a = vec![0.0; ld * q];
            pad(&plain, &mut a, n, ld, q);
            let (x, y0) = (
                sample(q, 7),
                sample(ld, 8).iter().enumerate().map(|(i, v)| if i < n { *v } else { 0.0 }).collect::<Vec<_>>(),
            );

            let mut want = vec![0.0; n];
            mul_vec(&plain, &x, &mut want, n, q);
            let (mut got, mut got2) = (vec![0.0; ld], vec![0.0; ld]);
            mul_vec_padded(&a, &x, &mut got, ld, q);
            assert_eq!(got[..n], want[..], "mul_vec_padded, n = {n}");
            mul_vec2_padded(&a, &a, &x, &mut got, &mut got2, ld, q);
            assert_eq!((&got[..n], &got2[..n]), (&want[..], &want[..]), "mul_vec2_padded, n = {n}");

            let mut want = y0[..n].to_vec();
            add_mul_vec(&plain, &x, &mut want, n, q);
            let mut got = y0.clone();
            add_mul_vec_padded(&a, &x, &mut got, ld, q);
            assert_eq!(got[..n], want[..], "add_mul_vec_padded, n = {n}");
            assert!(got[n..].iter().all(|&v| v == 0.0), "padding stays zero");

            let v = sample(q, 9);
            let (mut want_a, mut want_y) = (a.clone(), vec![0.0; ld]);
            sub_outer_padded(&mut want_a, &y0, &v, ld, q);
            mul_vec_padded(&want_a, &x, &mut want_y, ld, q);
            let (mut got_a, mut got_y) = (a.clone(), vec![0.0; ld]);
            sub_outer_mul_vec_padded(&mut got_a, &y0, &v, &x, &mut got_y, ld, q);
            assert_eq!((got_a, got_y), (want_a, want_y), "sub_outer_mul_vec_padded, n = {n}");

            // the plain kernel on the padded matrices is the reference (it has no constant paths)
            let b = sample(q * 3, 10);
            let (mut want_c, mut got_c) = (a.clone(), a.clone());
            sub_mul_nt(&mut want_c, &a[..ld * 3], &b, ld, 3, q);
            sub_mul_nt_padded(&mut got_c, &a[..ld * 3], &b, ld, 3, q);
            assert_eq!(got_c, want_c, "sub_mul_nt_padded, n = {n}");
        }
    }
}
