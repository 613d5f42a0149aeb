//! Robot skin: layouts, cell signal characteristics, aggregation into forces and torques.
//!
//! Data flow per control cycle (no allocation after setup):
//! 1. [`signals::CellReading`] per cell (indexed like [`layout::ResolvedLayout::cells`]);
//! 2. [`aggregate::aggregate_patches`]: interactive-force-control paper eq. (6)-(8), patch wrenches in patch frames
//!    (or [`aggregate::aggregate_live_patches`] from the non-silent cells, [`live::LiveCells`],
//!    collected once per cycle for the aggregation and the skin tasks);
//! 3. [`transforms`]: interactive-force-control paper eq. (11) (forces into a hand frame) and eq. (13) (world wrench);
//! 4. [`cell_forces`]: intentional-contact paper eq. (3) repulsion and contact forces per cell, in world frame;
//! 5. [`torques`]: `J^T F` over cells (intentional-contact paper eq. (4), (6)) and patches (interactive-force-control paper eq. (14)).
//!
//! Setup: [`layout::SkinLayout::load`] + `resolve` against the robot model,
//! [`params::SkinParams::load`] for the characteristics ([`characteristic`]) and gains.
//! [`tiling`] holds the geometry of the `skin_layout` generator; [`markers`] what a viewer
//! shows of the skin (`/skin/markers`).

pub mod aggregate;
pub mod cell_forces;
pub mod cell_input;
pub mod characteristic;
pub mod contacts;
pub mod coverage;
pub mod generate;
pub mod layout;
pub mod live;
pub mod markers;
pub mod measured;
pub mod mesh_tiling;
pub mod params;
pub mod repulsion;
pub mod resolved;
pub mod signals;
pub mod surface;
pub mod tiling;
pub mod torques;
pub mod transforms;
