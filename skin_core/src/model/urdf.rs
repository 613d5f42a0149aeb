//! Building the model from a URDF: the moving-body tree, fixed links merged, mimic joints
//! resolved, inertias checked (and repaired within tolerance), and M checked to be positive
//! definite.

use std::collections::HashMap;

use nalgebra::{DMatrix, Isometry3, Matrix3, Vector3};

use super::error::ModelError;
use super::inertia_check::{self, Verdict};
use super::robot::{
    Body, Collision, Frame, JointKind, JointLimits, MimicMode, RobotModel, Shape, UrdfOptions, STANDARD_GRAVITY,
};
use super::spatial::SpatialInertia;
use super::urdf_xml::{self, Geometry, JointType, Urdf};

impl RobotModel {
    /// Loads and validates a URDF file (plain URDF, no xacro) with the default options.
    pub fn from_urdf_file(path: &std::path::Path) -> Result<RobotModel, ModelError> {
        Self::from_urdf_file_with(path, &UrdfOptions::default())
    }

    /// Loads and validates a URDF file with the given options.
    pub fn from_urdf_file_with(path: &std::path::Path, options: &UrdfOptions) -> Result<RobotModel, ModelError> {
        let file = path.display().to_string();
        let xml = std::fs::read_to_string(path).map_err(|io| ModelError::Io { file: file.clone(), io })?;
        Self::from_urdf_str_with(&xml, &file, options)
    }

    /// Loads and validates URDF text with the default options; `source` names it (usually the
    /// file) in error messages.
    pub fn from_urdf_str(xml: &str, source: &str) -> Result<RobotModel, ModelError> {
        Self::from_urdf_str_with(xml, source, &UrdfOptions::default())
    }

    /// Loads and validates URDF text with the given options.
    pub fn from_urdf_str_with(xml: &str, source: &str, options: &UrdfOptions) -> Result<RobotModel, ModelError> {
        build(xml, source, options)
    }
}

/// Repair tolerance of link inertias, relative to the largest link inertia of the URDF
/// (Frobenius norm): a repair changes M by at most this fraction of the robot's inertia scale.
const INERTIA_REPAIR_TOL: f64 = 1e-6;

/// Mass, centre of mass and inertia about it, in the link frame.
type LinkInertia = (f64, Vector3<f64>, Matrix3<f64>);

struct Ctx<'a> {
    file: &'a str,
    warnings: Vec<String>,
}

impl Ctx<'_> {
    fn invalid(&self, element: String, message: impl Into<String>) -> ModelError {
        ModelError::Invalid { file: self.file.to_string(), element, message: message.into() }
    }
    fn unsupported(&self, element: String, message: impl Into<String>) -> ModelError {
        ModelError::Unsupported { file: self.file.to_string(), element, message: message.into() }
    }
}

fn link_el(l: &urdf_xml::Link) -> String {
    format!("link \"{}\" (line {})", l.name, l.line)
}
fn joint_el(j: &urdf_xml::Joint) -> String {
    format!("joint \"{}\" (line {})", j.name, j.line)
}

/// The link's inertial as (mass, com, inertia about com) in the link frame, checked and repaired
/// within `tol` (see [`inertia_check`]). `None` for a link without mass. A link fixed to the
/// world (`moves` false) does not enter the dynamics of this fixed-root model: what would refuse
/// a moving link is only a warning there.
fn link_inertia(
    ctx: &mut Ctx<'_>,
    link: &urdf_xml::Link,
    tol: f64,
    moves: bool,
) -> Result<Option<LinkInertia>, ModelError> {
    let Some(i) = &link.inertial else { return Ok(None) };
    let m = i.mass;
    let [xx, xy, xz, yy, yz, zz] = i.inertia;
    let mut inertia = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let verdict = if m < 0.0 {
        Verdict::Invalid(format!("negative mass {m}"))
    } else {
        inertia_check::check(&link.name, m, &inertia, tol)
    };
    match verdict {
        Verdict::Valid => {}
        Verdict::Changed { inertia: repaired, warning } => {
            inertia = repaired;
            ctx.warnings.push(warning);
        }
        Verdict::Kept { warning } => ctx.warnings.push(warning),
        Verdict::Invalid(reason) if !moves => {
            ctx.warnings.push(format!(
                "link \"{}\" is fixed to the world, so its inertial is not used; it would be refused on a moving link: {reason}",
                link.name
            ));
            return Ok(None);
        }
        Verdict::Invalid(reason) => return Err(ctx.invalid(format!("{} <inertial>", link_el(link)), reason)),
    }
    if m == 0.0 && inertia.iter().all(|x| *x == 0.0) {
        return Ok(None);
    }
    let r = i.origin.rotation.to_rotation_matrix();
    Ok(Some((m, i.origin.translation.vector, r.matrix() * inertia * r.matrix().transpose())))
}

fn collisions(ctx: &Ctx<'_>, link: &urdf_xml::Link) -> Result<Vec<Collision>, ModelError> {
    let mut out = Vec::with_capacity(link.collisions.len());
    for c in &link.collisions {
        let el = || format!("link \"{}\" <collision> (line {})", link.name, c.line);
        let positive = |x: f64| x > 0.0;
        let shape = match &c.geometry {
            Geometry::Box(size) => {
                if !size.iter().all(|x| positive(*x)) {
                    return Err(ctx.invalid(el(), "box size must be positive"));
                }
                Shape::Box { size: Vector3::from(*size) }
            }
            Geometry::Cylinder { radius, length } => {
                if !positive(*radius) || !positive(*length) {
                    return Err(ctx.invalid(el(), "cylinder radius and length must be positive"));
                }
                Shape::Cylinder { radius: *radius, length: *length }
            }
            Geometry::Capsule { radius, length } => {
                if !(positive(*radius) && *length >= 0.0) {
                    return Err(ctx.invalid(el(), "capsule radius must be positive, length non-negative"));
                }
                Shape::Capsule { radius: *radius, length: *length }
            }
            Geometry::Sphere { radius } => {
                if !positive(*radius) {
                    return Err(ctx.invalid(el(), "sphere radius must be positive"));
                }
                Shape::Sphere { radius: *radius }
            }
            Geometry::Mesh { filename, scale } => {
                Shape::Mesh { filename: filename.clone(), scale: Vector3::from(*scale) }
            }
        };
        out.push(Collision { name: c.name.clone(), origin: c.origin, shape });
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

/// Largest link inertia (Frobenius norm, between 1 and √3 times the largest principal moment):
/// the robot's inertia scale for the repair tolerance.
fn inertia_scale(robot: &Urdf) -> f64 {
    robot
        .links
        .iter()
        .filter_map(|l| l.inertial.as_ref())
        .map(|i| {
            let [xx, xy, xz, yy, yz, zz] = i.inertia;
            Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz).norm()
        })
        .filter(|n| n.is_finite())
        .fold(0.0, f64::max)
}

/// Limits of a moving joint: `<limit>` is required for revolute and prismatic joints (URDF
/// specification), optional for continuous ones (position unbounded, velocity and effort ∞
/// when absent).
fn joint_limits(ctx: &Ctx<'_>, j: &urdf_xml::Joint) -> Result<JointLimits, ModelError> {
    let el = joint_el(j);
    let lim = match (&j.limit, j.kind) {
        (Some(l), JointType::Continuous) => {
            JointLimits { lower: f64::NEG_INFINITY, upper: f64::INFINITY, velocity: l.velocity, effort: l.effort }
        }
        (None, JointType::Continuous) => JointLimits {
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            velocity: f64::INFINITY,
            effort: f64::INFINITY,
        },
        (Some(l), _) => JointLimits { lower: l.lower, upper: l.upper, velocity: l.velocity, effort: l.effort },
        (None, _) => {
            return Err(ctx.invalid(el, "missing <limit> (required for revolute and prismatic joints)"));
        }
    };
    if lim.lower > lim.upper {
        return Err(ctx.invalid(el, format!("<limit> lower {} is above upper {}", lim.lower, lim.upper)));
    }
    Ok(lim)
}

/// For `MimicMode::Follow`: the coordinate leader, multiplier and offset of every moving joint
/// (its own index, 1, 0 unless it mimics another moving joint; chains of mimics composed).
fn resolve_mimics(
    ctx: &Ctx<'_>,
    robot: &Urdf,
    moving: &[usize],
    mode: MimicMode,
) -> Result<Vec<(usize, f64, f64)>, ModelError> {
    let by_name: HashMap<&str, usize> =
        moving.iter().enumerate().map(|(b, &ji)| (robot.joints[ji].name.as_str(), b)).collect();
    let mut out: Vec<(usize, f64, f64)> = (0..moving.len()).map(|b| (b, 1.0, 0.0)).collect();
    if mode == MimicMode::Independent {
        return Ok(out);
    }
    for (b, o) in out.iter_mut().enumerate() {
        let (mut cur, mut mult, mut off) = (b, 1.0, 0.0);
        let mut steps = 0;
        while let Some(m) = &robot.joints[moving[cur]].mimic {
            let j = &robot.joints[moving[cur]];
            let leader = *by_name.get(m.joint.as_str()).ok_or_else(|| {
                ctx.invalid(
                    format!("{} <mimic>", joint_el(j)),
                    format!("mimics \"{}\", which is not a moving joint of this URDF", m.joint),
                )
            })?;
            // q_cur = m q_leader + o, so q_b = mult (m q_leader + o) + off
            off += mult * m.offset;
            mult *= m.multiplier;
            cur = leader;
            steps += 1;
            if steps > moving.len() {
                return Err(ctx.invalid(format!("{} <mimic>", joint_el(j)), "mimic joints form a cycle"));
            }
        }
        *o = (cur, mult, off);
    }
    Ok(out)
}

/// Builds the model from URDF text (see [`RobotModel::from_urdf_str_with`]).
pub(crate) fn build(xml: &str, file: &str, options: &UrdfOptions) -> Result<RobotModel, ModelError> {
    let robot = urdf_xml::read(xml, file)?;
    let mut ctx = Ctx { file, warnings: Vec::new() };
    if robot.links.is_empty() {
        return Err(ModelError::Parse { file: file.to_string(), message: "no <link> element".into() });
    }

    // --- names and tree structure ---
    let mut link_idx: HashMap<&str, usize> = HashMap::new();
    for (i, l) in robot.links.iter().enumerate() {
        if link_idx.insert(l.name.as_str(), i).is_some() {
            return Err(ctx.invalid(link_el(l), "duplicate link name"));
        }
    }
    let mut joint_names = HashMap::new();
    let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for (ji, j) in robot.joints.iter().enumerate() {
        let el = joint_el(j);
        if joint_names.insert(j.name.as_str(), ji).is_some() {
            return Err(ctx.invalid(el, "duplicate joint name"));
        }
        let p = *link_idx
            .get(j.parent.as_str())
            .ok_or_else(|| ctx.invalid(el.clone(), format!("parent link \"{}\" does not exist", j.parent)))?;
        let c = *link_idx
            .get(j.child.as_str())
            .ok_or_else(|| ctx.invalid(el.clone(), format!("child link \"{}\" does not exist", j.child)))?;
        if let Some(other) = parent_joint[c] {
            return Err(ctx.invalid(
                el,
                format!("child link \"{}\" already has parent joint \"{}\"", j.child, robot.joints[other].name),
            ));
        }
        parent_joint[c] = Some(ji);
        children[p].push(ji);
        if matches!(j.kind, JointType::Floating | JointType::Planar) {
            return Err(ctx.unsupported(
                el,
                format!(
                    "{:?} joints are not supported: the model has a fixed root; model a mobile base as prismatic and revolute joints",
                    j.kind
                ),
            ));
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
    let tol = INERTIA_REPAIR_TOL * inertia_scale(&robot);
    let mut bodies: Vec<Body> = Vec::new();
    let mut body_inertia: Vec<SpatialInertia> = Vec::new();
    let mut moving: Vec<usize> = Vec::new();
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
        let (body, placement) = match via {
            None => (None, Isometry3::identity()),
            Some(ji) => {
                let j = &robot.joints[ji];
                let kind = match j.kind {
                    JointType::Prismatic => Some(JointKind::Prismatic),
                    JointType::Revolute | JointType::Continuous => Some(JointKind::Revolute),
                    _ => None,
                };
                match kind {
                    None => (parent_body, parent_placement * j.origin),
                    Some(kind) => {
                        let axis = Vector3::from(j.axis);
                        let norm = axis.norm();
                        if norm < 1e-9 {
                            return Err(
                                ctx.invalid(joint_el(j), format!("joint axis {:?} has (near) zero length", j.axis))
                            );
                        }
                        limits.push(joint_limits(&ctx, j)?);
                        bodies.push(Body {
                            parent: parent_body,
                            frame: frames.len(),
                            kind,
                            axis: axis / norm,
                            placement: parent_placement * j.origin,
                            coord: bodies.len(),
                            multiplier: 1.0,
                            offset: 0.0,
                            mass: 0.0,
                            com: Vector3::zeros(),
                            inertia_com: Matrix3::zeros(),
                        });
                        body_inertia.push(SpatialInertia::zero());
                        moving.push(ji);
                        (Some(bodies.len() - 1), Isometry3::identity())
                    }
                }
            }
        };
        let inertia = link_inertia(&mut ctx, link, tol, body.is_some())?;
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
            let child = link_idx[robot.joints[ji].child.as_str()];
            stack.push((child, Some(ji), body, placement));
        }
    }
    if let Some(li) = visited.iter().position(|v| !v) {
        return Err(ctx.invalid(link_el(&robot.links[li]), "link is not connected to the root (cycle)"));
    }
    for (b, si) in bodies.iter_mut().zip(&body_inertia) {
        b.mass = si.mass;
        b.com = si.com();
        b.inertia_com = si.inertia_about_com();
    }

    // --- generalized coordinates: one per moving joint, except followed mimic joints ---
    let leaders = resolve_mimics(&ctx, &robot, &moving, options.mimic)?;
    let mut coord_of_leader = vec![usize::MAX; bodies.len()];
    let mut coord_names = Vec::new();
    let mut coord_limits = Vec::new();
    for (b, &(leader, _, _)) in leaders.iter().enumerate() {
        if leader == b {
            coord_of_leader[b] = coord_names.len();
            coord_names.push(robot.joints[moving[b]].name.clone());
            coord_limits.push(limits[b]);
        }
    }
    for (body, &(leader, multiplier, offset)) in bodies.iter_mut().zip(&leaders) {
        body.coord = coord_of_leader[leader];
        body.multiplier = multiplier;
        body.offset = offset;
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
    let model = RobotModel {
        ref_body,
        trunk,
        name: robot.name.clone(),
        source: file.to_string(),
        moving_joint_names: moving.iter().map(|&ji| robot.joints[ji].name.clone()).collect(),
        bodies,
        joint_names: coord_names,
        limits: coord_limits,
        frames,
        frame_names,
        gravity: Vector3::new(0.0, 0.0, -STANDARD_GRAVITY),
        warnings: std::mem::take(&mut ctx.warnings),
    };
    check_mass_matrix(&ctx, &model, &robot, &moving)?;
    Ok(model)
}

/// Refuses a model whose mass matrix is singular: massless links are fine as long as what each
/// joint moves has inertia about its motion that the joints after it cannot supply. Checked at
/// two configurations (zero and a generic one within the limits) by a Cholesky factorization
/// from the last coordinate to the first (the tree's natural order, RBDA Sec. 6.5): a vanishing
/// pivot names the joint.
fn check_mass_matrix(ctx: &Ctx<'_>, model: &RobotModel, robot: &Urdf, moving: &[usize]) -> Result<(), ModelError> {
    let n = model.nv();
    if n == 0 {
        return Ok(());
    }
    let mut data = super::ModelData::new(model);
    let mut m = DMatrix::zeros(n, n);
    let generic: Vec<f64> =
        model.limits.iter().enumerate().map(|(i, l)| (0.7 - 0.29 * i as f64).clamp(l.lower, l.upper)).collect();
    for (at, q) in [("the zero configuration", vec![0.0; n]), ("a generic configuration", generic)] {
        super::update_kinematics(model, &mut data, &q, &vec![0.0; n])?;
        super::crba(model, &mut data, &mut m)?;
        let scale = m.diagonal().amax();
        let diag = m.diagonal();
        for k in (0..n).rev() {
            let pivot = m[(k, k)];
            // NaN pivots (overflowing inputs) count as singular too
            let singular = pivot.is_nan() || pivot <= 1e-12 * diag[k] || diag[k] <= 1e-14 * scale;
            if singular {
                let b = model.bodies.iter().position(|b| b.coord == k).unwrap_or(k);
                let j = &robot.joints[moving[b]];
                return Err(ctx.invalid(
                    joint_el(j),
                    format!(
                        "the mass matrix is singular at {at}: nothing this joint moves has mass or inertia about its motion (massless child links need massive descendants)"
                    ),
                ));
            }
            // eliminate coordinate k from the leading block
            let col: Vec<f64> = (0..k).map(|r| m[(r, k)] / pivot).collect();
            for r in 0..k {
                for c in 0..k {
                    m[(r, c)] -= col[r] * m[(c, k)];
                }
            }
        }
    }
    Ok(())
}
