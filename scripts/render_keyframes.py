#!/usr/bin/env python3
"""Renders a run's view (`skin_sim run` writes it): DIR/scene.xml, the MJCF the run simulated, and
DIR/keyframes.json, the view (camera, links, goals and per frame MuJoCo's state, the link poses
and the /skin/markers updates the aggregator publishes). Draws what RViz would show: the robot,
the skin cells (grey; active cells in the marker colours, force red + proximity cyan, with a
legend), the patch force arrows, the goal and the floor, with the time and the arrangement in an
overlay (MuJoCo's renderer through EGL, headless).

Writes DIR/keyframe_<k>_<t>s.png per key frame (the start, the first switches, the end) and prints
their names; with --video also DIR/run.mp4 (ffmpeg) or, without ffmpeg, DIR/run.gif, at the
view's frame rate, printing progress and the rendering time; with --gif PATH a small animated GIF
(for the README). Exits 3, with the reason on stderr, when rendering is not possible here (no EGL,
no mujoco module): the caller writes that down instead of the pictures."""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

WIDTH, HEIGHT = 640, 480
# skin_sim::mjcf's geom groups: 1 the robot, 0 objects, 2 persons (see-through: the contact arrows
# point into them)
GROUP_RGBA = {0: (0.30, 0.50, 0.85, 0.55), 1: (0.95, 0.55, 0.15, 1.0), 2: (0.35, 0.80, 0.40, 0.55)}
IDLE_CELL_RGBA = (0.55, 0.55, 0.58, 1.0)
IDLE_CELL_DIAMETER_M = 0.012
GOAL_RGBA = (0.2, 0.9, 0.3, 0.55)
GOAL_RADIUS_M = 0.03


CELL_SITE_GROUP = 5


def styled_xml(xml: str, cells: list) -> tuple:
    """The run's MJCF with a checkered floor, a sky and lights (the generated one has none), and
    the skin cells as sites of their link bodies (drawn idle; MuJoCo draws them at no cost per
    frame). Returns the text and the cells whose link is no body (drawn per frame instead)."""
    root = ET.fromstring(xml)
    asset = root.find("asset")
    if asset is None:
        asset = ET.Element("asset")
        root.insert(0, asset)
    ET.SubElement(asset, "texture", name="skin_floor", type="2d", builtin="checker", rgb1="0.30 0.31 0.33",
                  rgb2="0.22 0.23 0.25", width="256", height="256", mark="edge", markrgb="0.4 0.4 0.42")
    ET.SubElement(asset, "material", name="skin_floor", texture="skin_floor", texrepeat="8 8", texuniform="true")
    ET.SubElement(asset, "texture", name="skin_sky", type="skybox", builtin="gradient", rgb1="0.32 0.36 0.42",
                  rgb2="0.08 0.09 0.11", width="64", height="64")
    visual = root.find("visual")
    if visual is None:
        visual = ET.Element("visual")
        root.insert(0, visual)
    # the lights add up to 1 at most: a marker's colour is not clipped (the picture test reads it)
    ET.SubElement(visual, "headlight", ambient="0.3 0.3 0.3", diffuse="0.4 0.4 0.4", specular="0.1 0.1 0.1")
    # what llvmpipe (EGL on the CPU) renders at ~0.04 s a frame: no shadows, no multisampling,
    # 12 slices per round geom (MuJoCo's 28 slices and 4 samples cost ten times that)
    ET.SubElement(visual, "quality", shadowsize="0", offsamples="0", numslices="12", numstacks="12")
    world = root.find("worldbody")
    for geom in world.iter("geom"):
        if geom.get("type") == "plane":
            geom.set("material", "skin_floor")
            geom.set("size", "5 5 0.1")
    ET.SubElement(world, "light", directional="true", pos="0 0 5", dir="0.3 0.2 -1", diffuse="0.3 0.3 0.3", castshadow="false")
    bodies = {b.get("name"): b for b in world.iter("body")}
    loose = []
    rgba = " ".join(f"{c:g}" for c in IDLE_CELL_RGBA)
    for cell in cells:
        body = bodies.get(cell["link"])
        if body is None:
            loose.append(cell)
            continue
        ET.SubElement(body, "site", type="sphere", size=f"{IDLE_CELL_DIAMETER_M / 2:g}", group=str(CELL_SITE_GROUP),
                      pos=" ".join(f"{v:.6g}" for v in cell["position"]), rgba=rgba)
    return ET.tostring(root, encoding="unicode"), loose


def rotation(pose):
    """Rotation matrix of `[x, y, z, qx, qy, qz, qw]`."""
    x, y, z, w = pose[3:7]
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def to_world(pose, p):
    """Point `p` of a link frame in the world, the link at `pose`."""
    r = rotation(pose)
    return [pose[i] + r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] for i in range(3)]


def apply_updates(shown: dict, updates: list) -> None:
    """Applies /skin/markers updates in order, as RViz does."""
    for m in updates:
        if m["action"] == "delete_all":
            shown.clear()
        elif m["action"] == "delete":
            shown.pop((m["ns"], m["id"]), None)
        else:
            shown[(m["ns"], m["id"])] = m


def active_goal(goals: list, t_s: float):
    """The goal in force at `t_s` (the last one started), or None."""
    started = [g for g in goals if g["start_s"] <= t_s + 1e-9]
    return started[-1] if started else None


class Painter:
    """MuJoCo's renderer with the view's overlay geoms added to its scene."""

    def __init__(self, directory: Path, view: dict, width: int, height: int):
        import mujoco
        import numpy as np

        self.mj, self.np = mujoco, np
        xml, self.loose_cells = styled_xml((directory / "scene.xml").read_text(), view["cells"])
        self.model = mujoco.MjModel.from_xml_string(xml)
        for g in range(self.model.ngeom):
            group = int(self.model.geom_group[g])
            if self.model.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE and group in GROUP_RGBA:
                self.model.geom_rgba[g] = GROUP_RGBA[group]
        self.renderer = mujoco.Renderer(self.model, height, width, max_geom=20000)
        self.data = mujoco.MjData(self.model)
        self.view = view
        self.link_index = {name: k for k, name in enumerate(view["links"])}
        spec = view["spec"]
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.camera.lookat[:] = spec["lookat_m"] if spec["lookat_m"] is not None else self.model.stat.center
        self.camera.distance = spec["distance_m"] if spec["distance_m"] is not None else 1.6 * self.model.stat.extent
        self.camera.azimuth, self.camera.elevation = spec["azimuth_deg"], spec["elevation_deg"]
        self.options = mujoco.MjvOption()
        self.options.sitegroup[:] = 0
        self.options.sitegroup[CELL_SITE_GROUP] = 1

    def close(self) -> None:
        self.renderer.close()

    def _geom(self, kind, size, pos, rgba):
        scene = self.renderer.scene
        if scene.ngeom >= scene.maxgeom:
            return None
        g = scene.geoms[scene.ngeom]
        np = self.np
        self.mj.mjv_initGeom(g, kind, np.asarray(size, float), np.asarray(pos, float), np.eye(3).flatten(), np.asarray(rgba, np.float32))
        # no highlights: the marker colour is what the picture shows (the picture test reads it)
        g.specular, g.shininess, g.reflectance = 0.0, 0.0, 0.0
        scene.ngeom += 1
        return g

    def _arrow(self, start, end, width, rgba):
        g = self._geom(self.mj.mjtGeom.mjGEOM_ARROW, [0, 0, 0], [0, 0, 0], rgba)
        if g is not None:
            self.mj.mjv_connector(g, self.mj.mjtGeom.mjGEOM_ARROW, width, self.np.asarray(start, float), self.np.asarray(end, float))
            # MuJoCo draws an arrow geom half as long as its size[2], which mjv_connector sets to
            # the distance (measured: the picture test projects the arrow's middle)
            g.size[2] *= 2
            g.rgba[:] = rgba

    def render(self, frame: dict, shown: dict):
        """The RGB image of `frame` with the markers `shown` (the state after its updates)."""
        mj, data = self.mj, self.data
        data.qpos[:] = frame["qpos"]
        if self.model.nmocap:
            data.mocap_pos[:] = frame["mocap_pos"]
        mj.mj_forward(self.model, data)
        self.renderer.update_scene(data, self.camera, self.options)
        poses = frame["poses"]
        pose_of = lambda link: poses[self.link_index[link]]  # noqa: E731
        sphere = mj.mjtGeom.mjGEOM_SPHERE
        r = IDLE_CELL_DIAMETER_M / 2
        for cell in self.loose_cells:  # an active cell's marker sphere covers its idle one
            self._geom(sphere, [r, r, r], to_world(pose_of(cell["link"]), cell["position"]), IDLE_CELL_RGBA)
        for m in shown.values():
            pose = pose_of(m["frame"])
            if m["shape"] == "sphere_list":
                r = m["scale"][0] / 2
                for p, rgba in zip(m["points"], m["colors"]):
                    self._geom(sphere, [r, r, r], to_world(pose, p), rgba)
            elif len(m["points"]) == 2:
                a, b = (to_world(pose, p) for p in m["points"])
                if math.dist(a, b) > 1e-4:
                    self._arrow(a, b, m["scale"][0], m["color"])
        goal = active_goal(self.view["goals"], frame["t_s"])
        if goal is not None:
            r = GOAL_RADIUS_M
            self._geom(sphere, [r, r, r], goal["position_m"], GOAL_RGBA)
            if goal.get("rpy") is not None:
                self._goal_axes(goal)
        return self.renderer.render()

    def _goal_axes(self, goal):
        roll, pitch, yaw = goal["rpy"]
        cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
        # columns of Rz(yaw) Ry(pitch) Rx(roll): the goal frame's axes
        axes = [
            (cy * cp, sy * cp, -sp),
            (cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr),
            (cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr),
        ]
        o = goal["position_m"]
        for axis, rgba in zip(axes, [(0.9, 0.2, 0.2, 1), (0.2, 0.9, 0.2, 1), (0.2, 0.4, 1.0, 1)]):
            self._arrow(o, [o[i] + 0.1 * axis[i] for i in range(3)], 0.006, rgba)


class Annotator:
    """The overlay: title, time and arrangement at the top, the colour legend bottom left."""

    def __init__(self, title: str):
        from PIL import Image, ImageDraw, ImageFont

        self.Image, self.ImageDraw = Image, ImageDraw
        self.font = ImageFont.load_default(size=15)
        self.small = ImageFont.load_default(size=12)
        self.title = title
        self.legend = self._legend()

    def _legend(self):
        Image, ImageDraw = self.Image, self.ImageDraw
        n = 56
        w, h = 200, n + 64
        img = Image.new("RGBA", (w, h), (16, 16, 20, 200))
        d = ImageDraw.Draw(img)
        # the cell colour map: force f up (red), proximity p right (cyan): (f, p, p)
        for y in range(n):
            f = 1 - y / (n - 1)
            for x in range(n):
                p = x / (n - 1)
                img.putpixel((10 + x, 8 + y), (int(255 * f), int(255 * p), int(255 * p), 255))
        d.text((10 + n + 6, 8), "force (red)", font=self.small, fill=(240, 240, 240))
        d.text((10 + n + 6, 8 + n // 2 - 7), "active cells:", font=self.small, fill=(200, 200, 200))
        d.text((10 + n + 6, 8 + n - 14), "proximity (cyan)", font=self.small, fill=(240, 240, 240))
        y = 8 + n + 8
        d.ellipse((10, y, 20, y + 10), fill=tuple(int(255 * c) for c in IDLE_CELL_RGBA[:3]))
        d.text((28, y - 2), "idle cell", font=self.small, fill=(240, 240, 240))
        d.line((100, y + 5, 122, y + 5), fill=(255, 217, 0), width=3)
        d.polygon([(122, y), (130, y + 5), (122, y + 10)], fill=(255, 217, 0))
        d.text((134, y - 2), "patch force", font=self.small, fill=(240, 240, 240))
        y += 18
        d.ellipse((10, y, 20, y + 10), fill=(51, 230, 77))
        d.text((28, y - 2), "goal", font=self.small, fill=(240, 240, 240))
        return img

    def __call__(self, rgb, frame: dict):
        img = self.Image.fromarray(rgb).convert("RGBA")
        band = self.Image.new("RGBA", (img.width, 26), (16, 16, 20, 190))
        img.alpha_composite(band, (0, 0))
        d = self.ImageDraw.Draw(img)
        d.text((8, 4), self.title, font=self.font, fill=(240, 240, 240))
        status = f"t = {frame['t_s']:5.2f} s   arrangement: {frame['mode'].replace('_', ' ')}"
        d.text((img.width - 8 - d.textlength(status, font=self.font), 4), status, font=self.font, fill=(255, 230, 120))
        img.alpha_composite(self.legend, (6, img.height - self.legend.height - 6))
        return img.convert("RGB")


def video_indices(frames: list, fps: float) -> list:
    """The frames on the view's fixed rate (the first at or after each 1/fps step); the extra key
    frames at switches are left out."""
    out, next_t = [], frames[0]["t_s"] if frames else 0.0
    for k, f in enumerate(frames):
        if f["t_s"] >= next_t - 1e-6:
            out.append(k)
            while next_t <= f["t_s"] + 1e-6:
                next_t += 1.0 / fps
    return out


class VideoSink:
    """MP4 through ffmpeg when there is one (fixed rate, H.264), else an animated GIF (Pillow)."""

    def __init__(self, directory: Path, fps: float, width: int, height: int):
        self.fps, self.images = fps, None
        ffmpeg = shutil.which("ffmpeg")
        if ffmpeg:
            self.path = directory / "run.mp4"
            cmd = [ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}",
                   "-r", f"{fps:g}", "-i", "-", "-c:v", "libx264", "-preset", "veryfast", "-crf", "23",
                   "-pix_fmt", "yuv420p", "-movflags", "+faststart", str(self.path)]
            self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE)
        else:
            self.path, self.proc, self.images = directory / "run.gif", None, []

    def add(self, img) -> None:
        if self.proc is not None:
            self.proc.stdin.write(img.tobytes())
        else:
            self.images.append(img.quantize(colors=128))

    def close(self) -> Path:
        if self.proc is not None:
            self.proc.stdin.close()
            if self.proc.wait() != 0:
                raise RuntimeError(f"ffmpeg failed writing {self.path}")
        elif self.images:
            self.images[0].save(self.path, save_all=True, append_images=self.images[1:], duration=round(1000 / self.fps), loop=0)
        return self.path


def write_gif(path: Path, images: list, fps: float) -> None:
    """A small animated GIF of `images` (PIL) at `fps`: a palette per frame, no dithering (flat
    colours compress well and the text stays sharp)."""
    from PIL import Image

    frames = [im.quantize(colors=128, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE) for im in images]
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=round(1000 / fps), loop=0, optimize=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", type=Path, help="the run's output directory (scene.xml, keyframes.json)")
    ap.add_argument("--video", action="store_true", help="also write run.mp4 (or run.gif without ffmpeg)")
    ap.add_argument("--no-stills", action="store_true", help="no keyframe_*.png")
    ap.add_argument("--gif", type=Path, help="also write a small animated GIF here (3/4 size, every second video frame)")
    ap.add_argument("--title", default=None, help="overlay title (default: the directory's name)")
    args = ap.parse_args()
    view = json.loads((args.dir / "keyframes.json").read_text())
    frames = view["frames"]
    try:
        painter = Painter(args.dir, view, WIDTH, HEIGHT)
    except Exception as e:  # no EGL device, no mujoco: say why, render nothing
        print(f"rendering unavailable: {type(e).__name__}: {e}", file=sys.stderr)
        return 3
    annotate = Annotator(args.title or args.dir.resolve().name)
    stills = [] if args.no_stills else [k for k, f in enumerate(frames) if f["label"]]
    if stills:  # an earlier run's key frames would mix with these
        for old in args.dir.glob("keyframe_*.png"):
            old.unlink()
    in_video = video_indices(frames, view["spec"]["fps"]) if (args.video or args.gif) else []
    video = set(in_video)
    gif_frames = set(in_video[::2])
    sink = VideoSink(args.dir, view["spec"]["fps"], WIDTH, HEIGHT) if args.video else None
    gif_images = []
    names, shown, start, done = [], {}, time.monotonic(), 0
    total = len(video | set(stills))
    try:
        for k, f in enumerate(frames):
            apply_updates(shown, f["markers"])
            if k not in video and k not in stills:
                continue
            img = annotate(painter.render(f, shown), f)
            if k in stills:
                name = f"keyframe_{len(names)}_{f['t_s']:.2f}s.png"
                img.save(args.dir / name)
                names.append(f"{name} ({f['label']})")
            if k in video:
                if sink is not None:
                    sink.add(img)
                if args.gif is not None and k in gif_frames:
                    gif_images.append(img.resize((WIDTH * 3 // 4, HEIGHT * 3 // 4), resample=3))
            done += 1
            if sink is not None and (done % max(1, total // 10) == 0 or done == total):
                print(f"render: {done}/{total} frames, {time.monotonic() - start:.1f} s", file=sys.stderr, flush=True)
    finally:
        painter.close()
    if sink is not None:
        path = sink.close()
        print(f"render: {path.name}, {len(video)} frames at {view['spec']['fps']:g} fps in {time.monotonic() - start:.1f} s", file=sys.stderr)
    if args.gif is not None and gif_images:
        write_gif(args.gif, gif_images, view["spec"]["fps"] / 2)
    print("\n".join(names))
    return 0


if __name__ == "__main__":
    sys.exit(main())
