"""task_controller, priority_supervisor and skin_aggregator on TOMM over real Fast DDS, with rclpy
as the outside peer playing robot drivers, skin and user.

Checked: zero commands on every command topic before the inputs are complete (the state says waiting); once both arms'
joint states (two partial messages, as two UR drivers send them), odometry, a scan and skin
cells arrive, commands in each arm's joint order and a controller state; a goal moves the right
arm (its commands become nonzero, the state's goal error is set); the aggregator's patches and
markers for the same cells; /supervisor/arrangement latched; /supervisor/set_phase refused with
the reason under TOMM's intentional_contact policy; the parameter services of task_controller
(list, get, set a run-time value, refuse a start-only one and an invalid one); on SIGINT zero
commands on every command topic and exit status 0."""
import signal

import pytest
import yaml
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from conftest import TOP, binary, call_service, cell_array, set_parameter, spin_until

QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
ARMS = {side: [f"{side}_{j}" for j in ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                        "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")]
        for side in ("left", "right")}
HOME = yaml.safe_load((TOP / "config" / "controller" / "tomm.yaml").read_text())["posture"]


class Peer:
    def __init__(self, node):
        from geometry_msgs.msg import PoseStamped, Twist
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState, LaserScan
        from skin_msgs.msg import Arrangement, ControllerState, PatchWrenchArray, SkinCellArray
        from std_msgs.msg import Float64MultiArray
        from visualization_msgs.msg import MarkerArray

        self.node = node
        self.got = {k: [] for k in ("left", "right", "base", "state", "arrangement", "patches", "markers")}
        node.create_subscription(Float64MultiArray, "/left_arm/forward_velocity_controller/commands",
                                 self.got["left"].append, QOS)
        node.create_subscription(Float64MultiArray, "/right_arm/forward_velocity_controller/commands",
                                 self.got["right"].append, QOS)
        node.create_subscription(Twist, "/base/cmd_vel", self.got["base"].append, QOS)
        node.create_subscription(ControllerState, "/controller/state", self.got["state"].append, QOS)
        node.create_subscription(Arrangement, "/supervisor/arrangement", self.got["arrangement"].append, LATCHED)
        node.create_subscription(PatchWrenchArray, "/skin/patches", self.got["patches"].append, QOS)
        node.create_subscription(MarkerArray, "/skin/markers", self.got["markers"].append, QOS)
        self.joints = node.create_publisher(JointState, "/joint_states", QOS)
        self.odom = node.create_publisher(Odometry, "/base/odom", QOS)
        self.scan = node.create_publisher(LaserScan, "/scan", QOS)
        self.cells = node.create_publisher(SkinCellArray, "/skin/cells", QOS)
        self.goal = node.create_publisher(PoseStamped, "/goal", LATCHED)
        self.streaming = False
        self.timer = node.create_timer(0.02, self.tick)

    def tick(self):
        """The robot at its home pose, at rest, stamped now (50 Hz, within input_timeout_s)."""
        if not self.streaming:
            return
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState, LaserScan

        now = self.node.get_clock().now().to_msg()
        for side, offset in (("left", 3), ("right", 9)):
            js = JointState(name=ARMS[side], position=HOME[offset:offset + 6], velocity=[0.0] * 6)
            js.header.stamp = now
            self.joints.publish(js)
        odom = Odometry()
        odom.header.stamp, odom.header.frame_id, odom.child_frame_id = now, "odom", "base_link"
        odom.pose.pose.orientation.w = 1.0
        self.odom.publish(odom)
        scan = LaserScan(angle_min=-3.14, angle_max=3.14, angle_increment=0.0175, range_min=0.05,
                         range_max=8.0, ranges=[8.5] * 360)
        scan.header.stamp, scan.header.frame_id = now, "laser"
        self.scan.publish(scan)
        self.cells.publish(cell_array([(self.cell_id, [0.0] * 3, 0.6)], now))

    def call(self, srv_type, name, request):
        return call_service(self.node, srv_type, name, request)

    def set_param(self, name, value):
        return set_parameter(self.node, "/task_controller", name, value)


def test_controller_graph(spawn, rclpy_node):
    from geometry_msgs.msg import PoseStamped
    from rcl_interfaces.srv import DescribeParameters, GetParameters, ListParameters
    from skin_msgs.srv import SetPhase

    layout = yaml.safe_load((TOP / "config" / "skin" / "tomm.yaml").read_text())
    forearm_cell = next(c["id"] for c in layout["cells"] if c["patch"] == 8)
    tc = spawn(binary("task_controller"), "--ros-args", "--params-file", TOP / "config/ros/task_controller.yaml",
               "-p", "autostart:=true")
    sup = spawn(binary("priority_supervisor"), "--ros-args", "--params-file",
                TOP / "config/ros/priority_supervisor.yaml")
    agg = spawn(binary("skin_aggregator"), "--ros-args", "--params-file", TOP / "config/ros/skin_aggregator.yaml")
    peer = Peer(rclpy_node)
    peer.cell_id = forearm_cell
    got = peer.got

    # Before any input: zero commands on every command topic (the timer runs).
    spin_until(rclpy_node, lambda: got["left"] and got["right"] and got["base"], 30.0, "zero commands")
    assert all(v == 0.0 for m in got["left"] + got["right"] for v in m.data)
    assert all(m.linear.x == m.linear.y == m.angular.z == 0.0 for m in got["base"])
    assert [len(got[s][0].data) for s in ("left", "right")] == [6, 6]
    assert all(s.input_status == s.INPUT_WAITING for s in got["state"]), "waiting for the inputs"
    spin_until(rclpy_node, lambda: got["arrangement"], 30.0, "the latched arrangement")
    assert got["arrangement"][-1].task_order == ["avoidance", "goal", "contact_reaction"]

    # Inputs: cycles run, the state says so; no goal yet.
    peer.streaming = True
    spin_until(rclpy_node, lambda: len(got["state"]) >= 5 and got["state"][-1].input_status
               == got["state"][-1].INPUT_FRESH, 30.0, "/controller/state with fresh inputs")
    assert got["state"][-1].goal_error < 0
    names = [t.name for t in got["state"][-1].tasks]
    assert "goal" in names and "posture" in names

    # A goal 10 cm beside the right hand: the right arm's commands become nonzero.
    goal = PoseStamped()
    goal.header.frame_id = "world"
    state_before = len(got["state"])
    goal.pose.position.x, goal.pose.position.y, goal.pose.position.z = 0.6, -0.5, 1.0
    goal.pose.orientation.w = 1.0
    peer.goal.publish(goal)
    spin_until(rclpy_node, lambda: len(got["state"]) > state_before and got["state"][-1].goal_error >= 0
               and any(abs(v) > 1e-6 for v in got["right"][-1].data), 30.0, "a moving right arm")

    # The aggregator sees the same cells.
    spin_until(rclpy_node, lambda: any(p.active_cells for m in got["patches"] for p in m.patches), 30.0,
               "an active patch on /skin/patches")
    spin_until(rclpy_node, lambda: got["markers"], 30.0, "/skin/markers")

    # The phase service refuses under Table I, with the reason.
    reply = peer.call(SetPhase, "/supervisor/set_phase", SetPhase.Request(phase=SetPhase.Request.CONTACT))
    assert not reply.accepted and "intentional_contact policy" in reply.message, reply.message

    # Parameters.
    names = peer.call(ListParameters, "/task_controller/list_parameters", ListParameters.Request()).result.names
    for n in ("setup_file", "control_rate_hz", "trigger", "input_timeout_s", "arms.namespaces",
              "skin.fusion.weight_force", "tasks.goal.kp_n_per_m"):
        assert n in names, f"{n} not listed"
    vals = peer.call(GetParameters, "/task_controller/get_parameters",
                     GetParameters.Request(names=["control_rate_hz", "trigger"])).values
    assert (vals[0].double_value, vals[1].string_value) == (125.0, "timer")
    ok = peer.set_param("input_timeout_s", 0.2)
    assert ok.successful, ok.reason
    bad = peer.set_param("input_timeout_s", -1.0)
    assert not bad.successful and "input_timeout_s" in bad.reason and "[0.001, 1] s" in bad.reason, bad.reason
    # Descriptions come from the declarations (declare_params!): unit, range, when it applies.
    desc = peer.call(DescribeParameters, "/task_controller/describe_parameters",
                     DescribeParameters.Request(names=["input_timeout_s", "control_rate_hz", "tasks.goal.kp_n_per_m"]))
    texts = [d.description for d in desc.descriptors]
    assert "[s], in [0.001, 1] (settable)" in texts[0], texts
    assert "[Hz], in (0, 10000] (start only)" in texts[1], texts
    assert "(start only)" in texts[2], texts
    ro_rate = peer.set_param("control_rate_hz", 250.0)
    assert not ro_rate.successful and "read-only" in ro_rate.reason, ro_rate.reason
    ro = peer.set_param("tasks.goal.kp_n_per_m", 10.0)
    assert not ro.successful and "read-only" in ro.reason, ro.reason

    # SIGINT: zero commands on every command topic, exit 0.
    peer.streaming = False
    n = {k: len(got[k]) for k in ("left", "right", "base")}
    tc.send_signal(signal.SIGINT)
    assert tc.wait(timeout=10) == 0

    def zero_last():
        b = got["base"][-1]
        return (all(len(got[k]) > n[k] for k in n) and b.linear.x == b.linear.y == b.angular.z == 0.0
                and all(v == 0.0 for k in ("left", "right") for v in got[k][-1].data))

    # In-flight cycle commands may come first; the last message on every topic must be zero.
    spin_until(rclpy_node, zero_last, 10.0, "zero commands as the last message on every command topic")
    out = tc.stdout.read()
    assert "zero commands sent on /left_arm/forward_velocity_controller/commands" in out, out
    for p in (sup, agg):
        p.send_signal(signal.SIGINT)
        assert p.wait(timeout=10) == 0
