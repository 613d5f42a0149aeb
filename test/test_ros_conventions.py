"""task_controller as a stock ROS 2 robot's drivers and users meet it (planar7, rclpy peers):
- QoS (REP 2003): sensor inputs from best-effort publishers (SensorDataQoS, as many drivers send
  them) are taken; goals from an ordinary volatile publisher (`ros2 topic pub`, RViz's goal tool)
  are taken.
- Names: `__ns:=/arm7` puts every topic and service of the node under /arm7; a remapping
  (`skin/cells:=/driver/cells`) moves one input.
- Frames: the goal's `header.frame_id` is honoured: a goal at the origin of the end effector's
  frame is where the hand is (goal error 0), 10 cm along it is 10 cm away; world and odom are the
  same frame here; any other frame is refused and counted in /controller/state."""
import pytest
import yaml
from rclpy.qos import qos_profile_sensor_data

from conftest import TOP, binary, cell_array, spin_until

SETUP = TOP / "config" / "controller" / "planar7.yaml"
JOINTS = [f"joint{k}" for k in range(1, 8)]
POSTURE = yaml.safe_load(SETUP.read_text())["posture"]
EE = yaml.safe_load(SETUP.read_text())["end_effector"]


class Drivers:
    """Best-effort sensor publishers (arm at its posture, at rest, stamped now) and a volatile goal
    publisher, all in namespace `pre`; the controller's state and commands read back."""

    def __init__(self, node, pre="", cells_topic=None):
        from geometry_msgs.msg import PoseStamped
        from sensor_msgs.msg import JointState
        from skin_msgs.msg import ControllerState, SkinCellArray
        from std_msgs.msg import Float64MultiArray

        self.node = node
        self.states, self.commands = [], []
        node.create_subscription(ControllerState, f"{pre}/controller/state", self.states.append, 10)
        node.create_subscription(Float64MultiArray, f"{pre}/arm/forward_velocity_controller/commands",
                                 self.commands.append, 10)
        self.joints = node.create_publisher(JointState, f"{pre}/joint_states", qos_profile_sensor_data)
        self.cells = node.create_publisher(SkinCellArray, cells_topic or f"{pre}/skin/cells", qos_profile_sensor_data)
        self.goal = node.create_publisher(PoseStamped, f"{pre}/goal", 10)
        self.timer = node.create_timer(0.02, self.tick)

    def tick(self):
        from sensor_msgs.msg import JointState

        now = self.node.get_clock().now().to_msg()
        js = JointState(name=JOINTS, position=POSTURE, velocity=[0.0] * 7)
        js.header.stamp = now
        self.joints.publish(js)
        self.cells.publish(cell_array([], now))

    def fresh(self):
        return self.states and self.states[-1].input_status == self.states[-1].INPUT_FRESH

    def send_goal(self, frame, x):
        from geometry_msgs.msg import PoseStamped

        spin_until(self.node, lambda: self.goal.get_subscription_count() > 0, 30.0, "the controller's /goal reader")
        goal = PoseStamped()
        goal.header.frame_id = frame
        goal.pose.position.x = x
        goal.pose.orientation.w = 1.0
        n = len(self.states)
        self.goal.publish(goal)
        return n

    def refused(self, topic):
        s = self.states[-1]
        return dict(zip(s.issue_names, s.issue_counts)).get(f"{topic}: message refused")


def controller(spawn, *ros_args):
    return spawn(binary("task_controller"), "--setup", SETUP, "--ros-args", "-p", "input_timeout_s:=0.5", *ros_args)


def test_best_effort_sensors_and_volatile_goals_in_frames(spawn, rclpy_node):
    controller(spawn)
    peer = Drivers(rclpy_node)
    spin_until(rclpy_node, peer.fresh, 30.0, "a fresh controller state from best-effort joint states and cells")

    # A goal at the end effector's own frame origin is where the hand is now.
    n = peer.send_goal(EE, 0.0)
    spin_until(rclpy_node, lambda: len(peer.states) > n and peer.states[-1].goal_error >= 0.0, 30.0, "the goal taken")
    first = next(s for s in peer.states[n:] if s.goal_error >= 0.0)
    assert first.goal_error < 1e-6, first.goal_error
    # 10 cm along the end effector's x axis: 10 cm away (the arm is held at its posture).
    n = peer.send_goal(EE, 0.1)
    spin_until(rclpy_node, lambda: len(peer.states) > n + 2, 30.0, "states after the second goal")
    assert abs(peer.states[-1].goal_error - 0.1) < 1e-6, peer.states[-1].goal_error
    # The same point given in world and in odom: the same goal.
    # (a third goal in `world` at the origin: the distance is the hand's distance from the origin)
    n = peer.send_goal("world", 0.0)
    spin_until(rclpy_node, lambda: len(peer.states) > n + 2, 30.0, "states after the world goal")
    in_world = peer.states[-1].goal_error
    n = peer.send_goal("odom", 0.0)
    spin_until(rclpy_node, lambda: len(peer.states) > n + 2, 30.0, "states after the odom goal")
    assert in_world > 0.1 and abs(peer.states[-1].goal_error - in_world) < 1e-9

    # A frame that is not the robot's: refused and counted, the last goal kept.
    before = peer.refused("/goal")
    n = peer.send_goal("map", 0.0)
    spin_until(rclpy_node, lambda: len(peer.states) > n and peer.refused("/goal") == before + 1, 30.0,
               "the refusal of the goal in `map` counted")
    assert abs(peer.states[-1].goal_error - in_world) < 1e-9


def test_namespace_and_remapping_apply_to_every_topic(spawn, rclpy_node):
    controller(spawn, "-r", "__ns:=/arm7", "-r", "skin/cells:=/driver/cells")
    peer = Drivers(rclpy_node, "/arm7", cells_topic="/driver/cells")
    spin_until(rclpy_node, peer.fresh, 30.0, "a fresh state on /arm7/controller/state (cells from /driver/cells)")
    spin_until(rclpy_node, lambda: peer.commands, 30.0, "commands on /arm7/arm/forward_velocity_controller/commands")
    # Asked per node: graphs of other sessions may share the machine.
    assert ("task_controller", "/arm7") in rclpy_node.get_node_names_and_namespaces()
    topics = [t for get in (rclpy_node.get_publisher_names_and_types_by_node, rclpy_node.get_subscriber_names_and_types_by_node)
              for t, _ in get("task_controller", "/arm7")]
    # global by ROS convention (/diagnostics: as diagnostic_updater publishes it), and the remapped one
    global_topics = {"/rosout", "/parameter_events", "/clock", "/diagnostics", "/driver/cells"}
    assert "/driver/cells" in topics and "/arm7/joint_states" in topics, topics
    assert not [t for t in topics if not t.startswith("/arm7/") and t not in global_topics], topics
    services = [s for s, _ in rclpy_node.get_service_names_and_types_by_node("task_controller", "/arm7")]
    assert services and all(s.startswith("/arm7/task_controller/") for s in services), services


@pytest.mark.parametrize("frame", ["", "skin_patch_1"])
def test_goal_frames_that_are_no_link_are_refused(frame, spawn, rclpy_node):
    controller(spawn)
    peer = Drivers(rclpy_node)
    spin_until(rclpy_node, peer.fresh, 30.0, "a fresh controller state")
    before = peer.refused("/goal")
    peer.send_goal(frame, 0.0)
    spin_until(rclpy_node, lambda: peer.refused("/goal") == before + 1, 30.0, f"the goal in `{frame}` refused")
    assert peer.states[-1].goal_error < 0, "no goal set"
