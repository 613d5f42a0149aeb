//! The tasks of both papers behind one interface, [`Task`]: each reads one [`Cycle`] and fills a
//! [`crate::hierarchy::TaskLevel`] (Jacobian rows and a reference) or a term of the posture
//! torque, once per control cycle, without allocating (buffers are sized at construction).
//! [`REGISTRY`] names them for `config/supervisor.yaml`. `docs/tasks.md` gives the equations as
//! implemented, the sign conventions, and how to add a task.
//!
//! | Task | Equation | Kind | Rows |
//! |---|---|---|---|
//! | [`goal::GoalPosition`] | intentional-contact paper eq. (7)-(9) | force | 3 (linear, world) |
//! | [`goal::GoalOrientation`] | intentional-contact paper eq. (7)-(9) on `axis·angle(R_d Rᵀ)` | force | 3 (angular, world) |
//! | [`avoidance::ProximityAvoidance`] | intentional-contact paper eq. (3)-(4) | force | 1 per cell within `d_range` |
//! | [`contact_reaction::ContactReaction`] | intentional-contact paper eq. (6) | force | 1 per contact cell |
//! | [`hand_force::HandForce`] | interactive-force-control paper eq. (9), Table 1 | acceleration | 1 (hand z) |
//! | [`wrist::CompliantWrist`] | interactive-force-control paper eq. (10) | acceleration | 3 (angular, world) |
//! | [`tactile_guidance::TactileGuidance`] | interactive-force-control paper eq. (11)-(12) | acceleration | 3 (linear, world) |
//! | [`position_hold::PositionHold`] | interactive-force-control paper eq. (4), Table 1 | acceleration | 3 (linear, world) |
//! | [`posture::Posture`] | interactive-force-control paper eq. (18) | null-space torque | — |
//! | [`compliance::BodyCompliance`] | interactive-force-control paper eq. (13)-(14) | torque (in `τ_s`) | — |
//! | [`base_avoidance::MobileBaseAvoidance`] | interactive-force-control paper eq. (15)-(17) | torque (in `τ_s`) | — |
//!
//! Parameters: [`params::TaskParams`] (`config/tasks.yaml`).

pub mod avoidance;
pub mod base_avoidance;
pub mod compliance;
pub mod contact_reaction;
mod error;
pub mod goal;
pub mod hand_force;
pub mod params;
mod point_rows;
pub mod position_hold;
pub mod posture;
pub mod tactile_guidance;
pub mod task;
mod terms;
pub mod wrist;

#[cfg(test)]
mod tests;

pub use error::TaskError;
pub use task::{entry, BaseReference, Cycle, HandSignals, Role, Rows, Task, TaskEntry, TaskSetup, WristMoments};

/// Every task by its name in `config/supervisor.yaml`. A new task is a file with its `impl Task`,
/// its `mod` line above and one entry here (`docs/tasks.md`).
pub static REGISTRY: std::sync::LazyLock<Vec<TaskEntry>> = std::sync::LazyLock::new(|| {
    vec![
        entry::<avoidance::ProximityAvoidance>(),
        entry::<goal::GoalPosition>(),
        entry::<goal::GoalOrientation>(),
        entry::<contact_reaction::ContactReaction>(),
        entry::<hand_force::HandDistance>(),
        entry::<hand_force::HandForce>(),
        entry::<wrist::CompliantWrist>(),
        entry::<tactile_guidance::TactileGuidance>(),
        entry::<position_hold::PositionHold>(),
        entry::<base_avoidance::MobileBaseAvoidance>(),
        entry::<compliance::BodyCompliance>(),
        entry::<posture::Posture>(),
    ]
});

/// The registered task called `name`.
pub fn lookup(name: &str) -> Option<&'static TaskEntry> {
    REGISTRY.iter().find(|e| e.name == name)
}
