//! `skin_stack`: the nodes composed in one process, one r2r node each, one executor (a single
//! thread): task_controller, priority_supervisor and, with --scene, mujoco_sim. For the demo and
//! the tests; each node behaves as its own binary does.
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context as _, Result};
use clap::Parser;
use futures::executor::LocalPool;
use r2r::{Parameter, ParameterValue};
use skin_control::nodes::{self, priority_supervisor, task_controller, Pass};
use skin_control::shutdown;
use skin_sim_ros::mujoco_sim;

/// The skin control graph in one process: task_controller + priority_supervisor (+ mujoco_sim
/// with --scene). Topics, services and parameters are those of the separate nodes (docs/ros.md);
/// per-node parameters go in a --params-file with one section per node name.
///
/// With --scene and --lockstep the controller runs with trigger:=inputs at the scene's control
/// rate; --internal-supervisor makes it decide the arrangement in its own cycle (the in-process
/// loop's behaviour, reproducible) while priority_supervisor still runs and publishes. --out
/// writes the run's metrics.json, summary.txt, figure.png and run.mcap as `skin_sim run` does.
///
/// Exit code: 0, 1 when an outcome check of --out failed, 2 when the run failed.
#[derive(Parser)]
#[command(
    version,
    after_help = "Examples:\n  skin_stack --scene intentional_contact --lockstep --internal-supervisor --out out/intentional_contact\n  skin_stack --setup config/controller/planar7.yaml --scene intentional_contact --lockstep --internal-supervisor --duration 4\n  skin_stack --ros-args --params-file config/ros/task_controller.yaml"
)]
struct Args {
    /// Controller setup file for the controller and the supervisor [default: the scenario's
    /// with --scene, else config/controller/tomm.yaml].
    #[arg(long, value_name = "FILE")]
    setup: Option<String>,
    /// Also run mujoco_sim on this scene (scenario name or scene file).
    #[arg(long, value_name = "SCENE")]
    scene: Option<String>,
    /// Lockstep simulation (needs --scene).
    #[arg(long, requires = "scene")]
    lockstep: bool,
    /// The controller decides the arrangement in its cycle (supervisor:=internal).
    #[arg(long)]
    internal_supervisor: bool,
    /// Stop the simulation after this much simulated time [s].
    #[arg(long, value_name = "SECONDS")]
    duration: Option<f64>,
    /// mujoco_sim: write the applied commands per period (JSON) here at the end.
    #[arg(long, value_name = "FILE")]
    record: Option<PathBuf>,
    /// mujoco_sim: write the run's outputs here (needs --lockstep).
    #[arg(long, value_name = "DIR", requires = "lockstep")]
    out: Option<PathBuf>,
}

fn set(node: &r2r::Node, key: &str, value: ParameterValue) {
    node.params.lock().unwrap().insert(key.to_string(), Parameter::new(value));
}

fn main() -> ExitCode {
    nodes::exit_code("skin_stack", run())
}

fn run() -> Result<Option<bool>> {
    let mut args = Args::parse_from(nodes::cli_args());
    if args.setup.is_none() {
        args.setup = args.scene.as_deref().and_then(mujoco_sim::scenario_setup).map(|p| p.display().to_string());
    }
    shutdown::install().context("installing the SIGINT/SIGTERM handler")?;
    let ctx = r2r::Context::create()?;
    let mut pool = LocalPool::new();
    let spawner = pool.spawner();
    let mut sim_node = match &args.scene {
        Some(_) => Some(r2r::Node::create(ctx.clone(), mujoco_sim::NODE, "")?),
        None => None,
    };
    let mut sim = match (&args.scene, &mut sim_node) {
        (Some(scene), Some(node)) => {
            let options = mujoco_sim::Options {
                scene: scene.clone(),
                lockstep: args.lockstep,
                realtime_factor: 1.0,
                duration: args.duration,
                resend: 1.0,
                arm_namespaces: vec![],
                arm_prefixes: vec![],
                base_command_stamped: false,
                record: args.record.clone(),
                out: args.out.clone(),
                controller: args.setup.as_ref().map(PathBuf::from),
                // in one process the nodes' subscriptions exist before the first state
                wait_topic_subscribers: vec![],
            };
            Some(mujoco_sim::start(node, &spawner, options)?)
        }
        _ => None,
    };
    let mut tc_node = r2r::Node::create(ctx.clone(), task_controller::NODE, "")?;
    if args.lockstep {
        set(&tc_node, "trigger", ParameterValue::String("inputs".into()));
        let scene = skin_sim::scene::Scene::load(&mujoco_sim::scene_file(args.scene.as_deref().unwrap_or_default())?)?;
        set(&tc_node, "control_rate_hz", ParameterValue::Double(scene.spec.control_rate_hz));
    }
    if args.internal_supervisor {
        set(&tc_node, "supervisor", ParameterValue::String("internal".into()));
    }
    let tc = task_controller::start(&mut tc_node, &spawner, task_controller::Options { setup: args.setup.clone() })?;
    let mut sup_node = r2r::Node::create(ctx, priority_supervisor::NODE, "")?;
    let sup = priority_supervisor::start(
        &mut sup_node,
        &spawner,
        priority_supervisor::Options { setup: args.setup.clone() },
    )?;

    let mut failure = None;
    {
        let mut tc_poll = || {
            let cycles = tc.counts().0;
            tc.poll();
            if tc.counts().0 == cycles {
                Pass::Idle
            } else {
                Pass::Busy
            }
        };
        let mut sup_poll = || Pass::Idle;
        let mut sim_poll = || match sim.as_mut().map(|s| s.poll()) {
            Some(Ok(pass)) => pass,
            None => Pass::Idle,
            Some(Err(e)) => {
                failure = Some(e);
                Pass::Done
            }
        };
        let mut all: Vec<(&mut r2r::Node, &mut dyn FnMut() -> Pass)> =
            vec![(&mut tc_node, &mut tc_poll), (&mut sup_node, &mut sup_poll)];
        if let Some(n) = sim_node.as_mut() {
            all.push((n, &mut sim_poll));
        }
        nodes::spin_nodes(&mut all, &mut pool);
    }
    tc.stop();
    sup.stop();
    let outcome = sim.map(|s| s.stop()).transpose()?.flatten();
    tc_node.spin_once(std::time::Duration::from_millis(50));
    nodes::bounded(match failure {
        Some(e) => Err(e.context("mujoco_sim")),
        None => Ok(outcome),
    })
}
