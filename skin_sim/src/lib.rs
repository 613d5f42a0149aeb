//! `skin_sim`: MuJoCo worlds for skin_control, built from our URDFs and scene files, laid out by
//! role, each layer using only the ones above it in this list:
//!
//! - [`scene`]: scene files (`config/scenes/*.yaml`, documented in `docs/scenes.md`), validated
//!   with errors that name the file and the key;
//! - [`world`]: the running MuJoCo simulation generated from the robot model and the scene, the
//!   robot's velocity interface and its state, and the simulated sensors (skin, LIDAR, contact
//!   probe);
//! - [`outputs`]: what a run produced: the per-cycle record, `metrics.json`, the one definition
//!   of a safe run, the outcome checks, the summary, figures in the papers' style and the files
//!   (`figure.png`, `run.mcap`, rendered frames of what RViz would show);
//! - [`run`]: the world and a skin_core `Controller` in lockstep with the scene's schedule, and
//!   the named scenarios of the papers, run from scene to report;
//! - [`study`]: the speed/accuracy study (`skin_sim sweep`, `docs/tradeoffs.md`); [`campaign`]:
//!   randomized scene families (`skin_sim campaign`, `docs/robustness.md`); [`performance`]:
//!   `docs/performance.md` from the benchmark results; [`new_robot`]: `skin_setup`'s files for a
//!   robot nobody here modelled.
#![warn(missing_docs)]

pub mod campaign;
pub mod new_robot;
pub mod outputs;
pub mod performance;
pub mod run;
pub mod scene;
pub mod study;
pub mod world;

pub use scene::{Scene, SceneError};
pub use world::{World, WorldError};
