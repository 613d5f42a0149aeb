//! The scene's objects (fixed or free bodies of primitives) and persons (mocap capsules).

use std::f64::consts::PI;
use std::fmt::Write;

use nalgebra::{Isometry3, Vector3};
use skin_core::model::Shape;
use skin_core::skin::layout::isometry_from_xyz_rpy;

use super::{pose_attrs, shape_attrs, OBJECT_GROUP, PERSON_GROUP};
use crate::scene::{ObjectSpec, PersonSpec, ShapeSpec};

/// The primitives of an object, each with its pose in the object frame.
fn primitives(shape: &ShapeSpec) -> Vec<(Shape, Isometry3<f64>)> {
    let at = |x: f64, y: f64, z: f64| Isometry3::translation(x, y, z);
    match *shape {
        ShapeSpec::Box { size_m } => vec![(Shape::Box { size: Vector3::from(size_m) }, Isometry3::identity())],
        ShapeSpec::Cylinder { radius_m, length_m } => {
            vec![(Shape::Cylinder { radius: radius_m, length: length_m }, Isometry3::identity())]
        }
        ShapeSpec::Sphere { radius_m } => vec![(Shape::Sphere { radius: radius_m }, Isometry3::identity())],
        ShapeSpec::Capsule { radius_m, length_m } => {
            vec![(Shape::Capsule { radius: radius_m, length: length_m }, Isometry3::identity())]
        }
        ShapeSpec::Table { top_m, height_m, leg_radius_m } => {
            let leg = height_m - top_m[2];
            let (lx, ly) = (top_m[0] / 2.0 - leg_radius_m, top_m[1] / 2.0 - leg_radius_m);
            let mut parts = vec![(Shape::Box { size: Vector3::from(top_m) }, at(0.0, 0.0, height_m - top_m[2] / 2.0))];
            for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                parts.push((Shape::Cylinder { radius: leg_radius_m, length: leg }, at(sx * lx, sy * ly, leg / 2.0)));
            }
            parts
        }
    }
}

fn volume(shape: &Shape) -> f64 {
    match *shape {
        Shape::Box { size } => size.x * size.y * size.z,
        Shape::Cylinder { radius, length } => PI * radius * radius * length,
        Shape::Sphere { radius } => 4.0 / 3.0 * PI * radius.powi(3),
        Shape::Capsule { radius, length } => PI * radius * radius * (length + 4.0 / 3.0 * radius),
        Shape::Mesh { .. } => 0.0,
    }
}

/// A fixed (static) or free body with the object's primitives; a free body's mass is spread
/// over its primitives by volume (uniform density). The geoms have contact priority 1, so the
/// object's `friction` is the one of its contacts with the floor and the robot (MuJoCo would
/// otherwise take the larger of the two geoms' coefficients, the floor's 1.0) and its
/// `contact_time_constant_s` (MuJoCo `solref`) the softness of those contacts.
pub(super) fn object_xml(o: &ObjectSpec, xml: &mut String) {
    let parts = primitives(&o.shape);
    let _ = writeln!(xml, "    <body name=\"{}\" {}>", o.name, pose_attrs(&isometry_from_xyz_rpy(&o.xyz, &o.rpy)));
    let density = match o.mass_kg {
        Some(m) => {
            xml.push_str("      <freejoint/>\n");
            format!(" density=\"{}\"", m / parts.iter().map(|(s, _)| volume(s)).sum::<f64>())
        }
        None => String::new(),
    };
    for (shape, pose) in &parts {
        let attrs = shape_attrs(shape).expect("objects are primitives");
        let _ = writeln!(
            xml,
            "      <geom {attrs} {} friction=\"{} 0.005 0.0001\" solref=\"{} 1\" priority=\"1\" group=\"{OBJECT_GROUP}\"{density}/>",
            pose_attrs(pose),
            o.friction,
            o.contact_time_constant_s
        );
    }
    xml.push_str("    </body>\n");
}

/// A mocap body with a vertical capsule standing on the floor (moved by [`crate::world::World`]).
pub(super) fn person_xml(p: &PersonSpec, floor_z_m: f64, xml: &mut String) {
    let [x, y] = p.path[0].xy_m;
    let _ = writeln!(
        xml,
        "    <body name=\"{}\" mocap=\"true\" pos=\"{x} {y} {floor_z_m}\">\n      \
         <geom type=\"capsule\" size=\"{r}\" fromto=\"0 0 {r} 0 0 {top}\" group=\"{PERSON_GROUP}\"/>\n    </body>",
        p.name,
        r = p.radius_m,
        top = p.height_m - p.radius_m
    );
}
