#!/usr/bin/env python3
"""Renders a run's key frames (`skin_sim run` writes them): DIR/scene.xml, the MJCF the run
simulated, and DIR/keyframes.json, MuJoCo's qpos and mocap_pos at the start, at the first switches
and at the end. Writes DIR/keyframe_<k>_<t>s.png per frame (640 x 480, MuJoCo's renderer through
EGL, headless) and prints their names. Exits 3, with the reason on stderr, when rendering is not
possible here (no EGL, no mujoco module): the caller writes that down instead of the pictures.

usage: render_keyframes.py DIR"""
import json
import os
import struct
import sys
import zlib
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")


def write_png(path: Path, rgb) -> None:
    """An 8-bit RGB PNG (the standard library only)."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(sys.argv[1])
    frames = json.loads((out / "keyframes.json").read_text())
    try:
        import mujoco

        model = mujoco.MjModel.from_xml_path(str(out / "scene.xml"))
        renderer = mujoco.Renderer(model, 480, 640)
    except Exception as e:  # no EGL device, no mujoco: say why, render nothing
        print(f"rendering unavailable: {type(e).__name__}: {e}", file=sys.stderr)
        return 3
    # the generated MJCF has no lights and grey geoms: a headlight, and colours by geom group
    # (skin_sim::mjcf: 1 the robot, 0 objects, 2 persons), the floor dark
    model.vis.headlight.ambient[:] = 0.3
    model.vis.headlight.diffuse[:] = 0.6
    colours = {0: (0.30, 0.50, 0.85, 1.0), 1: (0.95, 0.55, 0.15, 1.0), 2: (0.35, 0.80, 0.40, 1.0)}
    for g in range(model.ngeom):
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE:
            model.geom_rgba[g] = (0.22, 0.22, 0.24, 1.0)
        elif int(model.geom_group[g]) in colours:
            model.geom_rgba[g] = colours[int(model.geom_group[g])]
    data = mujoco.MjData(model)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = model.stat.center
    camera.distance = 1.6 * model.stat.extent
    camera.azimuth, camera.elevation = 135.0, -35.0
    names = []
    try:
        for k, f in enumerate(frames):
            data.qpos[:] = f["qpos"]
            if model.nmocap:
                data.mocap_pos[:] = f["mocap_pos"]
            mujoco.mj_forward(model, data)
            renderer.update_scene(data, camera)
            name = f"keyframe_{k}_{f['t_s']:.2f}s.png"
            write_png(out / name, renderer.render())
            names.append(f"{name} ({f['label']})")
    finally:
        renderer.close()
    print("\n".join(names))
    return 0


if __name__ == "__main__":
    sys.exit(main())
