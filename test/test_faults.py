"""Faults in the running graph (docs/reliability.md): task_controller, priority_supervisor and
skin_aggregator on TOMM over real Fast DDS, with rclpy as a robot that follows the commands and
misbehaves on a schedule:

  normal -> drop 10 % of every input -> bursts at 10x the rate -> inputs 50 ms late -> bad
  values on every topic -> aggregator and supervisor killed (SIGKILL) and restarted -> inputs
  stop (stale) -> inputs resume -> SIGTERM.

Checked over every command received: finite, within the velocity limits, and changing per
message by no more than the acceleration limit times the control period (arms and base); nothing
else crashes; control resumes after each fault (commands move again, the state says fresh); the
stale inputs ramp the commands to exactly zero; the killed nodes publish again after their
restart; every bad input is counted in /controller/state; SIGTERM ends with zero commands."""
import collections
import math
import random
import signal
import time

import yaml
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from conftest import TOP, binary, cell_array, spin_until
from test_controller_graph import ARMS, HOME, LATCHED

DEEP = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
RESOLVER = yaml.safe_load((TOP / "config" / "resolver.yaml").read_text())
RATE_HZ = 125.0
ARM_VMAX = math.pi * RESOLVER["arm"]["velocity_limit_scale"]  # UR5 URDF limit pi rad/s
ARM_STEP = RESOLVER["arm"]["max_acceleration"] / RATE_HZ
BASE = RESOLVER["base"]
TICK_S = 0.01  # the fake drivers publish at 100 Hz

# (phase, seconds); the robot's behaviour in each is in FaultyRobot.tick.
SCHEDULE = [("normal", 1.5), ("drop", 1.5), ("burst", 1.0), ("delay", 1.5), ("bad", 0.5),
            ("killed", 1.5), ("stale", 1.0), ("resumed", 1.5)]


class FaultyRobot:
    """Both arms and the base integrate the latest commands; the inputs are published at 100 Hz
    with the faults of the current phase."""

    def __init__(self, node, cell_id, aggregator_cell, bad_cell):
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState, LaserScan
        from skin_msgs.msg import Arrangement, ControllerState, PatchWrenchArray, SkinCellArray
        from std_msgs.msg import Float64MultiArray

        self.node, self.cell_id, self.aggregator_cell, self.bad_cell = node, cell_id, aggregator_cell, bad_cell
        self.got = collections.defaultdict(list)  # topic -> [(phase, msg)]
        self.phase, self.phase_start, self.running = "idle", time.monotonic(), False
        self.rng = random.Random(7)
        self.q = {side: list(HOME[o:o + 6]) for side, o in (("left", 3), ("right", 9))}
        self.cmd = {"left": [0.0] * 6, "right": [0.0] * 6}
        self.base, self.twist = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        self.delayed = collections.deque()
        for side in ("left", "right"):
            node.create_subscription(Float64MultiArray, f"/{side}_arm/forward_velocity_controller/commands",
                                     lambda m, s=side: self.on_arm(s, m), DEEP)
        node.create_subscription(Twist, "/base/cmd_vel", self.on_twist, DEEP)
        for topic, t in (("/controller/state", ControllerState), ("/skin/patches", PatchWrenchArray)):
            node.create_subscription(t, topic, lambda m, k=topic: self.record(k, m), DEEP)
        node.create_subscription(Arrangement, "/supervisor/arrangement",
                                 lambda m: self.record("/supervisor/arrangement", m), LATCHED)
        self.pub = {"/joint_states": node.create_publisher(JointState, "/joint_states", DEEP),
                    "/base/odom": node.create_publisher(Odometry, "/base/odom", DEEP),
                    "/scan": node.create_publisher(LaserScan, "/scan", DEEP),
                    "/skin/cells": node.create_publisher(SkinCellArray, "/skin/cells", DEEP)}
        node.create_timer(TICK_S, self.tick)

    def record(self, topic, msg):
        self.got[topic].append((self.phase, msg))

    def on_arm(self, side, msg):
        self.record(side, msg)
        self.cmd[side] = list(msg.data)

    def on_twist(self, msg):
        self.record("base", msg)
        self.twist = [msg.linear.x, msg.linear.y, msg.angular.z]

    def start(self, phase):
        self.phase, self.phase_start = phase, time.monotonic()

    def elapsed(self):
        return time.monotonic() - self.phase_start

    def messages(self, stamp, bad=False):
        """The inputs of one period, stamped `stamp` (bad: a bad value in each)."""
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import JointState, LaserScan
        out = []
        for side in ("left", "right"):
            js = JointState(name=list(ARMS[side]), position=list(self.q[side]), velocity=list(self.cmd[side]))
            if bad:
                js.position[2] = float("nan")
                js.name.append("unknown_joint")
                js.position.append(0.0)
                js.velocity.append(0.0)
            js.header.stamp = stamp
            out.append(("/joint_states", js))
        odom = Odometry()
        odom.header.stamp, odom.header.frame_id, odom.child_frame_id = stamp, "odom", "base_link"
        odom.pose.pose.position.x, odom.pose.pose.position.y = self.base[0], self.base[1]
        odom.pose.pose.orientation.z, odom.pose.pose.orientation.w = math.sin(self.base[2] / 2), math.cos(self.base[2] / 2)
        odom.twist.twist.linear.x, odom.twist.twist.linear.y, odom.twist.twist.angular.z = self.twist
        if bad:
            odom.pose.pose.orientation.w = float("inf")
        out.append(("/base/odom", odom))
        scan = LaserScan(angle_min=-3.14, angle_max=3.14, angle_increment=0.0175, range_min=0.05,
                         range_max=8.0, ranges=[1.2] * 360)
        scan.header.stamp, scan.header.frame_id = stamp, "laser"
        if bad:
            scan.ranges[5] = float("nan")  # read as no return
            scan.angle_increment = float("inf")
        out.append(("/scan", scan))
        cells = [(self.cell_id, [0.0] * 3, 0.5), (self.aggregator_cell, [0.2, 0.0, 0.0], 0.0)]
        if bad:
            cells += [(self.cell_id, [0.0] * 3, 0.9), (4_000_000, [0.0] * 3, 0.5),
                      (self.bad_cell, [float("nan"), 7.0, 0.0], -1.0)]
        out.append(("/skin/cells", cell_array(cells, stamp)))
        return out

    def integrate(self, dt):
        for side in ("left", "right"):
            self.q[side] = [q + v * dt for q, v in zip(self.q[side], self.cmd[side])]
        c, s = math.cos(self.base[2]), math.sin(self.base[2])
        vx, vy, wz = self.twist
        self.base = [self.base[0] + (c * vx - s * vy) * dt, self.base[1] + (s * vx + c * vy) * dt,
                     self.base[2] + wz * dt]

    def tick(self):
        if not self.running:
            return
        self.integrate(TICK_S)
        clock = self.node.get_clock()
        now = clock.now()
        while self.delayed and self.delayed[0][0] <= time.monotonic():
            _, topic, msg = self.delayed.popleft()
            self.pub[topic].publish(msg)
        if self.phase == "stale":
            return
        if self.phase == "burst":  # ten periods' worth per tick, stamps 1 ms apart
            for k in range(10):
                stamp = (now - rclpy_duration(0.001 * (9 - k))).to_msg()
                for topic, msg in self.messages(stamp):
                    self.pub[topic].publish(msg)
            return
        out = self.messages(now.to_msg())
        if self.phase == "bad":  # after the good inputs, the same period again with bad values
            out += self.messages(now.to_msg(), bad=True)
        for topic, msg in out:
            if self.phase == "drop" and self.rng.random() < 0.1:
                continue
            if self.phase == "delay":
                self.delayed.append((time.monotonic() + 0.05, topic, msg))
                continue
            self.pub[topic].publish(msg)
        if self.phase == "bad":  # a replayed old message: refused, it would move the state back
            old = self.messages((now - rclpy_duration(1.0)).to_msg())[0][1]
            self.pub["/joint_states"].publish(old)


def rclpy_duration(seconds):
    from rclpy.duration import Duration

    return Duration(nanoseconds=int(seconds * 1e9))


def in_phase(items, *phases):
    return [m for p, m in items if p in phases]


def check_limits(arm_msgs, base_msgs):
    """Every command finite, within the velocity limits, and within one period's acceleration
    of the previous command (all messages but the shutdown's, which are checked apart)."""
    for side, msgs in arm_msgs.items():
        prev = None
        for k, m in enumerate(msgs):
            v = list(m.data)
            assert len(v) == 6 and all(math.isfinite(x) and abs(x) <= ARM_VMAX * (1 + 1e-9) for x in v), (side, k, v)
            if prev is not None:
                jump = max(abs(a - b) for a, b in zip(v, prev))
                assert jump <= ARM_STEP * (1 + 1e-6), f"{side} message {k}: change {jump} > {ARM_STEP}"
            prev = v
    prev = None
    for k, m in enumerate(base_msgs):
        v = (m.linear.x, m.linear.y, m.angular.z)
        assert all(math.isfinite(x) for x in v), (k, v)
        assert math.hypot(v[0], v[1]) <= BASE["max_linear_m_s"] * (1 + 1e-9) and abs(v[2]) <= BASE["max_angular_rad_s"] * (1 + 1e-9), (k, v)
        if prev is not None:
            dv = math.hypot(v[0] - prev[0], v[1] - prev[1])
            assert dv <= BASE["max_linear_accel_m_s2"] / RATE_HZ * (1 + 1e-6), (k, v, prev)
            assert abs(v[2] - prev[2]) <= BASE["max_angular_accel_rad_s2"] / RATE_HZ * (1 + 1e-6), (k, v, prev)
        prev = v


def test_graph_survives_faults(spawn, rclpy_node):
    from geometry_msgs.msg import PoseStamped
    from skin_msgs.msg import ControllerState

    layout = yaml.safe_load((TOP / "config" / "skin" / "tomm.yaml").read_text())
    forearm = [c["id"] for c in layout["cells"] if c["patch"] == 8]
    params = ["--ros-args", "--params-file"]
    tc = spawn(binary("task_controller"), *params, TOP / "config/ros/task_controller.yaml",
               "-p", "input_timeout_s:=0.15", "-p", "autostart:=true")

    def start_peers():
        return (spawn(binary("priority_supervisor"), *params, TOP / "config/ros/priority_supervisor.yaml"),
                spawn(binary("skin_aggregator"), *params, TOP / "config/ros/skin_aggregator.yaml"))

    sup, agg = start_peers()
    robot = FaultyRobot(rclpy_node, forearm[0], forearm[3], forearm[5])
    got = robot.got
    spin_until(rclpy_node, lambda: got["/supervisor/arrangement"], 30.0, "the latched arrangement")
    robot.running = True
    goal = PoseStamped()
    goal.header.frame_id = "world"
    goal.pose.position.x, goal.pose.position.y, goal.pose.position.z = 0.6, -0.5, 1.0
    goal.pose.orientation.w = 1.0
    # The controller reads goals volatile (REP 2003): send once its reader is matched.
    goal_pub = rclpy_node.create_publisher(PoseStamped, "/goal", LATCHED)
    spin_until(rclpy_node, lambda: goal_pub.get_subscription_count() > 0, 30.0, "the controller's /goal reader")
    goal_pub.publish(goal)

    def states(*phases):
        return in_phase(got["/controller/state"], *phases)

    def moving(phase):
        return any(abs(v) > 1e-3 for m in in_phase(got["right"], phase) for v in m.data)

    robot.start("normal")
    spin_until(rclpy_node, lambda: moving("normal"), 30.0, "the right arm moving to the goal")
    for phase, seconds in SCHEDULE[1:]:
        robot.start(phase)
        if phase == "killed":
            for p in (sup, agg):
                p.send_signal(signal.SIGKILL)
                p.wait(timeout=10)
        spin_until(rclpy_node, lambda: robot.elapsed() >= seconds, seconds + 30.0, f"the end of phase {phase}")
        if phase == "killed":
            assert in_phase(got["right"], "killed"), "the controller kept commanding without its peers"
            robot.start("restarted")
            n_patches, n_arr = len(got["/skin/patches"]), len(got["/supervisor/arrangement"])
            sup, agg = start_peers()
            spin_until(rclpy_node, lambda: len(got["/skin/patches"]) > n_patches
                       and len(got["/supervisor/arrangement"]) > n_arr, 30.0,
                       "patches and the arrangement from the restarted nodes")
        if phase == "stale":
            # the commands ramp to exactly zero once the inputs are older than the timeout
            spin_until(rclpy_node, lambda: states("stale") and states("stale")[-1].input_status
                       == ControllerState.INPUT_STALE, 10.0, "a stale controller state")
            last = [in_phase(got[s], "stale")[-1].data for s in ("left", "right")]
            assert all(v == 0.0 for d in last for v in d), f"not stopped after {seconds} s stale: {last}"
    spin_until(rclpy_node, lambda: moving("resumed") and states("resumed")[-1].input_status
               == ControllerState.INPUT_FRESH, 30.0, "control resumed after the stale inputs")

    # Control went on through the faults that keep the inputs within the timeout.
    for phase in ("drop", "burst", "delay", "restarted"):
        assert any(s.input_status == ControllerState.INPUT_FRESH for s in states(phase)), phase
        assert moving(phase) or phase == "restarted", f"no motion during {phase}"
    # Every bad input was counted, by topic and kind.
    final = states("resumed")[-1]
    counts = dict(zip(final.issue_names, final.issue_counts))
    for name in ("/joint_states: non-finite value", "/joint_states: unknown joint",
                 "/joint_states: stamp out of order", "/skin/cells: duplicate cell id",
                 "/skin/cells: unknown cell id", "/skin/cells: non-finite signal",
                 "/skin/cells: signal outside [0, 1]",
                 "/base/odom: message refused", "/scan: message refused"):
        assert counts[name] > 0, (name, counts)
    assert final.safe_stop_cycles == 0, "bad input is sanitized or refused, never reaches the controller"
    assert final.idle_periods > 0

    # SIGTERM: zero commands on every command topic, exit 0; the peers never crashed.
    robot.running = False
    n = {k: len(got[k]) for k in ("left", "right", "base")}
    tc.send_signal(signal.SIGTERM)
    assert tc.wait(timeout=10) == 0
    def zero_last():
        b = got["base"][-1][1]
        return (all(len(got[k]) > n[k] for k in n) and b.linear.x == b.linear.y == b.angular.z == 0.0
                and all(v == 0.0 for k in ("left", "right") for v in got[k][-1][1].data))

    # cycle commands in flight may come first; the last message on every topic is the zero
    spin_until(rclpy_node, zero_last, 10.0, "zero commands as the last message on every command topic")
    arms = {s: [m for _, m in got[s]][:-1] for s in ("left", "right")}
    check_limits(arms, [m for _, m in got["base"]][:-1])
    for phase in [p for p, _ in SCHEDULE] + ["restarted"]:
        cmds = in_phase(got["right"], phase)
        fresh = sum(s.input_status == ControllerState.INPUT_FRESH for s in states(phase))
        peak = max((abs(v) for m in cmds for v in m.data), default=0.0)
        print(f"{phase:>9}: {len(cmds)} right-arm commands, peak {peak:.3f} rad/s, "
              f"{fresh}/{len(states(phase))} states fresh")
    print("input issues:", {k: v for k, v in counts.items() if v})
    for p in (sup, agg):
        assert p.poll() is None, p.stdout.read() if p.poll() is not None else ""
