//! The control cycle: model, skin, tasks, supervisor, hierarchy and resolver composed behind one
//! [`Controller::update`] per cycle (measurements in, velocity commands out), allocation-free
//! after [`Controller::new`]. Built from a setup file (`config/controller/<robot>.yaml`,
//! [`ControllerConfig::load`]) that names the URDF, the skin layout, the parameter files and the
//! frames the tasks act on. `docs/controller.md` describes the cycle.

mod approach;
mod cycle;
mod goal_damping;
mod hand_force;
mod io;
mod press;
mod setup;
mod stages;
mod task_set;

#[cfg(test)]
mod tests;

pub use crate::tasks::BaseReference;
pub use cycle::Controller;
pub use hand_force::HandForceMap;
pub use io::{ControllerInput, ControllerOutput, Fault};
pub use setup::{ControllerConfig, ControllerSetup, HierarchyDynamics, SetupError};
pub use stages::{Stage, StageTimes};
