"""MuJoCo simulation of a scene with the skin control graph.

    ros2 launch skin_control sim.launch.py scene:=intentional_contact setup:=config/controller/planar7.yaml
    ros2 launch skin_control sim.launch.py scene:=tomm_movable_obstacles rviz:=true

Starts mujoco_sim (real time, or lockstep:=true), task_controller, skin_watchdog (not in lockstep), priority_supervisor,
skin_aggregator (all on sim time), robot_state_publisher with our URDF, and RViz on request.
Paths are relative to the skin_control share directory (the nodes also look there)."""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.conditions import IfCondition, UnlessCondition
from launch.substitutions import LaunchConfiguration, PythonExpression
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare
from launch.substitutions import PathJoinSubstitution

PKG = "skin_control"


def share(*parts):
    return PathJoinSubstitution([FindPackageShare(PKG), *parts])


def generate_launch_description():
    scene = LaunchConfiguration("scene")
    setup = LaunchConfiguration("setup")
    urdf = LaunchConfiguration("urdf")
    lockstep = LaunchConfiguration("lockstep")
    sim_time = {"use_sim_time": True}
    return LaunchDescription([
        DeclareLaunchArgument("scene", default_value="tomm_movable_obstacles",
                              description="scenario name or scene file (config/scenes/)"),
        DeclareLaunchArgument("setup", default_value="config/controller/tomm.yaml",
                              description="controller setup file (the scene's robot)"),
        DeclareLaunchArgument("urdf", default_value="urdf/tomm.urdf", description="robot URDF for robot_state_publisher"),
        DeclareLaunchArgument("lockstep", default_value="false", description="reproducible lockstep simulation"),
        DeclareLaunchArgument("rviz", default_value="false", description="start RViz with config/skin.rviz"),
        DeclareLaunchArgument("autostart", default_value="true", description="activate task_controller at start"),
        Node(package=PKG, executable="mujoco_sim", name="mujoco_sim", output="screen",
             arguments=["--scene", scene,
                        PythonExpression(["'--lockstep' if '", lockstep, "' == 'true' else '--realtime-factor=1'"])]),
        Node(package=PKG, executable="task_controller", name="task_controller", output="screen",
             parameters=[share("config", "ros", "task_controller.yaml"), sim_time,
                         {"setup_file": setup, "autostart": LaunchConfiguration("autostart"),
                          "trigger": PythonExpression(["'inputs' if '", lockstep, "' == 'true' else 'timer'"])}]),
        # zeros on the command topics the controller's heartbeat names when it stops (not in
        # lockstep, where the simulation waits for the controller; sim time: a wider timeout)
        Node(package=PKG, executable="skin_watchdog", name="skin_watchdog", output="screen",
             arguments=["--learn-topics", "--timeout-s", "0.1"],
             condition=UnlessCondition(lockstep)),
        Node(package=PKG, executable="priority_supervisor", name="priority_supervisor", output="screen",
             parameters=[share("config", "ros", "priority_supervisor.yaml"), sim_time, {"setup_file": setup}]),
        Node(package=PKG, executable="skin_aggregator", name="skin_aggregator", output="screen",
             parameters=[share("config", "ros", "skin_aggregator.yaml"), sim_time]),
        Node(package="robot_state_publisher", executable="robot_state_publisher", output="screen",
             parameters=[sim_time, {"robot_description": PythonExpression(["open('", share(urdf), "').read()"])}]),
        Node(package="rviz2", executable="rviz2", arguments=["-d", share("config", "skin.rviz")],
             parameters=[sim_time], condition=IfCondition(LaunchConfiguration("rviz"))),
    ])
