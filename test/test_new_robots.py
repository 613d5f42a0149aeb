"""Any robot into the simulator: `skin_setup` writes the skin layout, controller setup and
reach-past-an-obstacle scene of robots that nobody here modelled (example-robot-data URDFs and
meshes, pinned in scripts/requirements.txt; nothing downloaded), and `skin_sim run` passes the
scene's outcome checks (goal reached, contact force at most eps_c, no safe-stop cycles) for
each. Also: the errors for choices a URDF cannot satisfy name the choice and the reason.

Meshes are used as meshes (MuJoCo: convex hulls), and once as their fitted boxes (the
primitive approximation). The robots' choices are what a user would give: the end-effector link and, where the root-to-
end-effector chain holds more than the arm (Tiago's torso), the arm joints."""
import json
import subprocess
import time

import pytest
import yaml

from conftest import binary
from test_robot_zoo import robots_dir

# name: (URDF under example-robot-data/robots, skin_setup options)
ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", ["--end-effector", "panda_hand"]),
    # The primitive approximation: skin on, and collisions with, the boxes fitted to the meshes.
    "panda_box": ("panda_description/urdf/panda.urdf", ["--end-effector", "panda_hand", "--meshes", "box"]),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", ["--end-effector", "wrist_3_link"]),
    "kinova": ("kinova_description/robots/kinova.urdf", ["--end-effector", "j2s6s200_link_6"]),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", ["--end-effector", "link7"]),
    # The mobile manipulator: planar base joints added in front of its root, the base moves.
    "tiago": ("tiago_description/robots/tiago.urdf",
              ["--end-effector", "arm_7_link", "--mobile-base",
               "--arm-joints", ",".join(f"arm_{i}_joint" for i in range(1, 8))]),
    # The same with its base (and torso) frozen.
    "tiago_fixed": ("tiago_description/robots/tiago.urdf",
                    ["--end-effector", "arm_7_link",
                     "--arm-joints", ",".join(f"arm_{i}_joint" for i in range(1, 8))]),
    # Two arms, casters and wheels without velocity limits: every joint outside the chosen arm is
    # held by the controller (locked_joints), so the URDF needs no limits there.
    "tiago_dual": ("tiago_description/robots/tiago_dual.urdf",
                   ["--end-effector", "arm_left_7_link",
                    "--arm-joints", ",".join(f"arm_left_{i}_joint" for i in range(1, 8))]),
}


def package_path():
    """The directory holding the `example-robot-data` package of the URDFs' package:// URIs."""
    return robots_dir().parent.parent


def base_travel(bag, link):
    """How far `link` got from its start in the run's /tf [m]."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    with open(bag, "rb") as f:
        xy = [(t.transform.translation.x, t.transform.translation.y)
              for _, _, _, msg in make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages(topics=["/tf"])
              for t in msg.transforms if t.child_frame_id == link]
    assert xy, f"no /tf of {link}"
    return max(((x - xy[0][0]) ** 2 + (y - xy[0][1]) ** 2) ** 0.5 for x, y in xy)


def setup(name, tmp_path, options=None):
    urdf, default = ROBOTS[name]
    return subprocess.run([binary("skin_setup"), "--urdf", robots_dir() / urdf, "--package-path", package_path(),
                           "--out", tmp_path, *(default if options is None else options)],
                          capture_output=True, text=True, check=False)


@pytest.mark.parametrize("name", list(ROBOTS))
def test_reach_past_a_movable_obstacle(name, tmp_path):
    t0 = time.monotonic()
    out = setup(name, tmp_path)
    setup_s = time.monotonic() - t0
    assert out.returncode == 0, out.stderr
    stem = (robots_dir() / ROBOTS[name][0]).stem
    scene, controller = tmp_path / f"{stem}_scene.yaml", tmp_path / f"{stem}_controller.yaml"
    t0 = time.monotonic()
    run = subprocess.run([binary("skin_sim"), "run", scene, "--controller", controller, "--out", tmp_path / "run",
                          "--quiet"], capture_output=True, text=True, check=False)
    run_s = time.monotonic() - t0
    print(f"{name}: {out.stdout.splitlines()[0]} | setup {setup_s:.1f} s, run {run_s:.1f} s\n{run.stdout}")
    assert run.returncode == 0, run.stdout + run.stderr
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert metrics["goal_reached"] and metrics["goal_error_m"] <= metrics["goal_tolerance_m"], metrics
    assert metrics["max_contact_force_n"] <= metrics["eps_c_n"], metrics
    # Past the obstacle: the arm was stuck in front of it and switched to intentional contact.
    assert any(s["to"] == "intentional_contact" for s in metrics["arrangement_switches"]), metrics
    if "--mobile-base" in ROBOTS[name][1]:
        assert base_travel(tmp_path / "run" / "run.mcap", "base_footprint") > 0.05
    held = yaml.safe_load(controller.read_text()).get("locked_joints", [])
    moving = set(yaml.safe_load(scene.read_text())["robot"]["joints"])
    assert not moving & set(held), "a joint the scene moves is held"


def test_choices_the_urdf_cannot_satisfy(tmp_path):
    def err(*extra):
        out = setup("panda", tmp_path, ["--end-effector", "panda_hand", *extra])
        assert out.returncode == 2
        return out.stderr

    e = setup("panda", tmp_path, ["--end-effector", "nope"]).stderr
    assert "--end-effector `nope`" in e and "not a link" in e and "panda.urdf" in e, e
    e = err("--arm-joints", "panda_joint1,panda_finger_joint1")
    assert "panda_finger_joint1" in e and "does not move the end effector" in e, e
    e = err("--arm-joints", "panda_joint1,panda_joint2")
    assert "at least 3" in e, e
    e = err("--skin-links", "panda_link8")
    assert "panda_link8" in e and "no collision geometry" in e, e
    e = err("--initial", "panda_joint4=1.0")
    assert "panda_joint4" in e and "outside the limits" in e, e
    urdf = robots_dir() / ROBOTS["panda"][0]
    out = subprocess.run([binary("skin_setup"), "--urdf", urdf, "--end-effector", "panda_hand", "--out", tmp_path],
                         capture_output=True, text=True, check=False, env={"PATH": "/usr/bin:/bin"})
    assert out.returncode == 2
    assert "package://example-robot-data/robots/panda_description/meshes/collision/" in out.stderr, out.stderr
    assert "--package-path" in out.stderr, out.stderr


# URDFs whose collision meshes cover the three formats: STL (panda, tiago), COLLADA with node
# transforms, units and Y_UP files (kinova, tiago, romeo_small, icub_reduced, hyq), OBJ (solo12,
# alex_nub_hands).
MESH_URDFS = ["panda_description/urdf/panda.urdf", "kinova_description/robots/kinova.urdf",
              "tiago_description/robots/tiago.urdf", "romeo_description/urdf/romeo_small.urdf",
              "icub_description/robots/icub_reduced.urdf", "hyq_description/robots/hyq_no_sensors.urdf",
              "solo_description/robots/solo12.urdf", "alex_description/urdf/alex_nub_hands.urdf"]


@pytest.mark.parametrize("urdf", MESH_URDFS)
def test_meshes_read_as_pinocchio_reads_them(urdf):
    """Every collision mesh as `skin_layout` reads it (STL, OBJ, COLLADA, package:// URIs) has the
    bounding box that pinocchio's loader (coal, through assimp) gives, to float32 precision."""
    import numpy as np
    import pinocchio as pin
    path = robots_dir() / urdf
    out = subprocess.run([binary("skin_layout"), "--urdf", path, "--package-path", package_path(), "--mesh-bounds"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    ours = {(r["link"], r["collision"]): r for r in json.loads(out.stdout)}
    assert ours and all(r["triangles"] > 0 for r in ours.values())
    model = pin.buildModelFromUrdf(str(path))
    geom = pin.buildGeomFromUrdf(model, str(path), pin.COLLISION, package_dirs=[str(package_path())])
    theirs = {}
    for o in geom.geometryObjects:
        if o.meshPath and hasattr(o.geometry, "vertices"):
            v = np.asarray(o.geometry.vertices())  # scale applied by the loader
            link, k = o.name.rsplit("_", 1)
            theirs[(link, int(k))] = (v.min(axis=0), v.max(axis=0))
    assert set(theirs) == set(ours), (sorted(set(theirs) ^ set(ours)))[:5]
    for key, (lo, hi) in theirs.items():
        r = ours[key]
        tol = 1e-5 * max(1.0, float(np.abs(hi - lo).max()))
        assert np.allclose(r["min"], lo, atol=tol) and np.allclose(r["max"], hi, atol=tol), (key, r, lo, hi)
