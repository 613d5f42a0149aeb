//! URDF loading and validation: builds the moving-body tree, merges fixed links, checks inertias.

use std::collections::HashMap;

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

use super::spatial::SpatialInertia;
use super::{Body, Collision, Frame, JointKind, JointLimits, ModelError, RobotModel, Shape, STANDARD_GRAVITY};

/// Relative tolerance of the inertia checks (triangle inequality).
const INERTIA_TOL: f64 = 1e-9;

/// Mass, centre of mass and inertia about it, in the link frame.
type LinkInertia = (f64, Vector3<f64>, Matrix3<f64>);

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn invalid(&self, element: String, message: impl Into<String>) -> ModelError {
        ModelError::Invalid { file: self.file.to_string(), element, message: message.into() }
    }
    fn unsupported(&self, element: String, message: impl Into<String>) -> ModelError {
        ModelError::Unsupported { file: self.file.to_string(), element, message: message.into() }
    }
}

fn link_el(name: &str) -> String {
    format!("link \"{name}\"")
}
fn joint_el(name: &str) -> String {
    format!("joint \"{name}\"")
}

/// URDF `<origin xyz rpy>` as an isometry (rpy = fixed-axis roll, pitch, yaw: R = Rz Ry Rx).
fn pose(ctx: &Ctx<'_>, element: &str, p: &urdf_rs::Pose) -> Result<Isometry3<f64>, ModelError> {
    if p.xyz.iter().chain(p.rpy.iter()).any(|x| !x.is_finite()) {
        return Err(ctx.invalid(element.to_string(), "origin contains a non-finite number"));
    }
    Ok(Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    ))
}

/// Checks a link's inertial and returns it as (mass, com, inertia about com) in the link frame.
/// `None` for a link without mass (allowed only for links that do not move on their own).
fn link_inertia(ctx: &Ctx<'_>, link: &urdf_rs::Link) -> Result<Option<LinkInertia>, ModelError> {
    let el = link_el(&link.name);
    let i = &link.inertial;
    let t = &i.inertia;
    let vals = [i.mass.value, t.ixx, t.ixy, t.ixz, t.iyy, t.iyz, t.izz];
    if vals.iter().any(|x| !x.is_finite()) {
        return Err(ctx.invalid(el, "inertial contains a non-finite number"));
    }
    let m = i.mass.value;
    let inertia = Matrix3::new(t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz);
    if m < 0.0 {
        return Err(ctx.invalid(el, format!("negative mass {m}")));
    }
    if m == 0.0 {
        if inertia.iter().any(|x| *x != 0.0) {
            return Err(ctx.invalid(el, "zero mass with a non-zero inertia"));
        }
        return Ok(None);
    }
    // Physically valid rotational inertia: symmetric positive definite, and the principal
    // moments satisfy the triangle inequality (a rigid body cannot have I1 > I2 + I3).
    let eig = inertia.symmetric_eigenvalues();
    let emin = eig.min();
    if emin <= 0.0 {
        return Err(ctx.invalid(
            el,
            format!("inertia is not positive definite (eigenvalues {:.3e}, {:.3e}, {:.3e})", eig[0], eig[1], eig[2]),
        ));
    }
    let sum: f64 = eig.iter().sum();
    for k in 0..3 {
        if eig[k] > (sum - eig[k]) * (1.0 + INERTIA_TOL) + INERTIA_TOL * sum {
            return Err(ctx.invalid(
                el,
                format!(
                    "inertia violates the triangle inequality (principal moments {:.4e}, {:.4e}, {:.4e})",
                    eig[0], eig[1], eig[2]
                ),
            ));
        }
    }
    let o = pose(ctx, &format!("{} <inertial>", link_el(&link.name)), &i.origin)?;
    let r = o.rotation.to_rotation_matrix();
    let i_link = r.matrix() * inertia * r.matrix().transpose();
    Ok(Some((m, o.translation.vector, i_link)))
}

fn collisions(ctx: &Ctx<'_>, link: &urdf_rs::Link) -> Result<Vec<Collision>, ModelError> {
    let el = || format!("{} <collision>", link_el(&link.name));
    let mut out = Vec::with_capacity(link.collision.len());
    for c in &link.collision {
        let origin = pose(ctx, &el(), &c.origin)?;
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let shape = match &c.geometry {
            urdf_rs::Geometry::Box { size } => {
                if !size.iter().all(|x| positive(*x)) {
                    return Err(ctx.invalid(el(), "box size must be positive"));
                }
                Shape::Box { size: Vector3::new(size[0], size[1], size[2]) }
            }
            urdf_rs::Geometry::Cylinder { radius, length } => {
                if !positive(*radius) || !positive(*length) {
                    return Err(ctx.invalid(el(), "cylinder radius and length must be positive"));
                }
                Shape::Cylinder { radius: *radius, length: *length }
            }
            urdf_rs::Geometry::Capsule { radius, length } => {
                if !(positive(*radius) && length.is_finite() && *length >= 0.0) {
                    return Err(ctx.invalid(el(), "capsule radius must be positive, length non-negative"));
                }
                Shape::Capsule { radius: *radius, length: *length }
            }
            urdf_rs::Geometry::Sphere { radius } => {
                if !positive(*radius) {
                    return Err(ctx.invalid(el(), "sphere radius must be positive"));
                }
                Shape::Sphere { radius: *radius }
            }
            urdf_rs::Geometry::Mesh { filename, scale } => Shape::Mesh {
                filename: filename.clone(),
                scale: scale.as_ref().map(|s| Vector3::new(s[0], s[1], s[2])).unwrap_or_else(|| Vector3::repeat(1.0)),
            },
        };
        out.push(Collision { name: c.name.clone(), origin, shape });
    }
    Ok(out)
}

/// Accumulator of a body's merged inertia in the body frame (about the body origin).
fn to_body(inertia: &LinkInertia, placement: &Isometry3<f64>) -> SpatialInertia {
    let (m, c, i) = inertia;
    let r = placement.rotation.to_rotation_matrix();
    let c_b = placement * nalgebra::Point3::from(*c);
    SpatialInertia::from_com(*m, &c_b.coords, &(r.matrix() * i * r.matrix().transpose()))
}

/// For a parser error about an unknown joint type, the name of the joint that uses it (found by
/// a plain text search, since the parser does not report the element).
fn joint_with_unknown_type(xml: &str, message: &str) -> Option<String> {
    let rest = &message[message.find("unknown variant `")? + "unknown variant `".len()..];
    let ty = &rest[..rest.find('`')?];
    let pos = xml.find(&format!("type=\"{ty}\"")).or_else(|| xml.find(&format!("type='{ty}'")))?;
    let tag = &xml[xml[..pos].rfind('<')?..];
    let tag = &tag[..tag.find('>')?];
    let name = &tag[tag.find("name=")? + 6..];
    Some(name[..name.find(['"', '\''])?].to_string())
}

/// Builds the model from URDF text (see [`RobotModel::from_urdf_str`]).
pub(crate) fn build(xml: &str, file: &str) -> Result<RobotModel, ModelError> {
    let ctx = Ctx { file };
    let robot = urdf_rs::read_from_string(xml).map_err(|e| {
        let message = e.to_string();
        match joint_with_unknown_type(xml, &message) {
            Some(joint) => ModelError::Invalid {
                file: file.to_string(),
                element: joint_el(&joint),
                message: format!("unknown joint type: {message}"),
            },
            None => ModelError::Parse { file: file.to_string(), message },
        }
    })?;
    if robot.links.is_empty() {
        return Err(ModelError::Parse { file: file.to_string(), message: "no <link> element".into() });
    }

    // --- names and tree structure ---
    let mut link_idx: HashMap<&str, usize> = HashMap::new();
    for (i, l) in robot.links.iter().enumerate() {
        if link_idx.insert(l.name.as_str(), i).is_some() {
            return Err(ctx.invalid(link_el(&l.name), "duplicate link name"));
        }
    }
    let mut joint_names = HashMap::new();
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (ji, j) in robot.joints.iter().enumerate() {
        let el = joint_el(&j.name);
        if joint_names.insert(j.name.as_str(), ji).is_some() {
            return Err(ctx.invalid(el, "duplicate joint name"));
        }
        let p = *link_idx
            .get(j.parent.link.as_str())
            .ok_or_else(|| ctx.invalid(el.clone(), format!("parent link \"{}\" does not exist", j.parent.link)))?;
        let c = *link_idx
            .get(j.child.link.as_str())
            .ok_or_else(|| ctx.invalid(el.clone(), format!("child link \"{}\" does not exist", j.child.link)))?;
        if let Some(other) = parent_joint[c] {
            return Err(ctx.invalid(
                el,
                format!("child link \"{}\" already has parent joint \"{}\"", j.child.link, robot.joints[other].name),
            ));
        }
        parent_joint[c] = Some(ji);
        children[p].push(ji);
        match j.joint_type {
            urdf_rs::JointType::Revolute
            | urdf_rs::JointType::Continuous
            | urdf_rs::JointType::Prismatic
            | urdf_rs::JointType::Fixed => {}
            ref t => {
                return Err(ctx.unsupported(
                    el,
                    format!("joint type {t:?} is not supported (revolute, continuous, prismatic, fixed only)"),
                ))
            }
        }
        if j.mimic.is_some() {
            return Err(ctx.unsupported(el, "mimic joints are not supported"));
        }
    }
    let roots: Vec<usize> = (0..robot.links.len()).filter(|&i| parent_joint[i].is_none()).collect();
    match roots.len() {
        0 => return Err(ctx.invalid("<robot>".into(), "no root link (the joints form a cycle)")),
        1 => {}
        _ => {
            let names: Vec<String> = roots.iter().map(|&i| format!("\"{}\"", robot.links[i].name)).collect();
            return Err(ctx.invalid(
                "<robot>".into(),
                format!("multiple root links {} (every link but one needs a parent joint)", names.join(", ")),
            ));
        }
    }

    // --- depth-first traversal ---
    let mut bodies: Vec<Body> = Vec::new();
    let mut body_inertia: Vec<SpatialInertia> = Vec::new();
    let mut jnames = Vec::new();
    let mut limits = Vec::new();
    let mut frames: Vec<Frame> = Vec::new();
    let mut frame_names = Vec::new();
    let mut visited = vec![false; robot.links.len()];

    // Stack entries: (link, joint leading to it, body of the parent link, parent link placement in
    // that body). Bodies are numbered when popped, which gives depth-first pre-order numbering.
    type Entry = (usize, Option<usize>, Option<usize>, Isometry3<f64>);
    let mut stack: Vec<Entry> = vec![(roots[0], None, None, Isometry3::identity())];
    while let Some((li, via, parent_body, parent_placement)) = stack.pop() {
        visited[li] = true;
        let link = &robot.links[li];
        let inertia = link_inertia(&ctx, link)?;
        let (body, placement) = match via {
            None => (None, Isometry3::identity()),
            Some(ji) => {
                let j = &robot.joints[ji];
                let el = joint_el(&j.name);
                let origin = pose(&ctx, &el, &j.origin)?;
                let kind = match j.joint_type {
                    urdf_rs::JointType::Fixed => None,
                    urdf_rs::JointType::Prismatic => Some(JointKind::Prismatic),
                    _ => Some(JointKind::Revolute),
                };
                match kind {
                    None => (parent_body, parent_placement * origin),
                    Some(kind) => {
                        let axis = Vector3::new(j.axis.xyz[0], j.axis.xyz[1], j.axis.xyz[2]);
                        let norm = axis.norm();
                        if !norm.is_finite() || norm < 1e-9 {
                            return Err(ctx.invalid(el, format!("joint axis {:?} has (near) zero length", j.axis.xyz.0)));
                        }
                        if inertia.is_none() {
                            return Err(ctx.invalid(
                                link_el(&link.name),
                                format!(
                                    "moving link (child of joint \"{}\") has no <inertial> or zero mass",
                                    j.name
                                ),
                            ));
                        }
                        let l = &j.limit;
                        let lim = if j.joint_type == urdf_rs::JointType::Continuous {
                            JointLimits {
                                lower: f64::NEG_INFINITY,
                                upper: f64::INFINITY,
                                velocity: l.velocity,
                                effort: l.effort,
                            }
                        } else {
                            JointLimits { lower: l.lower, upper: l.upper, velocity: l.velocity, effort: l.effort }
                        };
                        if [lim.velocity, lim.effort].iter().any(|x| x.is_nan())
                            || lim.lower.is_nan()
                            || lim.upper.is_nan()
                            || lim.lower > lim.upper
                        {
                            return Err(ctx.invalid(el, format!("invalid <limit> {lim:?}")));
                        }
                        let placement = parent_placement * origin;
                        bodies.push(Body {
                            parent: parent_body,
                            frame: frames.len(),
                            kind,
                            axis: axis / norm,
                            placement,
                            mass: 0.0,
                            com: Vector3::zeros(),
                            inertia_com: Matrix3::zeros(),
                        });
                        body_inertia.push(SpatialInertia::zero());
                        jnames.push(j.name.clone());
                        limits.push(lim);
                        (Some(bodies.len() - 1), Isometry3::identity())
                    }
                }
            }
        };
        if let (Some(b), Some(inr)) = (body, inertia.as_ref()) {
            body_inertia[b].add(&to_body(inr, &placement));
        }
        frames.push(Frame {
            body,
            placement,
            placement_is_identity: placement == Isometry3::identity(),
            collisions: collisions(&ctx, link)?,
        });
        frame_names.push(link.name.clone());
        // reversed so that children are visited in document order
        for &ji in children[li].iter().rev() {
            let child = link_idx[robot.joints[ji].child.link.as_str()];
            stack.push((child, Some(ji), body, placement));
        }
    }
    if let Some(li) = visited.iter().position(|v| !v) {
        return Err(ctx.invalid(link_el(&robot.links[li].name), "link is not connected to the root (cycle)"));
    }
    for (b, si) in bodies.iter_mut().zip(&body_inertia) {
        b.mass = si.mass;
        b.com = si.com();
        b.inertia_com = si.inertia_about_com();
    }
    // reference body: follow the chain of single-child bodies from a unique root body
    let n = bodies.len();
    let mut ref_body = 0;
    let mut trunk = vec![false; n];
    if n > 0 {
        let child_count = |b: usize| bodies.iter().filter(|x| x.parent == Some(b)).count();
        let roots = bodies.iter().filter(|x| x.parent.is_none()).count();
        trunk[0] = true;
        if roots == 1 {
            while child_count(ref_body) == 1 {
                ref_body = bodies.iter().position(|x| x.parent == Some(ref_body)).unwrap_or(ref_body);
                trunk[ref_body] = true;
            }
        }
    }
    Ok(RobotModel {
        ref_body,
        trunk,
        name: robot.name.clone(),
        source: file.to_string(),
        bodies,
        joint_names: jnames,
        limits,
        frames,
        frame_names,
        gravity: Vector3::new(0.0, 0.0, -STANDARD_GRAVITY),
    })
}
