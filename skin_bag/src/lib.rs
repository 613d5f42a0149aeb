//! `skin_bag`: rosbag2 MCAP files of the skin_control topics, written without ROS or MuJoCo
//! (the robot package and the simulator both write them): profile `ros2`, one schema per message
//! type (encoding `ros2msg`, the complete definition text rosbag2 records), one channel per topic
//! (message encoding `cdr`), CDR payloads with their encapsulation header.
//!
//! Files open with `ros2 bag`, rosbags, Foxglove and the [`read_bag`] reader used by the tests.

mod cdr;
mod defs;
mod error;
pub mod msgs;
mod reader;
mod writer;

pub use defs::full_definition;
pub use error::BagError;
pub use msgs::RosMessage;
pub use reader::{read_bag, BagMessage};
pub use writer::{BagWriter, TRANSIENT_LOCAL_QOS};

#[cfg(test)]
mod tests;
