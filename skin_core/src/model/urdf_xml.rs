//! Reading the URDF XML format (ROS `urdf` specification) into plain structs, nothing more.
//!
//! Only what the model needs is read: `<robot name>`, each `<link>` (its `<inertial>` and
//! `<collision>` elements) and each `<joint>`. Everything else the format allows — `<visual>`,
//! `<material>`, `<texture>`, `<gazebo>`, `<transmission>`, `<dynamics>`, `<calibration>`,
//! `<safety_controller>`, vendor extensions — is skipped unread, so that it can never make a
//! valid robot fail to load. What is read is checked as the specification states it (required
//! attributes present, numbers finite); errors name the element and its line.

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use roxmltree::Node;

use super::error::ModelError;

/// The parts of a URDF the model is built from.
pub(crate) struct Urdf {
    pub(crate) name: String,
    pub(crate) links: Vec<Link>,
    pub(crate) joints: Vec<Joint>,
}

/// A `<link>`.
pub(crate) struct Link {
    pub(crate) name: String,
    pub(crate) line: u32,
    pub(crate) inertial: Option<Inertial>,
    pub(crate) collisions: Vec<CollisionXml>,
}

/// An `<inertial>`: mass and the inertia about the centre of mass, in the `<origin>` frame.
pub(crate) struct Inertial {
    pub(crate) origin: Isometry3<f64>,
    pub(crate) mass: f64,
    /// `ixx, ixy, ixz, iyy, iyz, izz`.
    pub(crate) inertia: [f64; 6],
}

/// A `<collision>` with its geometry.
pub(crate) struct CollisionXml {
    pub(crate) name: Option<String>,
    pub(crate) line: u32,
    pub(crate) origin: Isometry3<f64>,
    pub(crate) geometry: Geometry,
}

/// A `<geometry>` child (`capsule` is not in the specification but is read by urdf-rs and
/// MuJoCo, and used by this project's URDFs).
pub(crate) enum Geometry {
    Box([f64; 3]),
    Cylinder { radius: f64, length: f64 },
    Sphere { radius: f64 },
    Capsule { radius: f64, length: f64 },
    Mesh { filename: String, scale: [f64; 3] },
}

/// URDF joint types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum JointType {
    Revolute,
    Continuous,
    Prismatic,
    Fixed,
    Floating,
    Planar,
}

/// A `<joint>`.
pub(crate) struct Joint {
    pub(crate) name: String,
    pub(crate) line: u32,
    pub(crate) kind: JointType,
    pub(crate) origin: Isometry3<f64>,
    pub(crate) parent: String,
    pub(crate) child: String,
    pub(crate) axis: [f64; 3],
    pub(crate) limit: Option<Limit>,
    pub(crate) mimic: Option<Mimic>,
}

/// A `<limit>` (lower and upper default to 0 as in the specification).
pub(crate) struct Limit {
    pub(crate) lower: f64,
    pub(crate) upper: f64,
    pub(crate) effort: f64,
    pub(crate) velocity: f64,
}

/// A `<mimic>`: this joint's value is `multiplier * leader + offset`.
pub(crate) struct Mimic {
    pub(crate) joint: String,
    pub(crate) multiplier: f64,
    pub(crate) offset: f64,
}

struct Reader<'a> {
    file: &'a str,
    doc: &'a roxmltree::Document<'a>,
}

impl Reader<'_> {
    fn line(&self, n: Node<'_, '_>) -> u32 {
        self.doc.text_pos_at(n.range().start).row
    }

    fn invalid(&self, element: String, message: impl Into<String>) -> ModelError {
        ModelError::Invalid { file: self.file.to_string(), element, message: message.into() }
    }

    /// `<tag>` of `owner` at its line, e.g. `joint "elbow" <limit> (line 12)`.
    fn el(&self, owner: &str, n: Node<'_, '_>) -> String {
        format!("{owner} <{}> (line {})", n.tag_name().name(), self.line(n))
    }

    fn required<'n>(&self, owner: &str, n: Node<'n, '_>, attr: &str) -> Result<&'n str, ModelError> {
        n.attribute(attr).ok_or_else(|| self.invalid(self.el(owner, n), format!("missing attribute `{attr}`")))
    }

    /// A list of finite numbers in attribute `attr`; `default` when the attribute is absent.
    fn numbers<const N: usize>(
        &self,
        owner: &str,
        n: Node<'_, '_>,
        attr: &str,
        default: Option<[f64; N]>,
    ) -> Result<[f64; N], ModelError> {
        let Some(text) = n.attribute(attr) else {
            return default.ok_or_else(|| self.invalid(self.el(owner, n), format!("missing attribute `{attr}`")));
        };
        let bad =
            || self.invalid(self.el(owner, n), format!("attribute `{attr}=\"{text}\"` must be {N} finite number(s)"));
        let mut out = [0.0; N];
        let mut it = text.split_whitespace();
        for o in out.iter_mut() {
            *o = it.next().and_then(|t| t.parse::<f64>().ok()).filter(|x| x.is_finite()).ok_or_else(bad)?;
        }
        if it.next().is_some() {
            return Err(bad());
        }
        Ok(out)
    }

    fn number(&self, owner: &str, n: Node<'_, '_>, attr: &str, default: Option<f64>) -> Result<f64, ModelError> {
        Ok(self.numbers::<1>(owner, n, attr, default.map(|d| [d]))?[0])
    }

    /// `<origin xyz rpy>` child of `n` (identity when absent); rpy = fixed-axis roll, pitch, yaw.
    fn origin(&self, owner: &str, n: Node<'_, '_>) -> Result<Isometry3<f64>, ModelError> {
        let Some(o) = child(n, "origin") else {
            return Ok(Isometry3::identity());
        };
        let xyz = self.numbers::<3>(owner, o, "xyz", Some([0.0; 3]))?;
        let rpy = self.numbers::<3>(owner, o, "rpy", Some([0.0; 3]))?;
        Ok(Isometry3::from_parts(
            Translation3::new(xyz[0], xyz[1], xyz[2]),
            UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
        ))
    }

    fn link(&self, n: Node<'_, '_>) -> Result<Link, ModelError> {
        let name = self.required("<robot>", n, "name")?.to_string();
        let owner = format!("link \"{name}\"");
        let inertial = match child(n, "inertial") {
            None => None,
            Some(i) => {
                let el = self.el(&owner, i);
                let mass = child(i, "mass").ok_or_else(|| self.invalid(el.clone(), "missing <mass>"))?;
                let t = child(i, "inertia").ok_or_else(|| self.invalid(el.clone(), "missing <inertia>"))?;
                let mut inertia = [0.0; 6];
                for (v, a) in inertia.iter_mut().zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]) {
                    *v = self.number(&owner, t, a, None)?;
                }
                Some(Inertial {
                    origin: self.origin(&owner, i)?,
                    mass: self.number(&owner, mass, "value", None)?,
                    inertia,
                })
            }
        };
        let mut collisions = Vec::new();
        for c in children(n, "collision") {
            let el = self.el(&owner, c);
            let g = child(c, "geometry").ok_or_else(|| self.invalid(el.clone(), "missing <geometry>"))?;
            let shape = g
                .children()
                .find(|s| s.is_element())
                .ok_or_else(|| self.invalid(el.clone(), "<geometry> has no shape"))?;
            let geometry = match shape.tag_name().name() {
                "box" => Geometry::Box(self.numbers(&owner, shape, "size", None)?),
                "cylinder" => Geometry::Cylinder {
                    radius: self.number(&owner, shape, "radius", None)?,
                    length: self.number(&owner, shape, "length", None)?,
                },
                "capsule" => Geometry::Capsule {
                    radius: self.number(&owner, shape, "radius", None)?,
                    length: self.number(&owner, shape, "length", None)?,
                },
                "sphere" => Geometry::Sphere { radius: self.number(&owner, shape, "radius", None)? },
                "mesh" => Geometry::Mesh {
                    filename: self.required(&owner, shape, "filename")?.to_string(),
                    scale: self.numbers(&owner, shape, "scale", Some([1.0; 3]))?,
                },
                other => return Err(self.invalid(el, format!("unknown geometry <{other}>"))),
            };
            collisions.push(CollisionXml {
                name: c.attribute("name").map(str::to_string),
                line: self.line(c),
                origin: self.origin(&owner, c)?,
                geometry,
            });
        }
        Ok(Link { name, line: self.line(n), inertial, collisions })
    }

    fn joint(&self, n: Node<'_, '_>) -> Result<Joint, ModelError> {
        let name = self.required("<robot>", n, "name")?.to_string();
        let owner = format!("joint \"{name}\"");
        let el = format!("{owner} (line {})", self.line(n));
        let kind = match self.required(&owner, n, "type")? {
            "revolute" => JointType::Revolute,
            "continuous" => JointType::Continuous,
            "prismatic" => JointType::Prismatic,
            "fixed" => JointType::Fixed,
            "floating" => JointType::Floating,
            "planar" => JointType::Planar,
            other => {
                return Err(self.invalid(
                    el,
                    format!(
                        "unknown joint type \"{other}\" (revolute, continuous, prismatic, fixed, floating, planar)"
                    ),
                ))
            }
        };
        let link_of = |tag: &str| -> Result<String, ModelError> {
            let c = child(n, tag).ok_or_else(|| self.invalid(el.clone(), format!("missing <{tag}>")))?;
            Ok(self.required(&owner, c, "link")?.to_string())
        };
        let axis = match child(n, "axis") {
            Some(a) => self.numbers(&owner, a, "xyz", Some([1.0, 0.0, 0.0]))?,
            None => [1.0, 0.0, 0.0],
        };
        let limit = match child(n, "limit") {
            Some(l) => Some(Limit {
                lower: self.number(&owner, l, "lower", Some(0.0))?,
                upper: self.number(&owner, l, "upper", Some(0.0))?,
                effort: self.number(&owner, l, "effort", None)?,
                velocity: self.number(&owner, l, "velocity", None)?,
            }),
            None => None,
        };
        let mimic = match child(n, "mimic") {
            Some(m) => Some(Mimic {
                joint: self.required(&owner, m, "joint")?.to_string(),
                multiplier: self.number(&owner, m, "multiplier", Some(1.0))?,
                offset: self.number(&owner, m, "offset", Some(0.0))?,
            }),
            None => None,
        };
        Ok(Joint {
            line: self.line(n),
            kind,
            origin: self.origin(&owner, n)?,
            parent: link_of("parent")?,
            child: link_of("child")?,
            axis,
            limit,
            mimic,
            name,
        })
    }
}

fn child<'a, 'i>(n: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.is_element() && c.tag_name().name() == tag)
}

fn children<'a, 'i: 'a>(n: Node<'a, 'i>, tag: &'a str) -> impl Iterator<Item = Node<'a, 'i>> + 'a {
    n.children().filter(move |c| c.is_element() && c.tag_name().name() == tag)
}

/// Reads URDF text; `file` names it in errors.
pub(crate) fn read(xml: &str, file: &str) -> Result<Urdf, ModelError> {
    let parse = |message: String| ModelError::Parse { file: file.to_string(), message };
    let options = roxmltree::ParsingOptions { allow_dtd: true, ..Default::default() };
    let doc = roxmltree::Document::parse_with_options(xml, options).map_err(|e| parse(e.to_string()))?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(parse(format!("the root element is <{}>, expected <robot>", root.tag_name().name())));
    }
    let r = Reader { file, doc: &doc };
    Ok(Urdf {
        name: root.attribute("name").unwrap_or_default().to_string(),
        links: children(root, "link").map(|n| r.link(n)).collect::<Result<_, _>>()?,
        joints: children(root, "joint").map(|n| r.joint(n)).collect::<Result<_, _>>()?,
    })
}
