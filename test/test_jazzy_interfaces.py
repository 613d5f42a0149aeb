"""task_controller and skin_watchdog against the interfaces of a stock ROS 2 Jazzy robot, over
real Fast DDS with rclpy as the robot (test_failsafe.Robot):

- the URDF from `/robot_description` (std_msgs/String, transient local, as robot_state_publisher
  publishes it: TOMM rooted at base_link, `mobile_base` puts the planar base back), from a
  publisher started before the controller and from one started after it (the controller says
  WAITING on /diagnostics until then); an invalid URDF and a URDF given twice end the node
  with an error naming the topic;
- `base_command_stamped`: /base/cmd_vel as geometry_msgs/TwistStamped in frame base_link with a
  fresh stamp; skin_watchdog --base-stamped zeroes the base in the same type;
- `/diagnostics` (diagnostic_msgs/DiagnosticArray): the control loop, the task hierarchy and one
  status per input;
  joint states that stop make the joint-state input and the loop ERROR, naming the input."""
import signal
import time
import xml.etree.ElementTree as ET

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from conftest import TOP, binary, spin_until
from test_failsafe import PARAMS, Robot, forearm_cell, start_controller

DEEP = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)
# robot_state_publisher's robot_description QoS
DESCRIPTION_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
OK, ERROR = 0, 2  # DiagnosticStatus levels
PLANAR_BASE = {"world", "base_x_link", "base_y_link", "base_x_joint", "base_y_joint", "base_yaw_joint"}


def tomm_from_base_link():
    """urdf/tomm.urdf as robot_state_publisher gets it on the robot: the virtual planar base's
    links and joints removed, base_link the root (TF has odom -> base_link from the base)."""
    root = ET.fromstring((TOP / "urdf" / "tomm.urdf").read_text())
    for e in [e for e in root if e.get("name") in PLANAR_BASE]:
        root.remove(e)
    return ET.tostring(root, encoding="unicode")


def publish_description(node, text):
    from std_msgs.msg import String

    pub = node.create_publisher(String, "/robot_description", DESCRIPTION_QOS)
    pub.publish(String(data=text))
    return pub


class Diagnostics:
    """/diagnostics as received: arrays, and statuses by name."""

    def __init__(self, node):
        from diagnostic_msgs.msg import DiagnosticArray

        self.arrays = []
        node.create_subscription(DiagnosticArray, "/diagnostics", self.arrays.append, DEEP)

    def statuses(self, since=0):
        return [{s.name: s for s in a.status} for a in self.arrays[since:]]

    def last(self, name):
        for a in reversed(self.arrays):
            for s in a.status:
                if s.name == name:
                    return s
        return None


def level(status):
    """DiagnosticStatus.level (a `byte`: bytes of length 1 in rclpy) as an int."""
    return status.level[0] if isinstance(status.level, bytes) else status.level


def values(status):
    return {v.key: v.value for v in status.values}


def from_description(spawn, *extra):
    return start_controller(spawn, "-p", "use_robot_description:=true", "-p", "mobile_base:=true", *extra)


def moving_arm(robot):
    got = robot.got
    return lambda: got["right"] and any(abs(v) > 0.05 for v in got["right"][-1][1])


def test_urdf_from_robot_description_published_before_and_after_the_controller(spawn, rclpy_node):
    from skin_msgs.msg import ControllerState

    diag = Diagnostics(rclpy_node)
    # after: the controller waits, says so on /diagnostics, commands nothing
    tc = from_description(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    robot.streaming = True
    robot.send_goal()
    waiting = lambda: (s := diag.last("task_controller: control loop")) and "WAITING" in s.message  # noqa: E731
    spin_until(rclpy_node, waiting, 30.0, "WAITING on /diagnostics")
    s = diag.last("task_controller: control loop")
    assert "/robot_description" in s.message and s.hardware_id == "none", s
    spin_until(rclpy_node, lambda: len(diag.arrays) >= 3, 10.0, "three reports")
    assert not robot.got["state"] and not robot.got["right"] and tc.poll() is None, "nothing before the URDF"
    pub = publish_description(rclpy_node, tomm_from_base_link())
    spin_until(rclpy_node, moving_arm(robot), 60.0, "the right arm moving once the URDF is in")
    assert any(s.input_status == ControllerState.INPUT_FRESH for s in robot.got["state"])
    spin_until(rclpy_node, lambda: diag.last("task_controller: control loop").hardware_id == "tomm", 10.0,
               "the robot's name as hardware_id")
    tc.send_signal(signal.SIGINT)
    assert tc.wait(timeout=10) == 0

    # before: a late-joining controller gets the description that was published already
    n = len(robot.got["state"])
    tc = from_description(spawn, "-r", "__node:=task_controller_late")
    spin_until(rclpy_node, lambda: len(robot.got["state"]) > n + 20, 60.0, "the second controller's states")
    tc.send_signal(signal.SIGINT)
    assert tc.wait(timeout=10) == 0
    del pub


def test_invalid_or_doubly_given_urdf_ends_the_node_naming_the_topic(spawn, rclpy_node):
    both = start_controller(spawn, "-p", "use_robot_description:=true", "-p", "urdf_file:=urdf/tomm.urdf")
    assert both.wait(timeout=30) != 0
    out = both.stdout.read()
    assert "given twice" in out and "/robot_description" in out, out

    pub = publish_description(rclpy_node, "<robot name='broken'><link name='a'/><joint name='j' type='revolute'/></robot>")
    bad = from_description(spawn)
    spin_until(rclpy_node, lambda: bad.poll() is not None, 60.0, "the controller ending on an invalid URDF")
    assert bad.returncode != 0
    out = bad.stdout.read()
    assert "/robot_description: invalid URDF" in out, out
    del pub


def test_twist_stamped_base_command_and_watchdog_zeros_of_the_same_type(spawn, rclpy_node):
    dog = spawn(binary("skin_watchdog"), "--base-stamped")
    tc = start_controller(spawn, "-p", "base_command_stamped:=true")
    robot = Robot(rclpy_node, forearm_cell(), stamped=True)
    robot.streaming = True
    robot.send_goal()
    got = robot.got
    spin_until(rclpy_node, lambda: got["base"] and any(abs(v) > 0.005 for v in got["base"][-1][1]), 60.0,
               "the base moving on TwistStamped commands")
    tc.send_signal(signal.SIGKILL)
    tc.wait(timeout=10)
    killed = time.time()
    spin_until(rclpy_node, lambda: got["base"][-1][0] > killed + 0.3, 30.0, "the watchdog's zeros")
    assert all(frame == "base_link" for _, frame, _ in robot.headers), {f for _, f, _ in robot.headers}
    # fresh: stamped at the period it was computed in, never after it was sent, and well within
    # diff_drive_controller's default cmd_vel_timeout (0.5 s), past which a ros2_control base
    # controller drops a command (the sender's clock against the DDS source time)
    lag = [source - stamp for source, _, stamp in robot.headers]
    assert all(0 <= x < 0.5 for x in lag), (min(lag), max(lag))
    zeros = [m for m in got["base"] if m[0] > killed + 0.05]
    assert zeros and all(v == 0.0 for m in zeros for v in m[1]), zeros[:3]
    print(f"{len(robot.headers)} stamped base commands, stamp to send {min(lag) * 1e3:.2f}-{max(lag) * 1e3:.2f} ms; "
          f"{len(zeros)} watchdog zeros")
    assert dog.poll() is None


def test_diagnostics_report_input_health_cycle_time_and_state(spawn, rclpy_node):
    diag = Diagnostics(rclpy_node)
    start_controller(spawn)
    robot = Robot(rclpy_node, forearm_cell())
    robot.streaming = True
    robot.send_goal()
    joints, loop = "task_controller: input /joint_states", "task_controller: control loop"
    fresh = lambda: (s := diag.last(loop)) and s.message.startswith("FRESH")  # noqa: E731
    spin_until(rclpy_node, fresh, 60.0, "a FRESH control loop on /diagnostics")
    n = len(diag.arrays)
    spin_until(rclpy_node, lambda: len(diag.arrays) > n, 10.0, "one more report")
    report = diag.statuses(n)[0]
    names = set(report)
    hierarchy = "task_controller: task hierarchy"
    assert {loop, hierarchy, joints, "task_controller: input /base/odom", "task_controller: input /skin/cells",
            "task_controller: input /scan"} <= names, names
    h = values(report[hierarchy])
    assert h["mode"] in {"avoidance", "intentional_contact", "hard_contact"} and "goal" in h["tasks"].split(" > "), h
    assert level(report[hierarchy]) == OK and report[hierarchy].message == f"{h['mode']}: {h['tasks']}", h
    v = values(report[loop])
    assert v["lifecycle state"] == "active" and float(v["cycle time max [ms]"]) >= float(v["cycle time mean [ms]"]) > 0, v
    assert int(v["cycles in the last period"]) > 0 and "overruns" in v, v
    assert level(report[joints]) == OK and values(report[joints])["health"] == "ok", report[joints]
    assert all(s.hardware_id == "tomm" for s in report.values())

    # the joint states stop: the input is stale (ERROR, named), and so is the loop
    robot.offset = {"left": None, "right": None}
    t0 = time.monotonic()
    stale = lambda: (s := diag.last(joints)) and level(s) == ERROR  # noqa: E731
    spin_until(rclpy_node, stale, 30.0, lambda: f"a stale /joint_states status (last: {diag.last(joints)})")
    took = time.monotonic() - t0
    s = diag.last(joints)
    assert s.message.startswith("stale:") and values(s)["health"] == "stale" and float(values(s)["age [s]"]) > 0.1, s
    lp = diag.last(loop)
    assert level(lp) == ERROR and "STALE: /joint_states" in lp.message, lp
    assert level(diag.last("task_controller: input /base/odom")) == OK, "the other inputs stay ok"
    n = len(diag.arrays)
    spin_until(rclpy_node, lambda: len(diag.arrays) >= n + 2, 10.0, "two more reports")
    # once a second, as diagnostic_updater (an rcl timer keeps its schedule: the mean period is 1 s)
    stamps = [a.header.stamp.sec + 1e-9 * a.header.stamp.nanosec for a in diag.arrays]
    mean = (stamps[-1] - stamps[0]) / (len(stamps) - 1)
    assert 0.9 < mean < 1.1, [round(b - a, 3) for a, b in zip(stamps, stamps[1:])]
    print(f"/diagnostics: {len(diag.arrays)} reports, mean period {mean:.3f} s; stale reported {took:.1f} s "
          "after the joint states stopped")
