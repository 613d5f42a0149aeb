#!/usr/bin/env python3
"""The ROS graph's figures for out/bench/summary.json (issue 6), with the release binaries
`scripts/bench` builds:

- ros_latency_p50_us, ros_latency_p99_us: task_controller (TOMM, trigger:=inputs) and the
  ros_latency probe: a 718-cell /skin/cells at 250 Hz to the right arm's command that uses it;
- ros_lockstep_realtime_factor: intentional_contact through mujoco_sim --lockstep and
  task_controller (4 s of simulation), two processes on loopback;
- ros_lockstep_realtime_factor_stack: the same composed in skin_stack (make demo's graph).

usage: bench_graph.py TARGET_DIR OUT_JSON   (other figures already in OUT_JSON are kept)"""
import json
import signal
import subprocess
import sys
import tempfile
from pathlib import Path


def stop(proc):
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def latency(bins: Path) -> dict:
    tc = subprocess.Popen([bins / "task_controller", "--setup", "config/controller/tomm.yaml", "--ros-args",
                           "-p", "trigger:=inputs", "-p", "supervisor:=internal"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        out = subprocess.run([bins / "examples" / "ros_latency", "--periods", "2000"], check=True,
                             capture_output=True, text=True, timeout=300).stdout
    finally:
        stop(tc)
    return json.loads(out.strip().splitlines()[-1])


def lockstep(bins: Path) -> dict:
    setup = "config/controller/planar7.yaml"
    tc = subprocess.Popen([bins / "task_controller", "--setup", setup, "--ros-args", "-p", "trigger:=inputs",
                           "-p", "supervisor:=internal", "-p", "control_rate_hz:=500.0"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            record = Path(tmp) / "graph.json"
            subprocess.run([bins / "mujoco_sim", "--scene", "intentional_contact", "--lockstep", "--duration", "4",
                            "--record", record], check=True, capture_output=True, timeout=300)
            rtf = json.loads(record.read_text())["realtime_factor"]
    finally:
        stop(tc)
    return {"ros_lockstep_realtime_factor": round(rtf, 2)}


def stack(bins: Path) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        record = Path(tmp) / "stack.json"
        subprocess.run([bins / "skin_stack", "--scene", "intentional_contact", "--lockstep", "--internal-supervisor",
                        "--duration", "4", "--record", record], check=True, capture_output=True, timeout=300)
        rtf = json.loads(record.read_text())["realtime_factor"]
    return {"ros_lockstep_realtime_factor_stack": round(rtf, 2)}


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    bins, out = Path(sys.argv[1]), Path(sys.argv[2])
    summary = json.loads(out.read_text()) if out.is_file() else {}
    for name, run in (("latency", latency), ("lockstep", lockstep), ("skin_stack lockstep", stack)):
        figures = run(bins)
        print(f"[bench] graph {name}: {figures}")
        summary.update(figures)
    out.write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
