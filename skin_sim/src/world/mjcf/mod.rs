//! MJCF (MuJoCo XML) generated from a [`Scene`]: the robot from its [`RobotModel`] (URDF
//! collision primitives and meshes, merged inertials, velocity-servoed joints), the scene's
//! objects and persons, a floor.
//!
//! Geom groups tell the sensors what they may see: the robot's geoms are in [`ROBOT_GROUP`], so
//! skin and LIDAR rays (which only test [`SENSED_GROUPS`]) never hit the robot itself.
//!
//! [`RobotModel`]: skin_core::model::RobotModel

mod attrs;
mod error;
mod groups;
mod objects;
mod robot;

use std::fmt::Write;

use crate::scene::Scene;

pub use error::MjcfError;
pub use groups::{OBJECT_GROUP, PERSON_GROUP, ROBOT_GROUP, SENSED_GROUPS};
pub(crate) use robot::body_name;
pub use robot::{servo_gain, SERVO_ERROR_FRACTION};

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
