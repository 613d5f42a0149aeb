"""r2r <-> rclpy interoperability of skin_msgs over Fast DDS on loopback, both directions.

rclpy publishes SkinCellArray messages; the r2r relay (skin_control example
`skin_cells_relay`) decodes them into its Rust types and publishes them again; rclpy checks that
every field of every cell comes back unchanged and in order."""
import math

from rclpy.qos import QoSProfile, ReliabilityPolicy, HistoryPolicy

from conftest import binary, spin_until

N_MSGS = 5


def make_msg(k: int):
    from skin_msgs.msg import SkinCell, SkinCellArray

    msg = SkinCellArray()
    msg.header.stamp.sec = 1000 + k
    msg.header.stamp.nanosec = 123456789
    msg.header.frame_id = f"frame_{k}"
    for i in range(3 + k):
        c = SkinCell()
        c.cell_id = 4_000_000_000 + 17 * i + k  # beyond int32: checks the uint32 mapping
        c.force = [0.25 * i % 1.0, 0.5, 1.0 - 0.125 * k]
        c.proximity = 0.0625 * (i + 1)
        c.acceleration.x = -9.81 + i
        c.acceleration.y = 1e-3 * k
        c.acceleration.z = math.pi
        c.temperature = 21.5 + 0.25 * i
        msg.cells.append(c)
    return msg


def assert_same(sent, got):
    assert got.header.stamp.sec == sent.header.stamp.sec
    assert got.header.stamp.nanosec == sent.header.stamp.nanosec
    assert got.header.frame_id == sent.header.frame_id
    assert len(got.cells) == len(sent.cells)
    for a, b in zip(sent.cells, got.cells):
        assert b.cell_id == a.cell_id
        assert list(b.force) == list(a.force)  # float32 in, float32 out: exact
        assert b.proximity == a.proximity
        assert (b.acceleration.x, b.acceleration.y, b.acceleration.z) == (
            a.acceleration.x, a.acceleration.y, a.acceleration.z)
        assert b.temperature == a.temperature


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
