//! Blind spots of a skin: the points of a skinned link's collision surface that no cell senses.
//! A point is covered when a cell lies within `reach` of it and faces it (the cell's normal
//! within 60° of the surface's); a point buried in another primitive of the same link is not
//! surface. The shipped layouts are checked with `reach` = one cell pitch; `skin_layout` fills
//! what its tiling leaves blind at the seams of primitives ([`blind_points`]) and prints the
//! figure for a new layout.

use nalgebra::{Point3, Vector3};

use super::resolved::ResolvedLayout;
use super::surface::{buried_in_others, samples};
use super::tiling::TiledCell;
use crate::model::{Collision, RobotModel, Shape};

/// A cell faces a surface point when their normals are at most 60° apart.
const FACING_COS: f64 = 0.5;

/// How much of one link's surface the skin covers.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkCoverage {
    /// Link name.
    pub link: String,
    /// Surface points sampled (meshes are not sampled).
    pub samples: usize,
    /// Of them, the points no cell covers.
    pub blind: usize,
    /// The first blind point, link frame \[m\].
    pub first_blind: Option<Vector3<f64>>,
}

impl LinkCoverage {
    /// Covered fraction of the sampled surface (None: nothing sampled, a link of meshes).
    pub fn covered(&self) -> Option<f64> {
        (self.samples > 0).then(|| 1.0 - self.blind as f64 / self.samples as f64)
    }
}

/// Whether a cell (position and normal) covers the surface point `p` with normal `n`.
fn covers(cell: &TiledCell, p: &Vector3<f64>, n: &Vector3<f64>, reach: f64) -> bool {
    (cell.position - p).norm() <= reach && cell.normal.dot(n) >= FACING_COS
}

/// The surface of the link's primitives `selected` (indices into `collisions`) as `sample`
/// gives it in a primitive's frame, in the link frame, without the points buried in the link's
/// other primitives.
pub fn surface(
    collisions: &[Collision],
    selected: &[usize],
    reach: f64,
    sample: impl Fn(&Shape) -> Vec<TiledCell>,
) -> Vec<TiledCell> {
    let mut out = Vec::new();
    for &i in selected {
        let c = &collisions[i];
        for s in sample(&c.shape) {
            let p = c.origin * Point3::from(s.position);
            if !buried_in_others(collisions, i, &p, 1e-3 * reach) {
                out.push(TiledCell { position: p.coords, normal: c.origin.rotation * s.normal });
            }
        }
    }
    out
}

/// The points of `surface` that none of `cells` (link frame) covers.
pub fn blind_points<'a>(
    surface: &'a [TiledCell],
    cells: &'a [TiledCell],
    reach: f64,
) -> impl Iterator<Item = &'a TiledCell> {
    surface.iter().filter(move |s| !cells.iter().any(|c| covers(c, &s.position, &s.normal, reach)))
}

/// The coverage of every link that carries a patch of `layout` (all its primitives).
pub fn coverage(model: &RobotModel, layout: &ResolvedLayout, reach: f64) -> Vec<LinkCoverage> {
    let mut frames: Vec<usize> = Vec::new();
    for p in layout.patches() {
        if !frames.contains(&p.frame) {
            frames.push(p.frame);
        }
    }
    frames
        .into_iter()
        .map(|frame| {
            let cells: Vec<TiledCell> = layout
                .cells()
                .iter()
                .filter(|c| c.frame == frame)
                .map(|c| TiledCell { position: c.position_link, normal: c.normal_link })
                .collect();
            let collisions = model.link_collisions(frame);
            let all: Vec<usize> = (0..collisions.len()).collect();
            let surface = surface(collisions, &all, reach, |shape| samples(shape, reach / 3.0));
            let blind: Vec<_> = blind_points(&surface, &cells, reach).collect();
            LinkCoverage {
                link: model.frame_names()[frame].clone(),
                samples: surface.len(),
                blind: blind.len(),
                first_blind: blind.first().map(|b| b.position),
            }
        })
        .collect()
}
