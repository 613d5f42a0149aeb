//! Minimal spatial (6D) algebra after Featherstone, *Rigid Body Dynamics Algorithms* (RBDA), ch. 2.
//!
//! Internal convention: a spatial motion vector is `[ω; v_O]` (angular first, then the linear
//! velocity of the body-fixed point that coincides with the reference point O), a spatial force is
//! `[n_O; f]` (moment about O first). All vectors used by the dynamics are expressed in world
//! orientation at a common reference point, so no coordinate transforms are needed between bodies
//! (the "ground coordinates" variant of RBDA's algorithms). The public Jacobians convert to the
//! robotics convention (linear rows first) at the boundary.

use nalgebra::{Matrix3, Vector3, Vector6};

/// Spatial motion or force vector, angular part first (RBDA convention).
pub type SVec = Vector6<f64>;

/// Angular (first) part of a spatial vector.
#[inline(always)]
pub fn ang(v: &SVec) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// Linear (second) part of a spatial vector.
#[inline(always)]
pub fn lin(v: &SVec) -> Vector3<f64> {
    Vector3::new(v[3], v[4], v[5])
}

/// Builds a spatial vector from its angular and linear parts.
#[inline(always)]
pub fn svec(a: &Vector3<f64>, l: &Vector3<f64>) -> SVec {
    Vector6::new(a[0], a[1], a[2], l[0], l[1], l[2])
}

/// Motion cross product `v ×m m` (RBDA eq. 2.31): the rate of change of a motion vector `m`
/// rigidly attached to a body moving with velocity `v`.
#[inline(always)]
pub fn cross_motion(v: &SVec, m: &SVec) -> SVec {
    let (w, vo) = (ang(v), lin(v));
    let (mw, mo) = (ang(m), lin(m));
    svec(&w.cross(&mw), &(w.cross(&mo) + vo.cross(&mw)))
}

/// Force cross product `v ×* f` (RBDA eq. 2.32), used for the gyroscopic term `v ×* I v`.
#[inline(always)]
pub fn cross_force(v: &SVec, f: &SVec) -> SVec {
    let (w, vo) = (ang(v), lin(v));
    let (fn_, ff) = (ang(f), lin(f));
    svec(&(w.cross(&fn_) + vo.cross(&ff)), &w.cross(&ff))
}

/// Spatial inertia about a reference point O in the compact form (RBDA eq. 2.63):
/// mass `m`, first moment `h = m c` (c = centre of mass relative to O) and rotational inertia
/// `i_o` about O (not about the centre of mass).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialInertia {
    /// Mass (kg).
    pub mass: f64,
    /// First moment of mass `m c` (kg m).
    pub h: Vector3<f64>,
    /// Rotational inertia about the reference point (kg m²).
    pub i_o: Matrix3<f64>,
}

impl SpatialInertia {
    /// The zero inertia (massless).
    pub fn zero() -> Self {
        Self { mass: 0.0, h: Vector3::zeros(), i_o: Matrix3::zeros() }
    }

    /// Inertia of a body with mass `m`, centre of mass `c` (relative to the reference point) and
    /// rotational inertia `i_com` about the centre of mass, all in the same orientation.
    /// Parallel-axis theorem: `I_O = I_c + m (|c|² 1 - c cᵀ)`.
    #[inline]
    pub fn from_com(m: f64, c: &Vector3<f64>, i_com: &Matrix3<f64>) -> Self {
        Self { mass: m, h: c * m, i_o: i_com + parallel_axis(m, c) }
    }

    /// Centre of mass relative to the reference point (zero for a massless inertia).
    pub fn com(&self) -> Vector3<f64> {
        if self.mass > 0.0 {
            self.h / self.mass
        } else {
            Vector3::zeros()
        }
    }

    /// Rotational inertia about the centre of mass.
    pub fn inertia_about_com(&self) -> Matrix3<f64> {
        self.i_o - parallel_axis(self.mass, &self.com())
    }

    /// `I v` (RBDA eq. 2.63 applied to a motion vector): the momentum of a body moving with `v`.
    #[inline(always)]
    pub fn mul_motion(&self, v: &SVec) -> SVec {
        let (w, vo) = (ang(v), lin(v));
        svec(&(self.i_o * w + self.h.cross(&vo)), &(vo * self.mass - self.h.cross(&w)))
    }

    /// Adds another inertia expressed about the same point (composite rigid body).
    #[inline(always)]
    pub fn add(&mut self, o: &SpatialInertia) {
        self.mass += o.mass;
        self.h += o.h;
        self.i_o += o.i_o;
    }

    /// Full 6x6 matrix (angular first); for tests and diagnostics.
    pub fn to_matrix(&self) -> nalgebra::Matrix6<f64> {
        let mut m = nalgebra::Matrix6::zeros();
        let hx = skew(&self.h);
        m.fixed_slice_mut::<3, 3>(0, 0).copy_from(&self.i_o);
        m.fixed_slice_mut::<3, 3>(0, 3).copy_from(&hx);
        m.fixed_slice_mut::<3, 3>(3, 0).copy_from(&hx.transpose());
        m.fixed_slice_mut::<3, 3>(3, 3).copy_from(&(Matrix3::identity() * self.mass));
        m
    }
}

/// `m (|c|² 1 - c cᵀ)`: the inertia of a point mass at `c` about the origin.
#[inline(always)]
pub fn parallel_axis(m: f64, c: &Vector3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * c.norm_squared() - c * c.transpose()) * m
}

/// Skew-symmetric cross-product matrix: `skew(a) b = a × b`.
#[inline(always)]
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a[2], a[1], a[2], 0.0, -a[0], -a[1], a[0], 0.0)
}

/// Rotation matrix about a unit axis by angle with given sine and cosine (Rodrigues' formula).
#[inline(always)]
pub fn axis_rotation(axis: &Vector3<f64>, s: f64, c: f64) -> Matrix3<f64> {
    let k = skew(axis);
    Matrix3::identity() + k * s + k * k * (1.0 - c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Matrix6;

    fn crm_matrix(v: &SVec) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        let wx = skew(&ang(v));
        m.fixed_slice_mut::<3, 3>(0, 0).copy_from(&wx);
        m.fixed_slice_mut::<3, 3>(3, 3).copy_from(&wx);
        m.fixed_slice_mut::<3, 3>(3, 0).copy_from(&skew(&lin(v)));
        m
    }

    fn sample(k: f64) -> SVec {
        SVec::new(0.3 * k, -1.1, 0.7, 2.0, -0.4 * k, 1.5)
    }

    #[test]
    fn skew_is_cross_product() {
        let a = Vector3::new(1.0, -2.0, 0.5);
        let b = Vector3::new(0.3, 0.2, -4.0);
        assert_relative_eq!(skew(&a) * b, a.cross(&b), epsilon = 1e-15);
        assert_relative_eq!(skew(&a).transpose(), -skew(&a), epsilon = 0.0);
    }

    #[test]
    fn cross_motion_matches_matrix_form() {
        let (v, m) = (sample(1.0), sample(-2.0));
        assert_relative_eq!(cross_motion(&v, &m), crm_matrix(&v) * m, epsilon = 1e-14);
        // v x v = 0
        assert_relative_eq!(cross_motion(&v, &v), SVec::zeros(), epsilon = 1e-14);
    }

    #[test]
    fn cross_force_is_minus_transpose_of_cross_motion() {
        let (v, f) = (sample(0.5), sample(3.0));
        let crf = -crm_matrix(&v).transpose();
        assert_relative_eq!(cross_force(&v, &f), crf * f, epsilon = 1e-14);
        // power conservation: (v x m) . f + m . (v x* f) = 0
        let m = sample(-1.3);
        let p = cross_motion(&v, &m).dot(&f) + m.dot(&cross_force(&v, &f));
        assert!(p.abs() < 1e-12, "{p}");
    }

    #[test]
    fn inertia_product_matches_matrix_and_is_symmetric_pd() {
        let ic = Matrix3::new(0.3, 0.01, 0.0, 0.01, 0.2, 0.02, 0.0, 0.02, 0.1);
        let c = Vector3::new(0.1, -0.2, 0.3);
        let i = SpatialInertia::from_com(2.0, &c, &ic);
        let v = sample(1.0);
        assert_relative_eq!(i.mul_motion(&v), i.to_matrix() * v, epsilon = 1e-14);
        let m = i.to_matrix();
        assert_relative_eq!(m, m.transpose(), epsilon = 0.0);
        assert!(m.symmetric_eigenvalues().min() > 0.0);
        assert_relative_eq!(i.com(), c, epsilon = 1e-15);
        assert_relative_eq!(i.inertia_about_com(), ic, epsilon = 1e-14);
    }

    #[test]
    fn kinetic_energy_of_point_mass() {
        // a point mass at c, body rotating with w about O: v_c = w x c, KE = 1/2 m |w x c|^2.
        let c = Vector3::new(0.5, 0.0, 0.0);
        let i = SpatialInertia::from_com(3.0, &c, &Matrix3::zeros());
        let w = Vector3::new(0.0, 0.0, 2.0);
        let v = svec(&w, &Vector3::zeros());
        let ke = 0.5 * v.dot(&i.mul_motion(&v));
        assert_relative_eq!(ke, 0.5 * 3.0 * w.cross(&c).norm_squared(), epsilon = 1e-14);
    }

    #[test]
    fn rodrigues_matches_nalgebra() {
        let axis = Vector3::new(1.0, 2.0, -0.5).normalize();
        let q: f64 = 0.83;
        let r = axis_rotation(&axis, q.sin(), q.cos());
        let expected = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), q);
        assert_relative_eq!(r, *expected.matrix(), epsilon = 1e-15);
    }
}
