//! A triangle soup and its geometry: area, normals, the fitted box, inside tests.

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, SymmetricEigen, Translation3, UnitQuaternion, Vector3};

/// A triangle soup in metres, in the frame of the URDF `<collision>` element (scale applied).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions \[m\].
    pub vertices: Vec<Vector3<f64>>,
    /// Vertex indices of each triangle (counter-clockwise seen from outside, when the file says so).
    pub triangles: Vec<[usize; 3]>,
}

impl TriMesh {
    /// Total surface area \[m²\].
    pub fn area(&self) -> f64 {
        self.triangles.iter().map(|t| self.triangle_normal(t).norm() / 2.0).sum()
    }

    /// `(b - a) × (c - a)` of a triangle: twice its area along its normal.
    pub fn triangle_normal(&self, t: &[usize; 3]) -> Vector3<f64> {
        let [a, b, c] = t.map(|i| self.vertices[i]);
        (b - a).cross(&(c - a))
    }

    /// The box that encloses the vertices, aligned with their principal axes (the eigenvectors
    /// of their covariance): its pose in the mesh frame and its full edge lengths. The primitive
    /// approximation of a mesh.
    pub fn fitted_box(&self) -> (Isometry3<f64>, Vector3<f64>) {
        let n = self.vertices.len().max(1) as f64;
        let mean: Vector3<f64> = self.vertices.iter().sum::<Vector3<f64>>() / n;
        let cov: Matrix3<f64> =
            self.vertices.iter().map(|v| (v - mean) * (v - mean).transpose()).sum::<Matrix3<f64>>() / n;
        let eig = SymmetricEigen::new(cov);
        let mut axes = eig.eigenvectors;
        if axes.determinant() < 0.0 {
            axes.set_column(2, &-axes.column(2));
        }
        let (mut lo, mut hi) = (Vector3::repeat(f64::MAX), Vector3::repeat(f64::MIN));
        for v in &self.vertices {
            let p = axes.transpose() * v;
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        let centre = axes * ((lo + hi) / 2.0);
        let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(axes));
        (Isometry3::from_parts(Translation3::from(centre), rotation), hi - lo)
    }

    /// Whether `p` lies inside the closed mesh: the parity of the crossings of a ray from `p`
    /// (Möller–Trumbore), along a fixed direction not aligned with any axis.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        let dir = Vector3::new(0.5773, 0.5774, 0.5775).normalize();
        let mut crossings = 0;
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.vertices[i]);
            let (e1, e2) = (b - a, c - a);
            let h = dir.cross(&e2);
            let det = e1.dot(&h);
            if det.abs() < 1e-18 {
                continue;
            }
            let s = p.coords - a;
            let u = s.dot(&h) / det;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let q = s.cross(&e1);
            let v = dir.dot(&q) / det;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            if e2.dot(&q) / det > 0.0 {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }
}

/// A closed box mesh of full edge lengths `s` centred at the origin, outward winding (inward
/// when `inverted`).
#[cfg(test)]
pub(crate) fn box_mesh(s: Vector3<f64>, inverted: bool) -> TriMesh {
    let h = s / 2.0;
    let corner = |i: usize| {
        Vector3::new(
            if i & 1 == 0 { -h.x } else { h.x },
            if i & 2 == 0 { -h.y } else { h.y },
            if i & 4 == 0 { -h.z } else { h.z },
        )
    };
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads
        .iter()
        .flat_map(|q| {
            if inverted {
                [[q[0], q[2], q[1]], [q[0], q[3], q[2]]]
            } else {
                [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
            }
        })
        .collect();
    TriMesh { vertices: (0..8).map(corner).collect(), triangles }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_mesh_area_inside_and_fit() {
        let m = box_mesh(Vector3::new(0.2, 0.1, 0.4), false);
        assert!((m.area() - 2.0 * (0.02 + 0.08 + 0.04)).abs() < 1e-12);
        for t in &m.triangles {
            let c = t.iter().map(|&i| m.vertices[i]).sum::<Vector3<f64>>() / 3.0;
            assert!(m.triangle_normal(t).dot(&c) > 0.0, "outward winding");
        }
        assert!(m.contains(&Point3::new(0.05, 0.01, 0.1)));
        assert!(!m.contains(&Point3::new(0.15, 0.0, 0.0)));
        let (pose, size) = m.fitted_box();
        let mut sorted: Vec<f64> = size.iter().copied().collect();
        sorted.sort_by(f64::total_cmp);
        assert!((sorted[0] - 0.1).abs() < 1e-9 && (sorted[1] - 0.2).abs() < 1e-9 && (sorted[2] - 0.4).abs() < 1e-9);
        assert!(pose.translation.vector.norm() < 1e-9);
    }
}
