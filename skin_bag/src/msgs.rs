//! Plain Rust mirrors of the ROS 2 messages the skin_control graph carries. Field order and types
//! follow the `.msg` definitions exactly: the serde derive is the CDR layout.

use serde::{Deserialize, Serialize};

/// A message type that can be written to (and read from) a bag.
pub trait RosMessage: Serialize + serde::de::DeserializeOwned {
    /// Full type name as rosbag2 stores it, e.g. `sensor_msgs/msg/JointState`.
    const TYPE_NAME: &'static str;
}

macro_rules! ros_type {
    ($($ty:ident => $name:literal),* $(,)?) => {
        $(impl RosMessage for $ty {
            const TYPE_NAME: &'static str = $name;
        })*
    };
}

ros_type! {
    Time => "builtin_interfaces/msg/Time",
    Header => "std_msgs/msg/Header",
    Clock => "rosgraph_msgs/msg/Clock",
    JointState => "sensor_msgs/msg/JointState",
    Odometry => "nav_msgs/msg/Odometry",
    LaserScan => "sensor_msgs/msg/LaserScan",
    Twist => "geometry_msgs/msg/Twist",
    Float64MultiArray => "std_msgs/msg/Float64MultiArray",
    SkinCellArray => "skin_msgs/msg/SkinCellArray",
    PatchWrenchArray => "skin_msgs/msg/PatchWrenchArray",
    Arrangement => "skin_msgs/msg/Arrangement",
    ControllerState => "skin_msgs/msg/ControllerState",
    StringMsg => "std_msgs/msg/String",
    TfMessage => "tf2_msgs/msg/TFMessage",
    MarkerArray => "visualization_msgs/msg/MarkerArray",
}

/// `builtin_interfaces/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds within the second, `< 1e9`.
    pub nanosec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after the epoch (sim time starts at 0).
    pub fn from_nanos(ns: u64) -> Self {
        // i32 seconds last until 2038 (wall clock) or 68 years of sim time.
        Self { sec: (ns / 1_000_000_000) as i32, nanosec: (ns % 1_000_000_000) as u32 }
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Stamp of the data.
    pub stamp: Time,
    /// Frame the data is expressed in.
    pub frame_id: String,
}

/// `rosgraph_msgs/Clock`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Clock {
    /// The current simulation time.
    pub clock: Time,
}

/// `sensor_msgs/JointState`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointState {
    /// Stamp of the sample.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions \[rad or m\].
    pub position: Vec<f64>,
    /// Velocities \[rad/s or m/s\].
    pub velocity: Vec<f64>,
    /// Efforts \[N m or N\].
    pub effort: Vec<f64>,
}

/// `geometry_msgs/Vector3`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/Point`: same layout as [`Vector3`], a position.
pub type Point = Vector3;

/// `geometry_msgs/Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    /// The identity rotation (the `.msg` default).
    fn default() -> Self {
        Self { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position \[m\].
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/PoseWithCovariance`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Row-major 6x6 covariance (x, y, z, rotations about x, y, z).
    #[serde(with = "fixed_array")]
    pub covariance: [f64; 36],
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity \[m/s\].
    pub linear: Vector3,
    /// Angular velocity \[rad/s\].
    pub angular: Vector3,
}

/// `geometry_msgs/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Row-major 6x6 covariance.
    #[serde(with = "fixed_array")]
    pub covariance: [f64; 36],
}

// serde and Default stop at 32-element arrays: the covariances need these by hand.
impl Default for PoseWithCovariance {
    fn default() -> Self {
        Self { pose: Pose::default(), covariance: [0.0; 36] }
    }
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        Self { twist: Twist::default(), covariance: [0.0; 36] }
    }
}

/// `geometry_msgs/Wrench`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Wrench {
    /// Force \[N\].
    pub force: Vector3,
    /// Moment \[N m\].
    pub torque: Vector3,
}

/// `nav_msgs/Odometry`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// Stamp; `frame_id`: the frame of the pose (odom).
    pub header: Header,
    /// The frame of the twist (base).
    pub child_frame_id: String,
    /// Pose in `header.frame_id`.
    pub pose: PoseWithCovariance,
    /// Twist in `child_frame_id`.
    pub twist: TwistWithCovariance,
}

/// `sensor_msgs/LaserScan`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LaserScan {
    /// Stamp of the first ray; frame of the scanner.
    pub header: Header,
    /// Angle of the first ray \[rad\].
    pub angle_min: f32,
    /// Angle of the last ray \[rad\].
    pub angle_max: f32,
    /// Angle between rays \[rad\].
    pub angle_increment: f32,
    /// Time between rays \[s\].
    pub time_increment: f32,
    /// Time between scans \[s\].
    pub scan_time: f32,
    /// Minimum valid range \[m\].
    pub range_min: f32,
    /// Maximum valid range \[m\].
    pub range_max: f32,
    /// Ranges \[m\].
    pub ranges: Vec<f32>,
    /// Intensities (device units), may be empty.
    pub intensities: Vec<f32>,
}

/// `std_msgs/MultiArrayDimension`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiArrayDimension {
    /// Label of the dimension.
    pub label: String,
    /// Size of the dimension.
    pub size: u32,
    /// Stride of the dimension.
    pub stride: u32,
}

/// `std_msgs/MultiArrayLayout`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiArrayLayout {
    /// Dimensions (empty: a plain vector).
    pub dim: Vec<MultiArrayDimension>,
    /// Padding elements at the front of `data`.
    pub data_offset: u32,
}

/// `std_msgs/Float64MultiArray` (the forward velocity controller's command).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Float64MultiArray {
    /// Layout of `data`.
    pub layout: MultiArrayLayout,
    /// The values.
    pub data: Vec<f64>,
}

/// `skin_msgs/SkinCellArray`: one array per signal, cell k at index k (three values per cell
/// for `force` and `acceleration`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SkinCellArray {
    /// Sampling time.
    pub header: Header,
    /// Cell ids from the skin layout, n.
    pub cell_id: Vec<u32>,
    /// The three normalized force sensors per cell, \[0, 1\], 3n.
    pub force: Vec<f32>,
    /// Normalized proximity per cell, \[0, 1\], n.
    pub proximity: Vec<f32>,
    /// Acceleration in the cell frame \[m/s^2\], 3n or none.
    pub acceleration: Vec<f32>,
    /// Temperature \[degC\], n or none.
    pub temperature: Vec<f32>,
}

/// `skin_msgs/PatchWrench`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PatchWrench {
    /// Patch frame and the stamp of the cell data.
    pub header: Header,
    /// Patch id from the skin layout.
    pub patch_id: u32,
    /// URDF link the patch is mounted on.
    pub link: String,
    /// Patch wrench in the patch frame.
    pub wrench: Wrench,
    /// Centroid of the active cells in the patch frame \[m\].
    pub centroid: Point,
    /// Number of active cells.
    pub active_cells: u32,
    /// Largest normalized force signal, \[0, 1\].
    pub max_force: f32,
    /// Largest normalized proximity signal, \[0, 1\].
    pub max_proximity: f32,
}

/// `skin_msgs/PatchWrenchArray`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PatchWrenchArray {
    /// Stamp of the cell data.
    pub header: Header,
    /// Every patch's wrench.
    pub patches: Vec<PatchWrench>,
}

/// `skin_msgs/Arrangement`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Arrangement {
    /// `MODE_*` constant of the `.msg`.
    pub mode: u8,
    /// Task names, highest priority first.
    pub task_order: Vec<String>,
    /// When the switch was triggered.
    pub switch_time: Time,
    /// Smoothing gain \[1/s\].
    pub smoothing_gain: f64,
    /// Proximity sensing range \[m\].
    pub sensing_range: f64,
    /// Fusion weight, \[0, 1\].
    pub fusion_weight: f64,
    /// The blocked hold.
    pub blocked: BlockedHold,
}

/// `skin_msgs/BlockedHold`: why the arm holds in (a) after a push that reached `ε_c`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct BlockedHold {
    /// Blocked.
    pub active: bool,
    /// When the push was given up.
    pub since: Time,
    /// The goal error then \[m\].
    pub goal_error: f64,
    /// The largest contact force of the hard contact that blocked the push \[N\].
    pub contact_force: f64,
}

/// `skin_msgs/TaskState`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TaskState {
    /// Task name.
    pub name: String,
    /// Priority level, 1 = highest, 0 = inactive.
    pub priority: u32,
    /// Norm of the task error.
    pub error_norm: f64,
    /// Norm of the task's projected torque \[N m\].
    pub torque_norm: f64,
}

/// `skin_msgs/ControllerState`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ControllerState {
    /// Stamp of the control cycle.
    pub header: Header,
    /// Active arrangement mode.
    pub mode: u8,
    /// Blend factor chi, \[0, 1\].
    pub blend: f64,
    /// End-effector speed \[m/s\].
    pub ee_speed: f64,
    /// Proximity avoidance force norm \[N\].
    pub avoidance_force: f64,
    /// Largest contact force \[N\].
    pub contact_force: f64,
    /// Speed at which the link pressed hardest moves into its contact \[m/s\], NaN without.
    pub contact_advance: f64,
    /// Commanded torque norm \[N m\].
    pub torque_norm: f64,
    /// Distance to the goal \[m\], negative without goal.
    pub goal_error: f64,
    /// Nothing is to be pressed.
    pub releasing: bool,
    /// The blocked hold.
    pub blocked: BlockedHold,
    /// Goals set since start.
    pub goal_count: u32,
    /// Per-task state.
    pub tasks: Vec<TaskState>,
    /// Input health: 0 fresh, 1 waiting, 2 stale (docs/reliability.md).
    pub input_status: u8,
    /// Safe-stop cycles since start.
    pub safe_stop_cycles: u64,
    /// Periods without a cycle since start.
    pub idle_periods: u64,
    /// Bad input counters: names (`<topic>: <kind>`) ...
    pub issue_names: Vec<String>,
    /// ... and counts.
    pub issue_counts: Vec<u64>,
}

/// `std_msgs/String` (`/robot_description`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StringMsg {
    /// The text.
    pub data: String,
}

/// `builtin_interfaces/Duration`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Duration {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

/// `geometry_msgs/Transform`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation \[m\].
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/TransformStamped`: the pose of `child_frame_id` in `header.frame_id`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Stamp; `frame_id`: the parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// Child frame in the parent frame.
    pub transform: Transform,
}

/// `tf2_msgs/TFMessage` (`/tf`, `/tf_static`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `std_msgs/ColorRGBA`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ColorRgba {
    /// Red, \[0, 1\].
    pub r: f32,
    /// Green, \[0, 1\].
    pub g: f32,
    /// Blue, \[0, 1\].
    pub b: f32,
    /// Alpha, \[0, 1\].
    pub a: f32,
}

/// `sensor_msgs/CompressedImage` (a marker's texture; empty in ours).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CompressedImage {
    /// Stamp and optical frame.
    pub header: Header,
    /// Format (`jpeg`, `png`, ...).
    pub format: String,
    /// Compressed image.
    pub data: Vec<u8>,
}

/// `visualization_msgs/UVCoordinate`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct UvCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

/// `visualization_msgs/MeshFile`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshFile {
    /// File name.
    pub filename: String,
    /// File content.
    pub data: Vec<u8>,
}

/// `visualization_msgs/Marker`, every field in `.msg` order.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Marker {
    /// Stamp; `frame_id`: the frame of `pose` and `points`.
    pub header: Header,
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Shape (`ARROW` 0, ..., `SPHERE_LIST` 7, ...).
    #[serde(rename = "type")]
    pub type_: i32,
    /// `ADD` 0, `DELETE` 2, `DELETEALL` 3.
    pub action: i32,
    /// Pose of the marker in the frame.
    pub pose: Pose,
    /// Size \[m\].
    pub scale: Vector3,
    /// Colour of the whole marker.
    pub color: ColorRgba,
    /// How long it is shown (0: until replaced).
    pub lifetime: Duration,
    /// Whether it moves with its frame after it was received.
    pub frame_locked: bool,
    /// Points (lists, arrows with two points).
    pub points: Vec<Point>,
    /// Per-point colours.
    pub colors: Vec<ColorRgba>,
    /// Texture resource name.
    pub texture_resource: String,
    /// Texture image.
    pub texture: CompressedImage,
    /// Texture coordinates.
    pub uv_coordinates: Vec<UvCoordinate>,
    /// Text of a text marker.
    pub text: String,
    /// Mesh resource name.
    pub mesh_resource: String,
    /// Embedded mesh.
    pub mesh_file: MeshFile,
    /// Whether the mesh's own materials are used.
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    /// `type`: an arrow.
    pub const ARROW: i32 = 0;
    /// `type`: a list of spheres.
    pub const SPHERE_LIST: i32 = 7;
    /// `action`: add or replace.
    pub const ADD: i32 = 0;
    /// `action`: remove.
    pub const DELETE: i32 = 2;
    /// `action`: remove every marker.
    pub const DELETEALL: i32 = 3;
}

/// `visualization_msgs/MarkerArray`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MarkerArray {
    /// The markers, applied in order.
    pub markers: Vec<Marker>,
}

/// Serde for fixed arrays longer than serde's built-in 32 (the 6x6 covariances): a tuple, which
/// CDR writes without a length, as the `.msg` `float64[36]` requires.
mod fixed_array {
    use serde::de::{Error, SeqAccess, Visitor};
    use serde::ser::SerializeTuple;
    use serde::{Deserializer, Serializer};
    use std::fmt;

    pub fn serialize<S: Serializer, const N: usize>(a: &[f64; N], s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(N)?;
        for v in a {
            t.serialize_element(v)?;
        }
        t.end()
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
        struct ArrayVisitor<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for ArrayVisitor<N> {
            type Value = [f64; N];
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "{N} float64 values")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = [0.0; N];
                for (i, v) in out.iter_mut().enumerate() {
                    *v = seq.next_element()?.ok_or_else(|| A::Error::invalid_length(i, &self))?;
                }
                Ok(out)
            }
        }
        d.deserialize_tuple(N, ArrayVisitor::<N>)
    }
}
