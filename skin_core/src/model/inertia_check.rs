//! Physical validity of a link's rotational inertia, and its smallest repair.
//!
//! A rigid body's inertia about its centre of mass has principal moments `λ` that satisfy the
//! triangle inequalities `λ_i ≤ λ_j + λ_k` (which imply `λ ≥ 0`). The dynamics need less: only
//! `λ ≥ 0` (a positive semi-definite spatial inertia, so that no motion has negative kinetic
//! energy); a violated triangle inequality describes no real body but a well-defined model.
//! Hence, with `tol` the repair tolerance:
//! - valid, or invalid by rounding noise only (a change below `1e-6 tol`): kept;
//! - the nearest valid inertia (Frobenius norm; same principal axes, moments projected onto the
//!   cone of the triangle inequalities) is at most `tol` away: repaired, with a warning;
//! - farther, but positive semi-definite up to `tol`: kept (negative moments within `tol`
//!   clipped to zero), with a warning, as pinocchio does;
//! - a moment below `−tol`: refused.

use nalgebra::{Matrix3, Vector3};

/// Outcome of [`check`].
#[derive(Debug)]
pub(crate) enum Verdict {
    /// Valid up to rounding; unchanged.
    Valid,
    /// Replaced by `inertia`; `warning` says why and by how much.
    Changed { inertia: Matrix3<f64>, warning: String },
    /// Kept as given; `warning` says what is wrong with it.
    Kept { warning: String },
    /// Not usable: the reason.
    Invalid(String),
}

/// Normals `n` of the triangle inequalities `n · λ ≤ 0`.
const NORMALS: [[f64; 3]; 3] = [[1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]];

/// Nearest point to `l` (Euclidean) in the cone `{x : x_i ≤ x_j + x_k}`: the projection onto
/// one face (the affine hull of an active set) is it; among the active sets whose projection is
/// feasible, the nearest one is the true projection.
pub(crate) fn project_principal_moments(l: &Vector3<f64>) -> Vector3<f64> {
    let feasible_tol = 1e-12 * l.abs().sum();
    let feasible = |x: &Vector3<f64>| NORMALS.iter().all(|n| Vector3::from(*n).dot(x) <= feasible_tol);
    if feasible(l) {
        return *l;
    }
    let mut best = Vector3::zeros(); // all three active: the apex
    for set in 1..7u8 {
        let active: Vec<Vector3<f64>> =
            (0..3).filter(|k| set & (1 << k) != 0).map(|k| Vector3::from(NORMALS[k])).collect();
        // x = l − Nᵀ (N Nᵀ)⁻¹ N l for the active normals N
        let k = active.len();
        let gram = nalgebra::DMatrix::from_fn(k, k, |i, j| active[i].dot(&active[j]));
        let rhs = nalgebra::DVector::from_fn(k, |i, _| active[i].dot(l));
        let Some(mu) = gram.lu().solve(&rhs) else { continue };
        let x = active.iter().zip(mu.iter()).fold(*l, |x, (n, m)| x - n * *m);
        if feasible(&x) && (x - l).norm() < (best - l).norm() {
            best = x;
        }
    }
    best
}

/// Checks the inertia `i` (about the centre of mass) of link `link` with mass `mass`.
pub(crate) fn check(link: &str, mass: f64, i: &Matrix3<f64>, tol: f64) -> Verdict {
    if mass == 0.0 {
        return if i.iter().all(|x| *x == 0.0) {
            Verdict::Valid
        } else {
            Verdict::Kept {
                warning: format!(
                    "link \"{link}\": zero mass with a non-zero inertia, kept as given (a rotor-like body)"
                ),
            }
        };
    }
    // beyond any real body; also keeps the eigen-solver away from overflow
    if mass > 1e100 || i.iter().any(|x| x.abs() > 1e100) {
        return Verdict::Invalid(format!("implausible mass {mass:e} or inertia magnitude"));
    }
    let eig = i.symmetric_eigen();
    let l = eig.eigenvalues;
    let fmt = |v: &Vector3<f64>| format!("{:.4e}, {:.4e}, {:.4e}", v[0], v[1], v[2]);
    let valid = project_principal_moments(&l);
    let change = (valid - l).norm();
    // rounding noise of the file (a millionth of the tolerance, e.g. 1e-20 moments of a point
    // mass): kept as given, without a warning
    if change <= 1e-6 * tol {
        return Verdict::Valid;
    }
    let rebuild = |moments: &Vector3<f64>| {
        let v = &eig.eigenvectors;
        let m = v * Matrix3::from_diagonal(moments) * v.transpose();
        (m + m.transpose()) * 0.5
    };
    if change <= tol {
        return Verdict::Changed {
            inertia: rebuild(&valid),
            warning: format!(
                "link \"{link}\": inertia repaired to the nearest physically valid one (principal moments {} -> {}, change {change:.3e} kg m², tolerance {tol:.3e})",
                fmt(&l),
                fmt(&valid)
            ),
        };
    }
    if l.min() < -tol {
        return Verdict::Invalid(format!(
            "inertia is not positive semi-definite (principal moments {}): a motion would have negative kinetic energy; the nearest valid inertia is {change:.3e} kg m² away, beyond the repair tolerance {tol:.3e}",
            fmt(&l)
        ));
    }
    let excess = NORMALS.iter().map(|n| Vector3::from(*n).dot(&l)).fold(f64::MIN, f64::max);
    let warning = format!(
        "link \"{link}\": inertia violates the triangle inequality by {excess:.3e} kg m² (principal moments {}), beyond the repair tolerance {tol:.3e}: kept as given (the dynamics stay well defined)",
        fmt(&l)
    );
    if l.min() < 0.0 {
        let clipped = l.map(|x| x.max(0.0));
        return Verdict::Changed {
            inertia: rebuild(&clipped),
            warning: format!("{warning}; negative moments clipped to zero"),
        };
    }
    Verdict::Kept { warning }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within the cone up to rounding at the scale of `scale`.
    fn feasible(x: &Vector3<f64>, scale: &Vector3<f64>) -> bool {
        NORMALS.iter().all(|n| Vector3::from(*n).dot(x) <= 1e-12 * scale.abs().sum())
    }

    /// The projection is feasible, leaves valid moments alone, and no valid moments are nearer.
    #[test]
    fn projection_is_the_nearest_valid_principal_moments() {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut uniform = |lo: f64, hi: f64| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            lo + (hi - lo) * (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let l = Vector3::new(uniform(-1.0, 2.0), uniform(-1.0, 2.0), uniform(-1.0, 2.0));
            let p = project_principal_moments(&l);
            assert!(feasible(&p, &l), "{l} -> {p}");
            if feasible(&l, &l) {
                assert_eq!(p, l);
            }
            let d = (p - l).norm();
            for _ in 0..50 {
                // a random valid point: non-negative combination of the cone's extreme rays
                let y = Vector3::new(0.0, 1.0, 1.0) * uniform(0.0, 2.0)
                    + Vector3::new(1.0, 0.0, 1.0) * uniform(0.0, 2.0)
                    + Vector3::new(1.0, 1.0, 0.0) * uniform(0.0, 2.0);
                assert!((y - l).norm() >= d - 1e-12, "{y} is nearer to {l} than {p}");
                // and points on the segment towards y are no nearer (p is the minimum)
                let z = p + (y - p) * 1e-3;
                assert!((z - l).norm() >= d - 1e-12, "moving from {p} towards {y} gets nearer to {l}");
            }
        }
    }

    #[test]
    fn verdicts_follow_the_tolerance() {
        let diag = |a: f64, b: f64, c: f64| Matrix3::from_diagonal(&Vector3::new(a, b, c));
        assert!(matches!(check("l", 1.0, &diag(1.0, 1.0, 1.0), 1e-6), Verdict::Valid));
        assert!(matches!(check("l", 1.0, &diag(1.0, 1.0, 2.0 + 1e-12), 1e-6), Verdict::Valid));
        assert!(matches!(check("l", 1.0, &diag(1.0, 1.0, 2.0 + 1e-7), 1e-6), Verdict::Changed { .. }));
        assert!(matches!(check("l", 1.0, &diag(1.0, 1.0, 3.0), 1e-6), Verdict::Kept { .. }));
        assert!(matches!(check("l", 1.0, &diag(1.0, 1.0, -1e-7), 1e-6), Verdict::Changed { .. }));
        assert!(matches!(check("l", 1.0, &diag(1.0, 1.0, -1e-5), 1e-6), Verdict::Invalid(_)));
        assert!(matches!(check("l", 0.0, &diag(1.0, 1.0, 1.0), 1e-6), Verdict::Kept { .. }));
    }
}
