//! `priority_supervisor`: `/controller/state` in, `/supervisor/arrangement` out (reliable,
//! transient local: on every change and every `republish_period_s`), `/supervisor/set_phase`
//! served. The work is in `crate::priority_supervisor`.
use std::cell::RefCell;
use std::rc::Rc;
use std::time::Duration;

use anyhow::{Context as _, Result};
use futures::executor::LocalSpawner;
use futures::task::LocalSpawnExt;
use futures::StreamExt;
use r2r::skin_msgs::msg::{Arrangement, ControllerState};
use r2r::skin_msgs::srv::SetPhase;
use r2r::ParameterValue;
use skin_core::controller::ControllerConfig;

use super::{file_setting, resolve, ros_now};
use crate::priority_supervisor::PrioritySupervisor;
use crate::qos;
use crate::topics::*;

/// Node name.
pub const NODE: &str = "priority_supervisor";

/// Start-up options (the binary's command line; `None`: the ROS parameter, else the default).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Controller setup file whose supervisor file (and policy override) is used, the same as the
    /// task controller's [default: config/controller/tomm.yaml; ROS parameter setup_file].
    #[arg(long, value_name = "FILE")]
    pub setup: Option<String>,
}

/// The running node.
pub struct SupervisorHandle {
    sup: Rc<RefCell<PrioritySupervisor>>,
    logger: String,
}

impl SupervisorHandle {
    /// Controller states taken so far.
    pub fn states_taken(&self) -> u64 {
        self.sup.borrow().updates()
    }

    /// Logs the summary.
    pub fn stop(&self) {
        let s = self.sup.borrow();
        let log = s.supervisor().log();
        r2r::log_info!(
            &self.logger,
            "stopping after {} controller states, {} switches; mode {:?}",
            s.updates(),
            log.total(),
            s.supervisor().mode()
        );
    }
}

/// Creates the node's entities and spawns its tasks.
pub fn start(node: &mut r2r::Node, spawner: &LocalSpawner, options: Options) -> Result<SupervisorHandle> {
    let logger = node.logger().to_string();
    let setup = file_setting(node, options.setup, "setup_file", "config/controller/tomm.yaml")?;
    let period: f64 = match node.get_parameter::<Option<f64>>("republish_period_s") {
        Ok(v) => v.unwrap_or(1.0),
        Err(e) => anyhow::bail!("ROS parameter `republish_period_s`: {e}"),
    };
    if !(period.is_finite() && period > 0.0) {
        anyhow::bail!("ROS parameter `republish_period_s` = {period}: must be finite and > 0");
    }
    let config = ControllerConfig::load(&resolve(&setup, "setup_file")?).context("controller setup")?;
    {
        // The standard parameter services, read-only values (nothing here changes at run time).
        let mut p = node.params.lock().unwrap();
        p.insert(
            "setup_file".into(),
            r2r::Parameter {
                value: ParameterValue::String(setup.clone()),
                description: "Controller setup file (read at start)",
            },
        );
        p.insert(
            "republish_period_s".into(),
            r2r::Parameter {
                value: ParameterValue::Double(period),
                description: "Arrangement republication period [s] (read at start)",
            },
        );
    }
    let (param_services, _changes) = node.make_parameter_handler().context("parameter services")?;
    spawner.spawn_local(param_services)?;
    let sup = PrioritySupervisor::new(&config.supervisor, ros_now(node))
        .map_err(|e| anyhow::anyhow!("{setup}: supervisor: {e}"))?;
    r2r::log_info!(
        &logger,
        "{setup}: policy {:?}, {CONTROLLER_STATE} -> {ARRANGEMENT}, service {SET_PHASE}",
        sup.supervisor().policy()
    );
    let sup = Rc::new(RefCell::new(sup));
    let publisher = node.create_publisher::<Arrangement>(super::local(ARRANGEMENT), qos::latched())?;
    let initial = sup.borrow().current();
    publisher.publish(&initial).context(ARRANGEMENT)?;
    sup.borrow_mut().published(&initial);

    let mut states = node.subscribe::<ControllerState>(super::local(CONTROLLER_STATE), qos::every_sample())?;
    let (s, p, log) = (sup.clone(), publisher.clone(), logger.clone());
    spawner.spawn_local(async move {
        while let Some(msg) = states.next().await {
            let out = s.borrow_mut().on_state(&msg);
            if let Some(a) = out {
                if let Some(tr) = s.borrow().supervisor().last_transition() {
                    r2r::log_info!(
                        &log,
                        "t = {:.3} s: {:?} -> {:?} ({:?}): {:?}",
                        tr.t_s,
                        tr.from,
                        tr.to,
                        tr.cause,
                        a.task_order
                    );
                }
                if let Err(e) = p.publish(&a) {
                    r2r::log_error!(&log, "{ARRANGEMENT}: {e}");
                }
            }
        }
    })?;

    let mut timer = node.create_wall_timer(Duration::from_secs_f64(period))?;
    let (s, p) = (sup.clone(), publisher);
    spawner.spawn_local(async move {
        while timer.tick().await.is_ok() {
            let msg = s.borrow().current();
            if p.publish(&msg).is_ok() {
                s.borrow_mut().published(&msg);
            }
        }
    })?;

    let mut service = node.create_service::<SetPhase::Service>(super::local(SET_PHASE), qos::services())?;
    let (s, log) = (sup.clone(), logger.clone());
    spawner.spawn_local(async move {
        while let Some(req) = service.next().await {
            let (accepted, message) = s.borrow_mut().request_phase(req.message.phase);
            r2r::log_info!(
                &log,
                "{SET_PHASE} phase {}: {} ({message})",
                req.message.phase,
                if accepted { "accepted" } else { "refused" }
            );
            if let Err(e) = req.respond(SetPhase::Response { accepted, message }) {
                r2r::log_error!(&log, "{SET_PHASE}: reply failed: {e}");
            }
        }
    })?;
    Ok(SupervisorHandle { sup, logger })
}
