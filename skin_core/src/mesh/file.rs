//! Mesh files: STL (`stl_io`), OBJ (`tobj`) and COLLADA ([`super::collada`]).

use std::path::Path;

use nalgebra::Vector3;

use super::collada;
use super::error::MeshError;
use super::tri_mesh::TriMesh;

/// Reads `path` (`.stl`, `.obj` or `.dae`, case-insensitive) and multiplies by `scale`.
pub fn read(path: &Path, scale: &Vector3<f64>) -> Result<TriMesh, MeshError> {
    let file = path.display().to_string();
    let read = |reason: String| MeshError::Read { file: file.clone(), reason };
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let mut mesh = match ext.as_str() {
        "stl" => {
            let mut f = std::fs::File::open(path).map_err(|e| read(e.to_string()))?;
            let m = stl_io::read_stl(&mut f).map_err(|e| read(e.to_string()))?;
            TriMesh {
                vertices: m.vertices.iter().map(|v| Vector3::new(v[0] as f64, v[1] as f64, v[2] as f64)).collect(),
                triangles: m.faces.iter().map(|f| f.vertices).collect(),
            }
        }
        "obj" => {
            let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
            let (models, _) = tobj::load_obj(path, &opts).map_err(|e| read(e.to_string()))?;
            let mut out = TriMesh::default();
            for m in models {
                let base = out.vertices.len();
                out.vertices.extend(
                    m.mesh.positions.chunks_exact(3).map(|p| Vector3::new(p[0] as f64, p[1] as f64, p[2] as f64)),
                );
                out.triangles.extend(
                    m.mesh
                        .indices
                        .chunks_exact(3)
                        .map(|t| [base + t[0] as usize, base + t[1] as usize, base + t[2] as usize]),
                );
            }
            out
        }
        "dae" => {
            let text = std::fs::read_to_string(path).map_err(|e| read(e.to_string()))?;
            collada::read(&text).map_err(read)?
        }
        other => return Err(read(format!("unsupported mesh format `.{other}` (STL, OBJ and DAE are read)"))),
    };
    if mesh.triangles.is_empty() {
        return Err(read("no triangles".into()));
    }
    if let Some(bad) = mesh.triangles.iter().flatten().find(|&&i| i >= mesh.vertices.len()) {
        return Err(read(format!("triangle vertex index {bad} beyond {} vertices", mesh.vertices.len())));
    }
    for v in &mut mesh.vertices {
        v.component_mul_assign(scale);
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_format_names_the_file() {
        let e = read(Path::new("/nonexistent/x.ply"), &Vector3::repeat(1.0)).unwrap_err().to_string();
        assert!(e.contains("x.ply") && e.contains("unsupported"), "{e}");
    }
}
