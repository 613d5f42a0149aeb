//! Per-cell Cartesian forces in the world frame: proximity repulsion (intentional-contact paper eq. (3)) and
//! measured contact forces (intentional-contact paper eq. (6)), ready for `J^T F` ([`super::torques`]).
//!
//! Both forces act ON the robot and point INWARD (along the cell's -normal): the obstacle or the
//! touching object is outside, along +normal, so the repulsion pushes the link away from it and
//! the contact force is the push the link receives.

use nalgebra::{Isometry3, Point3, Vector3};

use super::aggregate::{FusionParams, LengthMismatch};
use super::characteristic::{ForceCharacteristic, ProximityCharacteristic};
use super::layout::ResolvedLayout;
use super::repulsion::RepulsionParams;
use super::signals::CellReading;

/// A force applied at a point of a link; both vectors in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointForce {
    /// Frame index (link) the point is fixed to.
    pub frame: usize,
    /// Index of the source cell in the resolved layout (`usize::MAX` if not from a cell).
    pub cell: usize,
    /// Application point in world coordinates \[m\].
    pub point: Vector3<f64>,
    /// Force in world coordinates \[N\].
    pub force: Vector3<f64>,
}

/// Intentional-contact paper eq. (3) per cell: distance `d_i` from the proximity signal through the inverse
/// characteristic, magnitude `K (d_range - d_i)` for `d_i < d_range`, direction `-n_i` (world).
/// `frame_pose(frame)` gives the world pose of a link frame (kinematics already updated).
/// `out` is cleared and filled with one entry per repelled cell; reserve
/// `layout.num_cells()` once at setup so this never allocates.
pub fn cell_repulsion_forces<'a>(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    proximity: &ProximityCharacteristic,
    repulsion: &RepulsionParams,
    frame_pose: impl Fn(usize) -> &'a Isometry3<f64>,
    out: &mut Vec<PointForce>,
) -> Result<(), LengthMismatch> {
    let proximity = proximity.prepared();
    inward_cell_forces(layout, readings, frame_pose, out, |r| {
        let p = r.proximity_signal();
        if p <= 0.0 {
            return 0.0;
        }
        repulsion.linear_n(proximity.distance_m(p))
    })
}

/// Measured contact forces per cell (intentional-contact paper eq. (6)): cells whose force signal (reduced per
/// `fusion.force_reduction`) exceeds `fusion.activity_threshold` give `-n_i F_i` with `F_i` \[N\]
/// from the inverse force characteristic. Same `frame_pose` and `out` conventions as
/// [`cell_repulsion_forces`].
pub fn cell_contact_forces<'a>(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    force: &ForceCharacteristic,
    fusion: &FusionParams,
    frame_pose: impl Fn(usize) -> &'a Isometry3<f64>,
    out: &mut Vec<PointForce>,
) -> Result<(), LengthMismatch> {
    let force = force.prepared();
    inward_cell_forces(layout, readings, frame_pose, out, |r| fusion.cell_force_n(r, &force).unwrap_or(0.0))
}

/// The shared loop: every cell whose `magnitude(reading)` is positive gives a force of that
/// magnitude \[N\] along its inward normal `-n_i`, at its world position.
fn inward_cell_forces<'a>(
    layout: &ResolvedLayout,
    readings: &[CellReading],
    frame_pose: impl Fn(usize) -> &'a Isometry3<f64>,
    out: &mut Vec<PointForce>,
    magnitude: impl Fn(&CellReading) -> f64,
) -> Result<(), LengthMismatch> {
    LengthMismatch::check_readings(layout, readings)?;
    out.clear();
    for (i, (cell, r)) in layout.link_geometry.iter().zip(readings).enumerate() {
        let m = magnitude(r);
        if m <= 0.0 {
            continue;
        }
        let pose = frame_pose(cell.frame);
        out.push(PointForce {
            frame: cell.frame,
            cell: i,
            point: (pose * Point3::from(cell.position)).coords,
            force: pose.rotation * cell.normal * -m,
        });
    }
    Ok(())
}
