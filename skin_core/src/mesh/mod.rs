//! Triangle meshes of URDF collision geometry: STL (`stl_io`), OBJ (`tobj`) and COLLADA (a small
//! reader of the triangles, [`collada`]), found through `package://` URIs ([`package`]).
//! What the skin generator tiles and the simulator collides with (as the convex hull, or as the
//! box [`TriMesh::fitted_box`] when a scene asks for primitives).

pub mod collada;
mod error;
mod file;
pub mod package;
mod tri_mesh;

use std::path::Path;

use nalgebra::Vector3;

pub use error::MeshError;
pub use package::PackagePath;
#[cfg(test)]
pub(crate) use tri_mesh::box_mesh;
pub use tri_mesh::TriMesh;

/// How a URDF mesh collision element is used: the mesh itself, or its fitted box (the
/// primitive approximation). Chosen per layout (`skin_layout --meshes`) and per scene
/// (`robot.meshes`); a scene's skin should be generated with the scene's choice.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MeshMode {
    /// The mesh: cells on its surface; the simulator collides with its convex hull.
    #[default]
    Mesh,
    /// The box of [`TriMesh::fitted_box`]: cells on its six faces; the simulator collides with it.
    Box,
}

impl std::str::FromStr for MeshMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mesh" => Ok(MeshMode::Mesh),
            "box" => Ok(MeshMode::Box),
            other => Err(format!("unknown mesh mode `{other}` (use mesh or box)")),
        }
    }
}

/// Loads the mesh `uri` (as written in a `<mesh filename>` of the URDF file `urdf`) scaled by
/// `scale`, resolving `package://` URIs over `path`.
pub fn load_uri(uri: &str, scale: &Vector3<f64>, urdf: &Path, path: &PackagePath) -> Result<TriMesh, MeshError> {
    file::read(&path.resolve(uri, urdf)?, scale)
}
