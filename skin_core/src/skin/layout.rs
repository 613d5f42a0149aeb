//! Skin layouts (`config/skin/<robot>.yaml`): patches attached to links and the cells on them,
//! validated, then resolved against a robot model into frame indices and precomputed cell poses.
//!
//! File format (all lengths in m, angles in rad):
//!
//! ```yaml
//! robot: tomm                      # optional, informative
//! patches:                         # patch frame {p_j} in its link frame: xyz, then rpy (URDF order)
//!   - {id: 1, link: r_forearm_link, xyz: [0, 0, 0.1], rpy: [0, 0, 0]}
//! cells:                           # cell position and outward normal in the PATCH frame
//!   - {id: 1, patch: 1, position: [0.05, 0, 0], normal: [1, 0, 0]}
//! ```
//!
//! The cell frame {s_i} has its origin at the cell position and its z axis along the outward
//! normal; its x axis is built deterministically by [`cell_rotation`].

use std::collections::HashMap;
use std::fmt;
use std::path::Path;

use nalgebra::{Isometry3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};
use serde::Deserialize;
use serde_saphyr::Spanned;
use thiserror::Error;

pub use super::resolved::{ResolvedCell, ResolvedLayout, ResolvedPatch};
use crate::model::RobotModel;
use crate::param_file::yaml::{self, YamlError};

/// One skin patch: a rigid group of cells on one link, with its own frame {p_j}.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchSpec {
    /// Unique patch id.
    pub id: u32,
    /// Name of the URDF link the patch is attached to.
    pub link: String,
    /// Origin of the patch frame in the link frame \[m\].
    pub xyz: [f64; 3],
    /// Orientation of the patch frame in the link frame: roll, pitch, yaw \[rad\] (URDF convention).
    pub rpy: [f64; 3],
    /// 1-based line in the source file, when loaded from one.
    pub line: Option<u64>,
}

/// One skin cell on a patch.
#[derive(Debug, Clone, PartialEq)]
pub struct CellSpec {
    /// Unique cell id.
    pub id: u32,
    /// Id of the patch the cell belongs to.
    pub patch: u32,
    /// Cell position in the patch frame \[m\].
    pub position: [f64; 3],
    /// Outward normal in the patch frame (normalized on resolution; must be non-zero).
    pub normal: [f64; 3],
    /// 1-based line in the source file, when loaded from one.
    pub line: Option<u64>,
}

/// A skin layout as written in a file (not yet validated against a robot model).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkinLayout {
    /// Name of the source file (for error messages), or a description.
    pub source: String,
    /// Optional robot name.
    pub robot: Option<String>,
    /// The patches.
    pub patches: Vec<PatchSpec>,
    /// The cells.
    pub cells: Vec<CellSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLayout {
    #[serde(default)]
    robot: Option<String>,
    #[serde(default)]
    patches: Vec<RawPatch>,
    #[serde(default)]
    cells: Vec<RawCell>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPatch {
    id: Spanned<u32>,
    link: String,
    #[serde(default)]
    xyz: [f64; 3],
    #[serde(default)]
    rpy: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCell {
    id: Spanned<u32>,
    patch: u32,
    position: [f64; 3],
    normal: [f64; 3],
}

fn line_of<T>(s: &Spanned<T>) -> Option<u64> {
    Some(s.referenced.line()).filter(|&l| l > 0)
}

/// What is wrong with a layout element.
#[derive(Debug, Error)]
pub enum LayoutErrorKind {
    /// The file could not be read or parsed.
    #[error("{0}")]
    Yaml(Box<YamlError>),
    /// No patches or no cells.
    #[error("empty layout: no {0}")]
    Empty(&'static str),
    /// Two patches share an id.
    #[error("duplicate patch id (first defined{})", at(.first_line))]
    DuplicatePatchId {
        /// Line of the first patch with this id.
        first_line: Option<u64>,
    },
    /// Two cells share an id.
    #[error("duplicate cell id (first defined{})", at(.first_line))]
    DuplicateCellId {
        /// Line of the first cell with this id.
        first_line: Option<u64>,
    },
    /// A cell refers to a patch id that does not exist.
    #[error("unknown patch {0}")]
    UnknownPatch(u32),
    /// A cell normal of zero length or with non-finite components.
    #[error("normal {0:?} is zero-length or not finite")]
    BadNormal([f64; 3]),
    /// A non-finite number.
    #[error("`{0}` is not finite")]
    NonFinite(&'static str),
    /// A patch's link is empty or not in the robot model.
    #[error("unknown link `{0}`")]
    UnknownLink(String),
}

fn at(line: &Option<u64>) -> String {
    line.map(|l| format!(" at line {l}")).unwrap_or_default()
}

/// A layout error naming the file, the line (when known) and the element.
#[derive(Debug)]
pub struct LayoutError {
    /// The file (or source name).
    pub file: String,
    /// 1-based line of the element, when known.
    pub line: Option<u64>,
    /// The element, e.g. `cell 17` or `patch 3`.
    pub element: String,
    /// What is wrong.
    pub kind: LayoutErrorKind,
}

impl std::error::Error for LayoutError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            LayoutErrorKind::Yaml(e) => Some(e.as_ref()),
            _ => None,
        }
    }
}

impl fmt::Display for LayoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let LayoutErrorKind::Yaml(e) = &self.kind {
            return write!(f, "{e}");
        }
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        write!(f, ": {}: {}", self.element, self.kind)
    }
}

impl LayoutError {
    fn new(file: &str, line: Option<u64>, element: String, kind: LayoutErrorKind) -> Self {
        LayoutError { file: file.to_string(), line, element, kind }
    }
}

impl From<YamlError> for LayoutError {
    fn from(e: YamlError) -> Self {
        let (file, line) = match &e {
            YamlError::Io { file, .. } => (file.clone(), None),
            YamlError::Parse { file, line, .. } => (file.clone(), *line),
        };
        LayoutError { file, line, element: "document".into(), kind: LayoutErrorKind::Yaml(Box::new(e)) }
    }
}

/// Rotation of a cell frame: z axis along the (normalized) outward normal `n`; x axis the part
/// of the parent frame's x axis orthogonal to `n`, or of its y axis when `n` is within ~25 deg of
/// x (`|n.x| > 0.9`); y = z × x. Deterministic for a given normal.
pub fn cell_rotation(n: &Unit<Vector3<f64>>) -> Rotation3<f64> {
    let z = n.into_inner();
    let reference = if z.x.abs() > 0.9 { Vector3::y() } else { Vector3::x() };
    let x = (reference - z * z.dot(&reference)).normalize();
    let y = z.cross(&x);
    Rotation3::from_basis_unchecked(&[x, y, z])
}

/// Isometry from a URDF-style `xyz` translation and `rpy` rotation.
pub fn isometry_from_xyz_rpy(xyz: &[f64; 3], rpy: &[f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

impl SkinLayout {
    /// Parses YAML text and validates it ([`Self::validate`]); `source` names the file in errors.
    pub fn from_yaml_str(text: &str, source: &str) -> Result<Self, LayoutError> {
        let raw: RawLayout = yaml::parse_str(text, source)?;
        let layout = SkinLayout {
            source: source.to_string(),
            robot: raw.robot,
            patches: raw
                .patches
                .into_iter()
                .map(|p| PatchSpec { line: line_of(&p.id), id: p.id.value, link: p.link, xyz: p.xyz, rpy: p.rpy })
                .collect(),
            cells: raw
                .cells
                .into_iter()
                .map(|c| CellSpec {
                    line: line_of(&c.id),
                    id: c.id.value,
                    patch: c.patch,
                    position: c.position,
                    normal: c.normal,
                })
                .collect(),
        };
        layout.validate()?;
        Ok(layout)
    }

    /// Reads, parses and validates the layout file at `path`.
    pub fn load(path: &Path) -> Result<Self, LayoutError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|source| LayoutError::from(YamlError::Io { file: file.clone(), source }))?;
        Self::from_yaml_str(&text, &file)
    }

    /// Checks the layout on its own: not empty, unique patch and cell ids, every cell on an
    /// existing patch, finite numbers, non-zero finite normals, non-empty link names.
    pub fn validate(&self) -> Result<(), LayoutError> {
        let file = self.source.as_str();
        if self.patches.is_empty() {
            return Err(LayoutError::new(file, None, "patches".into(), LayoutErrorKind::Empty("patches")));
        }
        if self.cells.is_empty() {
            return Err(LayoutError::new(file, None, "cells".into(), LayoutErrorKind::Empty("cells")));
        }
        let mut patch_lines: HashMap<u32, Option<u64>> = HashMap::with_capacity(self.patches.len());
        for p in &self.patches {
            let element = format!("patch {}", p.id);
            if let Some(first) = patch_lines.insert(p.id, p.line) {
                let kind = LayoutErrorKind::DuplicatePatchId { first_line: first };
                return Err(LayoutError::new(file, p.line, element, kind));
            }
            if p.link.trim().is_empty() {
                return Err(LayoutError::new(file, p.line, element, LayoutErrorKind::UnknownLink(p.link.clone())));
            }
            if !p.xyz.iter().all(|v| v.is_finite()) {
                return Err(LayoutError::new(file, p.line, element, LayoutErrorKind::NonFinite("xyz")));
            }
            if !p.rpy.iter().all(|v| v.is_finite()) {
                return Err(LayoutError::new(file, p.line, element, LayoutErrorKind::NonFinite("rpy")));
            }
        }
        let mut cell_lines: HashMap<u32, Option<u64>> = HashMap::with_capacity(self.cells.len());
        for c in &self.cells {
            let element = format!("cell {}", c.id);
            if let Some(first) = cell_lines.insert(c.id, c.line) {
                let kind = LayoutErrorKind::DuplicateCellId { first_line: first };
                return Err(LayoutError::new(file, c.line, element, kind));
            }
            if !patch_lines.contains_key(&c.patch) {
                return Err(LayoutError::new(file, c.line, element, LayoutErrorKind::UnknownPatch(c.patch)));
            }
            if !c.position.iter().all(|v| v.is_finite()) {
                return Err(LayoutError::new(file, c.line, element, LayoutErrorKind::NonFinite("position")));
            }
            let n = Vector3::from(c.normal);
            let norm = n.norm();
            if !norm.is_finite() || norm < 1e-9 {
                return Err(LayoutError::new(file, c.line, element, LayoutErrorKind::BadNormal(c.normal)));
            }
        }
        Ok(())
    }

    /// Resolves the layout against a robot model: every patch link must be a frame of `model`.
    pub fn resolve(&self, model: &RobotModel) -> Result<ResolvedLayout, LayoutError> {
        self.resolve_with(|link| model.frame_index(link))
    }

    /// Resolves the layout with a link-name -> frame-index lookup (see [`Self::resolve`]).
    /// Validates first. Patches keep the file order; cells are grouped by patch, in file order
    /// within a patch.
    pub fn resolve_with(&self, frame_of: impl Fn(&str) -> Option<usize>) -> Result<ResolvedLayout, LayoutError> {
        self.validate()?;
        let file = self.source.as_str();
        let mut patches = Vec::with_capacity(self.patches.len());
        let mut patch_index: HashMap<u32, usize> = HashMap::with_capacity(self.patches.len());
        for (k, p) in self.patches.iter().enumerate() {
            let frame = frame_of(&p.link).ok_or_else(|| {
                LayoutError::new(file, p.line, format!("patch {}", p.id), LayoutErrorKind::UnknownLink(p.link.clone()))
            })?;
            patch_index.insert(p.id, k);
            patches.push(ResolvedPatch {
                id: p.id,
                link: p.link.clone(),
                frame,
                link_from_patch: isometry_from_xyz_rpy(&p.xyz, &p.rpy),
                cells: 0..0,
            });
        }
        let mut cells = Vec::with_capacity(self.cells.len());
        for (k, patch) in patches.iter_mut().enumerate() {
            let start = cells.len();
            for c in self.cells.iter().filter(|c| patch_index[&c.patch] == k) {
                let normal = Unit::new_normalize(Vector3::from(c.normal));
                let position = Vector3::from(c.position);
                let patch_from_cell = Isometry3::from_parts(
                    Translation3::from(position),
                    UnitQuaternion::from_rotation_matrix(&cell_rotation(&normal)),
                );
                let link_from_cell = patch.link_from_patch * patch_from_cell;
                cells.push(ResolvedCell {
                    id: c.id,
                    patch: k,
                    frame: patch.frame,
                    position_patch: position,
                    normal_patch: normal.into_inner(),
                    patch_from_cell,
                    position_link: link_from_cell.translation.vector,
                    normal_link: patch.link_from_patch.rotation * normal.into_inner(),
                    link_from_cell,
                });
            }
            patch.cells = start..cells.len();
        }
        Ok(ResolvedLayout::new(self.source.clone(), patches, cells))
    }

    /// Writes the layout as YAML (flow style, one element per line, 6 decimals; 9 for angles), preceded by
    /// `header` (each line prefixed with `# `). Deterministic for a given layout.
    pub fn to_yaml(&self, header: &str) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        for line in header.lines() {
            let _ = writeln!(s, "# {line}");
        }
        if let Some(robot) = &self.robot {
            let _ = writeln!(s, "robot: {robot}");
        }
        let _ = writeln!(s, "patches:");
        for p in &self.patches {
            let _ = writeln!(
                s,
                "  - {{id: {}, link: {}, xyz: {}, rpy: {}}}",
                p.id,
                p.link,
                fmt3(&p.xyz, 6),
                fmt3(&p.rpy, 9)
            );
        }
        let _ = writeln!(s, "cells:");
        for c in &self.cells {
            let _ = writeln!(
                s,
                "  - {{id: {}, patch: {}, position: {}, normal: {}}}",
                c.id,
                c.patch,
                fmt3(&c.position, 6),
                fmt3(&c.normal, 6)
            );
        }
        s
    }
}

fn fmt_num(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
        "0.0".to_string()
    } else {
        let t = s.trim_end_matches('0');
        if t.ends_with('.') {
            format!("{t}0")
        } else {
            t.to_string()
        }
    }
}

fn fmt3(v: &[f64; 3], decimals: usize) -> String {
    format!("[{}, {}, {}]", fmt_num(v[0], decimals), fmt_num(v[1], decimals), fmt_num(v[2], decimals))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const GOOD: &str = "robot: test
patches:
  - {id: 1, link: link_a, xyz: [0, 0, 0.1], rpy: [0, 0, 1.5707963267948966]}
  - {id: 2, link: link_b}
cells:
  - {id: 10, patch: 1, position: [0.05, 0, 0], normal: [2, 0, 0]}
  - {id: 11, patch: 2, position: [0, 0.05, 0], normal: [0, 1, 0]}
  - {id: 12, patch: 1, position: [0, 0, 0.02], normal: [0, 0, 1]}
";

    fn lookup(name: &str) -> Option<usize> {
        match name {
            "link_a" => Some(3),
            "link_b" => Some(5),
            _ => None,
        }
    }

    fn err(text: &str) -> String {
        match SkinLayout::from_yaml_str(text, "cfg/bad.yaml").and_then(|l| l.resolve_with(lookup)) {
            Ok(_) => panic!("expected an error for:\n{text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn cell_rotation_is_proper_and_z_is_normal() {
        for n in [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, -1.0),
            Vector3::new(0.3, -0.4, 0.5),
            Vector3::new(0.95, 0.1, 0.0),
        ] {
            let u = Unit::new_normalize(n);
            let r = cell_rotation(&u);
            let m = r.matrix();
            assert_relative_eq!(m * m.transpose(), nalgebra::Matrix3::identity(), epsilon = 1e-12);
            assert_relative_eq!(m.determinant(), 1.0, epsilon = 1e-12);
            assert_relative_eq!(r * Vector3::z(), u.into_inner(), epsilon = 1e-12);
        }
    }

    #[test]
    fn resolves_and_groups_cells() {
        let l = SkinLayout::from_yaml_str(GOOD, "good.yaml").unwrap();
        assert_eq!(l.cells[0].line, Some(6));
        let r = l.resolve_with(lookup).unwrap();
        assert_eq!(r.patches()[0].frame, 3);
        assert_eq!(r.patches()[1].frame, 5);
        assert_eq!(r.patches()[0].cells, 0..2);
        assert_eq!(r.patches()[1].cells, 2..3);
        assert_eq!(r.cells()[1].id, 12);
        assert_eq!(r.cell_index(11), Some(2));
        assert_eq!(r.cell_index(99), None);
        assert_eq!(r.cell_index(u32::MAX), None);
        // Sparse ids (a table would be huge): the same answers by binary search.
        let sparse = GOOD.replace("id: 11,", "id: 4000000000,");
        let r = SkinLayout::from_yaml_str(&sparse, "sparse.yaml").unwrap().resolve_with(lookup).unwrap();
        assert_eq!(r.cell_index(4_000_000_000), Some(2));
        assert_eq!(r.cell_index(10), Some(0));
        assert_eq!(r.cell_index(11), None);
        // Normal normalized; patch rotated by +90 deg about z and shifted by 0.1 in z.
        let c = &r.cells()[0];
        assert_relative_eq!(c.normal_patch, Vector3::x(), epsilon = 1e-12);
        assert_relative_eq!(c.normal_link, Vector3::y(), epsilon = 1e-12);
        assert_relative_eq!(c.position_link, Vector3::new(0.0, 0.05, 0.1), epsilon = 1e-12);
        assert_relative_eq!(c.link_from_cell * Vector3::z(), c.normal_link, epsilon = 1e-12);
    }

    #[test]
    fn yaml_round_trip() {
        let l = SkinLayout::from_yaml_str(GOOD, "good.yaml").unwrap();
        let text = l.to_yaml("generated by a test\nsecond line");
        assert!(text.starts_with("# generated by a test\n# second line\n"));
        let back = SkinLayout::from_yaml_str(&text, "round.yaml").unwrap();
        assert_eq!(back.patches.len(), 2);
        assert_eq!(back.cells.len(), 3);
        assert_eq!(back.cells[0].normal, [2.0, 0.0, 0.0]);
        assert_relative_eq!(back.patches[0].rpy[2], std::f64::consts::FRAC_PI_2, epsilon = 1e-6);
    }

    #[test]
    fn duplicate_cell_id() {
        let e = err(&GOOD.replace("id: 12", "id: 10"));
        assert!(e.contains("cfg/bad.yaml:8") && e.contains("cell 10") && e.contains("duplicate cell id"), "{e}");
        assert!(e.contains("line 6"), "{e}");
    }

    #[test]
    fn duplicate_patch_id() {
        let e = err(&GOOD.replace("{id: 2, link", "{id: 1, link"));
        assert!(e.contains("cfg/bad.yaml:4") && e.contains("patch 1") && e.contains("duplicate patch id"), "{e}");
    }

    #[test]
    fn unknown_patch() {
        let e = err(&GOOD.replace("{id: 11, patch: 2", "{id: 11, patch: 7"));
        assert!(e.contains("cfg/bad.yaml:7") && e.contains("cell 11") && e.contains("unknown patch 7"), "{e}");
    }

    #[test]
    fn unknown_link() {
        let e = err(&GOOD.replace("link_b", "no_such_link"));
        assert!(e.contains("cfg/bad.yaml:4") && e.contains("patch 2") && e.contains("no_such_link"), "{e}");
    }

    #[test]
    fn bad_normals() {
        let e = err(&GOOD.replace("normal: [0, 1, 0]", "normal: [0, 0, 0]"));
        assert!(e.contains("cfg/bad.yaml:7") && e.contains("cell 11") && e.contains("zero-length"), "{e}");
        let e = err(&GOOD.replace("normal: [0, 1, 0]", "normal: [0, .nan, 0]"));
        assert!(e.contains("cell 11") && e.contains("not finite"), "{e}");
    }

    #[test]
    fn empty_layouts() {
        let e = err("patches: []\ncells: []\n");
        assert!(e.contains("cfg/bad.yaml") && e.contains("no patches"), "{e}");
        let e = err("patches:\n  - {id: 1, link: link_a}\n");
        assert!(e.contains("cfg/bad.yaml") && e.contains("no cells"), "{e}");
    }

    #[test]
    fn parse_errors_name_file_and_line() {
        let e = err(&GOOD.replace("position: [0, 0.05, 0]", "position: [0, 0.05]"));
        assert!(e.starts_with("cfg/bad.yaml:"), "{e}");
        let e = err(&GOOD.replace("normal: [0, 0, 1]}", "normal: [0, 0, 1], colour: red}"));
        assert!(e.starts_with("cfg/bad.yaml:"), "{e}");
        eprintln!("example parse error: {e}");
        let e = SkinLayout::load(Path::new("does/not/exist.yaml")).unwrap_err().to_string();
        assert!(e.contains("does/not/exist.yaml"), "{e}");
    }

    #[test]
    fn file_errors_name_the_path() {
        let dir = std::env::temp_dir().join(format!("skin_layout_test_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("dup.yaml");
        std::fs::write(&path, GOOD.replace("id: 12", "id: 11")).unwrap();
        let e = SkinLayout::load(&path).unwrap_err();
        std::fs::remove_dir_all(&dir).unwrap();
        let text = e.to_string();
        assert_eq!(e.file, path.display().to_string());
        assert_eq!(e.line, Some(8));
        assert!(text.starts_with(&format!("{}:8: cell 11: duplicate cell id", path.display())), "{text}");
    }
}
