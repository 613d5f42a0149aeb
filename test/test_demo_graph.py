"""`make demo`'s graph run: skin_stack (mujoco_sim --lockstep --out, task_controller,
priority_supervisor over DDS) writes what `skin_sim run` writes for the same scenario.

intentional_contact for 2 s of simulated time through the graph and in process: all four outputs
are there, metrics.json has exactly skin_sim's keys and, the skin sensing nothing before
t = 3.476 s (the graph's float32 skin signals are then exact: docs/ros.md), the same values but
the wall-clock ones; the same outcome checks fail the same way (the goal is not reached in 2 s:
exit code 1 for both); run.mcap reads with rosbags, one message per period on each topic, and
its last /controller/state carries the goal error of metrics.json."""
import json
import subprocess

import pytest
from rosbags.highlevel import AnyReader

from conftest import TOP, binary

DURATION = 2.0
PERIODS = int(DURATION * 500)  # the scene's control rate
OUTPUTS = ("metrics.json", "summary.txt", "figure.png", "run.mcap", "scene.xml", "keyframes.json")
WALL_CLOCK = {"realtime_factor", "control_cycle_us_p50", "loop_time_s", "realtime_factor_physics_bound"}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(graph process, graph dir, in-process process, in-process dir)."""
    tmp = tmp_path_factory.mktemp("demo")
    graph_dir, local_dir = tmp / "graph", tmp / "in_process"
    graph = subprocess.run([str(binary("skin_stack")), "--scene", "intentional_contact", "--lockstep",
                            "--internal-supervisor", "--duration", str(DURATION), "--out", str(graph_dir)],
                           capture_output=True, text=True, timeout=180)
    local = subprocess.run([str(binary("skin_sim")), "run", "intentional_contact", "--duration", str(DURATION),
                            "--out", str(local_dir), "--quiet"], capture_output=True, text=True, timeout=120)
    return graph, graph_dir, local, local_dir


def test_graph_run_writes_every_output_with_skin_sims_metrics(runs):
    graph, graph_dir, local, local_dir = runs
    assert graph.returncode == local.returncode == 1, graph.stdout + graph.stderr
    for name in OUTPUTS:
        assert (graph_dir / name).stat().st_size > 0, name
    assert (graph_dir / "figure.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    labels = [[k["label"] for k in json.loads((d / "keyframes.json").read_text())["frames"] if k["label"]]
              for d in (graph_dir, local_dir)]
    assert labels[0] == labels[1] and labels[0][0] == "start" and labels[0][-1] == "end", labels
    got = json.loads((graph_dir / "metrics.json").read_text())
    want = json.loads((local_dir / "metrics.json").read_text())
    assert set(got) == set(want)
    assert got["sim_duration_s"] == DURATION
    assert {k: v for k, v in got.items() if k not in WALL_CLOCK} == \
        {k: v for k, v in want.items() if k not in WALL_CLOCK}
    summary = (graph_dir / "summary.txt").read_text()
    assert summary in graph.stdout, "the summary is printed"
    assert "outcome: FAIL" in summary
    local_summary = (local_dir / "summary.txt").read_text()
    checks = lambda s: [line for line in s.splitlines() if line.lstrip().startswith("[")]  # noqa: E731
    assert checks(summary) == checks(local_summary)


def test_graph_run_bag_reads_with_rosbags(runs):
    _, graph_dir, _, _ = runs
    counts, last_state = {}, None
    with AnyReader([graph_dir / "run.mcap"]) as reader:
        for conn, _, raw in reader.messages():
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            if conn.topic == "/controller/state":
                last_state = reader.deserialize(raw, conn.msgtype)
    for topic in ("/clock", "/joint_states", "/arm/forward_velocity_controller/commands", "/controller/state"):
        assert counts.get(topic) == PERIODS, (topic, counts)
    assert counts.get("/supervisor/arrangement", 0) >= 1
    # what a viewer needs (test_run_view.py checks their content on an in-process run)
    assert counts.get("/robot_description") == 1 and counts.get("/tf", 0) >= 1 and counts.get("/skin/markers", 0) >= 1, counts
    metrics = json.loads((graph_dir / "metrics.json").read_text())
    assert last_state.goal_error == pytest.approx(metrics["goal_error_m"], abs=1e-12)


def test_demo_names_a_node_left_on_its_domain(rclpy_node):
    """scripts/domain_nodes.py, which `make demo` runs before its graph run, lists a node another
    run left on the domain (here the rclpy peer), and not itself."""
    script = TOP / "scripts" / "domain_nodes.py"
    listed = subprocess.run(["python3", str(script), "--wait-s", "2"], capture_output=True, text=True, timeout=60)
    assert listed.returncode == 0, listed.stderr
    names = listed.stdout.split()
    assert f"/{rclpy_node.get_name()}" in names, listed.stdout
    assert not any("domain_probe" in n for n in names), names
