//! `priority_supervisor`: intentional-contact paper Table I / interactive-force-control paper Table 1 on the ROS graph. Wiring in
//! `skin_control::nodes::priority_supervisor`, work in `skin_control::priority_supervisor`.
use std::time::Duration;

use anyhow::{Context as _, Result};
use clap::Parser;
use futures::executor::LocalPool;
use skin_control::nodes::{self, priority_supervisor, Pass};
use skin_control::shutdown;

/// Priority supervisor: /controller/state in, /supervisor/arrangement out (reliable, transient
/// local; on every change and every republish_period_s), service /supervisor/set_phase
/// (skin_msgs/srv/SetPhase; refused with the reason under the intentional_contact policy).
///
/// The supervisor configuration comes from the controller setup file (the same one the
/// task_controller uses: both must agree on task names and arrangements).
#[derive(Parser)]
#[command(
    version,
    after_help = "ROS arguments go after --ros-args, e.g.\n  priority_supervisor --setup config/controller/tomm_phases.yaml --ros-args -p republish_period_s:=0.5"
)]
struct Args {
    #[command(flatten)]
    options: priority_supervisor::Options,
}

fn main() -> Result<()> {
    let args = Args::parse_from(nodes::cli_args());
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, priority_supervisor::NODE, "")?;
    let mut pool = LocalPool::new();
    let handle = priority_supervisor::start(&mut node, &pool.spawner(), args.options)?;
    nodes::spin(&mut node, &mut pool, || Pass::Idle);
    // Nothing delivered is lost on a stop: the dwell timers and the switch log count every state.
    nodes::drain(&mut node, &mut pool, || handle.states_taken(), Duration::from_secs(2));
    handle.stop();
    shutdown::bound_teardown(0);
    Ok(())
}
