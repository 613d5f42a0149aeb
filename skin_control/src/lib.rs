//! skin_control: the ROS 2 (Jazzy) layer of the system. Nodes are thin: messages are converted to
//! `skin_core` types in one place ([`convert`]), then the control law in `skin_core` does the work.
#![warn(missing_docs)]

pub mod aggregator;
pub mod convert;
pub mod markers;
pub mod paths;
pub mod qos;
pub mod ros_params;
pub mod shutdown;
