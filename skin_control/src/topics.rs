//! Topic names of the graph (docs/ros.md), as they resolve in the root namespace (logs and the
//! counters of `/controller/state` use these). The nodes create their publishers and
//! subscriptions with the relative name ([`crate::nodes::local`]), so that a node namespace
//! (`__ns:=/tomm`, a launch file's `namespace`) and remapping apply; `/clock` and `/tf*` stay
//! global, as in every ROS 2 node (rcl's time source subscribes `/clock`, tf2 `/tf`).

/// Skin cells (skin_msgs/SkinCellArray).
pub const CELLS: &str = "/skin/cells";
/// The type of [`CELLS`], for raw subscriptions.
pub const CELLS_TYPE: &str = "skin_msgs/msg/SkinCellArray";
/// Patch wrenches (skin_msgs/PatchWrenchArray).
pub const PATCHES: &str = "/skin/patches";
/// Skin markers for RViz (visualization_msgs/MarkerArray).
pub const MARKERS: &str = "/skin/markers";
/// Joint states (sensor_msgs/JointState).
pub const JOINT_STATES: &str = "/joint_states";
/// Base odometry (nav_msgs/Odometry).
pub const ODOM: &str = "/base/odom";
/// Base LIDAR (sensor_msgs/LaserScan).
pub const SCAN: &str = "/scan";
/// End-effector goal (geometry_msgs/PoseStamped).
pub const GOAL: &str = "/goal";
/// Hand force reference in newtons (std_msgs/Float64).
pub const FORCE_REFERENCE: &str = "/hand_force_reference";
/// Base twist command (geometry_msgs/Twist).
pub const CMD_VEL: &str = "/base/cmd_vel";
/// Controller state (skin_msgs/ControllerState).
pub const CONTROLLER_STATE: &str = "/controller/state";
/// Active arrangement (skin_msgs/Arrangement, latched).
pub const ARRANGEMENT: &str = "/supervisor/arrangement";
/// Phase service (skin_msgs/srv/SetPhase).
pub const SET_PHASE: &str = "/supervisor/set_phase";
/// `skin_watchdog`'s trips (std_msgs/Header: it sent zero commands).
pub const WATCHDOG: &str = "/controller/watchdog";
/// Simulation clock (rosgraph_msgs/Clock): global.
pub const CLOCK: &str = "/clock";
/// Transforms (tf2_msgs/TFMessage): global.
pub const TF: &str = "/tf";
/// Fixed transforms (tf2_msgs/TFMessage, transient local): global.
pub const TF_STATIC: &str = "/tf_static";
