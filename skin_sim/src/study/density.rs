//! Reduced skin layouts for the density axis: the same patches with fewer cells.

use std::collections::BTreeMap;

use skin_core::skin::layout::{CellSpec, SkinLayout};

use super::grid::Density;

/// Normals closer than this (component-wise) belong to the same face of a patch.
const SAME_NORMAL: f64 = 1e-3;

/// `layout` at `density`. Every patch keeps at least one cell, so the tasks that name patches
/// (hand, guidance) still find them.
///
/// - [`Density::Quarter`]: cells 0, 4, 8, ... of each patch in file order (the generator tiles
///   ring by ring, so the kept cells spread over the patch);
/// - [`Density::PerPatch`]: one virtual cell per patch, at the centroid of the patch's largest face
///   (its cells sharing one normal; the first such face on a tie) and facing along that normal:
///   the palm keeps a cell facing out of the palm, a forearm cylinder one line of its rings.
pub fn reduce(layout: &SkinLayout, density: Density) -> SkinLayout {
    let mut by_patch: BTreeMap<u32, Vec<&CellSpec>> = BTreeMap::new();
    for c in &layout.cells {
        by_patch.entry(c.patch).or_default().push(c);
    }
    let cells = by_patch
        .values()
        .flat_map(|cells| match density {
            Density::Full => cells.iter().map(|&c| c.clone()).collect(),
            Density::Quarter => cells.iter().step_by(4).map(|&c| c.clone()).collect(),
            Density::PerPatch => vec![virtual_cell(cells)],
        })
        .collect();
    SkinLayout { cells, ..layout.clone() }
}

/// The virtual cell of one patch (`cells` not empty).
fn virtual_cell(cells: &[&CellSpec]) -> CellSpec {
    let same = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < SAME_NORMAL);
    let mut faces: Vec<Vec<&CellSpec>> = Vec::new();
    for &c in cells {
        match faces.iter_mut().find(|f| same(&f[0].normal, &c.normal)) {
            Some(f) => f.push(c),
            None => faces.push(vec![c]),
        }
    }
    // max_by_key keeps the last maximum; reversing keeps the first face on a tie.
    let face = faces.iter().rev().max_by_key(|f| f.len()).expect("a patch has cells");
    let n = face.len() as f64;
    let mean = |k: usize| face.iter().map(|c| c.position[k]).sum::<f64>() / n;
    CellSpec { position: [mean(0), mean(1), mean(2)], ..face[0].clone() }
}
