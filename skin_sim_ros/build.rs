//! Link settings for ROS 2 (wheels or /opt/ros): see the `skin_ros_link` crate.
fn main() {
    skin_ros_link::emit();
}
