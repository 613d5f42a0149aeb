//! `mujoco_sim`: a skin_sim scene on the ROS graph (see `skin_control::nodes::mujoco_sim`).
use std::process::ExitCode;

use anyhow::{Context as _, Result};
use clap::Parser;
use futures::executor::LocalPool;
use skin_control::nodes::{self, Pass};
use skin_control::shutdown;
use skin_sim_ros::mujoco_sim;

/// MuJoCo simulation of a scene: publishes /clock, /joint_states, /base/odom, /scan,
/// /skin/cells, the scene's /goal and /hand_force_reference; applies
/// <arm ns>/forward_velocity_controller/commands and /base/cmd_vel.
///
/// --lockstep steps one control period per received command set (reproducible: run the
/// task_controller with trigger:=inputs); otherwise it runs in real time. Exits when the scene
/// (or --duration) is over, or on SIGINT/SIGTERM. With --out (lockstep) the run's metrics.json,
/// summary.txt, figure.png and run.mcap are written as `skin_sim run` writes them.
///
/// Exit code: 0, 1 when an outcome check of --out failed, 2 when the run failed.
#[derive(Parser)]
#[command(
    version,
    after_help = "Examples:\n  mujoco_sim --scene intentional_contact --lockstep --duration 2\n  mujoco_sim --scene intentional_contact --lockstep --out out/intentional_contact\n  mujoco_sim --scene config/scenes/tomm_movable_obstacles.yaml --realtime-factor 0.5"
)]
struct Args {
    #[command(flatten)]
    options: mujoco_sim::Options,
    /// Print what the launch files need for --scene (controller setup, URDF, skin layout, LIDAR,
    /// base, arm namespaces; --controller overrides the setup) as JSON, and exit.
    #[arg(long)]
    describe: bool,
}

fn main() -> ExitCode {
    nodes::exit_code("mujoco_sim", run())
}

fn run() -> Result<Option<bool>> {
    let args = Args::parse_from(nodes::cli_args());
    if args.describe {
        println!("{}", mujoco_sim::describe(&args.options.scene, args.options.controller.clone())?);
        return Ok(None);
    }
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    let ctx = r2r::Context::create()?;
    let mut node = r2r::Node::create(ctx, mujoco_sim::NODE, "")?;
    let mut pool = LocalPool::new();
    let mut handle = mujoco_sim::start(&mut node, &pool.spawner(), args.options)?;
    let mut failure = None;
    nodes::spin(&mut node, &mut pool, || match handle.poll() {
        Ok(pass) => pass,
        Err(e) => {
            failure = Some(e);
            Pass::Done
        }
    });
    let outcome = handle.stop()?;
    node.spin_once(std::time::Duration::from_millis(50));
    nodes::bounded(match failure {
        Some(e) => Err(e.context("publishing")),
        None => Ok(outcome),
    })
}
