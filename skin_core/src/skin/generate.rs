//! Building a [`SkinLayout`] by tiling the collision geometry of chosen links of a robot model
//! (the library side of the `skin_layout` command; geometry in [`super::tiling`] for primitives
//! and [`super::mesh_tiling`] for meshes, or their fitted boxes, [`MeshMode`]).

use std::path::Path;
use std::str::FromStr;

use nalgebra::{Isometry3, Point3};
use thiserror::Error;

use super::coverage::{blind_points, surface};
use super::layout::{CellSpec, PatchSpec, SkinLayout};
use super::mesh_tiling::tile_mesh;
use super::surface::buried_in_others;
use super::tiling::{tile_box, tile_caps, tile_cylinder, tile_sphere, Face, TiledCell};
use crate::mesh::{self, MeshError, MeshMode, PackagePath};
use crate::model::{RobotModel, Shape};

/// A link to cover, optionally restricted to some of its collision elements.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinkSelection {
    /// URDF link name.
    pub link: String,
    /// Indices of the link's `<collision>` elements to tile (document order); `None` = all.
    pub collisions: Option<Vec<usize>>,
}

impl FromStr for LinkSelection {
    type Err = String;
    /// Parses `name` (all collision elements) or `name:i+j+...` (only elements i, j, ...).
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        match s.split_once(':') {
            None if !s.is_empty() => Ok(LinkSelection { link: s.to_string(), collisions: None }),
            Some((link, idx)) if !link.is_empty() => {
                let collisions = idx
                    .split('+')
                    .map(|i| i.trim().parse::<usize>().map_err(|_| format!("bad collision index `{i}` in `{s}`")))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(LinkSelection { link: link.to_string(), collisions: Some(collisions) })
            }
            _ => Err(format!("bad link selection `{s}` (use `link` or `link:0+2`)")),
        }
    }
}

/// Where the patch frame of a link is put.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PatchFrame {
    /// At the link frame.
    Link,
    /// At the origin of the link's first tiled collision primitive (default): moments of the
    /// patch wrench are then about the primitive's centre.
    #[default]
    Primitive,
}

/// What to generate.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GeneratorSpec {
    /// Links to cover, in patch order. A link listed twice is one patch.
    pub links: Vec<LinkSelection>,
    /// Cell centre distance \[m\].
    pub pitch_m: f64,
    /// Box faces to tile per link (links not listed: all six faces).
    pub faces: Vec<(String, Vec<Face>)>,
    /// Tile spheres too.
    pub spheres: bool,
    /// Tile the end caps of cylinders (disks) and capsules (hemispheres) too.
    pub caps: bool,
    /// Placement of the patch frames.
    pub patch_frame: PatchFrame,
    /// Mesh collision elements: tiled on their surface or on their fitted box.
    pub meshes: MeshMode,
    /// Where `package://` mesh URIs are searched.
    pub package_path: PackagePath,
    /// Leave out the links on which no cell fits (a finger smaller than the pitch) instead of
    /// refusing them.
    pub skip_empty: bool,
}

/// Errors of [`generate_layout`].
#[derive(Debug, Error)]
pub enum GenerateError {
    /// The pitch is not finite and positive.
    #[error("pitch {0} m must be finite and > 0")]
    BadPitch(f64),
    /// The link is not in the URDF.
    #[error("{urdf}: unknown link `{link}`")]
    UnknownLink {
        /// URDF file.
        urdf: String,
        /// Link name.
        link: String,
    },
    /// A collision index beyond the link's collision elements.
    #[error("{urdf}: link `{link}` has {count} collision element(s), no index {index}")]
    BadCollisionIndex {
        /// URDF file.
        urdf: String,
        /// Link name.
        link: String,
        /// Requested index.
        index: usize,
        /// Number of collision elements.
        count: usize,
    },
    /// A mesh of a link could not be found or read.
    #[error("{urdf}: link `{link}`: {error}")]
    Mesh {
        /// URDF file.
        urdf: String,
        /// Link name.
        link: String,
        /// Why.
        error: MeshError,
    },
    /// Nothing could be tiled on a link.
    #[error("{urdf}: link `{link}`: no cells fit on its selected primitives at this pitch")]
    NoCells {
        /// URDF file.
        urdf: String,
        /// Link name.
        link: String,
    },
}

/// Cells on one collision element in its own frame (the element's `origin`). Box faces of a
/// fitted mesh box are all six; the box's pose in the mesh frame is applied here.
fn tile_shape(shape: &Shape, faces: &[Face], spec: &GeneratorSpec, urdf: &Path) -> Result<Vec<TiledCell>, MeshError> {
    let pitch = spec.pitch_m;
    Ok(match shape {
        Shape::Box { size } => tile_box(size, faces, pitch),
        Shape::Cylinder { radius, length } | Shape::Capsule { radius, length } => {
            let mut cells = tile_cylinder(*radius, *length, pitch);
            if spec.caps {
                cells.extend(tile_caps(*radius, *length, pitch, matches!(shape, Shape::Capsule { .. })));
            }
            cells
        }
        Shape::Sphere { radius } if spec.spheres => tile_sphere(*radius, pitch),
        Shape::Sphere { .. } => Vec::new(),
        Shape::Mesh { filename, scale } => {
            let m = mesh::load_uri(filename, scale, urdf, &spec.package_path)?;
            match spec.meshes {
                MeshMode::Mesh => tile_mesh(&m, pitch),
                MeshMode::Box => {
                    let (pose, size) = m.fitted_box();
                    tile_box(&size, &Face::ALL, pitch)
                        .into_iter()
                        .map(|c| TiledCell {
                            position: (pose * Point3::from(c.position)).coords,
                            normal: pose.rotation * c.normal,
                        })
                        .collect()
                }
            }
        }
    })
}

/// A cell this deep (in pitches) inside another primitive of its link is left out: a cell on
/// the seam of two primitives stays.
const BURIED_MARGIN: f64 = 0.05;

/// Tiles the selected links of `model` (see [`super::tiling`] for the rules). Patch ids and
/// cell ids count from 1 in output order; deterministic for a given model and spec.
pub fn generate_layout(model: &RobotModel, spec: &GeneratorSpec) -> Result<SkinLayout, GenerateError> {
    if !(spec.pitch_m.is_finite() && spec.pitch_m > 0.0) {
        return Err(GenerateError::BadPitch(spec.pitch_m));
    }
    let urdf = model.source().to_string();
    // Merge repeated links, keeping the first-mention order.
    let mut order: Vec<(String, Vec<usize>)> = Vec::new();
    for sel in &spec.links {
        let frame = model
            .frame_index(&sel.link)
            .ok_or_else(|| GenerateError::UnknownLink { urdf: urdf.clone(), link: sel.link.clone() })?;
        let count = model.link_collisions(frame).len();
        let idx: Vec<usize> = match &sel.collisions {
            None => (0..count).collect(),
            Some(v) => v.clone(),
        };
        if let Some(&index) = idx.iter().find(|&&i| i >= count) {
            return Err(GenerateError::BadCollisionIndex { urdf, link: sel.link.clone(), index, count });
        }
        match order.iter_mut().find(|(l, _)| *l == sel.link) {
            Some((_, v)) => {
                for i in idx {
                    if !v.contains(&i) {
                        v.push(i);
                    }
                }
            }
            None => order.push((sel.link.clone(), idx)),
        }
    }
    let mut layout = SkinLayout { source: urdf.clone(), robot: Some(model.name().to_string()), ..Default::default() };
    let mut next_cell = 1u32;
    for (link, idx) in &order {
        let frame = model.frame_index(link).expect("checked above");
        let collisions = model.link_collisions(frame);
        let faces: &[Face] =
            spec.faces.iter().find(|(l, _)| l == link).map(|(_, f)| f.as_slice()).unwrap_or(&Face::ALL);
        let link_from_patch = match (spec.patch_frame, idx.first()) {
            (PatchFrame::Primitive, Some(&i)) => collisions[i].origin,
            _ => Isometry3::identity(),
        };
        let patch_id = layout.patches.len() as u32 + 1;
        let first_cell = layout.cells.len();
        // Cells in the link frame: the tiling of each selected primitive without the cells
        // buried in the link's other primitives (they would sense nothing), then a cell on
        // every point the tiling leaves blind at the seams of primitives (where a neighbour's
        // cells were buried), so that every point of the surface has one within a pitch.
        let mut cells: Vec<TiledCell> = Vec::new();
        for &i in idx {
            let c = &collisions[i];
            let tiled = tile_shape(&c.shape, faces, spec, Path::new(&urdf)).map_err(|error| GenerateError::Mesh {
                urdf: urdf.clone(),
                link: link.clone(),
                error,
            })?;
            cells.extend(tiled.into_iter().filter_map(|cell| {
                let p = c.origin * Point3::from(cell.position);
                let hidden = buried_in_others(collisions, i, &p, BURIED_MARGIN * spec.pitch_m);
                (!hidden).then(|| TiledCell { position: p.coords, normal: c.origin.rotation * cell.normal })
            }));
        }
        if !cells.is_empty() {
            // the surfaces the tiling covers (selected faces, caps, spheres), sampled finer
            let fine = GeneratorSpec { pitch_m: spec.pitch_m / 3.0, ..spec.clone() };
            let sample = |shape: &Shape| match shape {
                Shape::Mesh { .. } => Vec::new(),
                _ => tile_shape(shape, faces, &fine, Path::new(&urdf)).unwrap_or_default(),
            };
            for s in surface(collisions, idx, spec.pitch_m, sample) {
                if blind_points(std::slice::from_ref(&s), &cells, spec.pitch_m).next().is_some() {
                    cells.push(s);
                }
            }
        }
        let patch_from_link = link_from_patch.inverse();
        for cell in cells {
            let p = patch_from_link * Point3::from(cell.position);
            let n = patch_from_link.rotation * cell.normal;
            layout.cells.push(CellSpec {
                id: next_cell,
                patch: patch_id,
                position: [p.x, p.y, p.z],
                normal: [n.x, n.y, n.z],
                line: None,
            });
            next_cell += 1;
        }
        if layout.cells.len() == first_cell {
            if spec.skip_empty {
                continue;
            }
            return Err(GenerateError::NoCells { urdf, link: link.clone() });
        }
        let (roll, pitch, yaw) = link_from_patch.rotation.euler_angles();
        let t = link_from_patch.translation.vector;
        layout.patches.push(PatchSpec {
            id: patch_id,
            link: link.clone(),
            xyz: [t.x, t.y, t.z],
            rpy: [roll, pitch, yaw],
            line: None,
        });
    }
    Ok(layout)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_link_selection() {
        assert_eq!("a".parse::<LinkSelection>().unwrap(), LinkSelection { link: "a".into(), collisions: None });
        assert_eq!(
            "arm:0+2".parse::<LinkSelection>().unwrap(),
            LinkSelection { link: "arm".into(), collisions: Some(vec![0, 2]) }
        );
        assert!(":1".parse::<LinkSelection>().is_err());
        assert!("a:x".parse::<LinkSelection>().is_err());
    }
}
