#!/usr/bin/env python3
"""The ROS graph's figures for out/bench/summary.json, with the release binaries
`scripts/bench` builds:

- ros_latency_p50_us, ros_latency_p99_us: task_controller (TOMM, trigger:=inputs) and the
  ros_latency probe: a 718-cell /skin/cells at 250 Hz to the right arm's command that uses it;
- ros_lockstep_realtime_factor: intentional_contact through mujoco_sim --lockstep and
  task_controller (4 s of simulation), two processes on loopback;
- ros_lockstep_realtime_factor_stack: the same composed in skin_stack (make demo's graph);
- ros_latency_netns_p50_us, ros_latency_netns_p99_us: the latency with task_controller and the
  probe on two "hosts" (network namespaces joined by a veth pair, UDPv4, scripts/netns.py); left
  out, with the reason printed, where namespaces cannot be made (not root).

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


def latency_netns(bins: Path) -> dict:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from netns import TwoHosts, unavailable

    why = unavailable()
    if why:
        print(f"[bench] graph latency across network namespaces left out: {why}")
        return {}
    with TwoHosts() as hosts:
        env = hosts.env()
        tc = subprocess.Popen(hosts.command("b", [bins / "task_controller", "--setup", "config/controller/tomm.yaml",
                                                  "--ros-args", "-p", "trigger:=inputs", "-p", "supervisor:=internal"]),
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            out = subprocess.run(hosts.command("a", [bins / "examples" / "ros_latency", "--periods", "2000"]), env=env,
                                 check=True, capture_output=True, text=True, timeout=300).stdout
        finally:
            stop(tc)
    figures = json.loads(out.strip().splitlines()[-1])
    return {k.replace("ros_latency_", "ros_latency_netns_"): v for k, v in figures.items()}


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
    for name, run in (("latency", latency), ("latency across network namespaces", latency_netns),
                      ("lockstep", lockstep), ("skin_stack lockstep", stack)):
        figures = run(bins)
        print(f"[bench] graph {name}: {figures}")
        summary.update(figures)
    out.write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
