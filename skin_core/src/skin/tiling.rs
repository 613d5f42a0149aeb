//! Hexagonal tiling of collision primitives with skin cells (geometry of the `skin_layout`
//! generator). Everything here is in the primitive's own frame (URDF conventions: cylinders and
//! capsules along local z and centred at the origin, boxes centred with full edge lengths).
//!
//! Rules, with `pitch` the centre distance of neighbouring cells (~ cell size):
//! - a cell's centre keeps half a pitch from every edge; an extent shorter than one pitch holds
//!   one row/column at its middle if it is at least 0.75 pitch long, else none;
//! - hexagonal packing: rows `pitch·√3/2` apart, odd rows shifted by half a pitch;
//! - cylinders: the lateral surface in rows along the axis, `n = floor(2πr/pitch)` cells per
//!   ring; even rings start facing +y, odd rings are turned by half a step (so for odd `n` they
//!   contain the cell facing -y, for even `n` both kinds of ring face ±y): a link moving in a
//!   plane that contains the primitive's y axis has cells facing within that plane on both
//!   sides; with caps ([`tile_caps`]), each end disk in concentric rings one pitch apart from
//!   half a pitch inside the rim (a centre cell where the innermost ring leaves more than 0.9
//!   pitch); capsules: their cylindrical part, with caps their two hemispheres;
//! - boxes: the selected faces, each a hexagonal grid;
//! - spheres: a Fibonacci lattice with as many cells as hexagons of the given pitch cover the
//!   surface.
//!
//! Normals are unit and point outward.

use std::f64::consts::PI;
use std::str::FromStr;

use nalgebra::Vector3;

/// A cell placed by the tiler: position \[m\] and outward unit normal, primitive frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiledCell {
    /// Cell centre on the surface \[m\].
    pub position: Vector3<f64>,
    /// Outward unit normal.
    pub normal: Vector3<f64>,
}

/// A face of a box, named by its outward normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Face {
    /// +x face.
    PosX,
    /// -x face.
    NegX,
    /// +y face.
    PosY,
    /// -y face.
    NegY,
    /// +z face.
    PosZ,
    /// -z face.
    NegZ,
}

impl Face {
    /// All six faces in the order +x, -x, +y, -y, +z, -z.
    pub const ALL: [Face; 6] = [Face::PosX, Face::NegX, Face::PosY, Face::NegY, Face::PosZ, Face::NegZ];

    /// Outward unit normal, its axis index and sign.
    fn axis(self) -> (usize, f64) {
        match self {
            Face::PosX => (0, 1.0),
            Face::NegX => (0, -1.0),
            Face::PosY => (1, 1.0),
            Face::NegY => (1, -1.0),
            Face::PosZ => (2, 1.0),
            Face::NegZ => (2, -1.0),
        }
    }
}

impl FromStr for Face {
    type Err = String;
    /// Parses `+x`, `-x`, `+y`, `-y`, `+z`, `-z` (also `x` for `+x`).
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s.trim() {
            "+x" | "x" => Face::PosX,
            "-x" => Face::NegX,
            "+y" | "y" => Face::PosY,
            "-y" => Face::NegY,
            "+z" | "z" => Face::PosZ,
            "-z" => Face::NegZ,
            other => return Err(format!("unknown box face `{other}` (use +x, -x, +y, -y, +z, -z)")),
        })
    }
}

/// Centres along an extent of length `extent`, `spacing` apart, symmetric about 0, keeping half a
/// pitch from both ends (see the module rules).
pub fn centres_along(extent: f64, spacing: f64, pitch: f64) -> Vec<f64> {
    let usable = extent - pitch;
    if usable < 0.0 {
        return if extent >= 0.75 * pitch { vec![0.0] } else { Vec::new() };
    }
    let n = (usable / spacing + 1e-9).floor() as usize + 1;
    let start = -((n - 1) as f64) * spacing / 2.0;
    (0..n).map(|k| start + k as f64 * spacing).collect()
}

/// Hexagonal grid of centres on a `width` × `height` rectangle centred at the origin
/// (x along width, y along height). Row by row from -y, each row from -x.
pub fn hex_grid_rect(width: f64, height: f64, pitch: f64) -> Vec<(f64, f64)> {
    let row_spacing = pitch * 3f64.sqrt() / 2.0;
    let rows = centres_along(height, row_spacing, pitch);
    let even = centres_along(width, pitch, pitch);
    let half_usable = ((width - pitch) / 2.0).max(0.0) + 1e-9;
    let mut odd = Vec::new();
    if let Some(&x0) = even.first() {
        for k in 0..=even.len() {
            let x = x0 - pitch / 2.0 + k as f64 * pitch;
            if x.abs() <= half_usable {
                odd.push(x);
            }
        }
    }
    let mut out = Vec::new();
    for (r, &y) in rows.iter().enumerate() {
        let cols = if r % 2 == 0 { &even } else { &odd };
        out.extend(cols.iter().map(|&x| (x, y)));
    }
    out
}

/// Cells per ring of a cylinder of radius `radius` (see the module rules).
pub fn cells_per_ring(radius: f64, pitch: f64) -> usize {
    (2.0 * PI * radius / pitch + 1e-9).floor() as usize
}

/// Tiles the lateral surface of a cylinder along z (centred, `length` long).
pub fn tile_cylinder(radius: f64, length: f64, pitch: f64) -> Vec<TiledCell> {
    let row_spacing = pitch * 3f64.sqrt() / 2.0;
    let rows = centres_along(length, row_spacing, pitch);
    let n = cells_per_ring(radius, pitch);
    let mut out = Vec::with_capacity(rows.len() * n);
    if n == 0 {
        return out;
    }
    let step = 2.0 * PI / n as f64;
    for (r, &z) in rows.iter().enumerate() {
        let offset = PI / 2.0 + if r % 2 == 0 { 0.0 } else { step / 2.0 };
        for k in 0..n {
            let a = offset + k as f64 * step;
            let normal = Vector3::new(a.cos(), a.sin(), 0.0);
            out.push(TiledCell { position: Vector3::new(radius * normal.x, radius * normal.y, z), normal });
        }
    }
    out
}

/// Centres on a disk of `radius` (its centre at the origin): rings one pitch apart from half a
/// pitch inside the rim, `floor(2πρ/pitch)` cells on a ring of radius `ρ` (at least one), and a
/// centre cell where the innermost ring leaves more than 0.9 pitch (see the module rules).
pub fn disk_centres(radius: f64, pitch: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut rho = radius - pitch / 2.0;
    while rho >= pitch / 2.0 {
        let n = cells_per_ring(rho, pitch).max(1);
        out.extend((0..n).map(|k| {
            let a = PI / 2.0 + 2.0 * PI * k as f64 / n as f64;
            (rho * a.cos(), rho * a.sin())
        }));
        rho -= pitch;
    }
    let innermost = rho + pitch;
    if (out.is_empty() && radius >= 0.375 * pitch) || (!out.is_empty() && innermost > 0.9 * pitch) {
        out.push((0.0, 0.0));
    }
    out
}

/// The end caps of a cylinder (`length` long along z, centred): a disk at each end, or a
/// capsule's hemispheres (its `length` between the centres of the caps).
pub fn tile_caps(radius: f64, length: f64, pitch: f64, capsule: bool) -> Vec<TiledCell> {
    let mut out = Vec::new();
    for sign in [1.0, -1.0] {
        let end = Vector3::z() * (sign * length / 2.0);
        if capsule {
            let half = tile_sphere(radius, pitch).into_iter().filter(|c| c.normal.z * sign > 0.0);
            out.extend(half.map(|c| TiledCell { position: c.position + end, normal: c.normal }));
        } else {
            let normal = Vector3::z() * sign;
            let disk = disk_centres(radius, pitch).into_iter();
            out.extend(disk.map(|(x, y)| TiledCell { position: end + Vector3::new(x, y, 0.0), normal }));
        }
    }
    out
}

/// Tiles the given faces of a box with full edge lengths `size`, in the order of `faces`.
pub fn tile_box(size: &Vector3<f64>, faces: &[Face], pitch: f64) -> Vec<TiledCell> {
    let mut out = Vec::new();
    for &face in faces {
        let (axis, sign) = face.axis();
        // In-face axes (u, v): the two other axes in cyclic order.
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut normal = Vector3::zeros();
        normal[axis] = sign;
        for (a, b) in hex_grid_rect(size[u], size[v], pitch) {
            let mut p = Vector3::zeros();
            p[axis] = sign * size[axis] / 2.0;
            p[u] = a;
            p[v] = b;
            out.push(TiledCell { position: p, normal });
        }
    }
    out
}

/// Tiles a sphere with a Fibonacci lattice (see the module rules).
pub fn tile_sphere(radius: f64, pitch: f64) -> Vec<TiledCell> {
    let cell_area = 3f64.sqrt() / 2.0 * pitch * pitch;
    let n = (4.0 * PI * radius * radius / cell_area).floor() as usize;
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / n as f64;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            let normal = Vector3::new(rho * phi.cos(), rho * phi.sin(), z);
            TiledCell { position: normal * radius, normal }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn centres() {
        assert_eq!(centres_along(0.01, 0.025, 0.025), Vec::<f64>::new());
        assert_eq!(centres_along(0.02, 0.025, 0.025), vec![0.0]);
        let c = centres_along(0.1, 0.025, 0.025);
        assert_eq!(c.len(), 4);
        assert_relative_eq!(c[0], -0.0375, epsilon = 1e-12);
        assert_relative_eq!(c[3], 0.0375, epsilon = 1e-12);
    }

    #[test]
    fn rect_counts_and_spacing() {
        // 0.1 × 0.1 at 0.025: 4 rows (0.075 / 0.02165 -> 3 gaps); even rows 4, odd rows 3.
        let g = hex_grid_rect(0.1, 0.1, 0.025);
        assert_eq!(g.len(), 4 + 3 + 4 + 3);
        for (i, a) in g.iter().enumerate() {
            assert!(a.0.abs() <= 0.0375 + 1e-9 && a.1.abs() <= 0.0375 + 1e-9);
            for b in &g[i + 1..] {
                let d = ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt();
                assert!(d >= 0.025 - 1e-9, "cells overlap: {d}");
            }
        }
    }

    #[test]
    fn cylinder_counts_normals_and_radius() {
        // r = 0.05: circumference 0.314 -> 12 per ring at 0.025; length 0.2: (0.175 / 0.02165) -> 9 rows.
        let cells = tile_cylinder(0.05, 0.2, 0.025);
        assert_eq!(cells_per_ring(0.05, 0.025), 12);
        assert_eq!(cells.len(), 12 * 9);
        for c in &cells {
            assert_relative_eq!(c.normal.norm(), 1.0, epsilon = 1e-12);
            let radial = Vector3::new(c.position.x, c.position.y, 0.0);
            assert_relative_eq!(radial.norm(), 0.05, epsilon = 1e-12);
            assert_relative_eq!(radial / 0.05, c.normal, epsilon = 1e-12); // outward
            assert!(c.position.z.abs() <= 0.1 - 0.0125 + 1e-9);
        }
        // Symmetric pattern: normals sum to zero.
        let s: Vector3<f64> = cells.iter().map(|c| c.normal).sum();
        assert_relative_eq!(s, Vector3::zeros(), epsilon = 1e-9);
        // Odd ring count: even rings face +y, odd rings -y.
        let odd = tile_cylinder(0.045, 0.2, 0.025);
        assert_eq!(cells_per_ring(0.045, 0.025), 11);
        let facing = |s: f64| odd.iter().filter(|c| c.normal.y * s > 1.0 - 1e-12).count();
        assert_eq!((facing(1.0), facing(-1.0)), (5, 4));
    }

    #[test]
    fn caps_cover_the_end_disks_and_hemispheres() {
        let pitch = 0.03;
        // a disk narrower than 0.75 pitch holds no cell (as any extent, see the module rules)
        assert!(tile_caps(0.01, 0.25, pitch, false).is_empty());
        for radius in [0.012, 0.02, 0.045, 0.06, 0.2] {
            let caps = tile_caps(radius, 0.25, pitch, false);
            for c in &caps {
                assert!((c.position.z.abs() - 0.125).abs() < 1e-12 && c.normal.z.abs() == 1.0);
                assert!(c.position.xy().norm() <= radius - pitch / 2.0 + 1e-12 || c.position.xy().norm() == 0.0);
            }
            // every point of a disk is within one pitch of a cell of its cap
            let top: Vec<_> = caps.iter().filter(|c| c.normal.z > 0.0).collect();
            for i in 0..50 {
                for j in 0..50 {
                    let (x, y) = (radius * (i as f64 / 24.5 - 1.0), radius * (j as f64 / 24.5 - 1.0));
                    if x.hypot(y) <= radius {
                        let d = top.iter().map(|c| (c.position.x - x).hypot(c.position.y - y)).fold(f64::MAX, f64::min);
                        assert!(d <= pitch, "r {radius}: ({x}, {y}) is {d} from a cell");
                    }
                }
            }
        }
        let capsule = tile_caps(0.05, 0.2, pitch, true);
        assert!(capsule.iter().all(|c| (c.position - Vector3::z() * 0.1 * c.normal.z.signum()).norm() - 0.05 < 1e-12));
    }

    #[test]
    fn box_faces_outward() {
        let size = Vector3::new(0.1, 0.2, 0.03);
        let cells = tile_box(&size, &Face::ALL, 0.025);
        assert!(!cells.is_empty());
        for c in &cells {
            assert_relative_eq!(c.normal.norm(), 1.0);
            // On the face the normal points to, at the half size.
            let (k, _) = c.normal.iamax_full();
            assert_relative_eq!(c.position[k] * c.normal[k], size[k] / 2.0, epsilon = 1e-12);
        }
        let top = tile_box(&size, &[Face::PosZ], 0.025);
        assert_eq!(top.len(), hex_grid_rect(0.1, 0.2, 0.025).len());
        // The 0.03 thin sides hold one row each (0.03 >= 0.025).
        assert!(!tile_box(&size, &[Face::PosX], 0.025).is_empty());
        assert_eq!("-z".parse::<Face>().unwrap(), Face::NegZ);
        assert!("up".parse::<Face>().is_err());
    }

    #[test]
    fn sphere_lattice() {
        let cells = tile_sphere(0.1, 0.025);
        let expected = (4.0 * PI * 0.01 / (3f64.sqrt() / 2.0 * 0.025 * 0.025)).floor() as usize;
        assert_eq!(cells.len(), expected);
        for c in &cells {
            assert_relative_eq!(c.normal.norm(), 1.0, epsilon = 1e-12);
            assert_relative_eq!(c.position, c.normal * 0.1, epsilon = 1e-12);
        }
    }
}
