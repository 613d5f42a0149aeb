"""MuJoCo simulation of a scene with the skin control graph.

    ros2 launch skin_sim_ros sim.launch.py scene:=intentional_contact
    ros2 launch skin_sim_ros sim.launch.py scene:=tomm_movable_obstacles rviz:=true
    ros2 launch skin_sim_ros sim.launch.py scene:=tactile_guidance namespace:=tomm

Starts mujoco_sim (real time, or lockstep:=true), task_controller, skin_watchdog (not in lockstep),
priority_supervisor,
skin_aggregator (all on sim time), robot_state_publisher with the robot's URDF (task_controller
then takes it from robot_description), and RViz on request; base_command_stamped:=true sends the
base command as TwistStamped. The robot, its skin layout, the controller setup and whether /scan is an input come from
the scene (`mujoco_sim --describe`); `setup:=FILE` replaces the scenario's controller setup.
Every node runs in `namespace` with relative topic names (/clock and /tf stay global). mujoco_sim
comes from this package, skin_sim_ros; the other nodes, their parameter files and the launch
helpers (skin_control_launch.py) from the robot package skin_control."""
import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from ament_index_python.packages import get_package_share_directory

sys.path.insert(0, os.path.join(get_package_share_directory("skin_control"), "launch"))
from skin_control_launch import SIM_PKG, describe, graph_nodes  # noqa: E402


def launch_setup(context):
    arg = lambda name: LaunchConfiguration(name).perform(context)  # noqa: E731
    lockstep, stamped = arg("lockstep") == "true", arg("base_command_stamped") == "true"
    description = describe(arg("scene"), arg("setup"))
    sim = Node(package=SIM_PKG, executable="mujoco_sim", name="mujoco_sim", namespace=arg("namespace"),
               output="screen",
               arguments=["--scene", description["scene"]]
               + (["--lockstep"] if lockstep else ["--realtime-factor", arg("realtime_factor")])
               + (["--base-command-stamped"] if stamped else []))
    return [sim] + graph_nodes(arg("namespace"), description, sim_time=True, autostart=arg("autostart"),
                               trigger="inputs" if lockstep else "timer", stamped=stamped)


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("scene", default_value="tomm_movable_obstacles",
                              description="scenario name (skin_sim list) or scene file"),
        DeclareLaunchArgument("setup", default_value="",
                              description="controller setup file (default: the scenario's)"),
        DeclareLaunchArgument("namespace", default_value="", description="namespace of every node"),
        DeclareLaunchArgument("lockstep", default_value="false",
                              description="reproducible lockstep simulation (controller trigger:=inputs)"),
        DeclareLaunchArgument("realtime_factor", default_value="1.0",
                              description="real-time mode: simulated seconds per wall-clock second"),
        DeclareLaunchArgument("robot_state_publisher", default_value="true",
                              description="start robot_state_publisher (TF of the robot's links); the "
                                          "controller takes the URDF from its robot_description (false: from the setup's file)"),
        DeclareLaunchArgument("base_command_stamped", default_value="false",
                              description="base command as geometry_msgs/TwistStamped (ros2_control's base controllers)"),
        DeclareLaunchArgument("rviz", default_value="false", description="start RViz with config/skin.rviz"),
        DeclareLaunchArgument("autostart", default_value="true",
                              description="activate task_controller at start (as ros2_control's spawner activates controllers)"),
        OpaqueFunction(function=launch_setup),
    ])
