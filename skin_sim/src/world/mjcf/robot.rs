//! The robot's part of the MJCF: one body per moving joint of the [`RobotModel`] (links joined by
//! fixed joints are already merged there), its collision geometry and merged inertial, a joint
//! and a velocity servo when the joint moves in the scene, none (welded at its fixed position)
//! when it is frozen. Collision meshes are MuJoCo meshes given by their vertices (MuJoCo collides
//! with their convex hull), or their fitted boxes (the scene's `robot.meshes`).

use std::fmt::Write;

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use skin_core::mesh::MeshMode;
use skin_core::model::{update_kinematics, JointKind, JointLimits, ModelData, RobotModel, Shape};

use super::{pose_attrs, shape_attrs, MjcfError, ROBOT_GROUP};
use crate::scene::Scene;

/// The servo reaches its effort limit when the velocity error is this fraction of the joint's
/// velocity limit (see [`servo_gain`]).
pub const SERVO_ERROR_FRACTION: f64 = 0.1;

/// Velocity servo gain `kv` \[N m s/rad or N s/m\] of a joint: `effort / (SERVO_ERROR_FRACTION *
/// velocity)`, so that the servo uses its whole effort for a 10 % velocity error. For a UR5
/// shoulder (150 N m, pi rad/s) that is 477 N m s/rad: with ~4 kg m² of arm inertia the time
/// constant `I / kv` is about 8 ms, one 125 Hz control period. Gravity is compensated by MuJoCo
/// (`gravcomp`), as a UR's own joint controllers do, so the servo does not sag under load.
pub fn servo_gain(limits: &JointLimits) -> f64 {
    limits.effort / (SERVO_ERROR_FRACTION * limits.velocity)
}

/// The robot's XML pieces: mesh assets, bodies (inside `<worldbody>`), contact exclusions, actuators.
pub(super) struct RobotXml {
    pub(super) assets: String,
    pub(super) bodies: String,
    pub(super) contact: String,
    pub(super) actuators: String,
}

/// MuJoCo body name of the body moved by joint `j`: the URDF name of the joint's child link.
pub(crate) fn body_name(model: &RobotModel, j: usize) -> &str {
    &model.frame_names()[model.joint_child_frame(j)]
}

pub(super) fn robot_xml(scene: &Scene) -> Result<RobotXml, MjcfError> {
    let model = &scene.model;
    let mut data = ModelData::new(model);
    let zero = vec![0.0; model.nv()];
    update_kinematics(model, &mut data, &zero, &zero).expect("q and qd have nv entries");
    // Each body's pose in its parent body at q = 0 (the URDF joint origins, fixed joints folded in).
    let placement: Vec<Isometry3<f64>> = (0..model.nv())
        .map(|j| match model.joint_parent(j) {
            Some(p) => data.joint_pose(p).inverse() * data.joint_pose(j),
            None => *data.joint_pose(j),
        })
        .collect();

    let mut bodies = String::new();
    let mut assets = String::new();
    // Links fixed to the world with geometry (e.g. planar7's base) are static bodies of their own:
    // MuJoCo never filters contacts with the world body itself, and such a link touches its child.
    let static_links: Vec<usize> = (0..model.nframes())
        .filter(|&f| model.frame_parent_joint(f).is_none() && !model.link_collisions(f).is_empty())
        .collect();
    for &f in &static_links {
        let _ = writeln!(bodies, "    <body name=\"{}\">", model.frame_names()[f]);
        frame_geoms(scene, f, "      ", &mut bodies, &mut assets)?;
        bodies.push_str("    </body>\n");
    }
    for root in (0..model.nv()).filter(|&j| model.joint_parent(j).is_none()) {
        body_xml(scene, &placement, root, 2, &mut bodies, &mut assets)?;
    }

    // Contacts of a body with its parent and grandparent are not meaningful: they overlap at the
    // joints (UR wrists). MuJoCo's own parent filter misses a parent welded to the world (a frozen
    // base), so both are excluded explicitly, as are the static links and the root bodies and
    // their children (a Tiago's first arm link touches the torso column its parent slides on).
    let mut contact = String::from("  <contact>\n");
    let mut exclude = |a: &str, b: &str| {
        let _ = writeln!(contact, "    <exclude body1=\"{a}\" body2=\"{b}\"/>");
    };
    for j in 0..model.nv() {
        let parent = model.joint_parent(j);
        for a in [parent, parent.and_then(|p| model.joint_parent(p))].into_iter().flatten() {
            exclude(body_name(model, a), body_name(model, j));
        }
        // The links fixed to the world are the parent of a root body, the grandparent of its children.
        if parent.and_then(|p| model.joint_parent(p)).is_none() {
            for &f in &static_links {
                exclude(&model.frame_names()[f], body_name(model, j));
            }
        }
    }
    contact.push_str("  </contact>\n");

    let mut actuators = String::from("  <actuator>\n");
    for j in (0..model.nv()).filter(|&j| scene.moving[j]) {
        let lim = model.joint_limits()[j];
        let name = &model.joint_names()[j];
        let finite = |x: f64| x.is_finite() && x > 0.0;
        if !(finite(lim.velocity) && finite(lim.effort)) {
            return Err(MjcfError::Limits { joint: name.clone(), velocity: lim.velocity, effort: lim.effort });
        }
        let _ = writeln!(
            actuators,
            "    <velocity name=\"{name}\" joint=\"{name}\" kv=\"{}\" forcerange=\"{} {}\" ctrlrange=\"{} {}\"/>",
            servo_gain(&lim),
            -lim.effort,
            lim.effort,
            -lim.velocity,
            lim.velocity
        );
    }
    actuators.push_str("  </actuator>\n");
    Ok(RobotXml { assets, bodies, contact, actuators })
}

/// The body of joint `j` and, recursively, its children.
fn body_xml(
    scene: &Scene,
    placement: &[Isometry3<f64>],
    j: usize,
    depth: usize,
    xml: &mut String,
    assets: &mut String,
) -> Result<(), MjcfError> {
    let model = &scene.model;
    let pad = "  ".repeat(depth);
    let moving = scene.moving[j];
    // A frozen joint is welded at its fixed position: its motion is folded into the placement.
    let pose = if moving { placement[j] } else { placement[j] * joint_motion(model, j, scene.q0[j]) };
    let _ = writeln!(xml, "{pad}<body name=\"{}\" {} gravcomp=\"1\">", body_name(model, j), pose_attrs(&pose));
    let (c, i) = (model.body_com(j), model.body_inertia(j));
    let _ = writeln!(
        xml,
        "{pad}  <inertial pos=\"{} {} {}\" mass=\"{}\" fullinertia=\"{} {} {} {} {} {}\"/>",
        c.x,
        c.y,
        c.z,
        model.body_mass(j),
        i[(0, 0)],
        i[(1, 1)],
        i[(2, 2)],
        i[(0, 1)],
        i[(0, 2)],
        i[(1, 2)]
    );
    if moving {
        let a = model.joint_axis(j);
        let lim = model.joint_limits()[j];
        let kind = match model.joint_kind(j) {
            JointKind::Revolute => "hinge",
            JointKind::Prismatic => "slide",
        };
        let range = if lim.lower.is_finite() && lim.upper.is_finite() {
            format!(" range=\"{} {}\"", lim.lower, lim.upper)
        } else {
            String::new()
        };
        let _ = writeln!(
            xml,
            "{pad}  <joint name=\"{}\" type=\"{kind}\" axis=\"{} {} {}\"{range}/>",
            model.joint_names()[j],
            a.x,
            a.y,
            a.z
        );
    }
    for f in (0..model.nframes()).filter(|&f| model.frame_parent_joint(f) == Some(j)) {
        frame_geoms(scene, f, &format!("{pad}  "), xml, assets)?;
    }
    for child in (0..model.nv()).filter(|&k| model.joint_parent(k) == Some(j)) {
        body_xml(scene, placement, child, depth + 1, xml, assets)?;
    }
    let _ = writeln!(xml, "{pad}</body>");
    Ok(())
}

/// Transform of joint `j` at position `q`.
fn joint_motion(model: &RobotModel, j: usize, q: f64) -> Isometry3<f64> {
    let a = model.joint_axis(j);
    match model.joint_kind(j) {
        JointKind::Revolute => Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_scaled_axis(a * q)),
        JointKind::Prismatic => Isometry3::from_parts(Translation3::from(a * q), UnitQuaternion::identity()),
    }
}

/// The collision geometry of frame `f`, placed in the frame's body; meshes as assets.
fn frame_geoms(scene: &Scene, f: usize, pad: &str, xml: &mut String, assets: &mut String) -> Result<(), MjcfError> {
    let model = &scene.model;
    for (i, c) in model.link_collisions(f).iter().enumerate() {
        let pose = model.frame_placement(f) * c.origin;
        let (shape, pose) = match (&c.shape, scene.spec.robot.meshes) {
            (Shape::Mesh { .. }, mode) => {
                let link = &model.frame_names()[f];
                let mesh = scene.meshes.get(&(f, i)).ok_or_else(|| MjcfError::Mesh { link: link.clone(), index: i })?;
                match mode {
                    MeshMode::Mesh => {
                        let name = format!("{link}_collision_{i}");
                        let mut seen = std::collections::HashSet::new();
                        let mut vertex = String::new();
                        for v in mesh.vertices.iter().filter(|v| seen.insert(v.map(f64::to_bits))) {
                            let _ = write!(vertex, "{} {} {} ", v.x, v.y, v.z);
                        }
                        let _ = writeln!(assets, "    <mesh name=\"{name}\" vertex=\"{}\"/>", vertex.trim_end());
                        (format!("type=\"mesh\" mesh=\"{name}\""), pose)
                    }
                    MeshMode::Box => {
                        let (box_pose, size) = mesh.fitted_box();
                        (shape_attrs(&Shape::Box { size }).expect("a box"), pose * box_pose)
                    }
                }
            }
            (shape, _) => (shape_attrs(shape).expect("a primitive"), pose),
        };
        let _ = writeln!(xml, "{pad}<geom {shape} {} group=\"{ROBOT_GROUP}\"/>", pose_attrs(&pose));
    }
    Ok(())
}
