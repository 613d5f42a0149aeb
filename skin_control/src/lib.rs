//! skin_control: the ROS 2 (Jazzy) layer of the system. Nodes are thin: messages are converted to
//! `skin_core` types in one place ([`convert`]), then the control law in `skin_core` does the work.
//! The nodes' work without ROS is in [`aggregator`], [`task_controller`] and [`supervisor_node`];
//! their wiring in [`nodes`]; the bag tool `skin_bag` in [`rosbag`]; the `skin_watchdog`'s
//! decision in [`watchdog`], the controller's heartbeat in [`heartbeat`]. This is the robot
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
pub mod qos;
pub mod robot_description;
pub mod ros_params;
pub mod rosbag;
pub mod shutdown;
pub mod supervisor_node;
pub mod task_controller;
pub mod tf;
pub mod watchdog;
