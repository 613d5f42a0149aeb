"""TOMM with the skin control graph: the real robot, or (hardware:=sim) its MuJoCo simulation
speaking the drivers' topics.

    ros2 launch skin_control tomm.launch.py left_ip:=192.168.1.11 right_ip:=192.168.1.12 \\
        base_package:=<pkg> base_executable:=<exe> skin_package:=<pkg> skin_executable:=<exe>
    ros2 launch skin_control tomm.launch.py hardware:=sim scene:=tactile_guidance

Each UR5 arm (ur_robot_driver, ros2_control) runs in its own namespace (`left_namespace`,
`right_namespace`: left_arm, right_arm) with its own controller manager
(/<ns>/controller_manager), tf_prefix (left_, right_: the joint and link names of urdf/tomm.urdf)
and ports (the driver opens four per arm: reverse, script sender, trajectory, script command;
50001-50004 left, 50005-50008 right by default). Active controllers: joint_state_broadcaster
(published on the graph's joint_states: the controller and robot_state_publisher merge the arms
by joint name), io_and_status_controller, speed_scaling_state_broadcaster and
forward_velocity_controller, which task_controller commands on
<ns>/forward_velocity_controller/commands (config/ros/ur_controllers.yaml). One
robot_state_publisher for the whole robot (urdf/tomm.urdf from base_link down); task_controller takes
the URDF from its robot_description (with robot_state_publisher:=false, from the setup's file).

Base and skin drivers are site packages named by arguments (none started when empty). Topic
contract, relative to `namespace`: the base driver publishes base/odom (nav_msgs/Odometry: pose
in odom, twist in base_link), scan (sensor_msgs/LaserScan, frame `laser`) and TF odom -> base_link,
and takes base/cmd_vel (geometry_msgs/Twist; geometry_msgs/TwistStamped in frame base_link with
base_command_stamped:=true, as ros2_control's mecanum/omni drive controllers take it); the skin driver publishes skin/cells
(skin_msgs/SkinCellArray). Sensors may be best effort (REP 2003). A static world -> odom
(tf2_ros) makes the goals' world frame the odometry frame, as the controller takes it
(`world_tf:=false` when a localization publishes it).

hardware:=sim: mujoco_sim (package skin_sim_ros) runs `scene` instead of the drivers, on the same
topics (the arms' commands in their namespaces, joint_states, base/odom, scan, skin/cells, TF)."""
import os
import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, GroupAction, LogInfo, OpaqueFunction, SetLaunchConfiguration
from launch.substitutions import Command, FindExecutable, LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node, PushRosNamespace
from launch_ros.parameter_descriptions import ParameterFile, ParameterValue
from launch_ros.substitutions import FindPackageShare

sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
from skin_control_launch import SIM_PKG, describe, graph_nodes, setup_files, share_file  # noqa: E402

SIDES = ("left", "right")
PORTS = ("reverse_port", "script_sender_port", "trajectory_port", "script_command_port")


def arms(arg):
    """Each arm's namespace, tf_prefix (= the URDF's joint prefix), IP and ports from the launch
    arguments (`arg(name)` gives one)."""
    return [{"side": side, "namespace": arg(f"{side}_namespace"), "tf_prefix": f"{side}_",
             "robot_ip": arg(f"{side}_ip"), **{p: arg(f"{side}_{p}") for p in PORTS}} for side in SIDES]


def ur_driver(arm, graph_ns, arg):
    """ur_robot_driver's nodes for one arm in its namespace (what its ur_control.launch.py starts,
    with the controller manager addressed in that namespace, and no robot_state_publisher)."""
    ns = f"{graph_ns}/{arm['namespace']}" if graph_ns else arm["namespace"]
    manager = f"/{ns}/controller_manager"
    ur = lambda *p: PathJoinSubstitution([FindPackageShare("ur_robot_driver"), *p])  # noqa: E731
    xacro_args = {
        "name": arm["side"] + "_ur5", "ur_type": arg("ur_type"), "tf_prefix": arm["tf_prefix"],
        "robot_ip": arm["robot_ip"], "script_filename": PathJoinSubstitution(
            [FindPackageShare("ur_client_library"), "resources", "external_control.urscript"]),
        "input_recipe_filename": ur("resources", "rtde_input_recipe.txt"),
        "output_recipe_filename": ur("resources", "rtde_output_recipe.txt"),
        "headless_mode": arg("headless_mode"), **{p: arm[p] for p in PORTS},
    }
    command = [PathJoinSubstitution([FindExecutable(name="xacro")]), " ", arg("ur_description_file") or ur("urdf", "ur.urdf.xacro")]
    for k, v in xacro_args.items():
        command += [f" {k}:=", v]
    description = {"robot_description": ParameterValue(Command(command), value_type=str)}
    spawner = lambda controllers: Node(  # noqa: E731
        package="controller_manager", executable="spawner",
        arguments=["--controller-manager", manager, "--controller-manager-timeout", "30", *controllers])
    joint_states = f"/{graph_ns}/joint_states" if graph_ns else "/joint_states"
    return GroupAction(scoped=True, actions=[
        SetLaunchConfiguration("tf_prefix", arm["tf_prefix"]),
        PushRosNamespace(ns),
        Node(package="controller_manager", executable="ros2_control_node", output="screen",
             parameters=[description, ParameterFile(share_file("config", "ros", "ur_controllers.yaml"), allow_substs=True)],
             remappings=[("joint_states", joint_states)]),
        Node(package="ur_robot_driver", executable="dashboard_client", name="dashboard_client", output="screen",
             parameters=[{"robot_ip": arm["robot_ip"]}]),
        Node(package="ur_robot_driver", executable="controller_stopper_node", name="controller_stopper", output="screen",
             parameters=[{"headless_mode": arg("headless_mode") == "true"}, {"joint_controller_active": True},
                         {"consistent_controllers": ["io_and_status_controller", "joint_state_broadcaster",
                                                     "speed_scaling_state_broadcaster"]}]),
        spawner(["joint_state_broadcaster", "io_and_status_controller", "speed_scaling_state_broadcaster",
                 "forward_velocity_controller"]),
    ])


def site_driver(kind, ns, arg):
    pkg, exe = arg(f"{kind}_package"), arg(f"{kind}_executable")
    if not pkg or not exe:
        return LogInfo(msg=f"no {kind} driver started ({kind}_package / {kind}_executable not given): "
                           "start yours with the topic contract of tomm.launch.py's docstring")
    return Node(package=pkg, executable=exe, name=f"{kind}_driver", namespace=ns, output="screen")


def launch_setup(context):
    arg = lambda name: LaunchConfiguration(name).perform(context)  # noqa: E731
    ns, sim, stamped = arg("namespace"), arg("hardware") == "sim", arg("base_command_stamped") == "true"
    if arg("hardware") not in ("real", "sim"):
        raise RuntimeError(f"hardware:={arg('hardware')}: must be real or sim")
    arm_list = arms(arg)
    if sim:
        # The scene's robot and setup (skin_sim_ros's mujoco_sim knows the scenarios).
        description = describe(arg("scene"), arg("setup"))
        if [a["tf_prefix"] for a in arm_list] != description["arms"]["joint_prefixes"]:
            raise RuntimeError(f"scene:={arg('scene')}: not a TOMM scene (arms {description['arms']})")
    else:
        # The real TOMM: the setup's files, its base and LIDAR.
        setup = os.path.abspath(arg("setup") or share_file("config", "controller", "tomm.yaml"))
        urdf, layout = setup_files(setup)
        description = {"setup": setup, "urdf": urdf, "layout": layout, "lidar": True, "base": True}
    namespaces = [a["namespace"] for a in arm_list]
    if sim:
        robot = [Node(package=SIM_PKG, executable="mujoco_sim", name="mujoco_sim", namespace=ns, output="screen",
                      arguments=["--scene", description["scene"], "--realtime-factor", "1.0",
                                 *[x for n in namespaces for x in ("--arm-namespace", n)],
                                 *[x for a in arm_list for x in ("--arm-prefix", a["tf_prefix"])]]
                      + (["--base-command-stamped"] if stamped else []))]
    else:
        robot = [ur_driver(a, ns, arg) for a in arm_list] + [site_driver("base", ns, arg), site_driver("skin", ns, arg)]
        if arg("world_tf") == "true":
            robot.append(Node(package="tf2_ros", executable="static_transform_publisher", name="world_to_odom",
                              arguments=["--frame-id", "world", "--child-frame-id", "odom"]))
    # The command namespaces of the arms, as the drivers (or the simulator) serve them.
    commands = {"arms.namespaces": namespaces, "arms.joint_prefixes": [a["tf_prefix"] for a in arm_list]}
    # The watchdog zeroes the arms' and the base's command topics from the start (relative: in ns).
    watchdog = [x for n in namespaces for x in ("--arm", f"{n}/forward_velocity_controller/commands=6")]
    autostart = arg("autostart") or ("true" if sim else "false")
    return robot + graph_nodes(ns, description, sim_time=sim, autostart=autostart, controller=commands,
                               watchdog=watchdog + (["--timeout-s", "0.1"] if sim else []), stamped=stamped)


def generate_launch_description():
    args = [
        ("hardware", "real", "real: the UR5 drivers and the site's base and skin drivers; sim: mujoco_sim"),
        ("scene", "tomm_movable_obstacles", "hardware:=sim: the TOMM scene to simulate"),
        ("setup", "", "controller setup file (default: config/controller/tomm.yaml; sim: the scenario's)"),
        ("namespace", "", "namespace of the whole graph"),
        ("autostart", "", "activate task_controller at start (default: false for hardware:=real, where "
                          "ros2 lifecycle set <ns>/task_controller configure, then activate; true for hardware:=sim)"),
        ("ur_type", "ur5", "UR type of both arms (ur_robot_driver)"),
        ("ur_description_file", "", "the UR description xacro (default: ur_robot_driver's urdf/ur.urdf.xacro)"),
        ("headless_mode", "false", "ur_robot_driver headless mode"),
        ("left_ip", "192.168.1.11", "left UR5 IP"),
        ("right_ip", "192.168.1.12", "right UR5 IP"),
        ("left_namespace", "left_arm", "left arm namespace (driver, controller manager, command topic)"),
        ("right_namespace", "right_arm", "right arm namespace"),
        ("base_package", "", "base driver package (empty: none started)"),
        ("base_executable", "", "base driver executable"),
        ("skin_package", "", "skin driver package (empty: none started)"),
        ("skin_executable", "", "skin driver executable"),
        ("world_tf", "true", "hardware:=real: publish world -> odom (identity, tf2_ros)"),
        ("robot_state_publisher", "true", "start robot_state_publisher (task_controller then takes the URDF from "
                                          "its robot_description; false: from the setup's file)"),
        ("base_command_stamped", "false", "base/cmd_vel as geometry_msgs/TwistStamped (frame base_link), as "
                                          "ros2_control's base controllers take it; false: geometry_msgs/Twist"),
        ("rviz", "false", "start RViz with config/skin.rviz"),
    ]
    for side, first in zip(SIDES, (50001, 50005)):
        args += [(f"{side}_{p}", str(first + k), f"{side} arm's ur_robot_driver {p}") for k, p in enumerate(PORTS)]
    return LaunchDescription([DeclareLaunchArgument(n, default_value=d, description=t) for n, d, t in args]
                             + [OpaqueFunction(function=launch_setup)])
