//! The references the lockstep ROS graph is compared with (test/test_graph.py), for one scene:
//! - `commands`: the graph's loop in one process without DDS (`sim_bridge::run_in_process`:
//!   every message conversion of the graph, the controller with its own supervisor in the
//!   cycle), what `mujoco_sim --lockstep` + `task_controller trigger:=inputs supervisor:=internal`
//!   must reproduce exactly;
//! - `closed_loop`: skin_sim's in-process loop (`ClosedLoop`, no messages), which differs from
//!   the first once the skin senses something (the messages carry float32 skin signals).
//!
//! `graph_reference --scene intentional_contact --duration 4 --out ref.json`
use anyhow::{Context as _, Result};
use clap::Parser;
use skin_control::task_controller::{SupervisorSource, TaskController, TaskControllerParams, Trigger};
use skin_core::controller::ControllerConfig;
use skin_sim::run::closed_loop::ClosedLoop;
use skin_sim::run::runner::RunTarget;
use skin_sim::scene::Scene;
use skin_sim_ros::sim_bridge::{run_in_process, SimBridge};

#[derive(Parser)]
#[command(about = "In-process references for the lockstep graph (JSON)")]
struct Args {
    /// Scenario name or scene file.
    #[arg(long, default_value = "intentional_contact")]
    scene: String,
    /// Controller setup (default: the scenario's).
    #[arg(long)]
    setup: Option<std::path::PathBuf>,
    /// Simulated time [s].
    #[arg(long, default_value_t = 4.0)]
    duration: f64,
    /// Output file.
    #[arg(long)]
    out: std::path::PathBuf,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let target = RunTarget::resolve(&args.scene, args.setup).map_err(anyhow::Error::msg)?;
    let scene = Scene::load(&target.scene)?;
    let config = ControllerConfig::load(&target.controller)?;
    let mut params = TaskControllerParams::defaults(&config);
    params.trigger = Trigger::Inputs;
    params.supervisor = SupervisorSource::Internal;
    params.control_rate_hz = scene.spec.control_rate_hz;
    let cycles = (args.duration * scene.spec.control_rate_hz).round() as usize;
    let mut tc = TaskController::new(config, params.clone(), 0.0).map_err(anyhow::Error::msg)?;
    let mut bridge = SimBridge::new(scene.clone(), &params.arms.namespaces, &params.arms.joint_prefixes)
        .map_err(anyhow::Error::msg)?;
    let commands = run_in_process(&mut bridge, &mut tc, cycles);
    let mut direct = ClosedLoop::new(scene, &target.controller)?;
    let closed: Vec<Vec<f64>> = (0..cycles).map(|_| direct.cycle().joint_velocities.clone()).collect();
    let json = serde_json::json!({ "commands": commands, "closed_loop": closed });
    std::fs::write(&args.out, serde_json::to_string(&json)?).with_context(|| args.out.display().to_string())?;
    Ok(())
}
