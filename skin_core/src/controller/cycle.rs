//! [`Controller`]: one control cycle from measurements to velocity commands.

use nalgebra::{DMatrix, DVector, Isometry3};

use super::approach::{ApproachBound, ContactIntent, ContactLevels};
use super::goal_damping::GoalDamping;
use super::io::{ControllerInput, ControllerOutput, Fault};
use super::press::Press;
use super::setup::{ControllerConfig, HierarchyDynamics, SetupError};
use super::stages::{Stage, StageClock, StageTimes};
use super::task_set::TaskSet;
use crate::hierarchy::{HierarchySolver, LevelDiagnostics};
use crate::model::{gravity, point_velocity, update_kinematics, ModelData};
use crate::resolver::{Commands, Resolver};
use crate::skin::aggregate::{aggregate_live_patches, FusionParams, PatchWrench};
use crate::skin::characteristic::PreparedForce;
use crate::skin::live::LiveCells;
use crate::skin::measured::measured_contact;
use crate::skin::transforms::{patch_poses_world, patch_wrench_world, sum_patch_forces_in_frame};
use crate::supervisor::blend::chi;
use crate::supervisor::{Arrangement, Imposed, Mode, Phase, PhaseRefused, Supervisor, SupervisorInput, TorqueBlender};
use crate::tasks::avoidance::ProximityAvoidance;
use crate::tasks::contact_reaction::ContactReaction;
use crate::tasks::{BaseReference, Cycle, HandSignals, TaskEntry, TaskSetup};

/// Maps a stage's error to [`Fault::Stage`] (the error's text would allocate).
fn stage<E>(name: &'static str) -> impl FnOnce(E) -> Fault {
    move |_| Fault::Stage(name)
}

/// The whole control law of both papers behind one call per cycle:
///
/// 1. kinematics at the measured state; the supervisor's signals (end-effector speed, `‖F_d‖` at
///    the nominal range, `‖F_c‖`, goal error) and its arrangement (intentional-contact paper Table I or interactive-force-control paper
///    Table 1);
/// 2. the skin: cells fused with the arrangement's weight `w(t)` (interactive-force-control paper eq. 6) into patch
///    wrenches (eq. 7-8), and the hand signals of eq. (9)-(11);
/// 3. the arrangement's tasks filled in priority order, the posture torque of eq. (18) with the
///    terms the arrangement names, solved by the hierarchy (interactive-force-control paper eq. 19-25, with the bias
///    `C q̇ + g`);
/// 4. the torque blended across arrangement switches (intentional-contact paper eq. 10-11);
/// 5. the admittance resolver (interactive-force-control paper eq. 26) turns it into joint and base velocity commands
///    within the limits, the skin's approach bound first (`docs/resolver.md`).
///
/// Bad input (wrong lengths, NaN state, bad `dt`) or a failed stage makes the cycle a safe-stop
/// step instead (`ControllerOutput::fault`), so the commands are always finite and within the
/// limits. Commands start at zero and every command continues from the last one within the
/// acceleration limits, from the first cycle on: a measured velocity never sets a command (one
/// wrong reading at start must not become a velocity step). After [`Controller::new`] nothing
/// allocates (`tests/no_alloc.rs`).
#[derive(Debug)]
pub struct Controller {
    config: ControllerConfig,
    data: ModelData,
    tasks: TaskSet,
    /// The supervisor's `‖F_d‖` and `‖F_c‖` (whether or not the arrangement has these tasks).
    proximity_signal: ProximityAvoidance,
    contact_signal: ContactReaction,
    /// Desired hand contact force \[N\]: `f_c,d` of interactive-force-control paper eq. (9),
    /// regulated in newtons (`skin::measured`).
    hand_force_reference_n: f64,
    /// The force characteristic, prepared: the hand cells' newtons (`skin::measured`).
    force: PreparedForce,
    /// The commanded base motion, if any.
    base_reference: Option<BaseReference>,
    solver: HierarchySolver,
    /// This cycle's measured cell forces and the force on each link.
    press: Press,
    /// The skin's approach bound on the command (`docs/resolver.md`).
    approach: ApproachBound,
    resolver: Resolver,
    supervisor: Supervisor,
    blender: TorqueBlender,
    /// End-effector frame index.
    ee: usize,
    hand_patches: Vec<bool>,
    guidance_patches: Vec<bool>,
    /// Patches that are not hand patches: the body of eq. (13)-(14).
    body_patches: Vec<bool>,
    /// Joints held still (setup `locked_joints`), per model joint.
    locked: Vec<bool>,
    goal: Option<Isometry3<f64>>,
    fusion: FusionParams,
    /// The non-silent cells of this cycle's readings (collected once, read by the skin tasks
    /// and the aggregation).
    live: LiveCells,
    wrenches: Vec<PatchWrench>,
    /// World poses of the hand and guidance patches (the others are not kept up to date).
    patch_poses: Vec<Isometry3<f64>>,
    tau_k: DVector<f64>,
    tau: DVector<f64>,
    gravity: DVector<f64>,
    /// [`HierarchyDynamics::AdmittanceInertia`]: the goal's level (configured task index), whose
    /// executed damping the bias sets.
    goal_level: Option<usize>,
    goal_damping: GoalDamping,
    /// [`HierarchyDynamics::Admittance`]: the resolver's virtual inertia and bias `g + C_a v`.
    mass: DMatrix<f64>,
    bias: DVector<f64>,
    /// A cycle has run on a valid measured state (the position hold captures its pose then).
    started: bool,
    output: ControllerOutput,
    /// Opt-in stage timing ([`Controller::set_stage_timing`]).
    clock: StageClock,
}

impl Controller {
    /// Builds the controller at time `t0_s`: checks that frames, patches, task names and the
    /// posture fit the model, and allocates every buffer.
    pub fn new(config: ControllerConfig, t0_s: f64) -> Result<Self, SetupError> {
        Self::with_tasks(config, t0_s, &[])
    }

    /// [`Controller::new`] with tasks of the caller's own beside [`crate::tasks::REGISTRY`]
    /// (`crate::tasks::entry::<MyTask>()`), found by their names in the supervisor file like the
    /// built-in ones (`docs/tasks.md`, "Adding a task").
    pub fn with_tasks(config: ControllerConfig, t0_s: f64, extra: &[TaskEntry]) -> Result<Self, SetupError> {
        let model = &config.model;
        let nv = model.nv();
        let ee = model.frame_index(&config.setup.end_effector).ok_or_else(|| {
            config
                .invalid("end_effector", format!("frame `{}` is not in {}", config.setup.end_effector, model.source()))
        })?;
        if !config.setup.posture.is_empty() && config.setup.posture.len() != nv {
            let reason = format!("has {} values, the model has {nv} joints", config.setup.posture.len());
            return Err(config.invalid("posture", reason));
        }
        config.setup.inverse.validate().map_err(|error| SetupError::Inverse { file: config.source.clone(), error })?;
        let hand_patches = config.patch_mask("hand_patches", &config.setup.hand_patches)?;
        let guidance_patches = config.patch_mask("guidance_patches", &config.setup.guidance_patches)?;
        let body_patches = hand_patches.iter().map(|h| !h).collect();
        let mut locked = vec![false; nv];
        for (i, name) in config.setup.locked_joints.iter().enumerate() {
            let j = model.joint_index(name).ok_or_else(|| {
                config.invalid(format!("locked_joints[{i}]"), format!("joint `{name}` is not in {}", model.source()))
            })?;
            locked[j] = true;
        }
        let base_joints = model.planar_base();
        let q_post = if config.setup.posture.is_empty() { vec![0.0; nv] } else { config.setup.posture.clone() };
        let setup = TaskSetup {
            model,
            params: &config.tasks,
            skin: &config.skin,
            end_effector: ee,
            base_joints,
            posture: &q_post,
        };
        let tasks = TaskSet::new(&config, &setup, extra)?;
        let max_rows = tasks.levels.iter().map(|l| l.max_rows()).max().unwrap_or(0);
        let mut solver = HierarchySolver::new(nv, tasks.levels.len(), max_rows, config.setup.inverse)
            .map_err(|error| SetupError::Inverse { file: config.source.clone(), error })?;
        solver
            .set_locked_joints(&locked)
            .map_err(|error| SetupError::Inverse { file: config.source.clone(), error })?;
        let mut resolver = Resolver::with_held(model, config.resolver.clone(), &locked)
            .map_err(|error| SetupError::Resolver { file: config.setup.resolver.display().to_string(), error })?;
        let levels = ContactLevels::of(&config.supervisor.thresholds);
        let force = config.skin.force.prepared();
        let press = Press::new(force, &config.layout, model.nframes());
        let approach = ApproachBound::new(config.resolver.approach, levels, nv, model.nframes(), &config.layout);
        *resolver.closing_bounds_mut() = approach.limits();
        let supervisor = Supervisor::new(&config.supervisor, t0_s)?;
        let output = ControllerOutput {
            commands: resolver.commands().clone(),
            fault: None,
            mode: supervisor.mode(),
            blocked: None,
            goal_count: 0,
            releasing: false,
            blend: 0.0,
            fusion_weight: config.skin.fusion.weight_force,
            signals: SupervisorInput::default(),
            torque_norm: 0.0,
            hand_moment: nalgebra::Vector3::zeros(),
        };
        Ok(Controller {
            data: ModelData::new(model),
            solver,
            press,
            approach,
            resolver,
            blender: TorqueBlender::new(nv),
            ee,
            hand_patches,
            guidance_patches,
            body_patches,
            locked,
            goal: None,
            fusion: config.skin.fusion,
            live: LiveCells::with_capacity(config.layout.num_cells(), &config.skin.proximity),
            wrenches: Vec::with_capacity(config.layout.patches().len()),
            patch_poses: Vec::with_capacity(config.layout.patches().len()),
            tau_k: DVector::zeros(nv),
            tau: DVector::zeros(nv),
            gravity: DVector::zeros(nv),
            goal_level: config.supervisor.tasks.iter().position(|n| n == "goal"),
            goal_damping: GoalDamping::new(nv),
            mass: DMatrix::zeros(nv, nv),
            bias: DVector::zeros(nv),
            started: false,
            output,
            clock: StageClock::default(),
            tasks,
            proximity_signal: ProximityAvoidance::new(nv, config.tasks.avoidance),
            contact_signal: ContactReaction::new(
                nv,
                config.model.nframes(),
                config.tasks.contact_reaction,
                &config.skin.force,
            ),
            hand_force_reference_n: config.tasks.hand_force.force_desired_n,
            force: config.skin.force.prepared(),
            base_reference: None,
            supervisor,
            config,
        })
    }

    /// Loads the setup file at `path` ([`ControllerConfig::load`]) and builds the controller.
    pub fn from_setup_file(path: &std::path::Path, t0_s: f64) -> Result<Self, SetupError> {
        Self::new(ControllerConfig::load(path)?, t0_s)
    }

    /// The configuration the controller was built from.
    pub fn config(&self) -> &ControllerConfig {
        &self.config
    }

    /// Sets the end-effector goal (world frame; the orientation is used by `goal_orientation`),
    /// or clears it (`None`: the goal tasks are empty). A non-finite pose is refused.
    pub fn set_goal(&mut self, goal: Option<Isometry3<f64>>) -> Result<(), Fault> {
        if let Some(g) = &goal {
            let finite = g.translation.vector.iter().chain(g.rotation.coords.iter()).all(|v| v.is_finite());
            if !finite {
                return Err(Fault::NonFinite { input: "goal", index: 0 });
            }
        }
        if goal != self.goal {
            self.supervisor.new_goal(); // a push given up toward the old goal may succeed now
            self.output.goal_count = self.output.goal_count.wrapping_add(1);
        }
        self.goal = goal;
        Ok(())
    }

    /// The current goal.
    pub fn goal(&self) -> Option<&Isometry3<f64>> {
        self.goal.as_ref()
    }

    /// Sets the desired hand contact force \[N\] along the hand's z axis, clamped to
    /// `[0, hand cells × max_n]` (what the hand can sense, each cell up to the saturation of the
    /// force characteristic); NaN is refused. It is `f_c,d` of interactive-force-control paper
    /// eq. (9), regulated against the pressed hand cells' newtons (`skin::measured`).
    pub fn set_hand_force_reference(&mut self, force_n: f64) -> Result<(), Fault> {
        if force_n.is_nan() {
            return Err(Fault::NonFinite { input: "hand force reference", index: 0 });
        }
        let layout = &self.config.layout;
        let hand_cells: usize =
            layout.patches().iter().zip(&self.hand_patches).filter(|(_, &h)| h).map(|(p, _)| p.cells.len()).sum();
        self.hand_force_reference_n = force_n.clamp(0.0, hand_cells as f64 * self.config.skin.force.max_n);
        Ok(())
    }

    /// Sets the commanded base motion (interactive-force-control paper Exp. 1: a circle, lateral swings): the moving
    /// target `q_d(t)`, `q̇_d(t)` of the base joints in the posture torque of eq. (18), the lowest
    /// level, so the higher levels keep the hand while the base follows; `None`: back to
    /// `q_post`. Call it every cycle with the reference for that cycle's time. Refused: a
    /// non-finite value (`NonFinite`, index 0-2 position, 3-5 velocity), a model without base.
    pub fn set_base_reference(&mut self, reference: Option<BaseReference>) -> Result<(), Fault> {
        if reference.is_some() && self.resolver.base_joints().is_none() {
            return Err(Fault::Stage("base reference (the model has no base joints)"));
        }
        if let Some(index) = reference.and_then(|r| r.non_finite()) {
            return Err(Fault::NonFinite { input: "base reference", index });
        }
        self.base_reference = reference;
        Ok(())
    }

    /// The commanded base motion in use ([`Controller::set_base_reference`]).
    pub fn base_reference(&self) -> Option<BaseReference> {
        self.base_reference
    }

    /// Requests a interactive-force-control paper phase (effective at the next update).
    pub fn request_phase(&mut self, phase: Phase) -> Result<(), PhaseRefused> {
        self.supervisor.request_phase(phase)
    }

    /// Follows an arrangement decided elsewhere (the `priority_supervisor` node) from now on
    /// instead of the controller's own supervisor rules ([`Supervisor::impose`]).
    pub fn impose_arrangement(&mut self, a: Imposed) -> Result<(), PhaseRefused> {
        self.supervisor.impose(a)
    }

    /// The supervisor (mode, arrangement, transition log, [`Blocked`] hold).
    ///
    /// [`Blocked`]: crate::supervisor::Blocked
    pub fn supervisor(&self) -> &Supervisor {
        &self.supervisor
    }

    /// The active arrangement.
    pub fn arrangement(&self) -> &Arrangement {
        self.supervisor.arrangement()
    }

    /// Per-level diagnostics of the last solve, in the arrangement's priority order (level
    /// tasks only).
    pub fn level_diagnostics(&self) -> &[LevelDiagnostics] {
        self.solver.diagnostics()
    }

    /// The patch wrenches of the last cycle (layout patch order).
    pub fn patch_wrenches(&self) -> &[PatchWrench] {
        &self.wrenches
    }

    /// The blended joint torque `τ*` of the last cycle (model order).
    pub fn torque(&self) -> &DVector<f64> {
        &self.tau
    }

    /// The output of the last cycle.
    pub fn output(&self) -> &ControllerOutput {
        &self.output
    }

    /// The resolver (arm joint order, limits).
    pub fn resolver(&self) -> &Resolver {
        &self.resolver
    }

    /// Switches the timing of the cycle's stages on (times from zero) or off (the default).
    pub fn set_stage_timing(&mut self, on: bool) {
        self.clock.set(on);
    }

    /// Time spent per stage since [`Controller::set_stage_timing`] switched timing on; `None`
    /// when it is off.
    pub fn stage_times(&self) -> Option<&StageTimes> {
        self.clock.times()
    }

    /// One control cycle. Always returns commands that are safe to send.
    pub fn update(&mut self, input: &ControllerInput) -> &ControllerOutput {
        match self.run(input) {
            Ok(()) => self.output.fault = None,
            Err(fault) => {
                self.resolver.safe_stop(input.dt_s);
                self.output.fault = Some(fault);
            }
        }
        let c: &Commands = self.resolver.commands();
        self.output.commands.joint_velocities.copy_from_slice(&c.joint_velocities);
        self.output.commands.base_twist = c.base_twist;
        &self.output
    }

    /// A period without usable inputs (a caller's staleness watchdog): one safe-stop step, every
    /// command decelerates towards zero within its acceleration limit; a later [`update`]
    /// continues from the commands reached. Before the first valid state the commands stay zero.
    ///
    /// [`update`]: Controller::update
    pub fn idle(&mut self, dt_s: f64) -> &Commands {
        self.resolver.safe_stop(dt_s)
    }

    /// Zero commands were sent to the robot by someone else (a watchdog, while this controller
    /// was late or its link was down): the next command continues from zero within the
    /// acceleration limits, not from this controller's last one.
    pub fn restart_from_zero(&mut self) {
        self.resolver.restart_from_zero();
        self.output.commands.joint_velocities.fill(0.0);
        self.output.commands.base_twist = [0.0; 3];
    }

    /// Lengths and finiteness of the measured state.
    fn check_state(&self, input: &ControllerInput) -> Result<(), Fault> {
        let nv = self.config.model.nv();
        for (name, v) in [("q", input.q), ("qd", input.qd)] {
            if v.len() != nv {
                return Err(Fault::Length { input: name, expected: nv, got: v.len() });
            }
            if let Some(index) = v.iter().position(|x| !x.is_finite()) {
                return Err(Fault::NonFinite { input: name, index });
            }
        }
        Ok(())
    }

    /// The other inputs: one reading per cell, a usable time step.
    fn check_rest(&self, input: &ControllerInput) -> Result<(), Fault> {
        let cells = self.config.layout.num_cells();
        if input.cells.len() != cells {
            return Err(Fault::Length { input: "cells", expected: cells, got: input.cells.len() });
        }
        if !(input.dt_s.is_finite() && input.dt_s > 0.0) {
            return Err(Fault::BadTimeStep);
        }
        Ok(())
    }

    fn run(&mut self, input: &ControllerInput) -> Result<(), Fault> {
        self.check_state(input)?;
        self.check_rest(input)?;
        let first = !std::mem::replace(&mut self.started, true);
        self.clock.start();
        self.live.collect(input.cells);
        self.clock.lap(Stage::Skin);
        update_kinematics(&self.config.model, &mut self.data, input.q, input.qd).map_err(stage("kinematics"))?;
        self.clock.lap(Stage::Dynamics);

        // 1. signals and arrangement
        let signals = self.signals()?;
        self.output.signals = signals;
        self.supervisor.update(input.t_s, &signals);
        if first || self.supervisor.last_transition().is_some() {
            self.tasks.on_switch(&self.data); // x_ef,init of interactive-force-control paper Table 1's contact phase
        }
        let arrangement = self.supervisor.arrangement();
        let model = &self.config.model;

        // 2. skin: fused with w(t), patch wrenches, hand signals
        self.fusion.weight_force = arrangement.fusion_weight;
        self.output.fusion_weight = arrangement.fusion_weight;
        let layout = &self.config.layout;
        aggregate_live_patches(layout, &self.live, &self.fusion, &mut self.wrenches)
            .map_err(stage("skin aggregation"))?;
        let data = &self.data;
        // the hand signals read the hand and guidance patches' poses only
        let (hand, guidance) = (&self.hand_patches, &self.guidance_patches);
        patch_poses_world(layout, |f| data.frame_pose(f), |j| hand[j] || guidance[j], &mut self.patch_poses);

        let hand = self.hand_signals();
        self.output.hand_moment = data.frame_pose(self.ee).rotation.inverse_transform_vector(&hand.moment_world);
        self.clock.lap(Stage::Skin);

        // 3. tasks in priority order, posture, hierarchy
        let cx = Cycle {
            model,
            data,
            layout,
            skin: &self.config.skin,
            cells: &self.live,
            wrenches: &self.wrenches,
            body_patches: &self.body_patches,
            hand,
            goal: self.goal.as_ref(),
            sensing_range_m: arrangement.sensing_range_m,
            scan: input.scan,
            base_reference: self.resolver.base_joints().zip(self.base_reference),
            dt_s: input.dt_s,
        };
        let order = arrangement.task_order();
        let any_locked = self.locked.contains(&true);
        for &i in order {
            self.tasks.fill(i, &cx).map_err(stage("task update"))?;
            if any_locked {
                self.tasks.levels[i].lock_joints(&self.locked);
            }
        }
        let has_posture = self.tasks.posture_torque(order, &cx, &self.locked).map_err(stage("posture torque"))?;
        self.clock.lap(Stage::Tasks);
        let tasks = &self.tasks;
        let posture = has_posture.then(|| tasks.posture().as_slice());
        let active = order.iter().filter(|&&i| tasks.is_level(i)).map(|&i| &tasks.levels[i]);
        gravity(model, &mut self.data, &mut self.gravity).map_err(stage("gravity"))?;
        for (g, _) in self.gravity.iter_mut().zip(&self.locked).filter(|(_, &l)| l) {
            *g = 0.0; // a locked joint's virtual dynamics stay at rest (its τ* is 0)
        }
        match self.config.setup.hierarchy_dynamics {
            HierarchyDynamics::Model => {
                self.solver.model_dynamics(model, &mut self.data, true).map_err(stage("hierarchy"))?;
                self.clock.lap(Stage::Dynamics);
                self.solver.solve_with_model(active, posture, true, &mut self.tau_k)
            }
            HierarchyDynamics::Admittance | HierarchyDynamics::AdmittanceInertia => {
                self.resolver.virtual_mass(input.q, &mut self.mass);
                if self.config.setup.hierarchy_dynamics == HierarchyDynamics::Admittance {
                    self.resolver.virtual_damping(input.q, input.qd, input.dt_s, &mut self.bias);
                } else {
                    self.bias.fill(0.0); // the resolver's damping stays out: bias g alone
                }
                for (j, _) in self.locked.iter().enumerate().filter(|(_, &l)| l) {
                    self.bias[j] = 0.0;
                    self.mass.row_mut(j).fill(0.0); // decoupled from the free joints (base x-y block)
                    self.mass.column_mut(j).fill(0.0);
                    self.mass[(j, j)] = 1.0;
                }
                self.bias += &self.gravity;
                let dynamics = self.config.setup.hierarchy_dynamics;
                let goal = self.goal_level.filter(|g| order.contains(g) && self.tasks.levels[*g].rows() == 3);
                if let Some(g) = goal.filter(|_| dynamics == HierarchyDynamics::AdmittanceInertia) {
                    let damping = self.goal_damping.damping_torque_mut();
                    self.resolver.virtual_damping(input.q, input.qd, input.dt_s, damping);
                    for (d, _) in damping.iter_mut().zip(&self.locked).filter(|(_, &l)| l) {
                        *d = 0.0;
                    }
                    let (jt, goal_params) = (self.tasks.levels[g].jacobian_transpose(), &self.config.tasks.goal);
                    if !self.goal_damping.add(jt, &self.mass, input.qd, goal_params, &mut self.bias) {
                        return Err(Fault::Stage("goal damping"));
                    }
                }
                self.clock.lap(Stage::Dynamics);
                self.solver.solve(&self.mass, active, posture, Some(self.bias.as_slice()), &mut self.tau_k)
            }
        }
        .map_err(stage("hierarchy"))?;

        // 4. blend across switches
        self.blender.sync(arrangement);
        self.blender.apply(input.t_s, self.tau_k.as_slice(), self.tau.as_mut_slice());
        self.output.blend = if self.blender.is_blending() {
            chi(arrangement.smoothing_gain_per_s, input.t_s - arrangement.switch_time_s)
        } else {
            0.0
        };
        self.output.mode = arrangement.mode;
        self.output.blocked = self.supervisor.blocked();
        self.output.releasing = self.supervisor.releasing();
        self.output.torque_norm = self.tau.norm();
        self.clock.lap(Stage::Hierarchy);

        // 5. admittance resolver, within the skin's approach bound
        let intent = match self.supervisor.mode() {
            _ if self.output.releasing => ContactIntent::Release,
            Mode::IntentionalContact => ContactIntent::Push,
            _ => ContactIntent::Touch,
        };
        let (live, press) = (&self.live, &self.press);
        let bounds = self.resolver.closing_bounds_mut();
        self.approach
            .update(model, &self.data, layout, live, press, intent, input.dt_s, bounds)
            .map_err(stage("approach bound"))?;
        self.resolver
            .update(self.tau.as_slice(), self.gravity.as_slice(), input.q, input.qd, input.dt_s)
            .map_err(stage("resolver"))?;
        self.clock.lap(Stage::Resolver);
        self.clock.finish();
        Ok(())
    }

    /// The supervisor's inputs: `‖F_d‖` at the nominal range, the largest contact force, the
    /// end-effector speed and goal error (task summaries only: no rows are built here).
    fn signals(&mut self) -> Result<SupervisorInput, Fault> {
        let (model, data, config) = (&self.config.model, &self.data, &self.config);
        let (skin, layout) = (&config.skin, &config.layout);
        let nominal = config.supervisor.sensing_range.nominal_m;
        let avoid = self.proximity_signal.summarize(layout, &self.live, nominal).map_err(stage("avoidance"))?;
        let contact =
            self.contact_signal.summarize(layout, &self.live, &skin.fusion).map_err(stage("contact reaction"))?;
        self.press.update(layout, &self.live, &skin.fusion);
        let speed = point_velocity(model, data, self.ee, &nalgebra::Vector3::zeros())
            .map_err(stage("end-effector velocity"))?
            .norm();
        let advance = match contact.pressed {
            Some(c) => {
                let v = point_velocity(model, data, c.frame, &c.point).map_err(stage("contact advance"))?;
                (data.frame_pose(c.frame).rotation * c.force.normalize()).dot(&v)
            }
            None => f64::NAN,
        };
        let goal_error = self
            .goal
            .as_ref()
            .map_or(f64::NAN, |g| (g.translation.vector - data.frame_pose(self.ee).translation.vector).norm());
        Ok(SupervisorInput {
            ee_speed_mps: speed,
            avoidance_force_n: avoid.force_norm_n,
            contact_force_n: self.press.largest_link_n(),
            goal_error_m: goal_error,
            contact_advance_mps: advance,
        })
    }

    /// Interactive-force-control paper eq. (9)-(11) inputs from this cycle's skin: the hand's
    /// force and moment in newtons (`skin::measured`), the proximity signals' moment, the
    /// guidance patches' force.
    fn hand_signals(&self) -> HandSignals {
        let hand_pose = self.data.frame_pose(self.ee);
        let (poses, wrenches) = (&self.patch_poses, &self.wrenches);
        let (layout, fusion) = (&self.config.layout, &self.fusion);
        let z_hand = hand_pose.rotation * nalgebra::Vector3::z();
        let hand = |j: usize| self.hand_patches[j];
        let contact = measured_contact(layout, &self.live, &self.force, fusion, &z_hand, poses, hand);
        let mut s = HandSignals {
            force_n: contact.force_n,
            force_reference_n: self.hand_force_reference_n,
            guidance_force: sum_patch_forces_in_frame(hand_pose, poses, wrenches, |j| self.guidance_patches[j]),
            ..HandSignals::default()
        };
        s.wrist.force_world_nm = contact.moment_nm;
        s.wrist.fusion_weight = fusion.weight_force;
        for (j, (pose, w)) in poses.iter().zip(wrenches).enumerate() {
            if self.hand_patches[j] {
                s.proximity = s.proximity.max(w.max_proximity_signal);
                s.moment_world += patch_wrench_world(pose, w).moment;
                s.wrist.proximity_world += pose.rotation * w.proximity_moment;
            }
        }
        s
    }
}
