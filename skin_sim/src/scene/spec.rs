//! The scene file schema (`config/scenes/*.yaml`), as written: every key, its unit and its
//! default. `docs/scenes.md` documents the same keys for readers of the files.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use skin_core::mesh::MeshMode;

/// One scene file. Relative paths are relative to the scene file's directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// The robot and the part of it that moves.
    pub robot: RobotSpec,
    /// Simulated skin (none: no skin readings).
    #[serde(default)]
    pub skin: Option<SkinSpec>,
    /// Simulated base LIDAR (none: no scan).
    #[serde(default)]
    pub lidar: Option<LidarSpec>,
    /// Boxes, cylinders, tables, walls around the robot.
    #[serde(default)]
    pub objects: Vec<ObjectSpec>,
    /// Scripted external forces on objects or robot links.
    #[serde(default)]
    pub pushes: Vec<PushSpec>,
    /// Person-sized bodies moving along scripted paths.
    #[serde(default)]
    pub persons: Vec<PersonSpec>,
    /// End-effector goals for the controller (data only: the simulation does not use them).
    #[serde(default)]
    pub goals: Vec<GoalSpec>,
    /// Contact force references for the controller (data only).
    #[serde(default)]
    pub force_references: Vec<ForceReferenceSpec>,
    /// Commanded base motions for the controller (interactive-force-control paper Exp. 1), relative to the base pose
    /// at the first one's start; they count as interaction periods of the metrics.
    #[serde(default)]
    pub base_motions: Vec<BaseMotionSpec>,
    /// Length of a run \[s\].
    pub duration_s: f64,
    /// MuJoCo integration step \[s\]; every other period is a multiple of it.
    #[serde(default = "default_timestep")]
    pub timestep_s: f64,
    /// Rate of the arm velocity commands \[Hz\] (TOMM's UR5: 125 Hz, interactive-force-control paper Sec. 4.1).
    #[serde(default = "default_control_rate")]
    pub control_rate_hz: f64,
    /// Height of the floor plane \[m\].
    #[serde(default)]
    pub floor_z_m: f64,
    /// Seed of every random number of the run (sensor noise).
    #[serde(default)]
    pub seed: u64,
    /// How the run is shown: camera and frame rate of the rendered frames and video.
    #[serde(default)]
    pub view: ViewSpec,
    /// What a run must show (`skin_sim::outputs::outcome`; none: the defaults of its kind of scene).
    #[serde(default)]
    pub expect: Option<ExpectSpec>,
}

impl SceneSpec {
    /// The windows `(start, end)` \[s\] of the pushes on objects (intentional-contact paper
    /// Fig. 2d: the obstacle pushed into the arm).
    pub fn object_push_windows(&self) -> Vec<(f64, f64)> {
        self.pushes.iter().filter(|p| p.object.is_some()).map(|p| (p.start_s, p.end_s)).collect()
    }
}

/// The outcome a run of the scene must show (`expect:`), beside what every run is checked for
/// (`skin_sim::outputs::safety`) and what every scene of its kind must show (a force scene: the first
/// touch, the rise, a finite from-touch RMS; a scene without goals and force references: no
/// link presses on anything). Absent: a scene with goals expects the supervisor's goal
/// tolerance and `ε_c`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectSpec {
    /// The final goal error must be at most this \[m\] (needs `goals`).
    #[serde(default)]
    pub goal_tolerance_m: Option<f64>,
    /// The largest contact force on one link outside the pushes (and 0.5 s after them) must be
    /// at most this, and every push on an object relieved within 0.5 s \[N\] (needs `goals`).
    #[serde(default)]
    pub eps_c_n: Option<f64>,
    /// The largest contact force on one link outside the pushes (and 0.5 s after them) must be
    /// at most this whatever the outcome, a blocked one included: the overshoot of a hard
    /// contact over `ε_c` that the contact reaction (intentional-contact paper eq. (6), first
    /// in Table I (c)) must cut short \[N\] (needs `goals`).
    #[serde(default)]
    pub max_contact_force_n: Option<f64>,
    /// Interactive-force-control paper Table 3 RMS force errors (needs `force_references`).
    #[serde(default)]
    pub force_targets: Option<ForceTargetsSpec>,
    /// The goal may be unreachable (a fixed or too heavy obstacle): a run that ends `blocked`
    /// passes when it is safe; the goal and `eps_c_n` checks then do not apply (needs `goals`).
    #[serde(default)]
    pub safety: bool,
}

/// Interactive-force-control paper Table 3 targets: RMS force-tracking errors \[N\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceTargetsSpec {
    /// Without interactions (`rms_force_error_from_reach_n`).
    pub rms_without_n: f64,
    /// During interactions (`rms_force_error_interaction_n`).
    pub rms_with_n: f64,
}

/// How a run is shown (`view:`): the camera of the rendered frames (MuJoCo's free camera) and
/// the rate of the video frames and of the recording's `/tf` and `/skin/markers`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ViewSpec {
    /// Point the camera looks at, world \[m\] (none: the centre of the model's bounding box).
    pub lookat_m: Option<[f64; 3]>,
    /// Distance of the camera from `lookat_m` \[m\] (none: 1.6 times the model's extent).
    pub distance_m: Option<f64>,
    /// Camera azimuth about the world z axis \[deg\] (90: looking along +y).
    pub azimuth_deg: f64,
    /// Camera elevation \[deg\] (negative: from above; -90: straight down).
    pub elevation_deg: f64,
    /// Frames per second of the view \[Hz\], at most the control rate.
    pub fps: f64,
}

impl Default for ViewSpec {
    fn default() -> Self {
        ViewSpec { lookat_m: None, distance_m: None, azimuth_deg: 135.0, elevation_deg: -35.0, fps: 10.0 }
    }
}

fn default_timestep() -> f64 {
    0.001
}
fn default_control_rate() -> f64 {
    125.0
}

/// The robot: its URDF, the joints that move, and where every joint starts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// URDF file.
    pub urdf: PathBuf,
    /// Moving joints kept in the simulation (none: all). Every other joint is frozen: welded at
    /// its `initial` position.
    #[serde(default)]
    pub joints: Option<Vec<String>>,
    /// Joint positions \[rad or m\] by joint name: where kept joints start and where frozen
    /// joints stay. Unlisted joints: 0.
    #[serde(default)]
    pub initial: BTreeMap<String, f64>,
    /// Mesh collision elements of the URDF: `mesh` (MuJoCo collides with each mesh's convex
    /// hull) or `box` (with its fitted box, the primitive approximation). Generate the skin
    /// layout with the same choice (`skin_layout --meshes`) so the cells lie on what collides.
    #[serde(default)]
    pub meshes: MeshMode,
    /// Directories searched for `package://` mesh URIs (relative to the scene file), before
    /// `ROS_PACKAGE_PATH` and `AMENT_PREFIX_PATH` (`skin_core::mesh::package`).
    #[serde(default)]
    pub package_path: Vec<PathBuf>,
}

/// The simulated skin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkinSpec {
    /// Skin layout file (`config/skin/<robot>.yaml`).
    pub layout: PathBuf,
    /// Skin model parameters (`config/skin_model.yaml`): the cells' characteristics.
    pub params: PathBuf,
    /// Ids of the patches that sense (none: all); cells of other patches read 0.
    #[serde(default)]
    pub patches: Option<Vec<u32>>,
    /// Sample rate \[Hz\] (interactive-force-control paper Sec. 4.1: 250 Hz).
    #[serde(default = "default_skin_rate")]
    pub rate_hz: f64,
    /// A contact that presses no cell's face (a corner or an edge between the faces' sample
    /// points) is given to the cells of the touched link within this distance of its points \[m\]
    /// (about one cell pitch).
    #[serde(default = "default_contact_radius")]
    pub contact_radius_m: f64,
    /// Radius of a cell's sensing face \[m\]: a contact loads the cells whose faces it presses,
    /// each in proportion to its face's compression. The cells tile the skin (hexagons of the
    /// layout's pitch `p`, 0.03 m), so a face is the disk of a tile's area, `0.525 p`.
    #[serde(default = "default_cell_radius")]
    pub cell_radius_m: f64,
    /// Standard deviation of the Gaussian noise added to each proximity signal (normalized).
    #[serde(default)]
    pub proximity_noise_std: f64,
    /// Standard deviation of the Gaussian noise added to each force signal (normalized).
    #[serde(default)]
    pub force_noise_std: f64,
}

fn default_skin_rate() -> f64 {
    250.0
}
fn default_contact_radius() -> f64 {
    0.035
}
fn default_cell_radius() -> f64 {
    0.016
}

/// A planar LIDAR fan in the plane of a robot frame (its x-y plane), reported in the base frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarSpec {
    /// The URDF link the scanner is at.
    #[serde(default = "default_lidar_frame")]
    pub frame: String,
    /// Number of rays, evenly spread over `fov_deg`.
    #[serde(default = "default_rays")]
    pub rays: usize,
    /// Field of view \[deg\], centred on the frame's x axis.
    #[serde(default = "default_fov")]
    pub fov_deg: f64,
    /// Maximum range \[m\]; farther hits are not reported.
    #[serde(default = "default_range")]
    pub range_m: f64,
    /// Scan rate \[Hz\].
    #[serde(default = "default_lidar_rate")]
    pub rate_hz: f64,
    /// Standard deviation of the Gaussian noise added to each range \[m\].
    #[serde(default)]
    pub noise_std_m: f64,
}

impl LidarSpec {
    /// The fan's first ray angle and the angle between rays \[rad\], in the scanner frame: a full
    /// circle has no end ray, a partial fan includes both of its edges.
    pub fn fan(&self) -> (f64, f64) {
        let fov = self.fov_deg.to_radians();
        let step = if self.rays == 1 {
            0.0
        } else if self.fov_deg >= 360.0 {
            fov / self.rays as f64
        } else {
            fov / (self.rays - 1) as f64
        };
        (if self.rays == 1 { 0.0 } else { -fov / 2.0 }, step)
    }
}

fn default_lidar_frame() -> String {
    "laser".into()
}
fn default_rays() -> usize {
    360
}
fn default_fov() -> f64 {
    360.0
}
fn default_range() -> f64 {
    10.0
}
fn default_lidar_rate() -> f64 {
    40.0
}

/// A rigid object: fixed to the world, or free (movable) when it has a mass.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name (also the MuJoCo body name).
    pub name: String,
    /// Geometry.
    pub shape: ShapeSpec,
    /// Position of the object frame in the world \[m\] (a table: the floor point under its top's
    /// centre).
    pub xyz: [f64; 3],
    /// Orientation, roll-pitch-yaw \[rad\] (URDF convention); a tilted wall is a rotated box.
    #[serde(default)]
    pub rpy: [f64; 3],
    /// Mass \[kg\]: the object is free (movable). None: fixed to the world.
    #[serde(default)]
    pub mass_kg: Option<f64>,
    /// Sliding friction coefficient against anything it touches.
    #[serde(default = "default_friction")]
    pub friction: f64,
    /// Time constant of the object's contacts (MuJoCo `solref`, critically damped) \[s\]: the
    /// contact's stiffness falls with its square. MuJoCo's default 0.02 s makes a rigid surface
    /// (about 1e5 N/m against the TOMM palm); a larger one stands for a compliant surface, or
    /// the soft cover of the skin pressed on it.
    #[serde(default = "default_contact_time_constant")]
    pub contact_time_constant_s: f64,
}

fn default_friction() -> f64 {
    1.0
}
fn default_contact_time_constant() -> f64 {
    0.02
}

/// Object geometry; lengths in m, centred on the object frame (cylinders and capsules along z).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// Box with full edge lengths.
    Box {
        /// Edge lengths along x, y, z \[m\].
        size_m: [f64; 3],
    },
    /// Cylinder along z.
    Cylinder {
        /// Radius \[m\].
        radius_m: f64,
        /// Length \[m\].
        length_m: f64,
    },
    /// Sphere.
    Sphere {
        /// Radius \[m\].
        radius_m: f64,
    },
    /// Capsule along z.
    Capsule {
        /// Radius \[m\].
        radius_m: f64,
        /// Length of the cylindrical part \[m\].
        length_m: f64,
    },
    /// A table: a box top on four cylindrical legs at its corners, standing on the object frame.
    Table {
        /// Top edge lengths along x, y and its thickness \[m\].
        top_m: [f64; 3],
        /// Height of the top's upper surface above the object frame \[m\].
        height_m: f64,
        /// Leg radius \[m\].
        #[serde(default = "default_leg_radius")]
        leg_radius_m: f64,
    },
}

fn default_leg_radius() -> f64 {
    0.025
}

/// A constant force on an object or a robot link during a time window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PushSpec {
    /// Target object name (exactly one of `object`, `link`).
    #[serde(default)]
    pub object: Option<String>,
    /// Target robot link (URDF link name).
    #[serde(default)]
    pub link: Option<String>,
    /// Force in the world frame \[N\].
    pub force_n: [f64; 3],
    /// Point of application in the target's frame \[m\].
    #[serde(default)]
    pub point_m: [f64; 3],
    /// Start of the window \[s\].
    pub start_s: f64,
    /// End of the window \[s\].
    pub end_s: f64,
    /// Rise and fall time of the force \[s\] (a hand's touch builds up and lets go: the force
    /// ramps linearly from 0 over the window's first and last `ramp_s`); 0: a step.
    #[serde(default)]
    pub ramp_s: f64,
    /// Speed of the hand that pushes \[m/s\]: the force acts only while the pushed point moves
    /// slower than this along it (a person pushing an object into the arm, intentional-contact
    /// paper Fig. 2d, follows it at a hand's speed; an unbounded force on an object that meets
    /// nothing throws it). None: the force acts whatever the speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_speed_mps: Option<f64>,
}

/// The fraction of a push's force acting at time `t`: 0 outside `[start_s, end_s)`, ramping
/// linearly over the window's first and last `ramp_s` (see [`PushSpec::ramp_s`]).
pub fn push_scale(t: f64, start_s: f64, end_s: f64, ramp_s: f64) -> f64 {
    if t < start_s || t >= end_s {
        0.0
    } else if ramp_s > 0.0 {
        ((t - start_s) / ramp_s).min((end_s - t) / ramp_s).min(1.0)
    } else {
        1.0
    }
}

/// A person-sized vertical capsule standing on the floor, moved along a path (a mocap body: it
/// pushes whatever it meets and is seen by the skin and the LIDAR).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PersonSpec {
    /// Unique name (also the MuJoCo body name).
    pub name: String,
    /// Radius \[m\].
    #[serde(default = "default_person_radius")]
    pub radius_m: f64,
    /// Height \[m\].
    #[serde(default = "default_person_height")]
    pub height_m: f64,
    /// Waypoints, times strictly increasing; the position is interpolated linearly between them
    /// and held before the first and after the last.
    pub path: Vec<WaypointSpec>,
}

fn default_person_radius() -> f64 {
    0.2
}
fn default_person_height() -> f64 {
    1.7
}

/// One waypoint of a person's path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaypointSpec {
    /// Time \[s\].
    pub t_s: f64,
    /// Floor position, world x and y \[m\].
    pub xy_m: [f64; 2],
}

/// A goal of an end-effector frame from a start time on (intentional-contact paper eq. (7)-(9)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GoalSpec {
    /// The URDF link (frame) that should reach the goal.
    pub frame: String,
    /// When the goal becomes active \[s\].
    #[serde(default)]
    pub start_s: f64,
    /// Goal position in the world \[m\].
    pub position_m: [f64; 3],
    /// Goal orientation, roll-pitch-yaw in the world \[rad\] (none: position only).
    #[serde(default)]
    pub rpy: Option<[f64; 3]>,
}

/// A contact force reference from a start time on: `mean + amplitude sin(2 pi (t - start) / period)`
/// (interactive-force-control paper Exp. 1, 3: sinusoids; Exp. 4: constant).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceReferenceSpec {
    /// When the reference becomes active \[s\].
    #[serde(default)]
    pub start_s: f64,
    /// Mean force \[N\].
    pub mean_n: f64,
    /// Amplitude \[N\] (0: constant).
    #[serde(default)]
    pub amplitude_n: f64,
    /// Period \[s\] (required when the amplitude is not 0).
    #[serde(default)]
    pub period_s: Option<f64>,
}

/// A commanded base motion during `[start_s, end_s)` (interactive-force-control paper Exp. 1: a circle, then lateral
/// swings), an offset of the base's x, y from the pose the base had when the first motion
/// started (its yaw is held). The offset's size is faded in over `ramp_s` after the start and
/// out over `ramp_s` before the end (a C¹ smoothstep), so the commanded position and velocity
/// have no step. Exactly one of `circle`, `swing`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseMotionSpec {
    /// Start of the window \[s\].
    pub start_s: f64,
    /// End of the window \[s\].
    pub end_s: f64,
    /// Fade-in and fade-out time \[s\] (at most half the window).
    #[serde(default = "default_ramp")]
    pub ramp_s: f64,
    /// A circle about the start pose.
    #[serde(default)]
    pub circle: Option<CircleSpec>,
    /// Swings to and fro along an axis through the start pose.
    #[serde(default)]
    pub swing: Option<SwingSpec>,
}

fn default_ramp() -> f64 {
    5.0
}

/// A circle about the start pose, counter-clockwise seen from above, starting along +x.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// Radius \[m\].
    pub radius_m: f64,
    /// Time of one turn \[s\] (base speed `2π radius / period`).
    pub period_s: f64,
}

/// `amplitude sin(2π (t − start) / period)` along a world-frame axis through the start pose.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwingSpec {
    /// Amplitude \[m\].
    pub amplitude_m: f64,
    /// Period of one swing to and fro \[s\] (peak speed `2π amplitude / period`).
    pub period_s: f64,
    /// World-frame direction (x, y), normalized on use.
    pub axis: [f64; 2],
}

impl ForceReferenceSpec {
    /// The reference at time `t_s` (the mean before `start_s`, where no sinusoid has begun).
    pub fn value(&self, t_s: f64) -> f64 {
        match self.period_s {
            Some(p) if t_s > self.start_s => {
                self.mean_n + self.amplitude_n * (std::f64::consts::TAU * (t_s - self.start_s) / p).sin()
            }
            _ => self.mean_n,
        }
    }
}

impl PersonSpec {
    /// Floor position at time `t_s`: piecewise-linear along the path, held at its ends.
    pub fn position(&self, t_s: f64) -> [f64; 2] {
        let path = &self.path;
        let (first, last) = (path[0], path[path.len() - 1]);
        if t_s <= first.t_s {
            return first.xy_m;
        }
        if t_s >= last.t_s {
            return last.xy_m;
        }
        // Validation guarantees increasing times, so exactly one segment contains t_s.
        let k = path.partition_point(|w| w.t_s <= t_s);
        let (a, b) = (path[k - 1], path[k]);
        let s = (t_s - a.t_s) / (b.t_s - a.t_s);
        [a.xy_m[0] + s * (b.xy_m[0] - a.xy_m[0]), a.xy_m[1] + s * (b.xy_m[1] - a.xy_m[1])]
    }
}
