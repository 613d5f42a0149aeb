//! MJCF (MuJoCo XML) generated from a [`Scene`]: the robot from its [`RobotModel`] (URDF
//! collision primitives and meshes, merged inertials, velocity-servoed joints), the scene's
//! objects and persons, a floor.
//!
//! Geom groups tell the sensors what they may see: the robot's geoms are in [`ROBOT_GROUP`], so
//! skin and LIDAR rays (which only test [`SENSED_GROUPS`]) never hit the robot itself.
//!
//! [`RobotModel`]: skin_core::model::RobotModel

mod objects;
mod robot;

use std::fmt::Write;

use nalgebra::Isometry3;
use skin_core::model::Shape;
use thiserror::Error;

use crate::scene::Scene;

pub(crate) use robot::body_name;
pub use robot::{servo_gain, SERVO_ERROR_FRACTION};

/// Geom group of the floor and the scene's objects.
pub const OBJECT_GROUP: u8 = 0;
/// Geom group of the robot.
pub const ROBOT_GROUP: u8 = 1;
/// Geom group of the persons.
pub const PERSON_GROUP: u8 = 2;
/// Groups the skin's and the LIDAR's rays test (`mj_ray`'s geomgroup): objects and persons.
pub const SENSED_GROUPS: [u8; 6] = [1, 0, 1, 0, 0, 0];

/// A robot that cannot be written as MJCF.
#[derive(Debug, Error)]
pub enum MjcfError {
    /// A mesh collision element whose mesh the scene did not read (a scene built by hand).
    #[error("link `{link}`: collision element {index} is a mesh the scene has not read")]
    Mesh {
        /// The URDF link.
        link: String,
        /// Its collision element index.
        index: usize,
    },
    /// A joint that moves in the scene without finite, positive velocity and effort limits.
    #[error(
        "joint `{joint}`: velocity limit {velocity}, effort limit {effort}: its velocity servo needs both finite and \
         > 0 (URDF <limit velocity effort>), or freeze the joint (leave it out of robot.joints)"
    )]
    Limits {
        /// The joint.
        joint: String,
        /// Its velocity limit.
        velocity: f64,
        /// Its effort limit.
        effort: f64,
    },
}

/// The whole MJCF document of `scene`.
pub fn scene_xml(scene: &Scene) -> Result<String, MjcfError> {
    let spec = &scene.spec;
    let g = scene.model.gravity();
    let mut xml = String::new();
    let _ = writeln!(xml, "<mujoco model=\"{}\">", scene.model.name());
    // Merged URDF inertias may miss the triangle inequality by rounding: let MuJoCo balance them.
    let _ = writeln!(xml, "  <compiler angle=\"radian\" balanceinertia=\"true\"/>");
    // implicitfast integrates the velocity servos' damping implicitly: stiff gains stay stable.
    let _ = writeln!(
        xml,
        "  <option timestep=\"{}\" gravity=\"{} {} {}\" integrator=\"implicitfast\"/>",
        spec.timestep_s, g.x, g.y, g.z
    );
    let robot = robot::robot_xml(scene)?;
    if !robot.assets.is_empty() {
        let _ = writeln!(xml, "  <asset>\n{}  </asset>", robot.assets);
    }
    xml.push_str("  <worldbody>\n");
    let _ = writeln!(
        xml,
        "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" pos=\"0 0 {}\" group=\"{OBJECT_GROUP}\"/>",
        spec.floor_z_m
    );
    xml.push_str(&robot.bodies);
    for o in &spec.objects {
        objects::object_xml(o, &mut xml);
    }
    for p in &spec.persons {
        objects::person_xml(p, spec.floor_z_m, &mut xml);
    }
    xml.push_str("  </worldbody>\n");
    xml.push_str(&robot.contact);
    xml.push_str(&robot.actuators);
    xml.push_str("</mujoco>\n");
    Ok(xml)
}

/// `pos="x y z" quat="w x y z"` of a pose.
fn pose_attrs(pose: &Isometry3<f64>) -> String {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    format!("pos=\"{} {} {}\" quat=\"{} {} {} {}\"", t.x, t.y, t.z, q.w, q.i, q.j, q.k)
}

/// `type="..." size="..."` of a primitive (MuJoCo sizes are half lengths); None for a mesh.
fn shape_attrs(shape: &Shape) -> Option<String> {
    Some(match shape {
        Shape::Box { size } => format!("type=\"box\" size=\"{} {} {}\"", size.x / 2.0, size.y / 2.0, size.z / 2.0),
        Shape::Cylinder { radius, length } => format!("type=\"cylinder\" size=\"{radius} {}\"", length / 2.0),
        Shape::Sphere { radius } => format!("type=\"sphere\" size=\"{radius}\""),
        Shape::Capsule { radius, length } => format!("type=\"capsule\" size=\"{radius} {}\"", length / 2.0),
        Shape::Mesh { .. } => return None,
    })
}
