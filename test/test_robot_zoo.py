"""Any robot from its URDF: the public robots of example-robot-data (PyPI `example-robot-data`,
pinned in scripts/requirements.txt, URDFs installed under the venv's cmeel.prefix; nothing is
downloaded at run time) load in `skin_model --urdf`, and its M, C(q, qd) qd + g, g, point
Jacobians J of several frames and J' qd agree with pinocchio's on random states.

Tolerance as in test_dynamics_reference.py: |ours - ref| <= 1e-9 * max(1, |ref|) per element.
Both models have a fixed root (a floating base is the URDF's root link held fixed, pinocchio's
`buildModelFromUrdf` without a root joint). Mimic joints are compared in both modes: independent
(ours `--mimic independent`, pinocchio `mimic=False`) and following their leader (`--mimic
follow`, `mimic=True`). docs/dynamics.md ("Loading any URDF") lists the measured errors."""
import importlib.metadata
import json
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

from conftest import binary
from test_dynamics_reference import pinocchio_quantities

TOL = 1e-9
N_STATES = 6
N_FRAMES = 3
KEYS = ["mass_matrix", "bias", "gravity", "jacobian", "jacobian_dot_qdot"]

ROBOTS = {
    # arms
    "panda": "panda_description/urdf/panda.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "kinova": "kinova_description/robots/kinova.urdf",
    "xarm7": "xarm_description/urdf/xarm7.urdf",
    "z1": "z1_description/urdf/z1.urdf",
    "so101": "so_arm_description/urdf/so101.urdf",
    "so100": "so_arm_description/urdf/so100.urdf",
    "double_pendulum": "double_pendulum_description/urdf/double_pendulum.urdf",
    "talos_left_arm": "talos_data/robots/talos_left_arm.urdf",
    "allegro_right_hand": "allegro_hand_description/urdf/allegro_right_hand.urdf",
    # mobile manipulators and dual arms
    "tiago": "tiago_description/robots/tiago.urdf",
    "tiago_dual": "tiago_description/robots/tiago_dual.urdf",
    "tiago_pro": "tiago_pro_description/robots/tiago_pro.urdf",
    "pr2": "pr2_description/urdf/pr2.urdf",
    "baxter": "baxter_description/urdf/baxter.urdf",
    # humanoids and legged robots (fixed root: the base link held in place)
    "talos_reduced": "talos_data/robots/talos_reduced.urdf",
    "talos_full_v2": "talos_data/robots/talos_full_v2.urdf",
    "icub_reduced": "icub_description/robots/icub_reduced.urdf",
    "icub": "icub_description/robots/icub.urdf",
    "g1": "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "romeo_small": "romeo_description/urdf/romeo_small.urdf",
    "human": "human_description/robots/human.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
    "go2": "go2_description/urdf/go2.urdf",
}


def robots_dir():
    dist = importlib.metadata.distribution("example-robot-data")
    return Path(dist.locate_file("cmeel.prefix/share/example-robot-data/robots"))


def has_mimic(urdf):
    return "<mimic" in Path(urdf).read_text()


def run_ours(urdf, states, mimic):
    with tempfile.NamedTemporaryFile("w", suffix=".json") as f:
        json.dump(states, f)
        f.flush()
        out = subprocess.run([binary("skin_model"), "--urdf", str(urdf), "--mimic", mimic, "--batch", f.name],
                             capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout), out.stderr


class Pinocchio:
    """pinocchio on the same URDF; our coordinates are mapped to its q by joint name (continuous
    joints are (cos, sin) pairs in pinocchio's q)."""

    def __init__(self, urdf, names, mimic):
        import pinocchio as pin
        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(urdf), mimic=mimic)
        self.data = self.model.createData()
        joints = [self.model.joints[self.model.getJointId(n)] for n in names]
        assert all(j.nv == 1 for j in joints), names
        self.vidx = [j.idx_v for j in joints]
        self.qidx = [(j.idx_q, j.nq) for j in joints]

    def limits(self):
        m = self.model
        return [(m.lowerPositionLimit[i], m.upperPositionLimit[i]) if nq == 1 else (-np.pi, np.pi)
                for i, nq in self.qidx]

    def frames(self, count):
        """`count` body frames spread over the tree (moved by some joint)."""
        m = self.model
        moving = [f.name for f in m.frames if f.type == self.pin.FrameType.BODY and f.parentJoint > 0]
        pick = np.linspace(len(moving) - 1, 0, count).round().astype(int)
        return [moving[i] for i in dict.fromkeys(pick)]

    def compute(self, q, qd, link, point):
        pin, m, d = self.pin, self.model, self.data
        qp = pin.neutral(m)
        for (i, nq), x in zip(self.qidx, q):
            if nq == 1:
                qp[i] = x
            else:
                qp[i:i + 2] = np.cos(x), np.sin(x)
        vp = np.zeros(m.nv)
        vp[self.vidx] = qd
        return pinocchio_quantities(pin, m, d, qp, vp, link, point, self.vidx)


class ComposedMimic:
    """Following mimic joints from first principles, for URDFs pinocchio's `mimic=True` refuses
    (talos_full_v2: a leader that comes after its follower in the tree): pinocchio's independent
    model at q_ind = G q + o, q'_ind = G q', then M = G^T M_ind G, tau = G^T tau_ind, J = J_ind G,
    with G and o from the URDF's <mimic> elements (chains composed)."""

    def __init__(self, urdf, names):
        import xml.etree.ElementTree as ET
        mimic = {}
        for j in ET.parse(urdf).getroot().iter("joint"):
            m = j.find("mimic")
            if m is not None and j.get("type") != "fixed":
                mimic[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
        all_names = self.all_names = self.joint_names(urdf)
        self.inner = Pinocchio(urdf, all_names, False)
        self.names = names
        self.g = np.zeros((len(all_names), len(names)))
        self.o = np.zeros(len(all_names))
        for row, n in enumerate(all_names):
            mult, off = 1.0, 0.0
            while n in mimic:
                n, m, o = mimic[n]
                off += mult * o
                mult *= m
            self.g[row, names.index(n)] = mult
            self.o[row] = off

    @staticmethod
    def joint_names(urdf):
        import pinocchio as pin
        return list(pin.buildModelFromUrdf(str(urdf)).names[1:])

    def limits(self):
        lim = self.inner.limits()
        return [lim[self.all_names.index(n)] for n in self.names]

    def frames(self, count):
        return self.inner.frames(count)

    def compute(self, q, qd, link, point):
        r = self.inner.compute(self.g @ q + self.o, self.g @ qd, link, point)
        g = self.g
        return {"mass_matrix": g.T @ r["mass_matrix"] @ g, "bias": g.T @ r["bias"], "gravity": g.T @ r["gravity"],
                "jacobian": r["jacobian"] @ g, "jacobian_dot_qdot": r["jacobian_dot_qdot"]}


def scaled_error(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    err = np.abs(a - b) / np.maximum(1.0, np.abs(b))
    return float(err.max()) if err.size else 0.0


def compare(urdf, mimic, reference_urdf=None):
    """Worst scaled error per quantity of ours (on `urdf`) against pinocchio (on
    `reference_urdf`, default the same file) over random states and a few frames."""
    import pinocchio as pin
    follow = mimic == "follow"
    reference_urdf = reference_urdf or urdf
    try:
        pin.buildModelFromUrdf(str(reference_urdf), mimic=follow)
        composed = False
    except ValueError:  # pinocchio's mimic=True refuses some valid trees
        assert follow
        composed = True
    out = subprocess.run([binary("skin_model"), "--urdf", str(urdf), "--mimic", mimic, "--joints"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    names = json.loads(out.stdout)
    ref = ComposedMimic(reference_urdf, names) if composed else Pinocchio(reference_urdf, names, follow)
    rng = np.random.default_rng(20261126)
    lim = np.array(ref.limits())
    lo = np.where(np.isfinite(lim[:, 0]), lim[:, 0], -np.pi)
    hi = np.where(np.isfinite(lim[:, 1]), lim[:, 1], np.pi)
    frames = ref.frames(N_FRAMES)
    states = []
    for _ in range(N_STATES):
        q = rng.uniform(lo, hi).tolist()
        qd = rng.uniform(-2.0, 2.0, len(names)).tolist()
        for f in frames:
            states.append({"q": q, "qd": qd, "link": f, "point": rng.uniform(-0.1, 0.1, 3).tolist()})
    results, stderr = run_ours(urdf, states, mimic)
    worst = {k: 0.0 for k in KEYS}
    for s, r in zip(states, results):
        expect = ref.compute(np.array(s["q"]), np.array(s["qd"]), s["link"], s["point"])
        for k in KEYS:
            worst[k] = max(worst[k], scaled_error(r[k], expect[k]))
    return names, worst, stderr


# every robot as pinocchio loads it by default; those with <mimic> elements also following them
CASES = [(name, "independent") for name in ROBOTS] + [
    (name, "follow") for name in ROBOTS if has_mimic(robots_dir() / ROBOTS[name])]


@pytest.mark.parametrize("name,mimic", CASES, ids=[f"{n}-{m}" for n, m in CASES])
def test_example_robot_matches_pinocchio(name, mimic):
    urdf = robots_dir() / ROBOTS[name]
    names, worst, stderr = compare(urdf, mimic)
    warnings = [line for line in stderr.splitlines() if "warning" in line]
    print(f"{name} ({mimic}, nv {len(names)}): worst scaled error {worst}; {len(warnings)} load warnings")
    for w in warnings:
        print("   ", w)
    bad = {k: v for k, v in worst.items() if v > TOL}
    assert not bad, f"{name} ({mimic}): pinocchio disagrees beyond {TOL}: {bad}"


def test_a_wrong_mimic_multiplier_is_detected(tmp_path):
    """The comparison can fail: panda's second finger following the first with multiplier 1.001
    instead of 1 disagrees with pinocchio on the original URDF."""
    urdf = robots_dir() / ROBOTS["panda"]
    text = urdf.read_text()
    assert '<mimic joint="panda_finger_joint1"/>' in text
    wrong = tmp_path / "panda_wrong_mimic.urdf"
    wrong.write_text(text.replace('<mimic joint="panda_finger_joint1"/>',
                                  '<mimic joint="panda_finger_joint1" multiplier="1.001"/>'))
    _, worst, _ = compare(wrong, "follow", reference_urdf=urdf)
    assert max(worst.values()) > 100 * TOL, worst
