"""What a viewer gets from a run: `run.mcap` as Foxglove and RViz read it, and the rendered frames.

One `skin_sim run` of intentional_contact (13 s: the arm pushes the obstacle from about 10 s on, after the stuck switch near 9 s) is read
back with the `mcap` library and its ROS 2 decoder (`mcap-ros2-support`, Foxglove's Python stack)
and with rosbags, as outside peers:
- `/tf` forms one tree under `odom`; every link pose it gives agrees with pinocchio's forward
  kinematics of `/robot_description` at the `/joint_states` of the same instant;
- every `/skin/markers` marker is in a frame of that tree;
- `/robot_description` is offered transient local (RViz's robot model subscribes late).
The picture test renders the frame of the firmest press again and finds each pressed cell's marker colour at the
cell's position projected through the camera, the position taken from MuJoCo's own body poses."""
import copy
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from conftest import TOP, binary

# the renderer's module, before anything imports mujoco (it picks its GL backend at import)
os.environ.setdefault("MUJOCO_GL", "egl")
sys.path.insert(0, str(TOP / "scripts"))

DURATION_S = 13.0


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("intentional_contact")
    proc = subprocess.run([str(binary("skin_sim")), "run", "intentional_contact", "--duration", str(DURATION_S),
                           "--out", str(out), "--quiet"], capture_output=True, text=True, timeout=300)
    assert proc.returncode in (0, 1), proc.stdout + proc.stderr
    assert (out / "run.mcap").is_file()
    return out


def mcap_messages(path: Path):
    """(channel, decoded message, log time) of every message, through mcap + mcap-ros2-support."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        return [(channel, decoded, message.log_time)
                for _schema, channel, message, decoded in reader.iter_decoded_messages()]


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def transform(t):
    """4x4 matrix of a geometry_msgs/Transform."""
    m = np.eye(4)
    r = t.rotation
    m[:3, :3] = quat_matrix((r.x, r.y, r.z, r.w))
    m[:3, 3] = (t.translation.x, t.translation.y, t.translation.z)
    return m


def world_poses(tf_msg):
    """Every child frame's pose in odom, composing the message's transforms."""
    parent = {t.child_frame_id: (t.header.frame_id, transform(t.transform)) for t in tf_msg.transforms}
    poses = {"odom": np.eye(4)}

    def pose(frame, depth=0):
        assert depth <= len(parent), f"{frame}: a cycle in /tf"
        if frame not in poses:
            assert frame in parent, f"{frame} does not reach odom"
            up, m = parent[frame]
            poses[frame] = pose(up, depth + 1) @ m
        return poses[frame]

    for frame in parent:
        pose(frame)
    return poses


def test_recording_shows_robot_skin_and_contacts_to_mcap_readers(run_dir):
    import pinocchio as pin

    msgs = mcap_messages(run_dir / "run.mcap")
    by_topic = {}
    for channel, decoded, t in msgs:
        by_topic.setdefault(channel.topic, []).append((decoded, t, channel))

    (description, _, channel), = by_topic["/robot_description"]
    assert "durability: transient_local" in channel.metadata["offered_qos_profiles"]
    urdf_links = {link.get("name") for link in ET.fromstring(description.data).iter("link")}

    tfs = by_topic["/tf"]
    assert len(tfs) >= DURATION_S * 10, "a /tf per view frame (10 fps)"
    parents = {}
    for msg, _, _ in tfs:
        for t in msg.transforms:
            assert parents.setdefault(t.child_frame_id, t.header.frame_id) == t.header.frame_id, \
                f"{t.child_frame_id}: two parents"
            assert t.child_frame_id in urdf_links, f"{t.child_frame_id} is no link of /robot_description"
        world_poses(msg)  # one tree under odom, no cycle
    tree = set(parents) | {"odom"}

    # the TF poses are the robot's forward kinematics at the joint states of that instant
    model = pin.buildModelFromXML(description.data)
    data = model.createData()
    joints = {t: m for m, t, _ in by_topic["/joint_states"]}
    checked = 0
    for msg, t, _ in tfs[:: max(1, len(tfs) // 10)]:
        if t not in joints:
            continue
        js = joints[t]
        q = pin.neutral(model)
        for name, value in zip(js.name, js.position):
            q[model.idx_qs[model.getJointId(name)]] = value
        pin.framesForwardKinematics(model, data, q)
        for frame, pose in world_poses(msg).items():
            if frame == "odom":
                continue
            ref = data.oMf[model.getFrameId(frame)]
            assert np.allclose(pose[:3, 3], ref.translation, atol=1e-9), frame
            assert np.allclose(pose[:3, :3], ref.rotation, atol=1e-9), frame
        checked += 1
    assert checked >= 5

    markers = by_topic["/skin/markers"]
    assert markers[0][0].markers[0].action == 3, "the first update clears the display (DELETEALL)"
    added = [m for arr, _, _ in markers for m in arr.markers if m.action == 0]
    assert any(m.type == 7 for m in added) and any(m.type == 0 for m in added), "cells and arrows"
    for m in added:
        assert m.header.frame_id in tree, f"marker {m.ns}/{m.id} in {m.header.frame_id!r}, not in the TF tree"
    # a pressed cell by the end: the contact is on the arm (force signal red channel > 0.3)
    assert any(c.r > 0.3 for m in added if m.type == 7 for c in m.colors)

    # rosbags reads the same file: same topics, same counts, same marker content
    from rosbags.highlevel import AnyReader

    with AnyReader([run_dir / "run.mcap"]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        assert counts == {topic: len(v) for topic, v in by_topic.items()}
        conns = [c for c in reader.connections if c.topic == "/skin/markers"]
        first = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=conns)][-1]
        last = markers[-1][0]
        assert [(m.ns, m.id, m.action, len(m.points)) for m in first.markers] == \
            [(m.ns, m.id, m.action, len(m.points)) for m in last.markers]


def project(scene, width, height, fovy_deg, p):
    """Pixel (column, row) of world point `p` through the camera of a rendered MuJoCo scene (mono:
    the mean of its two eyes)."""
    eyes = scene.camera
    pos = (np.array(eyes[0].pos) + np.array(eyes[1].pos)) / 2
    fwd, up = np.array(eyes[0].forward), np.array(eyes[0].up)
    right = np.cross(fwd, up)
    v = np.asarray(p) - pos
    z = v @ fwd
    f = (height / 2) / math.tan(math.radians(fovy_deg) / 2)
    return width / 2 + f * (v @ right) / z, height / 2 - f * (v @ up) / z


def look_at(camera, point, forward, distance=0.4):
    """Points MuJoCo's free camera at `point` along the unit vector `forward` (tilted to 85 degrees
    at most: straight up or down its up vector is undefined)."""
    camera.lookat[:] = point
    camera.distance = distance
    camera.azimuth = math.degrees(math.atan2(forward[1], forward[0]))
    camera.elevation = max(-85.0, min(85.0, math.degrees(math.asin(forward[2]))))


def test_the_pressed_cells_colour_is_where_the_cell_is(run_dir):
    """Renders the frame of the firmest press with the overlay and finds each pressed cell's (force signal > 0.3)
    marker colour at the cell's position projected through the camera: red/green = force /
    proximity, green = blue (lighting scales the channels alike; the overlay has no highlights);
    and the patch force arrow's yellow halfway along it, seen from above. Positions come from
    MuJoCo's own pose of the link body, not from the view. The camera looks at a cell against the
    patch force (the skin's outward side) without the arrow (it points at the camera and would
    hide the cell), objects and floor hidden (the obstacle is pressed against the cell)."""
    import render_keyframes as rk
    import mujoco

    view = json.loads((run_dir / "keyframes.json").read_text())
    # The frame of the firmest press (markers as RViz holds them after that frame's updates).
    shown, best = {}, None
    for f in view["frames"]:
        rk.apply_updates(shown, f["markers"])
        red = max((c[0] for m in shown.values() if m["shape"] == "sphere_list" for c in m["colors"]), default=0.0)
        if best is None or red > best[0]:
            best = (red, f, copy.deepcopy(shown))
    _, frame, shown = best
    pressed = [(m, p, c) for m in shown.values() if m["shape"] == "sphere_list"
               for p, c in zip(m["points"], m["colors"]) if c[0] > 0.3]
    assert pressed, "intentional_contact presses the arm on the obstacle by 13 s"
    cells_only = {k: m for k, m in shown.items() if m["shape"] == "sphere_list"}
    painter = rk.Painter(run_dir, view, rk.WIDTH, rk.HEIGHT)
    try:
        painter.options.geomgroup[0] = 0  # skin_sim::mjcf's objects (and the floor)
        model, data = painter.model, painter.data
        fovy = model.vis.global_.fovy
        for m, p, colour in pressed:
            arrow = shown[("skin_patch_wrench", m["id"])]
            painter.render(frame, shown)  # poses MuJoCo's data at the frame
            body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, m["frame"])
            assert body >= 0, m["frame"]
            rot = data.xmat[body].reshape(3, 3)
            world = data.xpos[body] + rot @ np.array(p)
            start, end = (data.xpos[body] + rot @ np.array(a) for a in arrow["points"])
            outward = (end - start) / np.linalg.norm(end - start)

            look_at(painter.camera, world + 0.05 * outward, -outward)
            img = painter.render(frame, cells_only).astype(float)
            u, v = project(painter.renderer.scene, rk.WIDTH, rk.HEIGHT, fovy, world)
            px = img[int(round(v)), int(round(u))]
            where = f"cell on {m['frame']} at pixel ({u:.0f}, {v:.0f}): {px}"
            assert px[1] > 60, f"{where} is too dark for a marker"
            assert abs(px[2] - px[1]) <= 0.08 * px[1] + 3, f"{where} is not on the cyan axis"
            assert abs(px[0] / px[1] - colour[0] / colour[1]) < 0.15, f"{where} vs marker colour {colour}"

            # from above (the arrow's perpendicular closest to -z), clear of the link's cells
            down = np.array([0.0, 0.0, -1.0]) - outward * -outward[2]
            middle = (start + end) / 2
            look_at(painter.camera, middle, down / np.linalg.norm(down))
            img = painter.render(frame, shown).astype(float)
            u, v = project(painter.renderer.scene, rk.WIDTH, rk.HEIGHT, fovy, middle)
            px = img[int(round(v)), int(round(u))]
            where = f"arrow of {m['frame']} at pixel ({u:.0f}, {v:.0f}): {px}"
            assert px[0] > 100 and px[2] < 0.3 * px[0], f"{where} is not the arrow's yellow"
            assert abs(px[1] / px[0] - arrow["color"][1] / arrow["color"][0]) < 0.15, f"{where} vs {arrow['color']}"
    finally:
        painter.close()
