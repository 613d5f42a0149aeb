//! `skin_sim`: MuJoCo worlds for skin_control, built from our URDFs and scene files.
//!
//! - [`scene`]: scene files (`config/scenes/*.yaml`, documented in `docs/scenes.md`), validated
//!   with errors that name the file and the key;
//! - [`mjcf`]: the MJCF generated from the robot model and the scene;
//! - [`world`]: the running simulation, the robot's velocity interface and its state;
//! - [`skin_sensor`] and [`lidar`]: the simulated sensors;
//! - [`noise`]: seeded Gaussian noise;
//! - [`closed_loop`]: the world and a skin_core `Controller` in lockstep, with the scene's
//!   [`schedule`] (goals, force references through skin_core's `HandForceMap`, phases), the [`interaction`]
//!   periods and the physical contact forces of [`probe`], recorded per cycle in [`record`];
//! - [`scenario`], [`runner`], [`metrics`], [`safety`], [`outcome`], [`report`]: the named
//!   scenarios of the papers, a run from scene to report, `metrics.json`, the one definition of a
//!   safe run, the outcome checks, the summary;
//! - [`plot`]: figures in the papers' style; [`outputs`] (with the `skin_bag` crate's MCAP writer)
//!   turns a run into `figure.png`, `run.mcap` and the rendered frames of its [`view`] (what
//!   RViz would show: robot, skin markers, contact arrows);
//! - [`study`]: the speed/accuracy study over control rate, timestep, skin density and the
//!   inverse's damping (`skin_sim sweep`, `docs/tradeoffs.md`);
//! - [`performance`]: `docs/performance.md` from the benchmark results (`skin_sim performance`).
#![warn(missing_docs)]

pub mod base_motion;
pub mod campaign;
mod cell_face;
pub mod closed_loop;
mod frames;
pub mod interaction;
pub mod lidar;
pub mod metrics;
pub mod mjcf;
pub mod new_robot;
pub mod noise;
pub mod outcome;
pub mod outputs;
pub mod performance;
pub mod plot;
pub mod probe;
mod proximity_rays;
pub mod record;
pub mod report;
pub mod runner;
pub mod safety;
pub mod scenario;
pub mod scene;
pub mod schedule;
pub mod skin_sensor;
pub mod study;
pub mod view;
pub mod world;

pub use scene::{Scene, SceneError};
pub use world::{World, WorldError};
