"""The real TOMM: two UR5 drivers with forward_velocity_controller active, the base driver, a skin
bridge, and the skin control graph.

    ros2 launch skin_control tomm.launch.py left_ip:=192.168.1.11 right_ip:=192.168.1.12

The UR drivers run in the namespaces the task_controller commands (<ns>/forward_velocity_controller/
commands; config/ros/task_controller.yaml arms.namespaces) and publish /joint_states (each its own
arm's joints; the controller merges them by name). The base driver must publish /base/odom (twist in
the base frame) and /scan and take /base/cmd_vel; the skin bridge must publish /skin/cells. Both are
site-specific packages: their package and executable are arguments."""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

PKG = "skin_control"


def share(*parts):
    return PathJoinSubstitution([FindPackageShare(PKG), *parts])


def ur_driver(side):
    """ur_robot_driver's ur_control.launch.py for one arm, forward_velocity_controller active."""
    return IncludeLaunchDescription(
        PythonLaunchDescriptionSource(PathJoinSubstitution(
            [FindPackageShare("ur_robot_driver"), "launch", "ur_control.launch.py"])),
        launch_arguments={
            "ur_type": "ur5",
            "robot_ip": LaunchConfiguration(f"{side}_ip"),
            "tf_prefix": f"{side}_",
            "initial_joint_controller": "forward_velocity_controller",
            "activate_joint_controller": "true",
            "launch_rviz": "false",
            "controller_manager_namespace": LaunchConfiguration(f"{side}_namespace"),
        }.items())


def generate_launch_description():
    setup = LaunchConfiguration("setup")
    return LaunchDescription([
        DeclareLaunchArgument("left_ip", default_value="192.168.1.11", description="left UR5 IP"),
        DeclareLaunchArgument("right_ip", default_value="192.168.1.12", description="right UR5 IP"),
        DeclareLaunchArgument("left_namespace", default_value="left_arm", description="left arm namespace"),
        DeclareLaunchArgument("right_namespace", default_value="right_arm", description="right arm namespace"),
        DeclareLaunchArgument("setup", default_value="config/controller/tomm.yaml", description="controller setup"),
        DeclareLaunchArgument("autostart", default_value="false",
                              description="activate task_controller at start (else: ros2 lifecycle set /task_controller activate)"),
        DeclareLaunchArgument("base_package", default_value="tomm_base", description="base driver package"),
        DeclareLaunchArgument("base_executable", default_value="base_driver", description="base driver executable"),
        DeclareLaunchArgument("skin_package", default_value="tomm_skin", description="skin bridge package"),
        DeclareLaunchArgument("skin_executable", default_value="skin_bridge", description="skin bridge executable"),
        ur_driver("left"),
        ur_driver("right"),
        Node(package=LaunchConfiguration("base_package"), executable=LaunchConfiguration("base_executable"),
             name="base_driver", output="screen",
             remappings=[("odom", "/base/odom"), ("cmd_vel", "/base/cmd_vel"), ("scan", "/scan")]),
        Node(package=LaunchConfiguration("skin_package"), executable=LaunchConfiguration("skin_executable"),
             name="skin_bridge", output="screen", remappings=[("cells", "/skin/cells")]),
        Node(package=PKG, executable="task_controller", name="task_controller", output="screen",
             parameters=[share("config", "ros", "task_controller.yaml"),
                         {"setup_file": setup, "autostart": LaunchConfiguration("autostart")}]),
        # zero commands on every command topic when the controller's heartbeat stops
        Node(package=PKG, executable="skin_watchdog", name="skin_watchdog", output="screen",
             arguments=["--arm", ["/", LaunchConfiguration("left_namespace"), "/forward_velocity_controller/commands=6"],
                        "--arm", ["/", LaunchConfiguration("right_namespace"), "/forward_velocity_controller/commands=6"],
                        "--base", "/base/cmd_vel"]),
        Node(package=PKG, executable="priority_supervisor", name="priority_supervisor", output="screen",
             parameters=[share("config", "ros", "priority_supervisor.yaml"), {"setup_file": setup}]),
        Node(package=PKG, executable="skin_aggregator", name="skin_aggregator", output="screen",
             parameters=[share("config", "ros", "skin_aggregator.yaml")]),
        Node(package="robot_state_publisher", executable="robot_state_publisher", output="screen",
             parameters=[{"robot_description": open_urdf()}]),
    ])


def open_urdf():
    from ament_index_python.packages import get_package_share_directory
    import os
    return open(os.path.join(get_package_share_directory(PKG), "urdf", "tomm.urdf")).read()
