//! skin_control: the ROS 2 (Jazzy) layer of the system. Nodes are thin: messages are converted to
//! `skin_core` types in one place, then the control law in `skin_core` does the work.
#![warn(missing_docs)]

pub mod qos;
