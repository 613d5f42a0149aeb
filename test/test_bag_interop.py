"""rosbag2 MCAP interoperability of the `skin_bag` crate with rosbags (an independent pure-Python
rosbag2 implementation) as the outside peer, both directions.

The skin_bag example `write_bag` writes one message of every topic type of the graph; rosbags reads
it, builds its types from the definitions stored in the bag, and every field must equal the values
below. Then rosbags writes the same messages and `write_bag --check` reads them back in Rust."""
import subprocess

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.interfaces import MessageDefinitionFormat
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import get_types_from_msg

from conftest import binary, plain

S = 1_000_000_000



def expected(ts):
    """(topic, log time [ns], message) of the `write_bag` example, in its order."""
    T = ts.types
    f64 = lambda *v: np.array(v, dtype=np.float64)  # noqa: E731
    f32 = lambda *v: np.array(v, dtype=np.float32)  # noqa: E731
    Time = T["builtin_interfaces/msg/Time"]
    V3 = T["geometry_msgs/msg/Vector3"]
    P = T["geometry_msgs/msg/Point"]
    Twist = T["geometry_msgs/msg/Twist"]

    def header(sec, frame):
        return T["std_msgs/msg/Header"](stamp=Time(sec=sec, nanosec=250_000_000), frame_id=frame)

    task = T["skin_msgs/msg/TaskState"]
    return [
        ("/clock", 1 * S, T["rosgraph_msgs/msg/Clock"](clock=Time(sec=1, nanosec=0))),
        ("/joint_states", 2 * S, T["sensor_msgs/msg/JointState"](
            header=header(2, ""), name=["shoulder_pan", "elbow"], position=f64(0.1, -1.2),
            velocity=f64(0.01, 0.02), effort=f64())),
        ("/base/odom", 3 * S, T["nav_msgs/msg/Odometry"](
            header=header(3, "odom"), child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](
                pose=T["geometry_msgs/msg/Pose"](
                    position=P(x=1.5, y=-0.5, z=0.0),
                    orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.6, w=0.8)),
                covariance=np.arange(36, dtype=np.float64) * 0.5),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](
                twist=Twist(linear=V3(x=0.2, y=0.1, z=0.0), angular=V3(x=0.0, y=0.0, z=0.3)),
                covariance=np.array([0.01 if i % 7 == 0 else 0.0 for i in range(36)])))),
        ("/scan", 4 * S, T["sensor_msgs/msg/LaserScan"](
            header=header(4, "base_laser"), angle_min=-1.5, angle_max=1.5, angle_increment=0.75,
            time_increment=0.0, scan_time=0.03125, range_min=0.0625, range_max=10.0,
            ranges=f32(1.0, 2.5, np.inf, 0.5, 3.25), intensities=f32())),
        ("/skin/cells", 5 * S, T["skin_msgs/msg/SkinCellArray"](
            header=header(5, ""), cell_id=np.array([7, 1042], dtype=np.uint32),
            force=f32(0.25, 0.5, 0.75, 0.0, 0.0, 0.0), proximity=f32(0.125, 1.0),
            acceleration=f32(0.0, 0.1, 9.81, 0.0, 0.0, 0.0), temperature=f32(31.5, 30.0))),
        ("/skin/patches", 6 * S, T["skin_msgs/msg/PatchWrenchArray"](header=header(6, ""), patches=[
            T["skin_msgs/msg/PatchWrench"](
                header=header(6, "patch_3"), patch_id=3, link="right_forearm_link",
                wrench=T["geometry_msgs/msg/Wrench"](force=V3(x=0.0, y=0.0, z=2.0),
                                                     torque=V3(x=0.1, y=-0.2, z=0.0)),
                centroid=P(x=0.01, y=0.02, z=0.0), active_cells=4, max_force=0.5,
                max_proximity=0.875)])),
        ("/right_arm/forward_velocity_controller/commands", 7 * S,
         T["std_msgs/msg/Float64MultiArray"](
             layout=T["std_msgs/msg/MultiArrayLayout"](
                 dim=[T["std_msgs/msg/MultiArrayDimension"](label="joints", size=6, stride=6)],
                 data_offset=0),
             data=f64(0.1, -0.2, 0.3, -0.4, 0.5, -0.6))),
        ("/base/cmd_vel", 8 * S,
         Twist(linear=V3(x=0.1, y=-0.05, z=0.0), angular=V3(x=0.0, y=0.0, z=0.2))),
        ("/supervisor/arrangement", 9 * S, T["skin_msgs/msg/Arrangement"](
            mode=1, task_order=["goal", "contact_reaction", "avoidance"],
            switch_time=Time(sec=8, nanosec=500_000_000), smoothing_gain=5.0, sensing_range=0.05,
            fusion_weight=0.75, blocked=T["skin_msgs/msg/BlockedHold"](
                active=True, since=Time(sec=7, nanosec=125_000_000), goal_error=0.25,
                contact_force=5.5))),
        ("/controller/state", 10 * S, T["skin_msgs/msg/ControllerState"](
            header=header(10, ""), mode=2, blend=0.3, ee_speed=0.012, avoidance_force=1.5,
            contact_force=12.5, contact_advance=0.004, torque_norm=42.0, goal_error=-1.0, releasing=True,
            blocked=T["skin_msgs/msg/BlockedHold"](
                active=False, since=Time(sec=0, nanosec=0), goal_error=0.0, contact_force=0.0),
            goal_count=3, tasks=[
                task(name="contact_reaction", priority=1, error_norm=2.5, torque_norm=30.0),
                task(name="goal", priority=2, error_norm=0.2, torque_norm=12.0)],
            input_status=2, safe_stop_cycles=3, idle_periods=40,
            issue_names=["/skin/cells: unknown cell id", "/scan: message refused"],
            issue_counts=np.array([5, 0], dtype=np.uint64))),
    ]


def test_rosbags_reads_every_field_of_a_rust_bag(tmp_path, store):
    bag = tmp_path / "rust.mcap"
    subprocess.run([binary("write_bag"), bag], check=True, timeout=60)
    want = expected(store)
    with AnyReader([bag]) as reader:
        assert len(reader.connections) == len(want)
        for conn in reader.connections:
            # The stored definition alone rebuilds the same types rosbags knows for Jazzy.
            assert conn.msgdef.format == MessageDefinitionFormat.MSG, conn.topic
            for name, fields in get_types_from_msg(conn.msgdef.data, conn.msgtype).items():
                assert fields == store.fielddefs[name], f"{conn.topic}: definition of {name}"
        got = [(c.topic, t, reader.deserialize(raw, c.msgtype))
               for c, t, raw in reader.messages()]
    assert [(topic, t) for topic, t, _ in got] == [(topic, t) for topic, t, _ in want]
    for (topic, _, g), (_, _, w) in zip(got, want):
        assert g.__msgtype__ == w.__msgtype__, topic
        assert plain(g) == plain(w), topic


def test_rust_reads_every_field_of_a_rosbags_bag(tmp_path, store):
    with Writer(tmp_path / "py", version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic, t, msg in expected(store):
            conn = writer.add_connection(topic, msg.__msgtype__, typestore=store)
            writer.write(conn, t, store.serialize_cdr(msg, msg.__msgtype__))
    (bag,) = (tmp_path / "py").glob("*.mcap")
    out = subprocess.run([binary("write_bag"), "--check", bag], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 0, out.stdout + out.stderr
    assert out.stdout.count("ok ") == len(expected(store))


# skin_bag (r2r raw subscriptions and publishers) against rclpy and rosbags.

def rclpy_class(msgtype):
    import importlib

    pkg, _, name = msgtype.split("/")
    return getattr(importlib.import_module(f"{pkg}.msg"), name)


def test_skin_bag_records_what_rclpy_publishes_and_rosbags_reads_it(tmp_path, store, spawn, rclpy_node):
    """Every message type of the graph, published by rclpy, recorded by `skin_bag record`
    (types given on the command line), read back by rosbags field for field."""
    import signal

    from rclpy.serialization import deserialize_message

    from conftest import spin_until

    want = expected(store)
    bag = tmp_path / "recorded.mcap"
    rec = spawn(binary("skin_bag"), "record", bag, "--topics",
                *[f"{topic}:{msg.__msgtype__}" for topic, _, msg in want])
    assert rec.stdout.readline().startswith("skin_bag: recording")
    pubs = [rclpy_node.create_publisher(rclpy_class(m.__msgtype__), topic, 10) for topic, _, m in want]
    spin_until(rclpy_node, lambda: all(p.get_subscription_count() > 0 for p in pubs), 30.0,
               "skin_bag record's subscriptions")
    for p, (_, _, m) in zip(pubs, want):
        p.publish(deserialize_message(bytes(store.serialize_cdr(m, m.__msgtype__)), rclpy_class(m.__msgtype__)))
    for p in pubs:
        assert p.wait_for_all_acked(), f"{p.topic_name}: not acknowledged by skin_bag record"
    rec.send_signal(signal.SIGINT)
    out, _ = rec.communicate(timeout=30)
    assert rec.returncode == 0 and f"recorded {len(want)} messages" in out, out
    with AnyReader([bag]) as reader:
        got = {c.topic: reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages()}
    assert sorted(got) == sorted(topic for topic, _, _ in want)
    for topic, _, w in want:
        assert plain(got[topic]) == plain(w), topic


def test_skin_bag_plays_a_rosbags_bag(tmp_path, store, spawn, rclpy_node):
    """A bag written by rosbags (10 s of log time) played by `skin_bag play --rate 50`: rclpy
    receives every message, field for field, in the bag's order."""
    from conftest import spin_until

    want = expected(store)
    with Writer(tmp_path / "py", version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        for topic, t, msg in want:
            conn = writer.add_connection(topic, msg.__msgtype__, typestore=store)
            writer.write(conn, t, store.serialize_cdr(msg, msg.__msgtype__))
    (bag,) = (tmp_path / "py").glob("*.mcap")
    got = []
    for topic, _, m in want:
        rclpy_node.create_subscription(
            rclpy_class(m.__msgtype__), topic,
            lambda raw, topic=topic, ty=m.__msgtype__: got.append((topic, store.deserialize_cdr(raw, ty))),
            10, raw=True)
    play = spawn(binary("skin_bag"), "play", bag, "--rate", "50")
    spin_until(rclpy_node, lambda: len(got) == len(want), 60.0, lambda: f"{len(want)} messages, got {len(got)}")
    out, _ = play.communicate(timeout=30)
    assert play.returncode == 0 and f"published {len(want)} messages" in out, out
    assert [t for t, _ in got] == [t for t, _, _ in want]
    for (topic, g), (_, _, w) in zip(got, want):
        assert plain(g) == plain(w), topic
