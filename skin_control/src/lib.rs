//! skin_control: the ROS 2 (Jazzy) layer of the system. Nodes are thin: messages are converted to
//! `skin_core` types in one place ([`convert`]), then the control law in `skin_core` does the work.
//! One naming scheme for every node: its work without ROS is the module named for what it does
//! ([`aggregator`], [`task_controller`], [`priority_supervisor`], [`watchdog`]), its ROS wiring
//! is `nodes::<executable>` ([`nodes`]), and `bin/<executable>.rs` only runs it. The bag tool
//! `skin_bag` is in [`rosbag`], the controller's heartbeat in [`heartbeat`]. This is the robot
//! package: it never links MuJoCo (the simulation nodes are the `skin_sim_ros` package).
#![warn(missing_docs)]

pub mod aggregator;
pub mod convert;
pub mod diagnostics;
pub mod heartbeat;
pub mod input_health;
pub mod lifecycle;
pub mod markers;
pub mod nodes;
pub mod paths;
pub mod priority_supervisor;
pub mod qos;
pub mod robot_description;
pub mod ros_params;
pub mod rosbag;
pub mod shutdown;
pub mod task_controller;
pub mod tf;
pub mod timing;
pub mod topics;
pub mod watchdog;
