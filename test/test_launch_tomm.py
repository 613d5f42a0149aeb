"""launch/tomm.launch.py. hardware:=sim through the real `ros2 launch`: mujoco_sim reads the two
arms' commands in the drivers' namespaces, the controller runs on its topics, the arm moves. hardware:=real
needs ur_robot_driver and ros2_control (C++, not installable here): its per-arm settings are
checked as data (own namespace, controller manager, tf_prefix, ports; the velocity controller's
joints are what task_controller commands there)."""
import importlib.util
import xml.etree.ElementTree as ET

import pytest
import yaml

from conftest import TOP, spin_until
from test_launch_sim import Watch, describe, launch  # noqa: F401 (the fixture)


def tomm_launch_module():
    pytest.importorskip("launch_ros", reason="needs the ROS 2 launch system (see conftest.ros2_or_skip)")
    spec = importlib.util.spec_from_file_location("tomm_launch", TOP / "launch" / "tomm.launch.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def defaults(module):
    """The launch arguments' default values (the plain-text ones)."""
    from launch.actions import DeclareLaunchArgument

    out = {}
    for a in module.generate_launch_description().entities:
        if isinstance(a, DeclareLaunchArgument) and all(hasattr(s, "text") for s in a.default_value):
            out[a.name] = "".join(s.text for s in a.default_value)
    return out


def texts(node):
    """The plain-text words of a launch Node's command line."""
    return ["".join(s.text for s in part) for part in node.cmd if all(hasattr(s, "text") for s in part)]


def test_real_arms_have_their_own_namespace_manager_prefix_and_ports(ament_prefix, monkeypatch):
    monkeypatch.setenv("AMENT_PREFIX_PATH", ament_prefix["AMENT_PREFIX_PATH"])
    from launch.launch_context import LaunchContext
    from launch.utilities import perform_substitutions
    from launch_ros.actions import Node, PushRosNamespace

    m = tomm_launch_module()
    args = defaults(m)
    arms = m.arms(args.__getitem__)
    assert [a["namespace"] for a in arms] == ["left_arm", "right_arm"]
    ports = [int(a[p]) for a in arms for p in m.PORTS]
    assert len(set(ports)) == len(ports) == 8, f"ports shared between the drivers: {ports}"

    urdf = ET.parse(TOP / "urdf" / "tomm.urdf").getroot()
    movable = [j.get("name") for j in urdf.findall("joint") if j.get("type") in ("revolute", "continuous")]
    controllers = (TOP / "config" / "ros" / "ur_controllers.yaml").read_text()
    ctx = LaunchContext()
    for arm in arms:
        # The velocity controller's joints, with the arm's tf_prefix, are the URDF's joints of that
        # arm in model order: the order task_controller writes its command in.
        joints = yaml.safe_load(controllers.replace("$(var tf_prefix)", arm["tf_prefix"]))
        joints = joints["/**/forward_velocity_controller"]["ros__parameters"]["joints"]
        assert joints == [j for j in movable if j.startswith(arm["tf_prefix"])], joints
        group = m.ur_driver(arm, "", args.__getitem__)
        actions = group.get_sub_entities()
        (push,) = [a for a in actions if isinstance(a, PushRosNamespace)]
        assert perform_substitutions(ctx, push.namespace) == arm["namespace"]
        spawners = [texts(a) for a in actions if isinstance(a, Node) and "spawner" in str(a.node_executable)]
        (spawn,) = spawners
        assert spawn[spawn.index("--controller-manager") + 1] == f"/{arm['namespace']}/controller_manager"
        assert "forward_velocity_controller" in spawn and "joint_state_broadcaster" in spawn
    # The command topics task_controller publishes to are the ones these controllers serve.
    d = describe("tomm_movable_obstacles")
    assert d["arms"]["namespaces"] == [a["namespace"] for a in arms]
    assert d["arms"]["joint_prefixes"] == [a["tf_prefix"] for a in arms]


def test_sim_hardware_speaks_the_drivers_topics(launch, rclpy_node):  # noqa: F811
    from sensor_msgs.msg import JointState

    d = describe("tomm_movable_obstacles")
    watch = Watch(rclpy_node, "", d)
    joints = []
    rclpy_node.create_subscription(JointState, "/joint_states", joints.append, 100)
    la = launch("skin_control", "tomm.launch.py", "hardware:=sim", "robot_state_publisher:=false")
    la.wait_for(rclpy_node, lambda: watch.fresh(20), "20 fresh controller states")
    # The simulator takes each arm's commands where its driver would (the arm's namespace) ...
    for ns in ("left_arm", "right_arm"):
        topic = f"/{ns}/forward_velocity_controller/commands"
        readers = lambda: {(i.node_namespace, i.node_name) for i in rclpy_node.get_subscriptions_info_by_topic(topic)}  # noqa: E731
        spin_until(rclpy_node, lambda: ("/", "mujoco_sim") in readers(), 30.0, lambda: f"mujoco_sim reading {topic}: {readers()}")
        spin_until(rclpy_node, lambda: watch.commands[topic], 30.0, f"task_controller's commands on {topic}")
    # ... and applies them: the right arm moves to the scene's goal.
    def right_arm():
        return [dict(zip(m.name, m.position)) for m in joints if "right_elbow_joint" in m.name]

    spin_until(rclpy_node, lambda: len(right_arm()) > 1, 30.0, "/joint_states with the right arm")
    first = right_arm()[0]

    def moved(prefix):
        last = right_arm()[-1]
        return max(abs(last[n] - first[n]) for n in first if n.startswith(prefix)) > 1e-2

    spin_until(rclpy_node, lambda: moved("right_"), 60.0, "the right arm moving in the simulation")
    watch.commands_only()
    rc, alive = la.interrupt()
    assert not alive and rc == 0 and "has died" not in la.output(), la.output()[-3000:]
    spin_until(rclpy_node, watch.last_commands_zero, 10.0, "zero commands last")


@pytest.mark.parametrize("scene", ["intentional_contact", "tomm_movable_obstacles", "tactile_guidance"])
def test_the_real_robot_path_reads_a_setup_as_the_controller_does(scene, ament_prefix, monkeypatch):
    """hardware:=real takes the URDF and skin layout from the controller setup without a scene
    (skin_control_launch.setup_files, following `base` files): the same files mujoco_sim
    --describe resolves through skin_core for the scenario's setup."""
    import os
    import sys

    monkeypatch.setenv("AMENT_PREFIX_PATH", ament_prefix["AMENT_PREFIX_PATH"])
    pytest.importorskip("launch_ros", reason="needs the ROS 2 launch system (see conftest.ros2_or_skip)")
    sys.path.insert(0, str(TOP / "launch"))
    from skin_control_launch import setup_files

    d = describe(scene)
    assert tuple(map(os.path.realpath, setup_files(d["setup"]))) == (d["urdf"], d["layout"])


def test_a_setup_without_urdf(ament_prefix, monkeypatch, tmp_path):
    """A robot setup whose controller takes robot_description (`urdf: null` over TOMM's): mujoco_sim
    --describe names the scene's URDF, and hardware:=real (robot_state_publisher needs a file) says
    the setup names none."""
    import json
    import subprocess
    import sys

    from conftest import binary

    setup = tmp_path / "no_urdf.yaml"
    setup.write_text(f"base: {TOP / 'config' / 'controller' / 'tomm.yaml'}\nurdf: null\n")
    out = subprocess.run([binary("mujoco_sim"), "--describe", "--scene", "tactile_guidance", "--controller", setup],
                         check=True, capture_output=True, text=True).stdout
    assert json.loads(out)["urdf"] == str((TOP / "urdf" / "tomm.urdf").resolve())
    monkeypatch.setenv("AMENT_PREFIX_PATH", ament_prefix["AMENT_PREFIX_PATH"])
    pytest.importorskip("launch_ros", reason="needs the ROS 2 launch system (see conftest.ros2_or_skip)")
    sys.path.insert(0, str(TOP / "launch"))
    from skin_control_launch import setup_files

    with pytest.raises(RuntimeError, match="names no urdf"):
        setup_files(str(setup))


def test_sim_hardware_with_a_stamped_base_command(launch, rclpy_node):  # noqa: F811
    """base_command_stamped:=true, as a ros2_control base controller needs it: the controller sends
    geometry_msgs/TwistStamped in base_link, mujoco_sim (--base-command-stamped) drives the base
    with it, and after Ctrl-C the last base command is a zero of the same type."""
    from geometry_msgs.msg import TwistStamped
    from nav_msgs.msg import Odometry

    base, odom = [], []
    rclpy_node.create_subscription(TwistStamped, "/base/cmd_vel", base.append, 1000)
    rclpy_node.create_subscription(Odometry, "/base/odom", odom.append, 100)
    # a scene whose base moves (tomm_movable_obstacles fixes it to the ground)
    la = launch("skin_control", "tomm.launch.py", "hardware:=sim", "scene:=tactile_guidance",
                "robot_state_publisher:=false", "base_command_stamped:=true")
    moving = lambda: base and any(abs(v) > 1e-3 for v in (base[-1].twist.linear.x, base[-1].twist.linear.y, base[-1].twist.angular.z))  # noqa: E731
    la.wait_for(rclpy_node, moving, "a moving TwistStamped base command")
    position = lambda m: (m.pose.pose.position.x, m.pose.pose.position.y)  # noqa: E731
    start = position(odom[-1])
    spin_until(rclpy_node, lambda: max(abs(a - b) for a, b in zip(position(odom[-1]), start)) > 1e-3, 60.0,
               "the simulated base moving on the stamped commands")
    assert {m.header.frame_id for m in base} == {"base_link"}
    assert all(m.header.stamp.sec > 0 or m.header.stamp.nanosec > 0 for m in base), "stamped (sim time)"
    rc, alive = la.interrupt()
    assert not alive and rc == 0 and "has died" not in la.output(), la.output()[-3000:]
    zero = lambda m: (m.twist.linear.x, m.twist.linear.y, m.twist.angular.z) == (0.0, 0.0, 0.0)  # noqa: E731
    spin_until(rclpy_node, lambda: zero(base[-1]), 10.0, "a zero TwistStamped last")
    assert base[-1].header.frame_id == "base_link"


@pytest.mark.parametrize("rsp, stamped", [("true", "false"), ("false", "true")])
def test_the_controller_takes_robot_state_publishers_description_and_the_base_type(rsp, stamped, ament_prefix,
                                                                                  monkeypatch):
    """hardware:=real as data: task_controller takes the URDF from robot_description when
    robot_state_publisher runs (mounted on the planar base: TOMM's starts at base_link there), else
    from the setup's file; base_command_stamped reaches the controller and the watchdog."""
    monkeypatch.setenv("AMENT_PREFIX_PATH", ament_prefix["AMENT_PREFIX_PATH"])
    from launch.actions import DeclareLaunchArgument
    from launch.launch_context import LaunchContext
    from launch_ros.actions import Node
    from launch_ros.utilities import evaluate_parameters

    m = tomm_launch_module()
    ctx = LaunchContext()
    for a in m.generate_launch_description().entities:
        if isinstance(a, DeclareLaunchArgument):
            ctx.launch_configurations[a.name] = "".join(s.text for s in a.default_value)
    ctx.launch_configurations.update(robot_state_publisher=rsp, base_command_stamped=stamped)
    nodes = {str(a.node_executable): a for a in m.launch_setup(ctx) if isinstance(a, Node)}
    params = {}
    for p in evaluate_parameters(ctx, nodes["task_controller"]._Node__parameters):
        params.update(p if isinstance(p, dict) else {})
    assert params["use_robot_description"] == (rsp == "true") and params["mobile_base"] is True, params
    assert params["base_command_stamped"] == (stamped == "true"), params
    dog = texts(nodes["skin_watchdog"])
    assert ("--base-stamped" in dog) == (stamped == "true"), dog
