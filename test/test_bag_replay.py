"""Bag replay into the running nodes: a lockstep scenario recorded with `skin_bag record`, its
inputs played back with `skin_bag play` into freshly started skin_aggregator, task_controller
and priority_supervisor, whose outputs must equal the recorded ones.

Scenario: force_tracking_base_motion (interactive-force-control paper Exp. 1, TOMM: skin cells, joint states,
odometry, LIDAR scan; /goal and /hand_force_reference, latched, when the scene sends them) for DURATION s of simulated time, with
mujoco_sim --lockstep and task_controller trigger:=inputs, supervisor:=internal (the decision in
the cycle: see test_graph.py for why a separate supervisor's timing is not reproducible).

Exactness, and why: the controller runs once per complete input set with one stamp, so its
outputs are a function of the sequence of input sets, not of timing, provided each set reaches
it whole and alone. `skin_bag play --step-on /controller/state` guarantees that: it publishes
the inputs grouped by header stamp and waits, after each group the recording answered, for the
live /controller/state with that stamp. The aggregator maps each /skin/cells message to one
/skin/patches message. Hence the tolerance is zero: every field of /skin/patches and
/controller/state per stamp, every arm and base command in order, and the sequence of distinct
arrangements must be equal (floats compared exactly). The one timing-dependent output is not
compared: priority_supervisor's periodic republication of an unchanged arrangement, and the
start-up arrangement's switch time (the node's start, wall clock)."""
import contextlib
import os
import signal

import pytest
from rosbags.highlevel import AnyReader

from conftest import binary, plain, spin_until

SCENE = "force_tracking_base_motion"
SETUP = "config/controller/tomm_phases.yaml"
RATE = 125.0
DURATION = 3.0
CMD = "/forward_velocity_controller/commands"
INPUTS = {
    "/skin/cells": "skin_msgs/msg/SkinCellArray",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/base/odom": "nav_msgs/msg/Odometry",
    "/scan": "sensor_msgs/msg/LaserScan",
    "/goal": "geometry_msgs/msg/PoseStamped",
    "/hand_force_reference": "std_msgs/msg/Float64",
}
OUTPUTS = {
    "/skin/patches": "skin_msgs/msg/PatchWrenchArray",
    "/left_arm" + CMD: "std_msgs/msg/Float64MultiArray",
    "/right_arm" + CMD: "std_msgs/msg/Float64MultiArray",
    "/base/cmd_vel": "geometry_msgs/msg/Twist",
    "/controller/state": "skin_msgs/msg/ControllerState",
    "/supervisor/arrangement": "skin_msgs/msg/Arrangement",
}
STAMPED = ("/controller/state", "/skin/patches")
LATCHED = ["/goal", "/hand_force_reference", "/supervisor/arrangement"]


def read(bag):
    """topic -> [message as plain data], in log order."""
    out = {}
    with AnyReader([bag]) as reader:
        for conn, _, raw in reader.messages():
            out.setdefault(conn.topic, []).append(plain(reader.deserialize(raw, conn.msgtype)))
    return out


def stamp(m):
    return (m["header"]["stamp"]["sec"], m["header"]["stamp"]["nanosec"])


def by_stamp(msgs, topic):
    """Messages keyed by header stamp; a repeated stamp (a lockstep resend) must repeat the same
    message."""
    out = {}
    for m in msgs:
        assert out.setdefault(stamp(m), m) == m, f"{topic}: two different messages at {stamp(m)}"
    return out


def distinct(msgs):
    """The arrangements without the periodic republications (consecutive repeats) and without
    the start-up one's `switch_time` (the node's clock when it started: wall time, as no node
    uses sim time here; every later switch time is a controller-state stamp)."""
    msgs = [m for k, m in enumerate(msgs) if k == 0 or m != msgs[k - 1]]
    return [{**m, "switch_time": None} if k == 0 else m for k, m in enumerate(msgs)]


def start_nodes(spawn):
    """The nodes under test, each holding its inputs until its outputs are matched by the one
    outside subscriber started before them (the recorder, or the rclpy capture; /controller/state
    also has priority_supervisor's), so that it gets their first messages: a volatile publisher
    drops what it sends before discovery has matched a subscriber, and discovery between two
    processes is not ordered with the simulator's own (CI lost the first 7 /skin/patches)."""
    wait = "--wait-topic-subscribers"
    nodes = [
        spawn(binary("skin_aggregator"), wait, "/skin/patches=1"),
        spawn(binary("task_controller"), "--setup", SETUP, wait, "/left_arm" + CMD + "=1", "/right_arm" + CMD + "=1",
              "/base/cmd_vel=1", "/controller/state=2", "--ros-args", "-p", "trigger:=inputs",
              "-p", "supervisor:=internal", "-p", f"control_rate_hz:={RATE}"),
        spawn(binary("priority_supervisor"), "--setup", SETUP),
    ]
    for p in nodes[:2]:
        lines = [p.stdout.readline()]  # the node's 30 s limit bounds this wait
        while lines[-1] and not any(w in lines[-1] for w in ("ready", "starting anyway")):
            lines.append(p.stdout.readline())
        assert "ready (subscribers matched)" in lines[-1], "".join(lines)
    return nodes


def start_recorder(spawn, out, topics):
    rec = spawn(binary("skin_bag"), "record", out, "--latched", *LATCHED, "--topics",
                *[f"{t}:{ty}" for t, ty in topics.items()])
    line = rec.stdout.readline()
    assert line.startswith("skin_bag: recording"), line
    return rec


def stop(procs):
    for p in procs:
        p.send_signal(signal.SIGINT)
    outs = []
    for p in procs:
        out, _ = p.communicate(timeout=30)
        assert p.returncode == 0, out
        outs.append(out)
    return outs


def capture(node, store, into):
    """rclpy subscriptions to the outputs; each message kept as the plain data of its CDR bytes
    (decoded by rosbags, as the recorded bag is)."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
    import importlib

    def get_message(ty):
        pkg, _, name = ty.split("/")
        return getattr(importlib.import_module(f"{pkg}.msg"), name)

    subs = []
    for topic, ty in OUTPUTS.items():
        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL if topic in LATCHED else DurabilityPolicy.VOLATILE)
        decode = lambda raw, ty=ty, topic=topic: into[topic].append(plain(store.deserialize_cdr(raw, ty)))  # noqa: E731
        subs.append(node.create_subscription(get_message(ty), topic, decode, qos, raw=True))
    return subs


def own_domains():
    """A ROS domain per phase, apart from the session's: the endpoints of processes that ended
    (an earlier test's, the recording's) can stay in a participant's view until their lease runs
    out, and would count in the nodes' subscriber waits."""
    base = int(os.environ["ROS_DOMAIN_ID"])
    return [(base + k) % 232 for k in (77, 155)]


def in_domain(spawn, domain):
    return lambda *args: spawn(*args, env={**os.environ, "ROS_DOMAIN_ID": str(domain)})


@contextlib.contextmanager
def rclpy_node_in(domain):
    import rclpy
    from rclpy.context import Context

    ctx = Context()
    rclpy.init(context=ctx, domain_id=domain)
    node = rclpy.create_node("replay_capture", context=ctx)
    try:
        yield node
    finally:
        node.destroy_node()
        rclpy.shutdown(context=ctx)


def test_replayed_inputs_reproduce_the_recorded_outputs(spawn, tmp_path, store):
    record_domain, replay_domain = own_domains()
    with rclpy_node_in(replay_domain) as rclpy_node:
        replayed_inputs_reproduce_the_recorded_outputs(in_domain(spawn, record_domain), in_domain(spawn, replay_domain),
                                                       tmp_path, store, rclpy_node)


def replayed_inputs_reproduce_the_recorded_outputs(spawn, spawn_replay, tmp_path, store, rclpy_node):
    # 1. The scenario in lockstep, everything recorded.
    recorded = tmp_path / "scenario.mcap"
    rec = start_recorder(spawn, recorded, {**INPUTS, **OUTPUTS})
    nodes = start_nodes(spawn)
    # the first state must reach the recorder too (and the cells the aggregator)
    sim = spawn(binary("mujoco_sim"), "--scene", SCENE, "--lockstep", "--duration", str(DURATION),
                "--wait-topic-subscribers", "/joint_states=2", "/base/odom=2", "/scan=2", "/skin/cells=3")
    out, _ = sim.communicate(timeout=120)
    assert sim.returncode == 0 and f"after {int(DURATION * RATE)} periods" in out, out
    (rec_out,) = stop([rec])
    print("\n" + rec_out.strip().splitlines()[-1])
    stop(nodes)
    a = read(recorded)
    states = by_stamp(a["/controller/state"], "/controller/state")
    assert len(states) == int(DURATION * RATE), f"{len(states)} controller states recorded"
    # The bag holds every input of every answered period (a precondition of the replay).
    for topic in ("/skin/cells", "/joint_states", "/base/odom", "/scan"):
        missing = set(states) - set(by_stamp(a[topic], topic))
        assert not missing, f"{topic}: inputs of {sorted(missing)[:3]} not recorded"
    played = [t for t in INPUTS if t in a]  # /goal, /hand_force_reference: if the scene sent them

    # 2. Fresh nodes, the inputs played back stepped on the controller's answers; their outputs
    # taken by rclpy as serialized bytes (subscribed before the nodes start: see start_nodes).
    b = {t: [] for t in OUTPUTS}
    capture(rclpy_node, store, b)
    nodes = start_nodes(spawn_replay)
    play = spawn_replay(binary("skin_bag"), "play", recorded, "--topics", *played,
                        "--step-on", "/controller/state", "--wait-subscribers", "1",
                        "--wait-topic-subscribers", "/skin/cells=2")  # controller and aggregator
    # Every output as many times as recorded (the aggregator's last /skin/patches and the
    # supervisor's arrangements are not stepped on: they may come after the last controller state).
    def count(topic, msgs):
        return len(by_stamp(msgs, topic)) if topic in STAMPED else len(distinct(msgs)) if topic in LATCHED else len(msgs)

    wanted = {t: count(t, a[t]) for t in OUTPUTS}
    spin_until(rclpy_node, lambda: play.poll() is not None and all(count(t, b[t]) >= n for t, n in wanted.items()),
               120.0, lambda: f"the replay (first state {min(map(stamp, b['/controller/state']), default=None)}; so far "
               + ", ".join(f"{t} {count(t, b[t])} of {n}" for t, n in wanted.items()) + ")")
    out, _ = play.communicate(timeout=10)
    assert play.returncode == 0, out
    print(out.strip().splitlines()[-1])
    stop(nodes)

    # 3. Per field, exactly.
    for topic in STAMPED:
        want, got = by_stamp(a[topic], topic), by_stamp(b[topic], topic)
        assert list(got) == list(want), f"{topic}: stamps differ"
        for s in want:
            assert got[s] == want[s], f"{topic} at {s}"
    for topic in ("/left_arm" + CMD, "/right_arm" + CMD, "/base/cmd_vel"):
        assert len(b[topic]) == len(a[topic]) == len(states), topic
        assert b[topic] == a[topic], topic
    arrangements = distinct(a["/supervisor/arrangement"])
    assert distinct(b["/supervisor/arrangement"]) == arrangements
    moving = max(abs(v) for m in a["/right_arm" + CMD] for v in m["data"])
    active = max(p["max_force"] + p["max_proximity"] for m in a["/skin/patches"] for p in m["patches"])
    print(f"{len(states)} cycles compared exactly; max right-arm command {moving:.3f} rad/s, "
          f"max patch signal {active:.3f}, {len(arrangements)} distinct arrangements")
    assert moving > 1e-3, "the arm moves"
