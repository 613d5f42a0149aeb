//! Link settings for ROS 2 (wheels or /opt/ros): see the `skin_ros_link` crate; and `cfg(tf2_msgs)`.
fn main() {
    skin_ros_link::emit();
    tf2_msgs_cfg();
}

/// `cfg(tf2_msgs)` when r2r generates tf2_msgs (installed in an AMENT_PREFIX_PATH prefix and not
/// filtered out): the type of `/tf`, which the wheels lack (a robot's /opt/ros/jazzy has it; here
/// scripts/bootstrap installs it with ROS2_PYTHON_TOOLS). Without it `skin_control::tf` publishes no TF.
fn tf2_msgs_cfg() {
    println!("cargo:rustc-check-cfg=cfg(tf2_msgs)");
    println!("cargo:rerun-if-env-changed=AMENT_PREFIX_PATH");
    println!("cargo:rerun-if-env-changed=IDL_PACKAGE_FILTER");
    let prefixes = std::env::var("AMENT_PREFIX_PATH").unwrap_or_default();
    let mut found = false;
    for prefix in std::env::split_paths(&prefixes) {
        let share = prefix.join("share");
        if share.is_dir() {
            // A package installed into an existing prefix later changes the directory.
            println!("cargo:rerun-if-changed={}", share.display());
            found |= share.join("tf2_msgs").join("package.xml").is_file();
        }
    }
    let filtered_out = std::env::var("IDL_PACKAGE_FILTER").is_ok_and(|f| !f.split(';').any(|p| p == "tf2_msgs"));
    if found && !filtered_out {
        println!("cargo:rustc-cfg=tf2_msgs");
    }
}
