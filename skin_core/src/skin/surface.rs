//! The surfaces of collision primitives, for the layout generator and the coverage check:
//! whether a point lies inside a primitive (a cell buried in its own link's geometry senses
//! nothing), and evenly spread sample points with their outward normals. Primitive frame, URDF
//! conventions (see [`super::tiling`]). Meshes have no inside and no samples here.

use nalgebra::{Point3, Vector3};

use super::tiling::{tile_box, tile_caps, tile_cylinder, tile_sphere, Face, TiledCell};
use crate::model::{Collision, Shape};

/// Whether `p` lies inside `shape` deeper than `margin` (a point on the surface is not).
pub fn buried(shape: &Shape, p: &Vector3<f64>, margin: f64) -> bool {
    match *shape {
        Shape::Box { size } => (0..3).all(|k| p[k].abs() < size[k] / 2.0 - margin),
        Shape::Sphere { radius } => p.norm() < radius - margin,
        Shape::Cylinder { radius, length } => p.xy().norm() < radius - margin && p.z.abs() < length / 2.0 - margin,
        Shape::Capsule { radius, length } => {
            let axis = Vector3::new(0.0, 0.0, p.z.clamp(-length / 2.0, length / 2.0));
            (p - axis).norm() < radius - margin
        }
        Shape::Mesh { .. } => false,
    }
}

/// Whether `p` (link frame) lies deeper than `margin` inside one of the link's `collisions`
/// other than the one at index `own` (the primitive `p` belongs to).
pub fn buried_in_others(collisions: &[Collision], own: usize, p: &Point3<f64>, margin: f64) -> bool {
    collisions.iter().enumerate().any(|(j, o)| j != own && buried(&o.shape, &(o.origin.inverse() * p).coords, margin))
}

/// Points on the surface of `shape` about `spacing` apart, each with its outward normal: every
/// face of a box, a cylinder's side and both end caps, a capsule's side and hemispheres, a
/// sphere (the tiling of [`super::tiling`] at pitch `spacing`, caps included).
pub fn samples(shape: &Shape, spacing: f64) -> Vec<TiledCell> {
    match *shape {
        Shape::Box { size } => tile_box(&size, &Face::ALL, spacing),
        Shape::Sphere { radius } => tile_sphere(radius, spacing),
        Shape::Cylinder { radius, length } => {
            [tile_cylinder(radius, length, spacing), tile_caps(radius, length, spacing, false)].concat()
        }
        Shape::Capsule { radius, length } => {
            [tile_cylinder(radius, length, spacing), tile_caps(radius, length, spacing, true)].concat()
        }
        Shape::Mesh { .. } => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_lie_on_the_surface_with_outward_normals() {
        let shapes = [
            Shape::Box { size: Vector3::new(0.1, 0.2, 0.3) },
            Shape::Sphere { radius: 0.05 },
            Shape::Cylinder { radius: 0.04, length: 0.2 },
            Shape::Capsule { radius: 0.04, length: 0.2 },
        ];
        for shape in &shapes {
            let s = samples(shape, 0.01);
            assert!(s.len() > 100, "{shape:?}");
            for c in &s {
                assert!((c.normal.norm() - 1.0).abs() < 1e-9);
                assert!(!buried(shape, &c.position, 1e-9), "{shape:?} {c:?}");
                assert!(buried(shape, &(c.position - c.normal * 0.002), 1e-3), "{shape:?} {c:?}");
                assert!(!buried(shape, &(c.position + c.normal * 0.002), 0.0), "{shape:?} {c:?}");
            }
        }
    }
}
