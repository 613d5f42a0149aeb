//! skin_sim_ros: the simulation on the ROS 2 graph. [`mujoco_sim`] runs a `skin_sim` scene as a
//! node that speaks the robot drivers' topics (joint states, odometry, scan, skin cells in; the
//! velocity commands out), so the robot package's nodes run against it unchanged; [`sim_bridge`]
//! is its work without ROS (the messages of one period, the commands applied). The binaries
//! `mujoco_sim` and `skin_stack` (every node in one process) live here, so that the robot package
//! `skin_control` builds without MuJoCo.
#![warn(missing_docs)]

pub mod mujoco_sim;
pub mod sim_bridge;
