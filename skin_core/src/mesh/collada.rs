//! A small COLLADA (`.dae`) triangle reader: no maintained Rust crate reads COLLADA, and a URDF's
//! collision meshes need only the triangles. Read: the `<unit meter>` scale, every
//! `<triangles>`, `<polylist>` and `<polygons>` of `<library_geometries>` (polygons fanned into
//! triangles), placed by the `<matrix>`, `<translate>`, `<rotate>` and `<scale>` transforms of the
//! visual scene's nodes that instance them (every geometry once, untransformed, when no node
//! does). Ignored: materials, normals, texture coordinates, `<lines>`, and `<up_axis>` (RViz and
//! Gazebo do not rotate `Y_UP` files either: the files are written for that).

use std::collections::HashMap;

use nalgebra::{Matrix4, Point3, Unit, Vector3};
use roxmltree::{Document, Node};

use super::tri_mesh::TriMesh;

fn numbers<T: std::str::FromStr>(text: Option<&str>, what: &str) -> Result<Vec<T>, String> {
    text.unwrap_or("")
        .split_ascii_whitespace()
        .map(|t| t.parse::<T>().map_err(|_| format!("bad number `{t}` in <{what}>")))
        .collect()
}

fn child<'a, 'i>(n: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    n.children().find(|c| c.has_tag_name(name))
}

fn local_id(url: &str) -> &str {
    url.strip_prefix('#').unwrap_or(url)
}

/// The triangles of one `<mesh>` in its geometry's frame.
fn mesh_triangles(mesh: Node<'_, '_>, out: &mut Vec<[Point3<f64>; 3]>) -> Result<(), String> {
    let sources: HashMap<&str, Vec<f64>> = mesh
        .children()
        .filter(|c| c.has_tag_name("source"))
        .filter_map(|s| Some((s.attribute("id")?, child(s, "float_array")?)))
        .map(|(id, a)| Ok((id, numbers::<f64>(a.text(), "float_array")?)))
        .collect::<Result<_, String>>()?;
    let vertices: HashMap<&str, &str> = mesh
        .children()
        .filter(|c| c.has_tag_name("vertices"))
        .filter_map(|v| {
            let pos = v.children().find(|i| i.has_tag_name("input") && i.attribute("semantic") == Some("POSITION"))?;
            Some((v.attribute("id")?, local_id(pos.attribute("source")?)))
        })
        .collect();
    for prim in mesh
        .children()
        .filter(|c| c.has_tag_name("triangles") || c.has_tag_name("polylist") || c.has_tag_name("polygons"))
    {
        let kind = prim.tag_name().name();
        let inputs: Vec<Node> = prim.children().filter(|c| c.has_tag_name("input")).collect();
        let stride = inputs.iter().filter_map(|i| i.attribute("offset")?.parse::<usize>().ok()).max().unwrap_or(0) + 1;
        let Some(vin) = inputs.iter().find(|i| i.attribute("semantic") == Some("VERTEX")) else {
            return Err(format!("<{kind}> without a VERTEX input"));
        };
        let offset: usize = vin.attribute("offset").and_then(|o| o.parse().ok()).unwrap_or(0);
        let vid = local_id(vin.attribute("source").unwrap_or(""));
        let src = vertices.get(vid).copied().unwrap_or(vid);
        let pos = sources.get(src).ok_or_else(|| format!("<{kind}>: no positions `{src}`"))?;
        let point = |k: usize| -> Result<Point3<f64>, String> {
            pos.get(3 * k..3 * k + 3)
                .map(|p| Point3::new(p[0], p[1], p[2]))
                .ok_or_else(|| format!("<{kind}>: vertex index {k} beyond the {} positions", pos.len() / 3))
        };
        // Polygons as vertex lists, then fanned.
        let mut polygons: Vec<Vec<usize>> = Vec::new();
        let ps: Vec<Vec<usize>> = prim
            .children()
            .filter(|c| c.has_tag_name("p"))
            .map(|p| numbers::<usize>(p.text(), "p"))
            .collect::<Result<_, _>>()?;
        let idx = |p: &[usize]| -> Vec<usize> { p.chunks(stride).filter_map(|c| c.get(offset).copied()).collect() };
        match kind {
            "triangles" => {
                for p in &ps {
                    polygons.extend(idx(p).chunks_exact(3).map(<[usize]>::to_vec));
                }
            }
            "polylist" => {
                let counts = numbers::<usize>(child(prim, "vcount").and_then(|v| v.text()), "vcount")?;
                let all = idx(ps.first().map(Vec::as_slice).unwrap_or(&[]));
                let mut at = 0;
                for n in counts {
                    let poly = all.get(at..at + n).ok_or("<polylist>: <vcount> longer than <p>")?;
                    polygons.push(poly.to_vec());
                    at += n;
                }
            }
            _ => polygons.extend(ps.iter().map(|p| idx(p))),
        }
        for poly in polygons.iter().filter(|p| p.len() >= 3) {
            let a = point(poly[0])?;
            for w in poly[1..].windows(2) {
                out.push([a, point(w[0])?, point(w[1])?]);
            }
        }
    }
    Ok(())
}

/// The transform of a `<node>` relative to its parent.
fn node_transform(node: Node<'_, '_>) -> Result<Matrix4<f64>, String> {
    let mut m = Matrix4::identity();
    for t in node.children().filter(|c| c.is_element()) {
        let v = || numbers::<f64>(t.text(), t.tag_name().name());
        let step = match t.tag_name().name() {
            "matrix" => {
                let v = v()?;
                if v.len() != 16 {
                    return Err("<matrix> needs 16 numbers".into());
                }
                Matrix4::from_row_slice(&v)
            }
            "translate" => match v()?.as_slice() {
                [x, y, z] => Matrix4::new_translation(&Vector3::new(*x, *y, *z)),
                _ => return Err("<translate> needs 3 numbers".into()),
            },
            "scale" => match v()?.as_slice() {
                [x, y, z] => Matrix4::new_nonuniform_scaling(&Vector3::new(*x, *y, *z)),
                _ => return Err("<scale> needs 3 numbers".into()),
            },
            "rotate" => match v()?.as_slice() {
                [x, y, z, deg] => {
                    Matrix4::from_axis_angle(&Unit::new_normalize(Vector3::new(*x, *y, *z)), deg.to_radians())
                }
                _ => return Err("<rotate> needs 4 numbers".into()),
            },
            _ => continue,
        };
        m *= step;
    }
    Ok(m)
}

/// Walks the nodes below `node`, collecting (geometry id, transform) of every `<instance_geometry>`.
fn instances<'a>(
    node: Node<'a, '_>,
    parent: &Matrix4<f64>,
    out: &mut Vec<(&'a str, Matrix4<f64>)>,
) -> Result<(), String> {
    for n in node.children().filter(|c| c.has_tag_name("node")) {
        let m = parent * node_transform(n)?;
        for g in n.children().filter(|c| c.has_tag_name("instance_geometry")) {
            out.push((local_id(g.attribute("url").unwrap_or("")), m));
        }
        instances(n, &m, out)?;
    }
    Ok(())
}

/// Reads the triangles of a COLLADA document (see the module documentation), in metres.
pub fn read(text: &str) -> Result<TriMesh, String> {
    let doc = Document::parse(text).map_err(|e| e.to_string())?;
    let root = doc.root_element();
    let meter = root
        .descendants()
        .find(|n| n.has_tag_name("unit"))
        .and_then(|u| u.attribute("meter")?.parse::<f64>().ok())
        .unwrap_or(1.0);
    let geometries: HashMap<&str, Node> = root
        .descendants()
        .filter(|n| n.has_tag_name("geometry"))
        .filter_map(|g| Some((g.attribute("id")?, child(g, "mesh")?)))
        .collect();
    let scene_url =
        root.descendants().find(|n| n.has_tag_name("instance_visual_scene")).and_then(|s| s.attribute("url"));
    let scene = root
        .descendants()
        .filter(|n| n.has_tag_name("visual_scene"))
        .find(|s| scene_url.is_none_or(|u| s.attribute("id") == Some(local_id(u))));
    let mut placed = Vec::new();
    if let Some(scene) = scene {
        instances(scene, &Matrix4::identity(), &mut placed)?;
    }
    if placed.is_empty() {
        placed = geometries.keys().map(|&id| (id, Matrix4::identity())).collect();
        placed.sort_by(|a, b| a.0.cmp(b.0));
    }
    let mut mesh = TriMesh::default();
    for (id, m) in placed {
        let geometry =
            geometries.get(id).ok_or_else(|| format!("<instance_geometry url=\"#{id}\">: no such geometry"))?;
        let mut tris = Vec::new();
        mesh_triangles(*geometry, &mut tris).map_err(|e| format!("geometry `{id}`: {e}"))?;
        for t in tris {
            let base = mesh.vertices.len();
            mesh.vertices.extend(t.iter().map(|p| m.transform_point(p).coords * meter));
            mesh.triangles.push([base, base + 1, base + 2]);
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_polylist_with_units_and_node_transform() {
        let dae = r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="g-pos"><float_array id="g-arr" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array></source>
    <source id="g-n"><float_array id="g-narr" count="3">0 0 1</float_array></source>
    <vertices id="g-v"><input semantic="POSITION" source="#g-pos"/></vertices>
    <polylist count="1"><input semantic="VERTEX" source="#g-v" offset="0"/><input semantic="NORMAL" source="#g-n" offset="1"/>
      <vcount>4</vcount><p>0 0 1 0 2 0 3 0</p></polylist>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node><translate>0 0 100</translate>
    <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##;
        let m = read(dae).unwrap();
        assert_eq!(m.triangles.len(), 2);
        assert!(m.vertices.iter().all(|v| (v.z - 1.0).abs() < 1e-12));
        let xmax = m.vertices.iter().map(|v| v.x).fold(f64::MIN, f64::max);
        assert!((xmax - 0.01).abs() < 1e-12);
        assert!(read("<COLLADA><library_geometries><geometry id=\"g\"><mesh><triangles/></mesh></geometry></library_geometries></COLLADA>").is_err());
    }
}
