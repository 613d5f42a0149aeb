"""skin_aggregator over real Fast DDS, with rclpy as the outside peer.

rclpy publishes skin cells (active ones, a NaN, an out-of-range value, an unknown id, a repeated
id); the patch wrenches that come back are checked field by field against an independent
computation from the layout YAML (interactive-force-control paper eq. 6-8: fused virtual forces along the outward
normals, summed in the patch frame, their moments about the patch origin, the centroid and count
of the active cells); the markers against the layout's link-frame cell positions and the colour
rule; the parameters through the standard parameter services (list, get, describe, set valid,
set invalid, set read-only). Then a clean stop on SIGINT with the bad-input totals."""
import math
import signal
import struct
import time

import numpy as np
import pytest
import yaml
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

from conftest import TOP, binary, call_service, cell_array, set_parameter, spin_until

NODE = "skin_aggregator"
LAYOUT = TOP / "config" / "skin" / "tomm.yaml"
PARAMS_FILE = TOP / "config" / "ros" / "skin_aggregator.yaml"
THRESHOLD = 0.05  # set on the command line: checks that overrides apply
QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE, history=HistoryPolicy.KEEP_LAST)


def f32(x: float) -> float:
    """x as the float32 the message carries."""
    return struct.unpack("f", struct.pack("f", x))[0]


def rpy_matrix(r, p, y):
    """URDF rpy: R = Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


class Layout:
    """The layout YAML, read independently of skin_core."""

    def __init__(self, path):
        doc = yaml.safe_load(path.read_text())
        self.patches = doc["patches"]
        self.cells = {c["id"]: c for c in doc["cells"]}
        self.patch = {p["id"]: p for p in self.patches}

    def cells_of(self, patch_id):
        return [c for c in self.cells.values() if c["patch"] == patch_id]


def sanitize(x):
    x = f32(x)
    return 0.0 if not math.isfinite(x) else min(max(x, 0.0), 1.0)


def signals(reading):
    force, prox = reading
    return sum(sanitize(v) for v in force) / 3.0, sanitize(prox)


def expected_patches(layout, readings, w, threshold):
    """Interactive-force-control paper eq. 6-8 per patch in the patch frame; `readings`: cell id -> (force[3], prox)."""
    out = {}
    for p in layout.patches:
        force, moment, positions = np.zeros(3), np.zeros(3), []
        max_f = max_p = 0.0
        for c in layout.cells_of(p["id"]):
            f, prox = signals(readings.get(c["id"], ([0.0] * 3, 0.0)))
            max_f, max_p = max(max_f, f), max(max_p, prox)
            s = w * f + (1 - w) * prox  # eq. 6
            if s > threshold:
                n = np.array(c["normal"], float)
                n /= np.linalg.norm(n)
                t = np.array(c["position"], float)
                force += n * s  # eq. 7
                moment += np.cross(t, n * s)  # eq. 8
                positions.append(t)
        centroid = np.mean(positions, axis=0) if positions else np.zeros(3)
        out[p["id"]] = dict(force=force, moment=moment, centroid=centroid, active=len(positions),
                            max_force=max_f, max_proximity=max_p)
    return out


def vec(v):
    return np.array([v.x, v.y, v.z])


def check_patches(msg, layout, readings, w, threshold, sec):
    exp = expected_patches(layout, readings, w, threshold)
    assert msg.header.stamp.sec == sec
    assert [p.patch_id for p in msg.patches] == [p["id"] for p in layout.patches]
    for p in msg.patches:
        e = exp[p.patch_id]
        where = f"patch {p.patch_id}"
        assert p.link == layout.patch[p.patch_id]["link"], where
        assert p.header.frame_id == f"skin_patch_{p.patch_id}", where
        assert p.header.stamp.sec == sec, where
        assert p.active_cells == e["active"], where
        np.testing.assert_allclose(vec(p.wrench.force), e["force"], atol=1e-9, err_msg=where)
        np.testing.assert_allclose(vec(p.wrench.torque), e["moment"], atol=1e-9, err_msg=where)
        np.testing.assert_allclose(vec(p.centroid), e["centroid"], atol=1e-9, err_msg=where)
        assert p.max_force == pytest.approx(e["max_force"], abs=1e-6), where
        assert p.max_proximity == pytest.approx(e["max_proximity"], abs=1e-6), where
    return exp


def cells_msg(sec, entries):
    msg = cell_array(entries)
    msg.header.stamp.sec = sec
    return msg


class Peer:
    """The rclpy side: publishes cells, collects patches and markers, calls parameter services."""

    def __init__(self, node):
        from skin_msgs.msg import PatchWrenchArray, SkinCellArray
        from visualization_msgs.msg import MarkerArray

        self.node = node
        self.patches, self.markers = [], []
        node.create_subscription(PatchWrenchArray, "/skin/patches", self.patches.append, QOS)
        node.create_subscription(MarkerArray, "/skin/markers", self.markers.append, QOS)
        self.pub = node.create_publisher(SkinCellArray, "/skin/cells", QOS)

    def patches_at(self, sec):
        return [m for m in self.patches if m.header.stamp.sec == sec]

    def exchange(self, msg, republish=False):
        """Publishes `msg` and waits for the patches stamped like it. With `republish`, sends it
        again every 0.5 s meanwhile: until the node's writer has matched our reader (discovery is
        not symmetric), a volatile sample can be lost; the other exchanges follow a received one."""
        sec = msg.header.stamp.sec
        self.pub.publish(msg)
        last = [time.monotonic()]

        def done():
            if republish and time.monotonic() - last[0] > 0.5:
                self.pub.publish(msg)
                last[0] = time.monotonic()
            return bool(self.patches_at(sec))

        spin_until(self.node, done, 30.0, f"/skin/patches stamped {sec}")
        return self.patches_at(sec)[0]

    def call(self, srv_type, name, request):
        return call_service(self.node, srv_type, f"/{NODE}/{name}", request)

    def set_param(self, name, value):
        return set_parameter(self.node, f"/{NODE}", name, value)


def marker_by(markers, ns, mid):
    found = [m for m in markers if m.ns == ns and m.id == mid]
    assert len(found) == 1, f"one marker {ns}/{mid} expected, got {len(found)}"
    return found[0]


def check_markers(array, layout, readings, w, threshold, exp):
    from visualization_msgs.msg import Marker

    for k, p in enumerate(layout.patches):
        if exp[p["id"]]["active"] == 0:
            assert not [m for m in array.markers if m.id == k], f"patch {p['id']} is inactive"
            continue
        cells = marker_by(array.markers, "skin_cells", k)
        assert (cells.action, cells.type) == (Marker.ADD, Marker.SPHERE_LIST)
        assert cells.header.frame_id == p["link"]
        rot, xyz = rpy_matrix(*p.get("rpy", [0, 0, 0])), np.array(p.get("xyz", [0, 0, 0]))
        active = []
        for c in layout.cells_of(p["id"]):
            f, prox = signals(readings.get(c["id"], ([0.0] * 3, 0.0)))
            if w * f + (1 - w) * prox > threshold:
                active.append((rot @ np.array(c["position"]) + xyz, f, prox))
        assert len(cells.points) == len(cells.colors) == len(active) == exp[p["id"]]["active"]
        for pt, col, (pos, f, prox) in zip(cells.points, cells.colors, active):
            np.testing.assert_allclose(vec(pt), pos, atol=1e-5)
            assert (col.r, col.g, col.b, col.a) == pytest.approx((f, prox, prox, 1.0), abs=1e-6)
        arrow = marker_by(array.markers, "skin_patch_wrench", k)
        assert (arrow.action, arrow.type, arrow.header.frame_id) == (Marker.ADD, Marker.ARROW, p["link"])
        start = rot @ exp[p["id"]]["centroid"] + xyz
        end = start + rot @ exp[p["id"]]["force"] * 0.05
        np.testing.assert_allclose(vec(arrow.points[0]), start, atol=1e-9)
        np.testing.assert_allclose(vec(arrow.points[1]), end, atol=1e-9)


def start(spawn, rclpy_node, layout):
    """The aggregator with the shipped parameter file and a threshold override, and a peer whose
    first exchange (an empty message: every patch zero) has gone through."""
    node = spawn(binary(NODE), "--ros-args", "--params-file", PARAMS_FILE,
                 "-p", f"fusion.activity_threshold:={THRESHOLD}")
    peer = Peer(rclpy_node)
    spin_until(rclpy_node, lambda: peer.pub.get_subscription_count() > 0
               and rclpy_node.count_publishers("/skin/patches") > 0, 30.0,
               "the aggregator to match /skin/cells and /skin/patches")
    first = peer.exchange(cells_msg(1, []), republish=True)
    check_patches(first, layout, {}, 0.5, THRESHOLD, 1)
    return node, peer


def stop(node):
    """SIGINT; the node must exit 0. Returns its output."""
    node.send_signal(signal.SIGINT)
    assert node.wait(timeout=10) == 0
    return node.stdout.read()


def test_skin_aggregator(spawn, rclpy_node):
    from rcl_interfaces.srv import DescribeParameters, GetParameters, ListParameters
    from visualization_msgs.msg import Marker

    layout = Layout(LAYOUT)
    node, peer = start(spawn, rclpy_node, layout)

    forearm, palm = layout.cells_of(8), layout.cells_of(12)
    entries = [
        (forearm[0]["id"], [0.8, 0.6, 0.7], 0.9),
        (forearm[1]["id"], [0.2, math.nan, 0.4], 0.5),     # NaN reads as 0
        (forearm[2]["id"], [0.0, 0.0, 0.0], 1.5),          # proximity clamped to 1
        (forearm[3]["id"], [0.01, 0.0, 0.0], 0.02),        # below the threshold: inactive
        (palm[5]["id"], [1.0, 1.0, 1.0], 0.0),
        (4_000_000_000, [1.0, 1.0, 1.0], 1.0),             # unknown id: ignored
        (forearm[0]["id"], [0.0, 0.0, 0.0], 0.0),          # repeated id: ignored
    ]
    readings = {cid: (force, prox) for cid, force, prox in reversed(entries)}  # first one wins
    got = peer.exchange(cells_msg(100, entries))
    exp = check_patches(got, layout, readings, 0.5, THRESHOLD, 100)
    assert exp[8]["active"] == 3 and exp[12]["active"] == 1

    def markers_at(sec):
        spin_until(rclpy_node, lambda: any(a.markers[-1].header.stamp.sec == sec for a in peer.markers),
                   30.0, f"/skin/markers stamped {sec}")
        return next(a for a in peer.markers if a.markers[-1].header.stamp.sec == sec)

    check_markers(markers_at(100), layout, readings, 0.5, THRESHOLD, exp)

    # Parameters through the standard services.
    names = peer.call(ListParameters, "list_parameters", ListParameters.Request()).result.names
    for name in ("fusion.weight_force", "fusion.activity_threshold", "fusion.force_reduction",
                 "proximity.range_m", "repulsion.range_m", "urdf_file", "layout_file", "skin_model_file"):
        assert name in names, f"{name} not listed: {names}"
    values = peer.call(GetParameters, "get_parameters",
                       GetParameters.Request(names=["fusion.activity_threshold", "fusion.weight_force"])).values
    assert [v.double_value for v in values] == [THRESHOLD, 0.5]
    desc = peer.call(DescribeParameters, "describe_parameters",
                     DescribeParameters.Request(names=["fusion.weight_force"])).descriptors[0]
    # declared once in skin_core (declare_params!): description, range and run-time flag
    assert "eq. (6)" in desc.description and "in [0, 1] (settable)" in desc.description, desc.description

    ok = peer.set_param("fusion.weight_force", 1.0)
    assert ok.successful, ok.reason
    # Absent cells keep their last reading: an empty message recomputes with the new weight.
    check_patches(peer.exchange(cells_msg(101, [])), layout, readings, 1.0, THRESHOLD, 101)

    bad = peer.set_param("fusion.weight_force", 1.5)
    assert not bad.successful
    assert "fusion.weight_force" in bad.reason and "must be in [0, 1]" in bad.reason, bad.reason
    ro = peer.set_param("urdf_file", "other.urdf")
    assert not ro.successful and "read-only" in ro.reason, ro.reason
    check_patches(peer.exchange(cells_msg(102, [])), layout, readings, 1.0, THRESHOLD, 102)

    # Everything released: the shown patches' markers are deleted, once.
    zeros = [(cid, [0.0] * 3, 0.0) for cid in readings if cid in layout.cells]
    check_patches(peer.exchange(cells_msg(103, zeros)), layout, {}, 1.0, THRESHOLD, 103)
    deleted = sorted((m.ns, m.id) for m in markers_at(103).markers if m.action == Marker.DELETE)
    assert deleted == [("skin_cells", 7), ("skin_cells", 11), ("skin_patch_wrench", 7), ("skin_patch_wrench", 11)]

    out = stop(node)
    assert out.count("non-finite signal (read as 0)") == 1, out  # logged once
    assert ("unknown cell id: 1, duplicate cell id: 1, non-finite signal: 1, signal outside [0, 1]: 1"
            in out), out


def test_round_trip_latency(spawn, rclpy_node):
    """Ping-pong: all TOMM cells in, the patches back, one message at a time. Prints the
    round-trip figures (rclpy publish -> r2r node -> rclpy callback) and the node's own
    aggregation time; asserts only that every message is answered, in order."""
    layout = Layout(LAYOUT)
    node, peer = start(spawn, rclpy_node, layout)
    ids = sorted(layout.cells)
    rtt = []
    for k in range(200):
        sec = 1000 + k
        msg = cells_msg(sec, [(cid, [0.3, 0.2, 0.1], 0.05 * (k % 10)) for cid in ids])
        t0 = time.perf_counter()
        peer.exchange(msg)
        rtt.append(time.perf_counter() - t0)
    assert [m.header.stamp.sec for m in peer.patches[-200:]] == list(range(1000, 1200))
    out = stop(node)
    ms = np.array(rtt) * 1e3
    print(f"\nround trip, {len(ids)} cells, {len(ms)} messages: median {np.median(ms):.2f} ms, "
          f"p90 {np.percentile(ms, 90):.2f} ms, max {ms.max():.2f} ms")
    print(next(line for line in out.splitlines() if "stopping" in line))
