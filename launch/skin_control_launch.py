"""What the launch files share (tomm.launch.py here, skin_sim_ros's sim.launch.py): the robot's
description (from a controller setup, or from mujoco_sim for a scene), the URDF as
robot_state_publisher must see it, and the skin control graph's nodes.

Not a launch file itself: the launch files import it from skin_control's share/launch."""
import json
import os
import subprocess
import xml.etree.ElementTree as ET

import yaml

from launch.conditions import IfCondition
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue
from ament_index_python.packages import get_package_prefix, get_package_share_directory

PKG = "skin_control"
# The simulation package (mujoco_sim); only hardware:=sim and sim.launch.py need it.
SIM_PKG = "skin_sim_ros"
# The base frame the base driver (or mujoco_sim) places in odom (REP 105).
BASE_FRAME = "base_link"


def share_file(*parts):
    """A file of the installed package's share directory (config/..., urdf/...)."""
    return os.path.join(get_package_share_directory(PKG), *parts)


def describe(scene, setup=""):
    """mujoco_sim --describe: the scene's controller setup (the scenario's unless `setup`), URDF,
    skin layout, LIDAR, base and arm namespaces; the one place that knows the scenarios."""
    exe = os.path.join(get_package_prefix(SIM_PKG), "lib", SIM_PKG, "mujoco_sim")
    cmd = [exe, "--describe", "--scene", scene] + (["--controller", setup] if setup else [])
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError(f"scene:={scene}: {run.stderr.strip() or run.stdout.strip()}")
    return json.loads(run.stdout)


def setup_files(setup):
    """The URDF and skin layout a controller setup file names (following its `base` files; paths
    relative to the file that sets them), as absolute paths: the robot's files without a scene."""
    found, path = {}, os.path.abspath(setup)
    while path and not {"urdf", "skin_layout"} <= set(found):
        data = yaml.safe_load(open(path))
        for key in ("urdf", "skin_layout"):
            if key in data and key not in found:  # `urdf: null`: none (the controller's comes from a topic)
                found[key] = data[key] and os.path.normpath(os.path.join(os.path.dirname(path), data[key]))
        path = os.path.join(os.path.dirname(path), data["base"]) if "base" in data else None
    missing = {k for k in ("urdf", "skin_layout") if not found.get(k)}
    if missing:
        raise RuntimeError(f"setup:={setup}: names no {', '.join(sorted(missing))} "
                           "(robot_state_publisher and skin_aggregator need the files)")
    return found["urdf"], found["skin_layout"]


def mounted_description(urdf_text):
    """The URDF as robot_state_publisher must see it on a robot with a base: rooted at base_link.
    The model's virtual planar base joints (world -> base_x_link -> base_y_link -> base_link) are
    the controller's view of the odometry; TF gets the base from the base driver's
    odom -> base_link, and a second parent of base_link would break the tree. URDFs without a
    base (planar7: world -> base, fixed) are returned as they are."""
    root = ET.fromstring(urdf_text)
    parent_of = {j.find("child").get("link"): j for j in root.findall("joint")}
    if BASE_FRAME not in parent_of:
        return urdf_text
    link = BASE_FRAME
    while link in parent_of:
        joint = parent_of[link]
        link = joint.find("parent").get("link")
        root.remove(joint)
        root.remove(next(e for e in root.findall("link") if e.get("name") == link))
    return ET.tostring(root, encoding="unicode")


def graph_nodes(namespace, description, sim_time, autostart, trigger="timer", controller=None, watchdog=None,
                stamped=False):
    """task_controller (with the parameters `controller` on top; activated at start when
    `autostart` is "true"; the base command as TwistStamped when `stamped`), skin_watchdog in
    timer mode (arguments `watchdog`, by default the command topics the controller's heartbeat
    names), priority_supervisor, skin_aggregator for `description` (a describe() result),
    robot_state_publisher and RViz when the launch arguments `robot_state_publisher` and `rviz`
    say so; every node but RViz in `namespace`. With robot_state_publisher the controller takes
    the URDF from its robot_description topic (rooted at base_link on a robot with a base:
    `mobile_base` puts the planar base joints back), else from the setup's file."""
    setup = description["setup"]
    time = {"use_sim_time": sim_time}
    urdf_text = open(description["urdf"]).read()
    # Zeros on the command topics when the controller's heartbeat stops; not in lockstep, where
    # the simulation waits for the controller. Sim time: a wider timeout.
    guard = [] if trigger != "timer" else [
        Node(package=PKG, executable="skin_watchdog", name="skin_watchdog", namespace=namespace, output="screen",
             arguments=(watchdog or ["--learn-topics", "--timeout-s", "0.1"]) + (["--base-stamped"] if stamped else []))]
    return guard + [
        Node(package=PKG, executable="task_controller", name="task_controller", namespace=namespace,
             output="screen",
             parameters=[share_file("config", "ros", "task_controller.yaml"), time,
                         {"setup_file": setup, "trigger": trigger, "use_scan": description["lidar"],
                          "autostart": autostart == "true", "base_command_stamped": stamped,
                          "use_robot_description": LaunchConfiguration("robot_state_publisher"),
                          "mobile_base": description["base"]},
                         controller or {}]),
        Node(package=PKG, executable="priority_supervisor", name="priority_supervisor", namespace=namespace,
             output="screen",
             parameters=[share_file("config", "ros", "priority_supervisor.yaml"), time, {"setup_file": setup}]),
        Node(package=PKG, executable="skin_aggregator", name="skin_aggregator", namespace=namespace,
             output="screen",
             parameters=[share_file("config", "ros", "skin_aggregator.yaml"), time,
                         {"urdf_file": description["urdf"], "layout_file": description["layout"]}]),
        Node(package="robot_state_publisher", executable="robot_state_publisher", namespace=namespace,
             output="screen", condition=IfCondition(LaunchConfiguration("robot_state_publisher")),
             parameters=[time, {"robot_description": ParameterValue(mounted_description(urdf_text), value_type=str)}]),
        # RViz views the root namespace's topics (config/skin.rviz names them).
        Node(package="rviz2", executable="rviz2",
             arguments=["-d", share_file("config", "skin.rviz")], parameters=[time],
             condition=IfCondition(LaunchConfiguration("rviz"))),
    ]
