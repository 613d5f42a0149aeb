"""A push given up, through the ROS graph: skin_stack with priority_supervisor deciding over DDS
(no --internal-supervisor) on the fixed-obstacle scene (the planar arm pushes an obstacle that
cannot move). The deciding supervisor gives the push up after it reaches eps_c; the hold and
its reason must reach the controller in `/supervisor/arrangement` and come back in every
`/controller/state` (`blocked`, `releasing`), so the graph run's outcome is `blocked` as the
in-process run's is, and the task_controller says why in its log."""
import json
import subprocess

from rosbags.highlevel import AnyReader

from conftest import binary

SCENE = "config/scenes/intentional_contact_fixed_obstacle.yaml"


def test_a_push_given_up_is_carried_through_the_graph(tmp_path):
    out = tmp_path / "run"
    run = subprocess.run([str(binary("skin_stack")), "--setup", "config/controller/planar7.yaml",
                          "--scene", SCENE, "--lockstep", "--out", str(out)],
                         capture_output=True, text=True, timeout=180)
    log = run.stdout + run.stderr
    assert run.returncode == 0, log
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["outcome"] == "blocked", metrics
    assert "blocked: the push was given up at t = " in log, log[-3000:]
    eps_c = metrics["eps_c_n"]
    held, arrangements = [], []
    with AnyReader([out / "run.mcap"]) as reader:
        for conn, _, raw in reader.messages():
            if conn.topic == "/controller/state":
                s = reader.deserialize(raw, conn.msgtype)
                if s.blocked.active:
                    held.append(s)
            elif conn.topic == "/supervisor/arrangement":
                arrangements.append(reader.deserialize(raw, conn.msgtype))
    assert held, "no /controller/state says blocked"
    first = held[0]
    since = first.blocked.since.sec + 1e-9 * first.blocked.since.nanosec
    assert abs(since - metrics["blocked_at_s"]) < 0.05, (since, metrics["blocked_at_s"])
    assert first.blocked.contact_force >= eps_c, "the force that blocked the push is over eps_c"
    assert first.blocked.goal_error > 0.05 and first.mode == 0  # held in avoidance (a), short of the goal
    assert all(s.releasing for s in held), "the hold presses nothing"
    assert any(a.blocked.active for a in arrangements)
