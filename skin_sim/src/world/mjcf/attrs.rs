//! MJCF attributes of a pose and of a primitive shape.

use nalgebra::Isometry3;
use skin_core::model::Shape;

/// `pos="x y z" quat="w x y z"` of a pose.
pub(super) fn pose_attrs(pose: &Isometry3<f64>) -> String {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    format!("pos=\"{} {} {}\" quat=\"{} {} {} {}\"", t.x, t.y, t.z, q.w, q.i, q.j, q.k)
}

/// `type="..." size="..."` of a primitive (MuJoCo sizes are half lengths); None for a mesh.
pub(super) fn shape_attrs(shape: &Shape) -> Option<String> {
    Some(match shape {
        Shape::Box { size } => format!("type=\"box\" size=\"{} {} {}\"", size.x / 2.0, size.y / 2.0, size.z / 2.0),
        Shape::Cylinder { radius, length } => format!("type=\"cylinder\" size=\"{radius} {}\"", length / 2.0),
        Shape::Sphere { radius } => format!("type=\"sphere\" size=\"{radius}\""),
        Shape::Capsule { radius, length } => format!("type=\"capsule\" size=\"{radius} {}\"", length / 2.0),
        Shape::Mesh { .. } => return None,
    })
}
