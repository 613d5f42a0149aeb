//! The in-process closed loop: a MuJoCo [`World`] and a skin_core [`Controller`] in lockstep at
//! the scene's control rate. Per control period: read the world (q, q̇ in model order, skin
//! cells, LIDAR points in the base frame), give the controller the scene's goal, force
//! reference, base motion and phase for this time ([`Schedule`]), run `Controller::update`, send its arm
//! joint velocities and base twist, and step the world through the period. Nothing depends on
//! wall-clock time, so a run is a function of the scene (and its seed).
//!
//! Frozen joints of the scene (welded in the world) are seen by the controller at their fixed
//! position with zero velocity and are locked in it (setup `locked_joints`): no task uses them,
//! so their commands, which the world drops, stay zero.

use std::path::Path;
use std::time::Instant;

use nalgebra::Vector2;
use skin_core::controller::{Controller, ControllerConfig, ControllerInput, SetupError};
use thiserror::Error;

use crate::outputs::record::{CycleRecord, RunRecord, Switch};
use crate::outputs::view::ViewRecorder;
use crate::run::interaction::Interactions;
use crate::run::schedule::{Schedule, ScheduleError, ScheduledInputs};
use crate::scene::Scene;
use crate::world::probe::ContactProbe;
use crate::world::{World, WorldError};

/// Why a closed loop could not be built or run.
#[derive(Debug, Error)]
pub enum LoopError {
    /// The scene or its world.
    #[error(transparent)]
    World(#[from] WorldError),
    /// The controller setup.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// Controller and scene disagree on the robot.
    #[error("{scene} vs {setup}: {reason}")]
    Mismatch {
        /// The scene file.
        scene: String,
        /// The controller setup file.
        setup: String,
        /// What differs.
        reason: String,
    },
    /// A scene input the controller cannot take.
    #[error("{file}: {error}")]
    Schedule {
        /// The scene file.
        file: String,
        /// The input.
        error: ScheduleError,
    },
}

/// A world and its controller, stepped together one control period at a time.
pub struct ClosedLoop {
    world: World,
    controller: Controller,
    schedule: Schedule,
    interactions: Interactions,
    probe: ContactProbe,
    steps_per_cycle: u64,
    dt_s: f64,
    scan: Vec<Vector2<f64>>,
    view: ViewRecorder,
    record: RunRecord,
}

impl ClosedLoop {
    /// The loop of `scene` with the controller of the setup file `setup`; the controller's robot
    /// must be the scene's (same joints in the same order). The joints the scene freezes are
    /// locked in the controller (no task uses them: their commands would be dropped).
    pub fn new(scene: Scene, setup: &Path) -> Result<Self, LoopError> {
        let mut config = ControllerConfig::load(setup)?;
        let frozen = scene.model.joint_names().iter().zip(&scene.moving).filter(|(_, &moving)| !moving);
        config.setup.locked_joints = frozen.map(|(name, _)| name.clone()).collect();
        let controller = Controller::new(config, 0.0)?;
        let world = World::from_scene(scene)?;
        let scene = world.scene();
        let mismatch = |reason: String| LoopError::Mismatch {
            scene: scene.file.clone(),
            setup: setup.display().to_string(),
            reason,
        };
        let model = &controller.config().model;
        if model.joint_names() != scene.model.joint_names() {
            return Err(mismatch(format!("joints {:?} vs {:?}", scene.model.joint_names(), model.joint_names())));
        }
        if controller.resolver().arm_joints() != world.arm_joints() {
            return Err(mismatch("the resolver's arm joints are not the world's".into()));
        }
        let cells = world.skin_readings().len();
        if cells != controller.config().layout.num_cells() {
            let n = controller.config().layout.num_cells();
            return Err(mismatch(format!("{cells} skin cells in the scene, {n} in the controller's layout")));
        }
        let schedule = Schedule::new(scene, &controller)
            .map_err(|error| LoopError::Schedule { file: scene.file.clone(), error })?;
        let ee = model.frame_index(&controller.config().setup.end_effector).expect("checked by Controller::new");
        let spec = &scene.spec;
        let record = RunRecord {
            name: Path::new(&scene.file).file_stem().map_or_else(String::new, |s| s.to_string_lossy().into()),
            scene_file: scene.file.clone(),
            joint_names: model.joint_names().to_vec(),
            arm_joints: world.arm_joints().iter().map(|&j| model.joint_names()[j].clone()).collect(),
            control_rate_hz: spec.control_rate_hz,
            timestep_s: spec.timestep_s,
            seed: spec.seed,
            eps_v_mps: controller.config().supervisor.thresholds.speed_mps,
            eps_c_n: controller.config().supervisor.thresholds.contact_force_n,
            object_pushes: spec.object_push_windows(),
            cycles: Vec::new(),
            switches: Vec::new(),
            wall_time_s: 0.0,
            busy: Default::default(),
            mjcf: world.mjcf().to_string(),
            view: Default::default(),
        };
        Ok(ClosedLoop {
            steps_per_cycle: (1.0 / (spec.control_rate_hz * spec.timestep_s)).round() as u64,
            dt_s: 1.0 / spec.control_rate_hz,
            interactions: Interactions::new(scene, controller.config().tasks.base_avoidance),
            probe: ContactProbe::new(&world, ee),
            scan: Vec::new(),
            view: ViewRecorder::new(scene, controller.config()),
            schedule,
            controller,
            world,
            record,
        })
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The controller.
    pub fn controller(&self) -> &Controller {
        &self.controller
    }

    /// The scene's schedule (goals, force references, hand force map).
    pub fn schedule(&self) -> &Schedule {
        &self.schedule
    }

    /// The record so far.
    pub fn record(&self) -> &RunRecord {
        &self.record
    }

    /// One control period: measure, decide, command, step. Returns the cycle's record.
    pub fn cycle(&mut self) -> &CycleRecord {
        let t_s = self.world.time();
        self.scan.clear();
        if let Some(lidar) = self.world.lidar() {
            self.scan.extend(lidar.points().iter().map(|&[x, y]| Vector2::new(x, y)));
        }
        let scheduled = self.schedule.apply(t_s, self.world.q(), &mut self.controller);
        let input = ControllerInput {
            t_s,
            dt_s: self.dt_s,
            q: self.world.q(),
            qd: self.world.qd(),
            cells: self.world.skin_readings(),
            scan: &self.scan,
        };
        let start = Instant::now();
        let out = self.controller.update(&input);
        let compute_us = start.elapsed().as_secs_f64() * 1e6;
        let forces = self.probe.measure(&self.world);
        let fault = match (scheduled, out.fault) {
            (Err(f), _) | (Ok(_), Some(f)) => Some(f.to_string()),
            _ => None,
        };
        let scheduled = scheduled.unwrap_or(ScheduledInputs::NONE);
        let cycle = CycleRecord {
            t_s,
            q: input.q.to_vec(),
            qd: input.qd.to_vec(),
            joint_velocities: out.commands.joint_velocities.clone(),
            base_twist: out.commands.base_twist,
            mode: out.mode,
            blocked: out.blocked,
            releasing: out.releasing,
            blend: out.blend,
            fusion_weight: out.fusion_weight,
            signals: out.signals,
            torque_norm: out.torque_norm,
            hand_force_n: forces.hand_n,
            link_force_n: forces.max_link_n,
            hand_position_m: forces.hand_position_m,
            hand_distance_m: forces.hand_distance_m,
            object_tilt_deg: forces.object_tilt_deg,
            hand_moment: out.hand_moment.into(),
            force_reference_n: scheduled.force_n,
            force_reference_signal: scheduled.force_signal,
            interaction: self.interactions.active(t_s, input.q),
            fault,
            compute_us,
        };
        let mut event = self.record.cycles.is_empty().then(|| "start".to_string());
        if let Some(tr) = self.controller.supervisor().last_transition() {
            self.record.switches.push(Switch { t_s: tr.t_s, from: tr.from, to: tr.to });
            event = Some(format!("{} -> {}", tr.from.name(), tr.to.name()));
        }
        self.view.cycle(&self.world, cycle.mode, event);
        let commands = &self.controller.output().commands;
        self.world.set_arm_velocity_commands(&commands.joint_velocities).expect("arm joints checked in new");
        self.world.set_base_twist(commands.base_twist);
        for _ in 0..self.steps_per_cycle {
            self.world.step();
        }
        self.record.cycles.push(cycle);
        self.record.cycles.last().expect("just pushed")
    }

    /// Runs `duration_s` of simulated time (whole control periods), calling `progress` with the
    /// fraction done after every cycle, and returns the record.
    pub fn run(mut self, duration_s: f64, mut progress: impl FnMut(f64)) -> RunRecord {
        let cycles = (duration_s / self.dt_s).round() as usize;
        let start = Instant::now();
        self.record.cycles.reserve(cycles);
        for k in 0..cycles {
            self.cycle();
            progress((k + 1) as f64 / cycles as f64);
        }
        self.record.wall_time_s = start.elapsed().as_secs_f64();
        self.record.busy = self.world.busy_time();
        let mode = self.record.cycles.last().map_or(self.controller.output().mode, |c| c.mode);
        self.record.view = self.view.finish(&self.world, mode);
        self.record
    }
}
