"""The simulation through the real `ros2 launch` (as users start it): a planar and a TOMM scene,
the TOMM one in a namespace. rclpy watches the graph: the controller cycles, the arm reaches a
goal given in its hand's frame by an ordinary (volatile) publisher, markers and TF arrive, every
frame the markers, the patch wrenches and config/skin.rviz name is in one TF tree (the published
/tf and /tf_static with what robot_state_publisher makes of the URDF it is given), and Ctrl-C
(SIGINT to the launch process) ends every process cleanly with zero commands last.
Skips without the `ros2` command line (conftest.ros2_or_skip)."""
import json
import os
import signal
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET

import pytest
import yaml

from conftest import TOP, binary, cell_array, ros2_or_skip, spin_until

# The graph's topics that are global by ROS convention (rcl's time source, tf2, logging).
GLOBAL_TOPICS = {"/clock", "/tf", "/tf_static", "/rosout", "/parameter_events", "/diagnostics"}


class Launch:
    """`ros2 launch <pkg> <file> <args>` in its own session; stopped with SIGINT."""

    def __init__(self, env, log, pkg, file, *args):
        self.log = log
        # SIGINT with its default disposition, as in a terminal: a test run started as a background
        # job inherits it ignored, and Python (so `ros2 launch`) then never sees Ctrl-C
        self.proc = subprocess.Popen(["ros2", "launch", pkg, file, *args], env=env,
                                     stdout=open(log, "w"), stderr=subprocess.STDOUT, start_new_session=True,
                                     preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))

    def output(self):
        return self.log.read_text()

    def children(self):
        import psutil

        return psutil.Process(self.proc.pid).children(recursive=True)

    def interrupt(self, timeout=60):
        """Ctrl-C: SIGINT to the launch process alone (it forwards it); its exit code, and the
        processes it had started that are still alive after `timeout`."""
        import psutil

        children = self.children()
        self.proc.send_signal(signal.SIGINT)
        rc = self.proc.wait(timeout=timeout)
        _, alive = psutil.wait_procs(children, timeout=timeout)
        # A node whose middleware teardown hung was ended by its bound (shutdown::bound_teardown):
        # the stop is clean, but the hang is worth seeing in the run's warnings.
        for line in self.output().splitlines():
            if "teardown did not end" in line:
                warnings.warn(line)
        return rc, alive

    def wait_for(self, node, predicate, what, timeout=90.0):
        """spin_until `predicate`, failing at once with the launch's output if it has ended."""
        spin_until(node, lambda: predicate() or self.proc.poll() is not None, timeout,
                   lambda: f"{what}\n{self.output()[-3000:]}")
        assert self.proc.poll() is None, f"ros2 launch ended before {what}:\n{self.output()[-3000:]}"

    def kill(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


@pytest.fixture
def launch(ament_prefix, tmp_path):
    ros2_or_skip()
    started = []

    def _launch(pkg, file, *args):
        started.append(Launch(ament_prefix, tmp_path / f"launch{len(started)}.log", pkg, file, *args))
        return started[-1]

    yield _launch
    for la in started:
        la.kill()


def describe(scene):
    out = subprocess.run([binary("mujoco_sim"), "--describe", "--scene", scene], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)


def urdf_links(path):
    return {link.get("name") for link in ET.parse(path).getroot().findall("link")}


def rsp_parents(urdf_path):
    """child -> parent of the joints robot_state_publisher would publish from the description the
    launch files give it (launch/skin_control_launch.py's mounted_description)."""
    sys.path.insert(0, str(TOP / "launch"))
    from skin_control_launch import mounted_description

    root = ET.fromstring(mounted_description(open(urdf_path).read()))
    return {j.find("child").get("link"): j.find("parent").get("link") for j in root.findall("joint")}


def rviz_fixed_frame():
    return yaml.safe_load((TOP / "config" / "skin.rviz").read_text())["Visualization Manager"]["Global Options"]["Fixed Frame"]


class Watch:
    """The rclpy side: subscriptions to the graph's outputs in namespace `pre`."""

    def __init__(self, node, pre, description):
        from geometry_msgs.msg import Twist
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from skin_msgs.msg import ControllerState, PatchWrenchArray
        from std_msgs.msg import Float64MultiArray
        from tf2_msgs.msg import TFMessage
        from visualization_msgs.msg import MarkerArray

        self.node = node
        self.states, self.markers, self.patches, self.tf, self.tf_static = [], [], [], [], []
        self.commands = {}
        latched = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.streams = [
            node.create_subscription(ControllerState, f"{pre}/controller/state", self.states.append, 100),
            node.create_subscription(MarkerArray, f"{pre}/skin/markers", self.markers.append, 100),
            node.create_subscription(PatchWrenchArray, f"{pre}/skin/patches", self.patches.append, 100),
            node.create_subscription(TFMessage, "/tf", self.tf.append, 100),
            node.create_subscription(TFMessage, "/tf_static", self.tf_static.append, latched),
        ]
        topics = [f"{pre}/{ns}/forward_velocity_controller/commands" for ns in description["arms"]["namespaces"]]
        for t in topics:
            self.commands[t] = []
            node.create_subscription(Float64MultiArray, t, self.commands[t].append, 1000)
        if description["base"]:
            self.commands[f"{pre}/base/cmd_vel"] = []
            node.create_subscription(Twist, f"{pre}/base/cmd_vel", self.commands[f"{pre}/base/cmd_vel"].append, 1000)

    def commands_only(self):
        """Stops reading everything but the commands (the 500 Hz streams would only load the
        reader while the last commands come in)."""
        for sub in self.streams:
            self.node.destroy_subscription(sub)
        self.streams = []

    def fresh(self, n):
        return sum(s.input_status == s.INPUT_FRESH for s in self.states) >= n

    def parents(self):
        """child -> {parents} over everything received on /tf and /tf_static."""
        out = {}
        for m in self.tf + self.tf_static:
            for t in m.transforms:
                out.setdefault(t.child_frame_id, set()).add(t.header.frame_id)
        return out

    def last_commands_zero(self):
        def zero(m):
            if hasattr(m, "data"):
                return all(v == 0.0 for v in m.data)
            return all(v == 0.0 for v in (m.linear.x, m.linear.y, m.linear.z, m.angular.x, m.angular.y, m.angular.z))

        return all(msgs and zero(msgs[-1]) for msgs in self.commands.values())


def root_of(frame, parent):
    seen = set()
    while frame in parent and frame not in seen:
        seen.add(frame)
        frame = parent[frame]
    return frame


@pytest.mark.parametrize("scene,ns", [("intentional_contact", ""), ("tomm_movable_obstacles", "tomm")])
def test_sim_launch(scene, ns, launch, rclpy_node):
    from geometry_msgs.msg import PoseStamped
    from rclpy.qos import qos_profile_sensor_data
    from skin_msgs.msg import SkinCellArray

    d = describe(scene)
    pre = f"/{ns}" if ns else ""
    watch = Watch(rclpy_node, pre, d)
    la = launch("skin_sim_ros", "sim.launch.py", f"scene:={scene}", "robot_state_publisher:=false", *([f"namespace:={ns}"] if ns else []))

    # The controller cycles on the scene's inputs (a TOMM scene without LIDAR: use_scan follows it).
    la.wait_for(rclpy_node, lambda: watch.fresh(20), "20 fresh controller states")

    # A goal 4 cm along the hand frame's x, from a volatile publisher, in the end effector's frame.
    setup = yaml.safe_load(open(d["setup"]))
    goal = PoseStamped()
    goal.header.frame_id = setup["end_effector"]
    goal.pose.position.x = 0.04
    goal.pose.orientation.w = 1.0
    pub = rclpy_node.create_publisher(PoseStamped, f"{pre}/goal", 10)
    spin_until(rclpy_node, lambda: pub.get_subscription_count() > 0, 30.0, f"a subscriber of {pre}/goal")
    n = len(watch.states)
    sent = {t: len(msgs) for t, msgs in watch.commands.items()}
    pub.publish(goal)
    spin_until(rclpy_node, lambda: len(watch.states) > n and 0.0 <= watch.states[-1].goal_error < 0.01, 60.0,
               lambda: f"the goal reached (goal_error {watch.states[-1].goal_error:.4f} m)")
    assert any(abs(v) > 1e-4 for t, msgs in watch.commands.items() for m in msgs[sent[t]:] for v in getattr(m, "data", [])), \
        "the arm moved to it"

    # Every topic and service of the graph's nodes is in the namespace (asked per node: graphs of
    # other sessions may share the machine).
    topics = {t for t, _ in rclpy_node.get_topic_names_and_types()}
    if ns:
        nodes = rclpy_node.get_node_names_and_namespaces()
        for name in ("mujoco_sim", "task_controller", "priority_supervisor", "skin_aggregator"):
            assert (name, f"/{ns}") in nodes, f"{name} not in /{ns}: {sorted(nodes)}"
            names = [t for get in (rclpy_node.get_publisher_names_and_types_by_node,
                                   rclpy_node.get_subscriber_names_and_types_by_node,
                                   rclpy_node.get_service_names_and_types_by_node)
                     for t, _ in get(name, f"/{ns}")]
            stray = sorted(t for t in set(names) - GLOBAL_TOPICS if not t.startswith(f"/{ns}/"))
            assert not stray, f"{name}: topics or services outside /{ns}: {stray}"
    for t in ("/joint_states", "/skin/cells", "/controller/state", "/supervisor/arrangement", "/skin/patches", "/goal"):
        assert f"{pre}{t}" in topics, f"{pre}{t} missing from {sorted(topics)}"

    # Markers and TF arrive; every frame named is in one tree with the RViz fixed frame. The skin
    # is event driven and may be idle here: one cell reading from a skin driver's side makes its
    # patch active (markers are sent when a patch changes).
    layout = yaml.safe_load(open(d["layout"]))
    cells = rclpy_node.create_publisher(SkinCellArray, f"{pre}/skin/cells", qos_profile_sensor_data)
    spin_until(rclpy_node, lambda: cells.get_subscription_count() >= 2, 30.0, "the aggregator's and controller's cell readers")
    # Sent every 0.1 s until it shows: the readers take sensor data best effort.
    touch = rclpy_node.create_timer(0.1, lambda: cells.publish(cell_array([(layout["cells"][0]["id"], [0.0] * 3, 0.5)])))
    spin_until(rclpy_node, lambda: any(m.action == m.ADD for a in watch.markers for m in a.markers), 30.0, "an active marker")
    rclpy_node.destroy_timer(touch)
    spin_until(rclpy_node, lambda: watch.patches, 30.0, f"{pre}/skin/patches")
    spin_until(rclpy_node, lambda: watch.tf_static, 30.0, "/tf_static")
    patch_frames = {f"skin_patch_{p['id']}" for p in layout["patches"]}
    spin_until(rclpy_node, lambda: patch_frames <= set(watch.parents()), 30.0,
               lambda: f"the patch frames on /tf_static (have {sorted(watch.parents())})")
    if d["base"]:
        spin_until(rclpy_node, lambda: "odom" in watch.parents().get("base_link", set()), 30.0, "odom -> base_link on /tf")
    tf = watch.parents()
    assert tf.get("odom") == {"world"}, tf.get("odom")
    parent = rsp_parents(d["urdf"])
    for child, parents in tf.items():
        assert len(parents) == 1, f"{child} has parents {parents} on /tf"
        (p,) = parents
        assert parent.get(child, p) == p, f"{child}: parent {p} on /tf, {parent[child]} from robot_state_publisher"
        parent[child] = p
    frames = {m.header.frame_id for a in watch.markers for m in a.markers if m.action == m.ADD}
    frames |= {p.header.frame_id for a in watch.patches for p in a.patches}
    frames.add(rviz_fixed_frame())
    links = urdf_links(d["urdf"])
    for f in sorted(frames):
        assert f in links or f in parent, f"frame {f} is neither a URDF link nor on TF"
        assert root_of(f, parent) == root_of(rviz_fixed_frame(), parent), f"{f} is not connected to the fixed frame"

    # Ctrl-C: every process ends cleanly, zero commands last.
    watch.commands_only()
    rc, alive = la.interrupt()
    assert not alive, f"still running after SIGINT: {alive}"
    out = la.output()
    assert "has died" not in out, out[-3000:]
    assert rc == 0, out[-3000:]
    spin_until(rclpy_node, watch.last_commands_zero, 10.0,
               lambda: f"zero commands last on {list(watch.commands)}: {[m[-1] if m else None for m in watch.commands.values()]}")
