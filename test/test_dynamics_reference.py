"""Our rigid-body dynamics (skin_core, through `skin_model --batch`) against two outside
references on the same URDF: pinocchio (PyPI `pin`) and MuJoCo (PyPI `mujoco`).

Compared at 1000 random configurations and velocities per URDF (plus exactly singular ones):
mass matrix M, bias C(q, qd) qd + g, gravity g, the world-aligned Jacobian of a point on a link
(linear rows first) and its classical acceleration Jdot qd. Tolerance: |ours - ref| <= 1e-9 *
max(1, |ref|) per element, i.e. absolute 1e-9 for entries up to 1 and relative 1e-9 above."""
import json
import subprocess

import numpy as np
import pytest

from conftest import TOP, binary

N_STATES = 1000
TOL = 1e-9
URDFS = {"tomm": TOP / "urdf" / "tomm.urdf", "planar7": TOP / "urdf" / "planar7.urdf"}
# Points on moving links, in the link frame (exercise offsets in every direction).
PROBES = {
    "tomm": [("right_wrist_3_link", [0.01, -0.02, 0.05]), ("left_forearm_link", [0.2, 0.03, -0.04]),
             ("base_link", [0.3, -0.2, 0.1]), ("right_upper_arm_link", [0.1, 0.0, 0.12])],
    "planar7": [("link7", [0.2, 0.01, 0.0]), ("link3", [0.1, -0.05, 0.02])],
}


def ours(urdf, states):
    """Run skin_model in batch mode on a list of states; returns its list of results."""
    import tempfile
    with tempfile.NamedTemporaryFile("w", suffix=".json") as f:
        json.dump(states, f)
        f.flush()
        out = subprocess.run([binary("skin_model"), "--urdf", urdf, "--batch", f.name],
                             capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def random_states(names, limits, rng, n):
    """Uniform positions within the limits (base translations within +-2 m), velocities in
    +-3 rad/s or m/s, and a probe point; the first states are exactly singular arms."""
    lo = np.array([max(l[0], -2.0) for l in limits])
    hi = np.array([min(l[1], 2.0) if "base_" in nm else l[1] for nm, l in zip(names, limits)])
    lo = np.where(np.isfinite(lo), lo, -np.pi)
    hi = np.where(np.isfinite(hi), hi, np.pi)
    qs = rng.uniform(lo, hi, size=(n, len(names)))
    qs[:3] = 0.0  # stretched arms, aligned wrist axes
    qds = rng.uniform(-3.0, 3.0, size=(n, len(names)))
    return qs, qds


def close(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    err = np.abs(a - b) / np.maximum(1.0, np.abs(b))
    return float(err.max()) if err.size else 0.0


def pinocchio_quantities(pin, m, d, qp, vp, link, point, vidx):
    """pinocchio's M, C q' + g, g, the point Jacobian of `point` on `link` (world axes, linear part
    at the point) and its J' q' at (qp, vp), restricted to the velocity indices `vidx`."""
    M = pin.crba(m, d, qp)
    M = np.triu(M) + np.triu(M, 1).T
    b = pin.rnea(m, d, qp, vp, np.zeros(m.nv))
    g = pin.computeGeneralizedGravity(m, d, qp)
    pin.forwardKinematics(m, d, qp, vp, np.zeros(m.nv))
    pin.updateFramePlacements(m, d)
    fid = m.getFrameId(link)
    r = d.oMf[fid].rotation @ np.asarray(point)
    J = pin.computeFrameJacobian(m, d, qp, fid, pin.LOCAL_WORLD_ALIGNED)
    pin.forwardKinematics(m, d, qp, vp, np.zeros(m.nv))
    J[:3] = J[:3] - skew(r) @ J[3:]
    acc = pin.getFrameClassicalAcceleration(m, d, fid, pin.LOCAL_WORLD_ALIGNED)
    vel = pin.getFrameVelocity(m, d, fid, pin.LOCAL_WORLD_ALIGNED)
    w, alpha = vel.angular, acc.angular
    a_lin = acc.linear + np.cross(alpha, r) + np.cross(w, np.cross(w, r))
    ix = np.ix_(vidx, vidx)
    return {"mass_matrix": M[ix], "bias": b[vidx], "gravity": g[vidx],
            "jacobian": J[:, vidx], "jacobian_dot_qdot": np.concatenate([a_lin, alpha])}


class Pinocchio:
    def __init__(self, urdf, names):
        import pinocchio as pin
        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(urdf))
        self.data = self.model.createData()
        self.vidx = [self.model.joints[self.model.getJointId(n)].idx_v for n in names]
        self.qidx = [self.model.joints[self.model.getJointId(n)].idx_q for n in names]

    def compute(self, q, qd, link, point):
        pin, m, d = self.pin, self.model, self.data
        nq = m.nq
        qp = np.zeros(nq); vp = np.zeros(m.nv)
        qp[self.qidx] = q; vp[self.vidx] = qd
        return pinocchio_quantities(pin, m, d, qp, vp, link, point, self.vidx)


class Mujoco:
    def __init__(self, urdf, names):
        import mujoco
        self.mj = mujoco
        self.model = mujoco.MjModel.from_xml_path(str(urdf))
        self.data = mujoco.MjData(self.model)
        jids = [mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in names]
        assert min(jids) >= 0, f"MuJoCo lost a joint of {names}"
        self.qadr = [self.model.jnt_qposadr[j] for j in jids]
        self.vadr = [self.model.jnt_dofadr[j] for j in jids]

    def compute(self, q, qd, link, point):
        mj, m, d = self.mj, self.model, self.data
        d.qpos[:] = 0; d.qvel[:] = 0; d.qacc[:] = 0
        d.qpos[self.qadr] = q
        mj.mj_forward(m, d)
        g = d.qfrc_bias.copy()
        d.qvel[self.vadr] = qd
        mj.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv)); mj.mj_fullM(m, d, M)
        body = mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, link)
        assert body >= 0, f"MuJoCo has no body {link} (fused as a static link?)"
        pw = d.xpos[body] + d.xmat[body].reshape(3, 3) @ np.asarray(point)
        jp = np.zeros((3, m.nv)); jr = np.zeros((3, m.nv))
        mj.mj_jac(m, d, jp, jr, pw, body)
        jdp = np.zeros((3, m.nv)); jdr = np.zeros((3, m.nv))
        mj.mj_jacDot(m, d, jdp, jdr, pw, body)
        ix = np.ix_(self.vadr, self.vadr)
        return {"mass_matrix": M[ix], "bias": d.qfrc_bias[self.vadr].copy(),
                "gravity": g[self.vadr], "jacobian": np.vstack([jp, jr])[:, self.vadr],
                "jacobian_dot_qdot": np.concatenate([jdp @ d.qvel, jdr @ d.qvel])}


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


@pytest.fixture(scope="module", params=sorted(URDFS))
def robot(request):
    """One URDF, N_STATES random states and our results for them."""
    name = request.param
    urdf = URDFS[name]
    import pinocchio as pin
    pm = pin.buildModelFromUrdf(str(urdf))
    names = ours(urdf, [{"q": [0.0] * pm.nv, "qd": [0.0] * pm.nv}])[0]["joints"]
    idx = [pm.joints[pm.getJointId(n)].idx_q for n in names]
    limits = [(pm.lowerPositionLimit[i], pm.upperPositionLimit[i]) for i in idx]
    rng = np.random.default_rng(20261123)
    qs, qds = random_states(names, limits, rng, N_STATES)
    probes = PROBES[name]
    states = [{"q": qs[i].tolist(), "qd": qds[i].tolist(), "link": probes[i % len(probes)][0],
               "point": probes[i % len(probes)][1]} for i in range(N_STATES)]
    return name, urdf, names, states, ours(urdf, states)


KEYS = ["mass_matrix", "bias", "gravity", "jacobian", "jacobian_dot_qdot"]


@pytest.mark.parametrize("reference", ["pinocchio", "mujoco"])
def test_dynamics_match_reference(robot, reference):
    name, urdf, names, states, results = robot
    ref = (Pinocchio if reference == "pinocchio" else Mujoco)(urdf, names)
    worst = {k: 0.0 for k in KEYS}
    for s, r in zip(states, results):
        assert r["joints"] == names
        expect = ref.compute(np.array(s["q"]), np.array(s["qd"]), s["link"], s["point"])
        for k in KEYS:
            worst[k] = max(worst[k], close(r[k], expect[k]))
    print(f"{name} vs {reference}: worst scaled error per quantity over {len(states)} states: {worst}")
    bad = {k: v for k, v in worst.items() if v > TOL}
    assert not bad, f"{name}: {reference} disagrees beyond {TOL}: {bad}"
