"""r2r <-> rclpy interoperability of skin_msgs over Fast DDS on loopback, both directions.

rclpy publishes SkinCellArray messages; the r2r relay (skin_control example
`skin_cells_relay`) decodes them into its Rust types and publishes them again; rclpy checks that
every array comes back unchanged and in order."""
import math

from rclpy.qos import QoSProfile, ReliabilityPolicy, HistoryPolicy

from conftest import binary, spin_until

N_MSGS = 5


def make_msg(k: int):
    from skin_msgs.msg import SkinCellArray

    msg = SkinCellArray()
    msg.header.stamp.sec = 1000 + k
    msg.header.stamp.nanosec = 123456789
    msg.header.frame_id = f"frame_{k}"
    n = 3 + k
    msg.cell_id = [4_000_000_000 + 17 * i + k for i in range(n)]  # beyond int32: the uint32 mapping
    msg.force = [v for i in range(n) for v in (0.25 * i % 1.0, 0.5, 1.0 - 0.125 * k)]
    msg.proximity = [0.0625 * (i + 1) for i in range(n)]
    if k % 2 == 0:  # acceleration and temperature are optional: sent in every other message
        msg.acceleration = [v for i in range(n) for v in (-9.81 + i, 1e-3 * k, math.pi)]
        msg.temperature = [21.5 + 0.25 * i for i in range(n)]
    return msg


FIELDS = ("cell_id", "force", "proximity", "acceleration", "temperature")


def assert_same(sent, got):
    assert got.header.stamp.sec == sent.header.stamp.sec
    assert got.header.stamp.nanosec == sent.header.stamp.nanosec
    assert got.header.frame_id == sent.header.frame_id
    for field in FIELDS:  # float32 in, float32 out: exact
        assert list(getattr(got, field)) == list(getattr(sent, field)), field


def test_skin_cells_roundtrip_rclpy_r2r(spawn, rclpy_node):
    from skin_msgs.msg import SkinCellArray

    qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE,
                     history=HistoryPolicy.KEEP_LAST)
    relay = spawn(binary("skin_cells_relay"), "--input", "/interop/cells_in",
                  "--output", "/interop/cells_out")
    received = []
    rclpy_node.create_subscription(SkinCellArray, "/interop/cells_out", received.append, qos)
    pub = rclpy_node.create_publisher(SkinCellArray, "/interop/cells_in", qos)
    # Discovery takes 0-3 s: publish only once both directions are matched.
    spin_until(rclpy_node, lambda: pub.get_subscription_count() > 0
               and rclpy_node.count_publishers("/interop/cells_out") > 0, 30.0,
               "the r2r relay to match both topics")
    sent = [make_msg(k) for k in range(N_MSGS)]
    for m in sent:
        pub.publish(m)
    spin_until(rclpy_node, lambda: len(received) >= N_MSGS, 30.0,
               lambda: f"{N_MSGS} relayed messages (got {len(received)})")
    for s, g in zip(sent, received):
        assert_same(s, g)
    assert relay.poll() is None, f"the relay exited: {relay.stdout.read()}"
