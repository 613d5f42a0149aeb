//! `task_controller`: the whole-body controller of both papers on the ROS graph. Wiring in
//! `skin_control::nodes::task_controller`, work in `skin_control::task_controller`; see docs/ros.md.
use anyhow::{Context as _, Result};
use clap::Parser;
use futures::executor::LocalPool;
use skin_control::nodes::{self, task_controller, Pass};
use skin_control::shutdown;

/// Whole-body skin controller: /joint_states, /base/odom, /scan, /skin/cells, /goal,
/// /hand_force_reference, /supervisor/arrangement in; <arm ns>/forward_velocity_controller/commands,
/// /base/cmd_vel, /controller/state out.
///
/// Runs on a timer at control_rate_hz (ROS time; sim time with use_sim_time:=true), or once per
/// complete input set with trigger:=inputs (lockstep simulation). Zero commands until every input
/// has arrived, when inputs go stale, and on SIGINT/SIGTERM. Sends /controller/heartbeat with every
/// period's commands (skin_watchdog zeroes the command topics when it stops); exits with an error
/// when another task_controller already commands the same topics.
#[derive(Parser)]
#[command(
    version,
    after_help = "ROS arguments go after --ros-args, e.g.\n  task_controller --ros-args --params-file config/ros/task_controller.yaml -p use_sim_time:=true\n  task_controller --setup config/controller/planar7.yaml --ros-args -p trigger:=inputs -p supervisor:=internal"
)]
struct Args {
    #[command(flatten)]
    options: task_controller::Options,
    #[command(flatten)]
    wait: nodes::SubscriberWait,
}

/// How long the node stays on the graph after a lifecycle shutdown.
const LIFECYCLE_LINGER: std::time::Duration = std::time::Duration::from_secs(1);

fn main() -> Result<()> {
    let args = Args::parse_from(nodes::cli_args());
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, task_controller::NODE, "")?;
    let mut pool = LocalPool::new();
    let handle = match task_controller::start(&mut node, &pool.spawner(), args.options) {
        Ok(handle) => handle,
        // SIGINT/SIGTERM while waiting for the URDF on robot_description: nothing was commanded
        Err(e) if shutdown::requested() => {
            r2r::log_info!(node.logger(), "{e:#}");
            return Ok(());
        }
        Err(e) => return Err(e),
    };
    args.wait.wait(task_controller::NODE, &handle.output_topics(), |t| handle.subscription_count(t))?;
    nodes::spin(&mut node, &mut pool, || {
        handle.poll();
        if handle.yielded().is_some() {
            Pass::Done
        } else {
            Pass::Idle
        }
    });
    if let Some(why) = handle.yielded() {
        anyhow::bail!("{why}");
    }
    handle.stop();
    // The zeros are the last word: sent twice more, 30 ms apart, so that one lost sample (a loaded
    // host; a reader that is best effort) does not leave a driver on its last velocity; then let
    // them leave before the node goes away.
    for _ in 0..2 {
        node.spin_once(std::time::Duration::from_millis(30));
        handle.send_zeros();
    }
    // A lifecycle shutdown's reply is in flight: stay on the graph long enough for a reliable
    // resend (a reply lost on a loaded host is sent again only while its writer lives).
    let linger = if handle.finalized() { LIFECYCLE_LINGER } else { std::time::Duration::from_millis(50) };
    let until = std::time::Instant::now() + linger;
    while std::time::Instant::now() < until {
        node.spin_once(std::time::Duration::from_millis(50));
    }
    shutdown::bound_teardown(0);
    Ok(())
}
