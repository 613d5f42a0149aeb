//! The simulated world of a scene: MuJoCo model and data generated from it ([`mjcf`]), the
//! robot's velocity interface (arm joint velocities, a base twist in the base frame), its state in
//! skin_core's joint order, scripted pushes and persons, and the simulated sensors sampled at
//! their rates: the [`skin_sensor`] (proximity rays, contact forces per cell), the [`lidar`]
//! and the physical contact forces of the [`probe`], with seeded [`noise`].

mod cell_face;
mod contact_patches;
mod frames;
pub mod lidar;
pub mod mjcf;
pub mod noise;
pub mod probe;
mod proximity_rays;
pub mod skin_sensor;

use std::path::Path;
use std::sync::Once;
use std::time::{Duration, Instant};

use mujoco_rs::prelude::*;
use nalgebra::{Isometry3, Point3, Vector3};
use skin_core::skin::markers::SkinMarker;
use skin_core::skin::signals::CellReading;
use thiserror::Error;

use crate::scene::spec::push_scale;
use crate::scene::{Scene, SceneError};
use crate::world::frames::{body_pose, FrameRef};
use crate::world::lidar::Lidar;
use crate::world::mjcf::{scene_xml, MjcfError};
use crate::world::skin_sensor::{SkinSensor, Touch};

/// The simulation's state at one moment of a run, for the recording's `/tf` and `/skin/markers`
/// and for rendering (`keyframes.json`): one frame of the run's [`crate::outputs::view::View`].
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct KeyFrame {
    /// Simulation time \[s\].
    pub t_s: f64,
    /// What happens then (`start`, `end`, a switch `(a) -> (b)`) for a key frame; empty for a
    /// frame of the view rate.
    pub label: String,
    /// The arrangement (`config/supervisor.yaml`'s name).
    pub mode: String,
    /// MuJoCo `qpos` (robot joints, movable objects).
    pub qpos: Vec<f64>,
    /// MuJoCo `mocap_pos` (persons).
    pub mocap_pos: Vec<[f64; 3]>,
    /// World (odom) pose of every link of [`crate::outputs::view::View::links`], `[x, y, z, qx, qy, qz, qw]`.
    pub poses: Vec<[f64; 7]>,
    /// The `/skin/markers` updates since the previous frame (applied in order, as RViz does).
    pub markers: Vec<SkinMarker>,
}

/// Errors building or driving a [`World`].
#[derive(Debug, Error)]
pub enum WorldError {
    /// The scene file is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The robot cannot be written as MJCF.
    #[error("{file}: {source}")]
    Mjcf {
        /// The scene file.
        file: String,
        /// What is wrong.
        source: MjcfError,
    },
    /// MuJoCo rejected the generated model.
    #[error("{file}: MuJoCo cannot load the generated model: {message}")]
    MuJoCo {
        /// The scene file.
        file: String,
        /// MuJoCo's message.
        message: String,
    },
    /// A command vector of the wrong length.
    #[error("expected {expected} arm joint velocities (model order of the arm joints), got {got}")]
    CommandLength {
        /// Number of arm joints of the model.
        expected: usize,
        /// Length given.
        got: usize,
    },
}

/// A model joint as MuJoCo holds it.
#[derive(Debug, Clone, Copy)]
struct JointIo {
    qpos: usize,
    dof: usize,
    actuator: usize,
}

/// A scripted push, resolved to a MuJoCo body.
#[derive(Debug, Clone, Copy)]
struct Push {
    body: usize,
    /// Point of application in the body frame.
    point: Point3<f64>,
    force: Vector3<f64>,
    start_s: f64,
    end_s: f64,
    ramp_s: f64,
    max_speed_mps: Option<f64>,
}

impl Push {
    /// The force acting now (world) \[N\]: none once the pushed point moves along it at the
    /// hand's speed ([`crate::scene::spec::PushSpec::max_speed_mps`]).
    fn force_now(&self, data: &MjData<Box<MjModel>>) -> Vector3<f64> {
        let force = self.force * push_scale(data.time(), self.start_s, self.end_s, self.ramp_s);
        let outrun = self.max_speed_mps.is_some_and(|v_max| {
            // Rotation then translation, at the body's centre of mass, world axes.
            let v = data.object_velocity(MjtObjBase::mjOBJ_BODY, self.body, false);
            let lever = (body_pose(data, self.body) * self.point).coords - Vector3::from(data.xipos()[self.body]);
            let velocity = Vector3::new(v[3], v[4], v[5]) + Vector3::new(v[0], v[1], v[2]).cross(&lever);
            force.norm() > 0.0 && velocity.dot(&force.normalize()) >= v_max
        });
        if outrun {
            Vector3::zeros()
        } else {
            force
        }
    }
}

/// The pushes acting now, as the skin feels them (pushes on objects touch no cell).
fn touches(pushes: &[Push], data: &MjData<Box<MjModel>>) -> Vec<Touch> {
    pushes
        .iter()
        .map(|p| (p, p.force_now(data)))
        .filter(|(_, force)| *force != Vector3::zeros())
        .map(|(p, force)| Touch { body: p.body, point: body_pose(data, p.body) * p.point, force })
        .collect()
}

/// A MuJoCo world built from a scene. One [`World::step`] advances one `timestep_s`; the skin and
/// the LIDAR are sampled during the steps at their own rates (and once at construction).
pub struct World {
    scene: Scene,
    mjcf: String,
    data: MjData<Box<MjModel>>,
    /// Per model joint: its MuJoCo addresses when it moves (None: frozen).
    joints: Vec<Option<JointIo>>,
    /// Model indices of the arm joints (all but the base joints), in model order.
    arm: Vec<usize>,
    /// Moving base joints (x, y, yaw), model indices.
    base: Option<[usize; 3]>,
    twist: [f64; 3],
    pushes: Vec<Push>,
    /// Mocap index of each scene person.
    persons: Vec<usize>,
    /// Each movable object's body and its z axis at the start (world): how far it tipped.
    movable: Vec<(usize, Vector3<f64>)>,
    skin: Option<SkinSensor>,
    lidar: Option<Lidar>,
    steps: u64,
    skin_every: u64,
    lidar_every: u64,
    q: Vec<f64>,
    qd: Vec<f64>,
    busy: BusyTime,
}

/// Wall-clock time the world's steps spent so far, by part (what bounds the simulation's speed).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BusyTime {
    /// In `mj_step`: collision detection, the constraint solver, integration.
    pub physics: Duration,
    /// In the simulated sensors (skin rays and contact forces, LIDAR scans) at their rates.
    pub sensors: Duration,
}

/// Routes MuJoCo's messages to the `log` crate once per process, instead of MUJOCO_LOG.TXT in
/// the working directory.
fn quiet_mujoco_log() {
    static ONCE: Once = Once::new();
    // SAFETY: installs a process-wide callback once; MuJoCo reads it only when it logs.
    ONCE.call_once(|| unsafe { install_logging_hook() });
}

fn steps_per(rate_hz: f64, timestep_s: f64) -> u64 {
    // Scene validation guarantees a whole number.
    (1.0 / (rate_hz * timestep_s)).round() as u64
}

impl World {
    /// Loads the scene file and builds its world.
    pub fn from_scene_file(path: &Path) -> Result<World, WorldError> {
        Self::from_scene(Scene::load(path)?)
    }

    /// Builds the world of a loaded scene, at its initial state (kinematics, skin and LIDAR
    /// evaluated at t = 0).
    pub fn from_scene(scene: Scene) -> Result<World, WorldError> {
        quiet_mujoco_log();
        let file = scene.file.clone();
        let xml = scene_xml(&scene).map_err(|source| WorldError::Mjcf { file: file.clone(), source })?;
        let mj = MjModel::from_xml_string(&xml).map_err(|e| WorldError::MuJoCo { file, message: e.to_string() })?;
        let model = &scene.model;
        let body = |name: &str| mj.name_to_id(MjtObjBase::mjOBJ_BODY, name).expect("generated body");
        let joints = (0..model.nv())
            .map(|j| {
                let name = &model.joint_names()[j];
                let id = mj.name_to_id(MjtObjBase::mjOBJ_JOINT, name)?;
                Some(JointIo {
                    qpos: mj.jnt_qposadr()[id] as usize,
                    dof: mj.jnt_dofadr()[id] as usize,
                    actuator: mj.name_to_id(MjtObjBase::mjOBJ_ACTUATOR, name).expect("actuator per joint"),
                })
            })
            .collect();
        let arm = (0..model.nv()).filter(|&j| !model.is_base_joint(j)).collect();
        let pushes = scene
            .spec
            .pushes
            .iter()
            .map(|p| {
                let (b, placement) = match (&p.object, &p.link) {
                    (Some(o), _) => (body(o), Isometry3::identity()),
                    (None, Some(link)) => {
                        let f = FrameRef::new(model, &mj, model.frame_index(link).expect("validated link"));
                        (f.body, f.placement)
                    }
                    (None, None) => unreachable!("validated: object or link"),
                };
                Push {
                    body: b,
                    point: placement * Point3::from(p.point_m),
                    force: Vector3::from(p.force_n),
                    start_s: p.start_s,
                    end_s: p.end_s,
                    ramp_s: p.ramp_s,
                    max_speed_mps: p.max_speed_mps,
                }
            })
            .collect();
        let persons = scene.spec.persons.iter().map(|p| mj.body_mocapid()[body(&p.name)] as usize).collect();
        let movable: Vec<usize> =
            scene.spec.objects.iter().filter(|o| o.mass_kg.is_some()).map(|o| body(&o.name)).collect();
        let skin = SkinSensor::new(&scene, &mj);
        let lidar = Lidar::new(&scene, &mj);
        let spec = &scene.spec;
        let skin_every = spec.skin.as_ref().map_or(0, |s| steps_per(s.rate_hz, spec.timestep_s));
        let lidar_every = spec.lidar.as_ref().map_or(0, |l| steps_per(l.rate_hz, spec.timestep_s));
        let n = model.nv();
        let mut world = World {
            mjcf: xml,
            base: scene.moving_base(),
            data: MjData::new(Box::new(mj)),
            joints,
            arm,
            twist: [0.0; 3],
            pushes,
            persons,
            movable: Vec::new(),
            skin,
            lidar,
            steps: 0,
            skin_every,
            lidar_every,
            q: scene.q0.clone(),
            qd: vec![0.0; n],
            busy: BusyTime::default(),
            scene,
        };
        for (j, io) in world.joints.iter().enumerate() {
            if let Some(io) = io {
                world.data.qpos_mut()[io.qpos] = world.scene.q0[j];
            }
        }
        world.apply_inputs();
        world.data.forward();
        world.movable = movable.into_iter().map(|b| world.body_axis_z(b)).collect();
        world.sample_sensors();
        Ok(world)
    }

    /// Body `b` and its z axis now (world).
    fn body_axis_z(&self, b: usize) -> (usize, Vector3<f64>) {
        (b, body_pose(&self.data, b).rotation * Vector3::z())
    }

    /// The largest tilt of a movable object from its start orientation \[deg\] (0 without
    /// any): over 45° a standing obstacle toppled, which a planar scene does not model.
    pub fn object_tilt_deg(&self) -> f64 {
        let tilt = |&(b, z0): &(usize, Vector3<f64>)| self.body_axis_z(b).1.angle(&z0).to_degrees();
        self.movable.iter().map(tilt).fold(0.0, f64::max)
    }

    /// The scene the world was built from.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// MuJoCo's model (read-only: for inspection, rendering, tests).
    pub fn mj_model(&self) -> &MjModel {
        self.data.model()
    }

    /// The current MuJoCo state as a key frame labelled `label` (no poses, no markers).
    pub fn key_frame(&self, label: String) -> KeyFrame {
        KeyFrame {
            t_s: self.time(),
            label,
            qpos: self.data.qpos().to_vec(),
            mocap_pos: self.data.mocap_pos().to_vec(),
            ..KeyFrame::default()
        }
    }

    /// The generated MJCF of the world.
    pub fn mjcf(&self) -> &str {
        &self.mjcf
    }

    /// MuJoCo's data (read-only).
    pub fn mj_data(&self) -> &MjData<Box<MjModel>> {
        &self.data
    }

    /// Simulation time \[s\].
    pub fn time(&self) -> f64 {
        self.data.ffi().time
    }

    /// Joint positions in skin_core's model order (frozen joints: their fixed value).
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Joint velocities in skin_core's model order (frozen joints: 0).
    pub fn qd(&self) -> &[f64] {
        &self.qd
    }

    /// Model indices of the arm joints, the order of [`Self::set_arm_velocity_commands`].
    pub fn arm_joints(&self) -> &[usize] {
        &self.arm
    }

    /// Commands the arm joint velocities \[rad/s or m/s\], one per arm joint in model order (as
    /// skin_core's resolver gives them); commands of frozen joints are ignored. The servos clamp
    /// to the URDF velocity limits. Held until the next call.
    pub fn set_arm_velocity_commands(&mut self, qd: &[f64]) -> Result<(), WorldError> {
        if qd.len() != self.arm.len() {
            return Err(WorldError::CommandLength { expected: self.arm.len(), got: qd.len() });
        }
        for (&j, &v) in self.arm.iter().zip(qd) {
            if let Some(io) = self.joints[j] {
                self.data.ctrl_mut()[io.actuator] = v;
            }
        }
        Ok(())
    }

    /// Commands the base twist `(vx \[m/s\], vy \[m/s\], wz \[rad/s\])` in the BASE frame; ignored when
    /// the scene freezes the base. Held until the next call; turned into world-frame joint
    /// velocities at every step from the current yaw.
    pub fn set_base_twist(&mut self, twist: [f64; 3]) {
        self.twist = twist;
    }

    /// The skin's last sample, indexed like the scene layout's cells (None: no skin).
    pub fn skin(&self) -> Option<&SkinSensor> {
        self.skin.as_ref()
    }

    /// The skin's last readings (empty without skin).
    pub fn skin_readings(&self) -> &[CellReading] {
        self.skin.as_ref().map_or(&[], |s| s.readings())
    }

    /// The LIDAR's last scan (None: no LIDAR).
    pub fn lidar(&self) -> Option<&Lidar> {
        self.lidar.as_ref()
    }

    /// World pose of a robot frame (URDF link index of the scene's model) at the current state.
    pub fn frame_pose(&self, frame: usize) -> Isometry3<f64> {
        FrameRef::new(&self.scene.model, self.data.model(), frame).world_pose(&self.data)
    }

    /// World position of a scene object or person (MuJoCo body by name), None if unknown.
    pub fn body_position(&self, name: &str) -> Option<[f64; 3]> {
        let b = self.data.model().name_to_id(MjtObjBase::mjOBJ_BODY, name)?;
        Some(self.data.xpos()[b])
    }

    /// Advances one timestep: scripted inputs at the current time, `mj_step`, the state, then the
    /// skin and the LIDAR when their periods come round.
    pub fn step(&mut self) {
        self.apply_inputs();
        let start = Instant::now();
        self.data.step();
        let stepped = Instant::now();
        self.steps += 1;
        self.read_state();
        self.sample_due_sensors();
        self.busy.physics += stepped - start;
        self.busy.sensors += stepped.elapsed();
    }

    /// Wall-clock time [`World::step`] spent so far in the physics and in the sensors.
    pub fn busy_time(&self) -> BusyTime {
        self.busy
    }

    /// Samples the skin and scans with the LIDAR now, at the current state (the steps do it at
    /// their rates).
    pub fn sample_sensors(&mut self) {
        if let Some(skin) = &mut self.skin {
            let touches = touches(&self.pushes, &self.data);
            skin.sample(&mut self.data, touches.into_iter());
        }
        if let Some(lidar) = &mut self.lidar {
            lidar.scan(&mut self.data);
        }
    }

    /// Base twist to joint velocities, pushes and persons at the current time.
    fn apply_inputs(&mut self) {
        if let Some([x, y, yaw]) = self.base {
            let (ix, iy, iw) = (self.io(x), self.io(y), self.io(yaw));
            let (s, c) = self.data.qpos()[iw.qpos].sin_cos();
            let [vx, vy, wz] = self.twist;
            let ctrl = self.data.ctrl_mut();
            ctrl[ix.actuator] = c * vx - s * vy;
            ctrl[iy.actuator] = s * vx + c * vy;
            ctrl[iw.actuator] = wz;
        }
        let t = self.time();
        for f in self.data.xfrc_applied_mut() {
            *f = [0.0; 6];
        }
        for k in 0..self.pushes.len() {
            let p = self.pushes[k];
            let force = p.force_now(&self.data);
            if force == Vector3::zeros() {
                continue;
            }
            // xfrc_applied acts at the body's centre of mass: add the moment of the offset.
            let pose = body_pose(&self.data, p.body);
            let com = Vector3::from(self.data.xipos()[p.body]);
            let torque = ((pose * p.point).coords - com).cross(&force);
            let f = &mut self.data.xfrc_applied_mut()[p.body];
            for i in 0..3 {
                f[i] += force[i];
                f[3 + i] += torque[i];
            }
        }
        for (k, person) in self.scene.spec.persons.iter().enumerate() {
            let [x, y] = person.position(t);
            self.data.mocap_pos_mut()[self.persons[k]] = [x, y, self.scene.spec.floor_z_m];
        }
    }

    fn io(&self, j: usize) -> JointIo {
        self.joints[j].expect("a moving joint")
    }

    fn read_state(&mut self) {
        let (qpos, qvel) = (self.data.qpos(), self.data.qvel());
        for (j, io) in self.joints.iter().enumerate() {
            if let Some(io) = io {
                self.q[j] = qpos[io.qpos];
                self.qd[j] = qvel[io.dof];
            }
        }
    }

    fn sample_due_sensors(&mut self) {
        if let Some(skin) = &mut self.skin {
            if self.steps % self.skin_every == 0 {
                let touches = touches(&self.pushes, &self.data);
                skin.sample(&mut self.data, touches.into_iter());
            }
        }
        if let Some(lidar) = &mut self.lidar {
            if self.steps % self.lidar_every == 0 {
                lidar.scan(&mut self.data);
            }
        }
    }
}
