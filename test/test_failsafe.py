"""Fail-safe behaviour of task_controller on TOMM over real Fast DDS (docs/reliability.md), with
rclpy as the robot: two UR5 drivers publishing /joint_states separately with their own stamps,
the base (odometry, LIDAR), the skin. The robot integrates the commands it receives.

Checked, each against the running binary:
- per-joint health: the right driver lagging the left by 20 ms is accepted (fresh, no stamp
  refusal); the left driver going silent, or reporting NaN, makes the state STALE and the
  commands ramp to zero within the acceleration limits;
- honest time: a joint state stamped 0.5 s ahead is refused and counted and holds nothing back;
- a scan in an unknown frame never counts as a scan (the controller keeps waiting);
- the first command after WAITING starts from zero although the drivers report 1.57 rad/s and
  the base 0.5 m/s; a 90 degree jump of the odometry yaw does not turn /base/cmd_vel beyond its
  acceleration limit;
- parameters: a timeout of 1e300 is refused with its range; a 20 000-entry SetParameters request
  does not hold up the control cycle;
- one commander: a second task_controller on the same command topics exits with the reason and
  never publishes a command."""
import math
import signal
import time

import yaml
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from conftest import TOP, binary, call_service, cell_array, set_parameter, spin_until
from test_controller_graph import ARMS, HOME, LATCHED

DEEP = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
RESOLVER = yaml.safe_load((TOP / "config" / "resolver.yaml").read_text())
RATE_HZ = 125.0
ARM_STEP = RESOLVER["arm"]["max_acceleration"] / RATE_HZ
BASE = RESOLVER["base"]
PARAMS = TOP / "config" / "ros" / "task_controller.yaml"


class Robot:
    """Two arm drivers, the base and the skin at 100 Hz; each arm's joint states stamped now +
    `offset[side]`, `None` silences a side, `nan` puts NaN into one of its positions. `stamped`:
    the base takes geometry_msgs/TwistStamped (each one's frame and stamp kept in `headers`)."""

    def __init__(self, node, cell_id, stamped=False):
        from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState, LaserScan
        from skin_msgs.msg import ControllerState, SkinCellArray
        from std_msgs.msg import Float64MultiArray

        self.node, self.cell_id = node, cell_id
        self.got = {k: [] for k in ("left", "right", "base", "state")}
        self.offset = {"left": 0.0, "right": 0.0}
        self.nan = set()
        self.reported = None  # velocities the drivers report instead of the commands
        self.yaw_jump = 0.0
        self.scan_frame = "laser"
        self.streaming = False
        self.q = {side: list(HOME[o:o + 6]) for side, o in (("left", 3), ("right", 9))}
        self.cmd = {"left": [0.0] * 6, "right": [0.0] * 6}
        self.base, self.twist = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        for side in ("left", "right"):
            node.create_subscription(Float64MultiArray, f"/{side}_arm/forward_velocity_controller/commands",
                                     lambda m, info, s=side: self.on_arm(s, m, info), DEEP)
        self.headers = []  # stamped: (source time, frame_id, header stamp) per base command
        if stamped:
            node.create_subscription(TwistStamped, "/base/cmd_vel", self.on_twist_stamped, DEEP)
        else:
            node.create_subscription(Twist, "/base/cmd_vel", self.on_twist, DEEP)
        node.create_subscription(ControllerState, "/controller/state", self.got["state"].append, DEEP)
        self.pub = {"js": node.create_publisher(JointState, "/joint_states", DEEP),
                    "odom": node.create_publisher(Odometry, "/base/odom", DEEP),
                    "scan": node.create_publisher(LaserScan, "/scan", DEEP),
                    "cells": node.create_publisher(SkinCellArray, "/skin/cells", DEEP),
                    "goal": node.create_publisher(PoseStamped, "/goal", LATCHED)}
        self.goal, self.ticks = None, 0
        node.create_timer(0.01, self.tick)

    def on_arm(self, side, msg, info):
        self.got[side].append((info["source_timestamp"] * 1e-9, list(msg.data)))
        self.cmd[side] = list(msg.data)

    def on_twist(self, msg, info):
        self.twist = [msg.linear.x, msg.linear.y, msg.angular.z]
        self.got["base"].append((info["source_timestamp"] * 1e-9, list(self.twist)))

    def on_twist_stamped(self, msg, info):
        stamp = msg.header.stamp.sec + 1e-9 * msg.header.stamp.nanosec
        self.headers.append((info["source_timestamp"] * 1e-9, msg.header.frame_id, stamp))
        self.on_twist(msg.twist, info)

    def send_goal(self, x=2.0, y=-0.3, z=1.0):
        """A goal out of reach of the arm alone: the right arm and the base move."""
        from geometry_msgs.msg import PoseStamped

        goal = PoseStamped()
        goal.header.frame_id = "world"
        goal.pose.position.x, goal.pose.position.y, goal.pose.position.z = x, y, z
        goal.pose.orientation.w = 1.0
        self.goal = goal
        self.pub["goal"].publish(goal)

    def joint_state(self, side, stamp_offset):
        from rclpy.duration import Duration
        from sensor_msgs.msg import JointState

        velocity = list(self.reported or self.cmd[side])
        js = JointState(name=list(ARMS[side]), position=list(self.q[side]), velocity=velocity)
        if side in self.nan:
            js.position[1] = float("nan")
        now = self.node.get_clock().now()
        js.header.stamp = (now + Duration(nanoseconds=int(stamp_offset * 1e9))).to_msg()
        return js

    def tick(self):
        dt = 0.01
        for side in ("left", "right"):
            self.q[side] = [q + v * dt for q, v in zip(self.q[side], self.cmd[side])]
        c, s = math.cos(self.base[2]), math.sin(self.base[2])
        vx, vy, wz = self.twist
        self.base = [self.base[0] + (c * vx - s * vy) * dt, self.base[1] + (s * vx + c * vy) * dt, self.base[2] + wz * dt]
        if not self.streaming:
            return
        # The goal again every 0.5 s, as an operator's tool does: controllers read goals volatile
        # (REP 2003), so one that matched after the first send (slow discovery, a restart) gets it.
        self.ticks += 1
        if self.goal is not None and self.ticks % 50 == 0:
            self.pub["goal"].publish(self.goal)
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import LaserScan

        now = self.node.get_clock().now().to_msg()
        for side in ("left", "right"):
            if self.offset[side] is not None:
                self.pub["js"].publish(self.joint_state(side, self.offset[side]))
        odom = Odometry()
        odom.header.stamp, odom.header.frame_id, odom.child_frame_id = now, "odom", "base_link"
        yaw = self.base[2] + self.yaw_jump
        odom.pose.pose.position.x, odom.pose.pose.position.y = self.base[0], self.base[1]
        odom.pose.pose.orientation.z, odom.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        twist = [0.5, 0.0, 0.0] if self.reported else self.twist
        odom.twist.twist.linear.x, odom.twist.twist.linear.y, odom.twist.twist.angular.z = twist
        self.pub["odom"].publish(odom)
        # an obstacle 0.7 m ahead of the base: base avoidance pushes it back
        ranges = [0.7 if abs(-3.14 + 0.0175 * k) < 0.3 else 8.5 for k in range(360)]
        scan = LaserScan(angle_min=-3.14, angle_max=3.14, angle_increment=0.0175, range_min=0.05,
                         range_max=8.0, ranges=ranges)
        scan.header.stamp, scan.header.frame_id = now, self.scan_frame
        self.pub["scan"].publish(scan)
        self.pub["cells"].publish(cell_array([(self.cell_id, [0.0] * 3, 0.0)], now))

    def states(self, since=0):
        return self.got["state"][since:]

    def counts(self):
        s = self.got["state"][-1]
        return dict(zip(s.issue_names, s.issue_counts))


def forearm_cell():
    layout = yaml.safe_load((TOP / "config" / "skin" / "tomm.yaml").read_text())
    return next(c["id"] for c in layout["cells"] if c["patch"] == 8)


def start_controller(spawn, *extra):
    return spawn(binary("task_controller"), "--ros-args", "--params-file", PARAMS,
                 "-p", "commander_wait_s:=0.5", "-p", "autostart:=true", *extra)


def arm_steps_ok(msgs, excused=lambda m: False):
    """Every change between consecutive commands within a_max / rate (prints the first that is not);
    a step into a message `excused(m)` accepts is not checked."""
    for k, (p, m) in enumerate(zip(msgs, msgs[1:])):
        if max(abs(a - b) for a, b in zip(m[1], p[1])) > ARM_STEP * (1 + 1e-6) and not excused(m):
            print(f"step {k}: {p} -> {m}")
            return False
    return True


def test_joint_health_is_per_joint_and_per_driver(spawn, rclpy_node):
    from skin_msgs.msg import ControllerState

    start_controller(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    robot.offset["right"] = -0.02  # the right driver's stamps lag by 20 ms
    robot.streaming = True
    robot.send_goal()
    got = robot.got
    spin_until(rclpy_node, lambda: got["right"] and any(abs(v) > 0.05 for v in got["right"][-1][1]), 60.0,
               "the right arm moving to the goal")
    n = len(got["state"])
    spin_until(rclpy_node, lambda: len(got["state"]) > n + 50, 30.0, "50 more states")
    assert any(s.input_status == ControllerState.INPUT_FRESH for s in robot.states(n))
    counts = robot.counts()  # both drivers' messages accepted: no stamp refused
    assert counts["/joint_states: stamp out of order"] == 0, counts
    assert counts["/joint_states: joint stamp out of order"] == 0, counts

    # the left driver goes silent: stale once its joints are older than input_timeout_s
    for fault in ("silent", "nan"):
        if fault == "silent":
            robot.offset["left"] = None
        else:
            robot.offset["left"], robot.nan = 0.0, {"left"}
        n = len(got["state"])
        spin_until(rclpy_node, lambda: any(s.input_status == ControllerState.INPUT_STALE for s in robot.states(n)),
                   30.0, f"a stale state with the left driver {fault}")
        k = len(got["right"])
        spin_until(rclpy_node, lambda: len(got["right"]) > k + 60, 30.0, "60 more right-arm commands")
        assert all(v == 0.0 for v in got["right"][-1][1]), f"{fault}: ramped to zero: {got['right'][-1]}"
        assert arm_steps_ok(got["right"][k - 5:]), f"{fault}: the ramp is within the acceleration limits"
        assert all(s.input_status == ControllerState.INPUT_STALE for s in robot.states(n + 20)), fault
        robot.nan, robot.offset["left"] = set(), 0.0
        n = len(got["state"])
        spin_until(rclpy_node, lambda: any(s.input_status == ControllerState.INPUT_FRESH for s in robot.states(n)),
                   30.0, "fresh again")
    assert robot.counts()["/joint_states: non-finite value"] > 0

    # a joint state from 0.5 s ahead: refused, counted, and the honest ones go on
    future = robot.joint_state("left", 0.5)
    future.position = [p + 1.0 for p in future.position]
    before = robot.counts()
    robot.pub["js"].publish(future)
    spin_until(rclpy_node, lambda: robot.counts()["/joint_states: stamp in the future"] > before["/joint_states: stamp in the future"],
               30.0, "the future stamp refused")
    n = len(got["state"])
    spin_until(rclpy_node, lambda: len(got["state"]) > n + 30, 30.0, "30 more states")
    after = robot.counts()
    assert any(s.input_status == ControllerState.INPUT_FRESH for s in robot.states(n))
    for kind in ("stamp out of order", "joint stamp out of order"):
        assert after[f"/joint_states: {kind}"] == before[f"/joint_states: {kind}"], \
            "the refused future stamp holds no honest message back"


def test_first_command_from_zero_and_base_rate_limit_across_a_yaw_jump(spawn, rclpy_node):
    from skin_msgs.msg import ControllerState

    start_controller(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    got = robot.got
    # the drivers report a wrong velocity (1.57 rad/s on every joint, the base at 0.5 m/s)
    robot.reported = [math.pi / 2] * 6
    spin_until(rclpy_node, lambda: got["left"] and got["base"], 30.0, "zero commands while waiting")
    robot.streaming = True
    robot.send_goal()
    spin_until(rclpy_node, lambda: any(s.input_status == ControllerState.INPUT_FRESH for s in got["state"]),
               30.0, "a cycle")
    spin_until(rclpy_node, lambda: len(got["right"]) > 20, 30.0, "commands")
    for side in ("left", "right"):
        assert arm_steps_ok(got[side]), f"{side}: {[m[1] for m in got[side][:5]]}"
    steps = [math.hypot(m[1][0] - p[1][0], m[1][1] - p[1][1]) for p, m in zip(got["base"], got["base"][1:])]
    assert max(steps) <= BASE["max_linear_accel_m_s2"] / RATE_HZ * (1 + 1e-6), max(steps)

    # the real velocities again; the base is pushed back by the obstacle; then the yaw jumps by 90 deg
    robot.reported = None
    spin_until(rclpy_node, lambda: math.hypot(*got["base"][-1][1][:2]) > 0.005, 30.0, "the base moving")
    k = len(got["base"])
    robot.yaw_jump = math.pi / 2
    spin_until(rclpy_node, lambda: len(got["base"]) > k + 50, 30.0, "50 base commands after the jump")
    msgs = got["base"][k - 10:]
    for p, m in zip(msgs, msgs[1:]):
        dv = math.hypot(m[1][0] - p[1][0], m[1][1] - p[1][1])
        assert dv <= BASE["max_linear_accel_m_s2"] / RATE_HZ * (1 + 1e-6), (p, m)
        assert abs(m[1][2] - p[1][2]) <= BASE["max_angular_accel_rad_s2"] / RATE_HZ * (1 + 1e-6), (p, m)


def test_refused_scans_do_not_count(spawn, rclpy_node):
    from skin_msgs.msg import ControllerState

    start_controller(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    robot.scan_frame = "right_hand"  # not a frame on the base: every scan is refused
    robot.streaming = True
    got = robot.got
    spin_until(rclpy_node, lambda: len(got["state"]) > 60 and robot.counts()["/scan: message refused"] > 30,
               30.0, "refused scans")
    assert all(s.input_status == ControllerState.INPUT_WAITING for s in got["state"]), \
        f"a refused scan is no scan: {[s.input_status for s in got['state']]}"
    robot.scan_frame = "laser"
    spin_until(rclpy_node, lambda: got["state"][-1].input_status == ControllerState.INPUT_FRESH, 30.0, "fresh")
    robot.scan_frame = "right_hand"
    n = len(got["state"])
    spin_until(rclpy_node, lambda: any(s.input_status == ControllerState.INPUT_STALE for s in robot.states(n)),
               30.0, "stale once the last good scan is older than scan_timeout_s")


def test_parameters_are_bounded_and_never_stall_the_cycle(spawn, rclpy_node):
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParameters
    from skin_msgs.msg import ControllerState

    start_controller(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    robot.streaming = True
    got = robot.got
    spin_until(rclpy_node, lambda: got["state"] and got["state"][-1].input_status == ControllerState.INPUT_FRESH,
               30.0, "fresh inputs")
    for name, value in (("input_timeout_s", 1e300), ("scan_timeout_s", -1.0), ("max_stamp_lead_s", 5.0),
                        ("odom_timeout_s", float("nan"))):
        r = set_parameter(rclpy_node, "/task_controller", name, value)
        why = "not a finite number" if math.isnan(value) else "must be in ["
        assert not r.successful and name in r.reason and why in r.reason, (name, r.reason)
    r = set_parameter(rclpy_node, "/task_controller", "input_timeout_s", 0.2)
    assert r.successful, r.reason

    # 20 000 entries in one request: the control cycle goes on meanwhile
    req = SetParameters.Request()
    value = ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=0.1)
    req.parameters = [Parameter(name="input_timeout_s", value=value) for _ in range(20_000)]
    n = len(got["state"])
    t0 = time.monotonic()
    reply = call_service(rclpy_node, SetParameters, "/task_controller/set_parameters", req, timeout=120.0)
    took = time.monotonic() - t0
    assert len(reply.results) == 20_000 and all(r.successful for r in reply.results)
    stamps = [s.header.stamp.sec + 1e-9 * s.header.stamp.nanosec for s in robot.states(n)]
    gap = max(b - a for a, b in zip(stamps, stamps[1:]))
    print(f"20 000-entry request answered in {took:.2f} s; longest gap between controller states {gap * 1e3:.1f} ms "
          f"over {len(stamps)} states")
    assert gap < 0.25, f"the control cycle stalled for {gap:.3f} s during the request"


def test_one_commander(spawn, rclpy_node):
    first = start_controller(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    robot.streaming = True
    robot.send_goal()
    got = robot.got
    spin_until(rclpy_node, lambda: got["right"] and any(abs(v) > 0.05 for v in got["right"][-1][1]), 60.0,
               "the first controller moving the right arm")
    k = len(got["right"])
    # a second one on the same topics (here under its own node name; the same name works alike)
    second = spawn(binary("task_controller"), "--ros-args", "--params-file", PARAMS, "-r", "__node:=task_controller_2")
    spin_until(rclpy_node, lambda: second.poll() is not None, 30.0, "the second controller giving way")
    assert second.returncode != 0, "the second controller must not stay"
    out = second.stdout.read()
    assert "another task_controller" in out and "/left_arm/forward_velocity_controller/commands" in out, out
    assert first.poll() is None
    spin_until(rclpy_node, lambda: len(got["right"]) > k + 50, 30.0, "more commands from the first")
    # the second never sent a command: no zero (or other) command interleaved with the motion
    assert arm_steps_ok(got["right"][k - 5:]) and arm_steps_ok(got["left"][k - 5:])
    first.send_signal(signal.SIGINT)
    assert first.wait(timeout=10) == 0


def test_safe_start_with_the_managed_node_interface(spawn, rclpy_node):
    """The shipped robot parameters (autostart: false): zero commands until activated through
    the standard lifecycle services; deactivation ramps to zero within the limits; shutdown ends
    the node with zero commands."""
    from lifecycle_msgs.msg import Transition, TransitionEvent
    from lifecycle_msgs.srv import ChangeState, GetAvailableTransitions, GetState

    tc = spawn(binary("task_controller"), "--ros-args", "--params-file", PARAMS, "-p", "commander_wait_s:=0.5")
    events = []
    rclpy_node.create_subscription(TransitionEvent, "/task_controller/transition_event", events.append, DEEP)
    robot = Robot(rclpy_node, forearm_cell())
    robot.streaming = True
    robot.send_goal()
    got = robot.got

    def state():
        return call_service(rclpy_node, GetState, "/task_controller/get_state", GetState.Request()).current_state.label

    def change(id=0, label=""):
        req = ChangeState.Request(transition=Transition(id=id, label=label))
        return call_service(rclpy_node, ChangeState, "/task_controller/change_state", req).success

    assert state() == "unconfigured"
    spin_until(rclpy_node, lambda: len(got["right"]) > 100, 30.0, "100 holding periods")
    assert all(v == 0.0 for k in ("left", "right") for m in got[k] for v in m[1]), "holding: zero commands"
    assert not change(Transition.TRANSITION_ACTIVATE), "activate needs configure first"
    assert change(Transition.TRANSITION_CONFIGURE) and state() == "inactive"
    k = len(got["right"])
    spin_until(rclpy_node, lambda: len(got["right"]) > k + 50, 30.0, "50 inactive periods")
    assert all(v == 0.0 for m in got["right"][k:] for v in m[1]), "inactive: zero commands"

    assert change(label="activate") and state() == "active"
    spin_until(rclpy_node, lambda: any(abs(v) > 0.05 for v in got["right"][-1][1]), 30.0, "the arm moving once active")
    names = [t.transition.label for t in call_service(rclpy_node, GetAvailableTransitions,
             "/task_controller/get_available_transitions", GetAvailableTransitions.Request()).available_transitions]
    assert names == ["deactivate", "shutdown"], names

    k = len(got["right"])
    assert change(label="deactivate") and state() == "inactive"
    spin_until(rclpy_node, lambda: len(got["right"]) > k + 100, 30.0, "100 periods after deactivation")
    assert all(v == 0.0 for v in got["right"][-1][1]), "ramped to zero"
    assert arm_steps_ok(got["right"][k - 5:]), "the ramp is within the acceleration limits"
    spin_until(rclpy_node, lambda: len(events) >= 3, 10.0, "three transition events")
    assert [(e.transition.label, e.start_state.label, e.goal_state.label) for e in events] == [
        ("configure", "unconfigured", "inactive"), ("activate", "inactive", "active"),
        ("deactivate", "active", "inactive")]
    assert change(label="shutdown")
    assert tc.wait(timeout=10) == 0
