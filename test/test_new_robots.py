"""Any robot into the simulator: `skin_setup` writes the skin layout, controller setup and
reach-past-an-obstacle scene of robots that nobody here modelled (example-robot-data URDFs and
meshes, pinned in scripts/requirements.txt; nothing downloaded), and `skin_sim run` passes the
scene's outcome checks (goal reached, contact force at most eps_c, no safe-stop cycles) for
each. Also: the errors for choices a URDF cannot satisfy name the choice and the reason.

The robots' choices are what a user would give: the end-effector link and, where the root-to-
end-effector chain holds more than the arm (Tiago's torso), the arm joints."""
import json
import subprocess
import time

import pytest

from conftest import binary
from test_robot_zoo import robots_dir

# name: (URDF under example-robot-data/robots, skin_setup options)
ROBOTS = {
    "panda": ("panda_description/urdf/panda.urdf", ["--end-effector", "panda_hand"]),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", ["--end-effector", "wrist_3_link"]),
    "kinova": ("kinova_description/robots/kinova.urdf", ["--end-effector", "j2s6s200_link_6"]),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", ["--end-effector", "link7"]),
    "tiago": ("tiago_description/robots/tiago.urdf",
              ["--end-effector", "arm_7_link",
               "--arm-joints", ",".join(f"arm_{i}_joint" for i in range(1, 8))]),
}

# Short scenes: the reach and the push take a few seconds.
DURATION_S = "12"


def package_path():
    """The directory holding the `example-robot-data` package of the URDFs' package:// URIs."""
    return robots_dir().parent.parent


def setup(name, tmp_path, *extra):
    urdf, options = ROBOTS[name]
    return subprocess.run([binary("skin_setup"), "--urdf", robots_dir() / urdf, "--package-path", package_path(),
                           "--duration", DURATION_S, "--out", tmp_path, *options, *extra],
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
    assert metrics["goal"]["goal_error_m"] <= 0.01, metrics["goal"]


def test_choices_the_urdf_cannot_satisfy(tmp_path):
    def err(*extra):
        out = setup("panda", tmp_path, *extra)
        assert out.returncode == 2
        return out.stderr

    e = err("--end-effector", "nope")
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
