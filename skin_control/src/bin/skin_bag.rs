//! `skin_bag`: record topics into a rosbag2 MCAP file and play one back, as raw CDR (any type
//! r2r was built with). Work in `skin_control::rosbag`; see docs/ros.md.
use anyhow::{Context as _, Result};
use clap::{Parser, Subcommand};
use skin_control::rosbag::{play, record};
use skin_control::{nodes, shutdown};

/// Records and plays rosbag2 MCAP files without a ROS installation's rosbag2: the messages stay
/// serialized CDR bytes end to end. Bags read in rosbags, `ros2 bag` and Foxglove, and bags they
/// write play here.
#[derive(Parser)]
#[command(
    version,
    after_help = "Examples:\n  skin_bag record run.mcap --topics /skin/cells /joint_states /goal:geometry_msgs/msg/PoseStamped\n  skin_bag play run.mcap --rate 2 --clock\n  skin_bag play run.mcap --topics /skin/cells /joint_states --step-on /controller/state\n\nROS arguments go after --ros-args."
)]
struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Record topics until SIGINT/SIGTERM (then the file is finished: nothing already received is lost).
    Record(record::RecordOptions),
    /// Play a bag: recorded timing scaled by --rate, or stepped on a topic's answers (--step-on).
    Play(play::PlayOptions),
}

fn main() -> Result<()> {
    let args = Args::parse_from(nodes::cli_args());
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    match args.command {
        Command::Record(o) => record::record(o),
        Command::Play(o) => play::play(o),
    }
}
