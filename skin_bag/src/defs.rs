//! The `.msg` text of every type a bag may carry, and the complete `ros2msg` definition that
//! rosbag2 records per schema: the type's own text, then each dependency not yet written (in
//! sorted order, depth first) after a line of 80 `=` and a `MSG: pkg/Type` line.

use std::collections::BTreeSet;

/// `(pkg/Type, .msg text)` of a standard Jazzy message (copied under `assets/ros_msgs`).
macro_rules! std_msg {
    ($pkg:literal, $ty:literal) => {
        (concat!($pkg, "/", $ty), include_str!(concat!("../assets/ros_msgs/", $pkg, "/", $ty, ".msg")))
    };
}

/// `(skin_msgs/Type, .msg text)` read from the interface package itself, so it never drifts.
macro_rules! skin_msg {
    ($ty:literal) => {
        (concat!("skin_msgs/", $ty), include_str!(concat!("../../skin_msgs/msg/", $ty, ".msg")))
    };
}

const DEFINITIONS: &[(&str, &str)] = &[
    std_msg!("builtin_interfaces", "Time"),
    std_msg!("builtin_interfaces", "Duration"),
    std_msg!("std_msgs", "Header"),
    std_msg!("std_msgs", "Float64MultiArray"),
    std_msg!("std_msgs", "MultiArrayLayout"),
    std_msg!("std_msgs", "MultiArrayDimension"),
    std_msg!("std_msgs", "ColorRGBA"),
    std_msg!("std_msgs", "String"),
    std_msg!("rosgraph_msgs", "Clock"),
    std_msg!("geometry_msgs", "Point"),
    std_msg!("geometry_msgs", "Pose"),
    std_msg!("geometry_msgs", "PoseWithCovariance"),
    std_msg!("geometry_msgs", "Quaternion"),
    std_msg!("geometry_msgs", "Twist"),
    std_msg!("geometry_msgs", "TwistWithCovariance"),
    std_msg!("geometry_msgs", "Vector3"),
    std_msg!("geometry_msgs", "Wrench"),
    std_msg!("geometry_msgs", "Transform"),
    std_msg!("geometry_msgs", "TransformStamped"),
    std_msg!("tf2_msgs", "TFMessage"),
    std_msg!("visualization_msgs", "Marker"),
    std_msg!("visualization_msgs", "MarkerArray"),
    std_msg!("visualization_msgs", "MeshFile"),
    std_msg!("visualization_msgs", "UVCoordinate"),
    std_msg!("sensor_msgs", "CompressedImage"),
    std_msg!("sensor_msgs", "JointState"),
    std_msg!("sensor_msgs", "LaserScan"),
    std_msg!("nav_msgs", "Odometry"),
    skin_msg!("Arrangement"),
    skin_msg!("BlockedHold"),
    skin_msg!("ControllerState"),
    skin_msg!("PatchWrench"),
    skin_msg!("PatchWrenchArray"),
    skin_msg!("SkinCellArray"),
    skin_msg!("TaskState"),
];

const PRIMITIVES: &[&str] = &[
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64",
    "uint64", "string", "wstring",
];

/// The `.msg` text of `pkg/Type` (or `pkg/msg/Type`), if it is one of ours.
pub fn msg_text(type_name: &str) -> Option<&'static str> {
    let key = type_name.replacen("/msg/", "/", 1);
    DEFINITIONS.iter().find(|(name, _)| *name == key).map(|(_, text)| *text)
}

/// The complete `ros2msg` definition of `type_name` (`pkg/msg/Type`) as rosbag2 writes it into
/// an MCAP schema. Err: the name of the first type without a definition.
pub fn full_definition(type_name: &str) -> Result<String, String> {
    let mut seen = BTreeSet::new();
    append(&type_name.replacen("/msg/", "/", 1), &mut seen)
}

fn append(type_name: &str, seen: &mut BTreeSet<String>) -> Result<String, String> {
    let text = msg_text(type_name).ok_or_else(|| type_name.to_string())?;
    let package = type_name.split('/').next().unwrap_or_default();
    let mut out = text.to_string();
    for dep in dependencies(text, package) {
        if seen.insert(dep.clone()) {
            out.push('\n');
            out.push_str(&"=".repeat(80));
            out.push_str("\nMSG: ");
            out.push_str(&dep);
            out.push('\n');
            out.push_str(&append(&dep, seen)?);
        }
    }
    Ok(out)
}

/// Non-primitive field types of a `.msg` text as `pkg/Type`, sorted (rosbag2 keeps a std::set).
fn dependencies(text: &str, package: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|line| line.split('#').next()?.split_whitespace().next())
        // Strip an array suffix (`[]`, `[3]`, `[<=5]`) and a string bound (`string<=8`).
        .map(|ty| ty.split(['[', '<']).next().unwrap_or(ty))
        .filter(|ty| !PRIMITIVES.contains(ty))
        .map(|ty| if ty.contains('/') { ty.to_string() } else { format!("{package}/{ty}") })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odometry_lists_each_dependency_once_depth_first() {
        let full = full_definition("nav_msgs/msg/Odometry").unwrap();
        let headers: Vec<&str> = full.lines().filter(|l| l.starts_with("MSG: ")).collect();
        assert_eq!(
            headers,
            [
                "MSG: geometry_msgs/PoseWithCovariance",
                "MSG: geometry_msgs/Pose",
                "MSG: geometry_msgs/Point",
                "MSG: geometry_msgs/Quaternion",
                "MSG: geometry_msgs/TwistWithCovariance",
                "MSG: geometry_msgs/Twist",
                "MSG: geometry_msgs/Vector3",
                "MSG: std_msgs/Header",
                "MSG: builtin_interfaces/Time",
            ]
        );
        assert!(full.starts_with(msg_text("nav_msgs/Odometry").unwrap()));
        assert!(full.contains(&format!("\n{}\nMSG: std_msgs/Header\n", "=".repeat(80))));
    }

    #[test]
    fn skin_types_resolve_their_package_local_dependencies() {
        let full = full_definition("skin_msgs/msg/PatchWrenchArray").unwrap();
        for dep in ["skin_msgs/PatchWrench", "geometry_msgs/Wrench", "geometry_msgs/Point"] {
            assert!(full.contains(&format!("MSG: {dep}\n")), "{dep} missing");
        }
        // Constants are primitives, not dependencies; Time is written once though used twice.
        let arrangement = full_definition("skin_msgs/msg/Arrangement").unwrap();
        assert_eq!(arrangement.matches("MSG: ").count(), 2);
        assert!(arrangement.contains("MSG: skin_msgs/BlockedHold\n"));
    }

    #[test]
    fn unknown_type_is_named() {
        assert_eq!(full_definition("foo_msgs/msg/Bar"), Err("foo_msgs/Bar".to_string()));
    }
}
