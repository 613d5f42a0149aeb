//! One closed-loop run from start to report: load the scene (with run overrides), build the loop,
//! run it, compute the metrics and the outcome checks. [`ExternalRun`]: the same report for a
//! run whose controller is outside this process (the ROS graph).

use std::path::PathBuf;
use std::time::Instant;

use skin_core::controller::Controller;
use skin_core::supervisor::{Blocked, Mode, SupervisorInput};

use crate::outputs::metrics::{self, Limits};
use crate::outputs::outcome;
use crate::outputs::record::{CycleRecord, RunRecord, Switch};
use crate::outputs::report::RunReport;
use crate::outputs::safety::SafetyLimits;
use crate::outputs::view::ViewRecorder;
use crate::run::closed_loop::{ClosedLoop, LoopError};
use crate::run::interaction::Interactions;
use crate::run::scenario::{self, Scenario};
use crate::scene::{RunOverrides, Scene};
use crate::world::probe::ContactProbe;
use skin_core::controller::HandForceMap;

/// What to run: a scene and the controller setup for it (what it is judged on is in the scene
/// file's `expect:`).
#[derive(Debug, Clone, PartialEq)]
pub struct RunTarget {
    /// Name in the report (the scenario's, or the scene file's stem).
    pub name: String,
    /// Scene file.
    pub scene: PathBuf,
    /// Controller setup file.
    pub controller: PathBuf,
}

impl From<&Scenario> for RunTarget {
    fn from(s: &Scenario) -> Self {
        RunTarget { name: s.name.to_string(), scene: s.scene_file(), controller: s.controller_file() }
    }
}

impl RunTarget {
    /// A scenario by name, or a scene file; `controller` overrides the scenario's setup and is
    /// required for a scene file that is not a scenario's.
    pub fn resolve(arg: &str, controller: Option<PathBuf>) -> Result<RunTarget, String> {
        let path = PathBuf::from(arg);
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let mut target = match (scenario::find(arg), path.is_file()) {
            (Some(s), _) => RunTarget::from(s),
            (None, true) => match scenario::find(&stem) {
                Some(s) => RunTarget { scene: path, ..RunTarget::from(s) },
                None => RunTarget {
                    name: stem,
                    controller: controller.clone().ok_or_else(|| {
                        format!("{arg} is not a scenario's scene file: give its controller setup with --controller")
                    })?,
                    scene: path,
                },
            },
            (None, false) => {
                let names: Vec<&str> = scenario::SCENARIOS.iter().map(|s| s.name).collect();
                return Err(format!("`{arg}` is neither a scenario ({}) nor a scene file", names.join(", ")));
            }
        };
        if let Some(c) = controller {
            target.controller = c;
        }
        Ok(target)
    }

    /// Runs it with `overrides`, calling `progress` with the fraction done after every cycle.
    pub fn run(&self, overrides: &RunOverrides, progress: impl FnMut(f64)) -> Result<RunReport, LoopError> {
        let mut scene = Scene::load(&self.scene).map_err(crate::world::WorldError::from)?;
        scene.override_run(overrides).map_err(crate::world::WorldError::from)?;
        self.run_scene(scene, progress)
    }

    /// Runs `scene`, this target's scene as loaded and possibly changed by the caller (the
    /// study's variants: sensor rates, a reduced skin layout), for its `duration_s`.
    pub fn run_scene(&self, scene: Scene, progress: impl FnMut(f64)) -> Result<RunReport, LoopError> {
        let duration = scene.spec.duration_s;
        let closed_loop = ClosedLoop::new(scene.clone(), &self.controller)?;
        let limits = limits_of(closed_loop.controller());
        let record = closed_loop.run(duration, progress);
        Ok(self.report(record, &scene, limits))
    }

    /// The report of `record`, a run of `scene` (named after this target): metrics and checks.
    pub fn report(&self, mut record: RunRecord, scene: &Scene, limits: Limits) -> RunReport {
        record.name = self.name.clone();
        let metrics = metrics::compute(&record, scene, &limits);
        let checks = outcome::checks(&metrics, scene.spec.expect.as_ref());
        RunReport { record, metrics, checks }
    }
}

/// The supervisor thresholds and the arm's URDF velocity limits the metrics compare with.
fn limits_of(controller: &Controller) -> Limits {
    let config = controller.config();
    let thresholds = config.supervisor.thresholds;
    let joint_speed_limits = controller
        .resolver()
        .arm_joints()
        .iter()
        .filter_map(|&j| Some((j, config.model.joint_limits().get(j)?.velocity)))
        .collect();
    Limits {
        eps_c_n: thresholds.contact_force_n,
        goal_tolerance_m: thresholds.goal_tolerance_m,
        hand_distance_desired_m: config.tasks.hand_force.distance_desired_m,
        safety: SafetyLimits { eps_c_n: thresholds.contact_force_n, joint_speed_limits },
    }
}

/// One cycle of a controller outside this process, as it published it (the ROS graph's
/// `/controller/state` and commands).
#[derive(Debug, Clone, PartialEq)]
pub struct Decision {
    /// Commanded arm joint velocities, the world's arm joint order.
    pub joint_velocities: Vec<f64>,
    /// Commanded base twist `(vx, vy, wz)`, base frame.
    pub base_twist: [f64; 3],
    /// Active arrangement.
    pub mode: Mode,
    /// Why the arm holds in (a) after a push given up (`ControllerState.blocked`).
    pub blocked: Option<Blocked>,
    /// Nothing is to be pressed (`ControllerState.releasing`).
    pub releasing: bool,
    /// Blend factor `χ`.
    pub blend: f64,
    /// Fusion weight of the skin (the graph publishes the arrangement's target).
    pub fusion_weight: f64,
    /// The supervisor's signals.
    pub signals: SupervisorInput,
    /// `‖τ*‖` \[N m\].
    pub torque_norm: f64,
    /// The fault text when the cycle was a safe-stop step.
    pub fault: Option<String>,
    /// Wall-clock time the cycle took as its caller saw it \[µs\].
    pub compute_us: f64,
}

/// A run of a target whose controller runs elsewhere (the ROS graph in lockstep): the caller
/// steps its own world and, per control period, gives the world before the step and the
/// controller's [`Decision`]; the physical measurements (contact forces, interactions) are taken
/// here as [`ClosedLoop`] takes them, and [`ExternalRun::finish`] gives the report that
/// [`RunTarget::run`] gives, from the same metrics and checks.
pub struct ExternalRun {
    target: RunTarget,
    scene: Scene,
    limits: Limits,
    probe: ContactProbe,
    interactions: Interactions,
    hand: Option<HandForceMap>,
    view: ViewRecorder,
    record: RunRecord,
    started: Instant,
}

impl ExternalRun {
    /// Starts the record of `target` run on `scene` in `world` (a world of that scene). The
    /// controller setup is checked against the scene as the in-process loop checks it, and the
    /// record has its header.
    pub fn new(target: &RunTarget, scene: Scene, world: &crate::world::World) -> Result<Self, LoopError> {
        let in_process = ClosedLoop::new(scene.clone(), &target.controller)?;
        let config = in_process.controller().config();
        let ee = config.model.frame_index(&config.setup.end_effector).expect("checked by Controller::new");
        Ok(ExternalRun {
            limits: limits_of(in_process.controller()),
            probe: ContactProbe::new(world, ee),
            interactions: Interactions::new(&scene, config.tasks.base_avoidance),
            hand: HandForceMap::new(config),
            view: ViewRecorder::new(&scene, config),
            record: in_process.record().clone(),
            target: target.clone(),
            scene,
            started: Instant::now(),
        })
    }

    /// Records one control period: `world` at the state the controller answered (before the
    /// step), `force_n` the force reference the scene gave it \[N\] (None: none), `decision`
    /// its answer.
    pub fn cycle(&mut self, world: &crate::world::World, force_n: Option<f64>, decision: Decision) {
        let t_s = world.time();
        let mut event = self.record.cycles.is_empty().then(|| "start".to_string());
        if let Some(last) = self.record.cycles.last().filter(|c| c.mode != decision.mode) {
            self.record.switches.push(Switch { t_s, from: last.mode, to: decision.mode });
            event = Some(format!("{} -> {}", last.mode.name(), decision.mode.name()));
        }
        self.view.cycle(world, decision.mode, event);
        let forces = self.probe.measure(world);
        // As the schedule gives it: a reference only with a hand to map it to.
        let (force_reference_n, force_reference_signal) = match (force_n, &self.hand) {
            (Some(f), Some(map)) => (f, map.signal(f)),
            _ => (f64::NAN, f64::NAN),
        };
        self.record.cycles.push(CycleRecord {
            t_s,
            q: world.q().to_vec(),
            qd: world.qd().to_vec(),
            joint_velocities: decision.joint_velocities,
            base_twist: decision.base_twist,
            mode: decision.mode,
            blocked: decision.blocked,
            releasing: decision.releasing,
            blend: decision.blend,
            fusion_weight: decision.fusion_weight,
            signals: decision.signals,
            torque_norm: decision.torque_norm,
            hand_force_n: forces.hand_n,
            link_force_n: forces.max_link_n,
            hand_position_m: forces.hand_position_m,
            hand_distance_m: forces.hand_distance_m,
            object_tilt_deg: forces.object_tilt_deg,
            hand_moment: [f64::NAN; 3],
            force_reference_n,
            force_reference_signal,
            interaction: self.interactions.active(t_s, world.q()),
            fault: decision.fault,
            compute_us: decision.compute_us,
        });
    }

    /// The cycles recorded so far.
    pub fn cycles(&self) -> usize {
        self.record.cycles.len()
    }

    /// The report, `world` at the end of the run (its last key frame); the wall time runs from
    /// [`ExternalRun::new`].
    pub fn finish(mut self, world: &crate::world::World) -> RunReport {
        self.record.wall_time_s = self.started.elapsed().as_secs_f64();
        self.record.busy = world.busy_time();
        let mode = self.record.cycles.last().map_or(Mode::Avoidance, |c| c.mode);
        self.record.view = self.view.finish(world, mode);
        self.target.report(self.record, &self.scene, self.limits)
    }
}
