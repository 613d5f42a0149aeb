//! Joint-space mass matrix by the Composite-Rigid-Body Algorithm (Featherstone, RBDA Table 6.2).

use nalgebra::DMatrix;

use super::data::ModelData;
use super::error::ModelError;
use super::robot::RobotModel;

/// Writes the joint-space inertia matrix `M(q)` (full, symmetric) of the configuration of the
/// last [`super::update_kinematics`] into `m_out` (must be nv × nv).
///
/// CRBA (RBDA Table 6.2) in world-aligned coordinates about one reference point: composite
/// inertias are plain sums (no transforms between bodies), and `M_ij = S_jᵀ I^c_i S_i` is only
/// evaluated for `j` on the supporting chain of `i` (all other entries are zero), so the cost is
/// O(nv · depth). A mimic joint that follows its leader adds its entries to the leader's
/// coordinate. Does not allocate.
pub fn crba(model: &RobotModel, data: &mut ModelData, m_out: &mut DMatrix<f64>) -> Result<(), ModelError> {
    let n = model.nv();
    if m_out.nrows() != n || m_out.ncols() != n {
        return Err(ModelError::Dimension {
            what: "mass matrix rows/columns",
            expected: n,
            got: m_out.nrows().max(m_out.ncols()),
        });
    }
    data.composite.copy_from_slice(&data.inertia_w);
    // children have larger indices than their parents (depth-first numbering)
    for i in (0..model.njoints()).rev() {
        if let Some(p) = model.bodies[i].parent {
            let ci = data.composite[i];
            data.composite[p].add(&ci);
        }
    }
    // column-major n x n storage: entry (r, c) at r + c n
    let m = m_out.as_mut_slice();
    m.fill(0.0);
    // joint-level entries summed into coordinates (M = Gᵀ M_joints G, G the 0/1 map of joints to
    // their coordinates, S already scaled by the mimic multiplier); plain stores without mimics
    for (i, bi) in model.bodies.iter().enumerate() {
        let f = data.composite[i].mul_motion(&data.s[i]);
        let ci = bi.coord;
        m[ci + ci * n] += data.s[i].dot(&f);
        let mut k = bi.parent;
        while let Some(j) = k {
            let cj = model.bodies[j].coord;
            let mij = data.s[j].dot(&f);
            m[ci + cj * n] += mij;
            m[cj + ci * n] += mij;
            k = model.bodies[j].parent;
        }
    }
    Ok(())
}
