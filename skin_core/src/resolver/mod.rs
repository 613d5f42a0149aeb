//! The admittance torque resolver of interactive-force-control paper eq. (26): torques in, joint and base velocity commands out.
//!
//! The fused torque `τ*` of the hierarchy (interactive-force-control paper eq. (19)) drives virtual dynamics
//! (`M_a q̈_a + C_a q̇_a + g = τ_a*` for the arm joints, `M_b ẍ_b + D_b ẋ_b = τ_b*` for the
//! holonomic base) whose velocities, after the last-stage limits, are the commands of the
//! velocity-controlled arms and base (TOMM: arms at 125 Hz, base at 1 kHz, each updated at its
//! own rate). See `docs/resolver.md` for the equations, the inner velocity loop, the limits
//! and their order, and the safe stop.
//!
//! Setup: [`ResolverParams::load`] (`config/resolver.yaml`) and [`Resolver::new`] with the
//! [`crate::model::RobotModel`]; then [`Resolver::reset`] from the measured state and, per cycle,
//! [`Resolver::update_arms`] / [`Resolver::update_base`] (no allocation after `new`).

mod admittance;
mod closing;
mod error;
mod limits;
mod params;

#[cfg(test)]
mod tests;

/// The base joint names live with the model; re-exported where the resolver splits arm and base.
pub use admittance::{Commands, Resolver};
pub use closing::ClosingBounds;
pub use error::ResolverError;
pub use params::{ApproachParams, ArmParams, BaseParams, JointOverride, ResolverParams};
