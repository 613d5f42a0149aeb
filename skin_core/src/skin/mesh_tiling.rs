//! Skin cells on a triangle mesh (the `skin_layout` generator's mesh rule; primitives are in
//! [`super::tiling`]). A mesh has no rows to lay a hexagonal grid along, so the cells are a
//! maximal Poisson-disk set of its surface:
//! - candidates: the centroids of each triangle's subdivision into `n²` similar triangles, `n`
//!   the smallest with edges at most `pitch / 3` (so every surface point is within `pitch / 3` of
//!   a candidate), in file order;
//! - a candidate becomes a cell unless a cell already lies closer than `pitch`: cells are at
//!   least one pitch apart, as in the hexagonal tiling, and every candidate (hence every surface
//!   point, within `pitch / 3` more) has a cell within one pitch;
//! - the normal is the triangle's, turned outward: when a point just outside along it is inside
//!   the closed mesh and a point just inside is not, it is flipped (meshes with inverted winding).
//!
//! About 0.6-0.7 times the cells of a hexagonal packing of the same area: random close packing.

use std::collections::HashMap;

use nalgebra::{Point3, Vector3};

use super::tiling::TiledCell;
use crate::mesh::TriMesh;

/// Tiles `mesh` with cells `pitch` apart (see the module rules), positions and outward normals
/// in the mesh frame. Deterministic for a given mesh.
pub fn tile_mesh(mesh: &TriMesh, pitch: f64) -> Vec<TiledCell> {
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let key =
        |p: &Vector3<f64>| [(p.x / pitch).floor() as i64, (p.y / pitch).floor() as i64, (p.z / pitch).floor() as i64];
    let mut cells: Vec<TiledCell> = Vec::new();
    let spacing = pitch / 3.0;
    for t in &mesh.triangles {
        let n2 = mesh.triangle_normal(t);
        let Some(normal) = n2.try_normalize(1e-300) else { continue };
        let [a, b, c] = t.map(|i| mesh.vertices[i]);
        let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
        let n = ((longest / spacing).ceil() as usize).max(1);
        let (u, v) = ((b - a) / n as f64, (c - a) / n as f64);
        for i in 0..n {
            for j in 0..n - i {
                // The upright sub-triangle's centroid, then the inverted one's (when inside).
                let mut points = vec![a + u * (i as f64 + 1.0 / 3.0) + v * (j as f64 + 1.0 / 3.0)];
                if i + j + 1 < n {
                    points.push(a + u * (i as f64 + 2.0 / 3.0) + v * (j as f64 + 2.0 / 3.0));
                }
                for p in points {
                    let k = key(&p);
                    let near = (-1..=1).any(|dx| {
                        (-1..=1).any(|dy| {
                            (-1..=1).any(|dz| {
                                grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]).is_some_and(|ids| {
                                    ids.iter().any(|&id| (cells[id].position - p).norm() < pitch * (1.0 - 1e-9))
                                })
                            })
                        })
                    });
                    if !near {
                        grid.entry(k).or_default().push(cells.len());
                        cells.push(TiledCell { position: p, normal });
                    }
                }
            }
        }
    }
    let eps = pitch * 1e-3;
    for c in &mut cells {
        let out = Point3::from(c.position + c.normal * eps);
        let inn = Point3::from(c.position - c.normal * eps);
        if mesh.contains(&out) && !mesh.contains(&inn) {
            c.normal = -c.normal;
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::box_mesh;

    #[test]
    fn spacing_coverage_and_outward_normals() {
        let size = Vector3::new(0.3, 0.12, 0.08);
        let pitch = 0.03;
        for inverted in [false, true] {
            let mesh = box_mesh(size, inverted);
            let cells = tile_mesh(&mesh, pitch);
            for (i, a) in cells.iter().enumerate() {
                // On the surface, normal unit and outward (the face's axis, pointing away from the centre).
                let (k, _) = a.normal.iamax_full();
                assert!((a.normal.norm() - 1.0).abs() < 1e-12);
                assert!((a.position[k] * a.normal[k] - size[k] / 2.0).abs() < 1e-12, "{a:?}");
                for b in &cells[i + 1..] {
                    assert!((a.position - b.position).norm() >= pitch * (1.0 - 1e-9));
                }
            }
            // Coverage: a fine sample of the surface has a cell within pitch + pitch / 3.
            for p in tile_mesh(&mesh, pitch / 4.0) {
                let d = cells.iter().map(|c| (c.position - p.position).norm()).fold(f64::MAX, f64::min);
                assert!(d <= pitch * 4.0 / 3.0, "gap {d} at {:?}", p.position);
            }
            // Density: between a third and one times the hexagonal packing of the area.
            let hex = mesh.area() / (3f64.sqrt() / 2.0 * pitch * pitch);
            assert!(cells.len() as f64 > hex / 3.0 && (cells.len() as f64) < hex, "{} vs {hex}", cells.len());
        }
    }
}
