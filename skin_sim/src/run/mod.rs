//! Running a scene: the [`closed_loop`] steps the world and a skin_core `Controller` in
//! lockstep with the scene's [`schedule`] (goals, force references, phases, the [`base_motion`]
//! of force scenes) and its [`interaction`] periods; [`scenario`] names the papers' scenes and
//! [`runner`] takes one from scene file to report.

pub mod base_motion;
pub mod closed_loop;
pub mod interaction;
pub mod runner;
pub mod scenario;
pub mod schedule;
