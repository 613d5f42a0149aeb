#!/usr/bin/env python3
"""In-process simulation speed of every scenario (issue #5's speed report).

Usage: bench_sim.py RELEASE_DIR SUMMARY_JSON

Runs `skin_sim run <name> --out DIR` (release build, the whole scene at its own rates) for every
scenario of `skin_sim list` and merges into SUMMARY_JSON (created if missing):
- sim_realtime_factor_planar: intentional_contact (the planar arm of intentional-contact paper);
- sim_realtime_factor_tomm: the slowest of the TOMM scenarios (intentional-contact paper Figs. 5-6, interactive-force-control paper);
- sim_realtime_factor_<name>: each scenario;
- sim_physics_bound_<name>: the factor the physics alone allows (simulated time over the time in
  mj_step), and sim_ms_per_s_<part>_<name>: wall milliseconds per simulated second in each part of
  the loop (physics, sensors, controller, other), both from the best run;
- sim_physics_bound_planar and sim_physics_bound_tomm, of the same scenarios as the factors above.
The factor is simulated time over the wall time of the loop (set-up and output writing excluded),
as skin_sim's metrics.json reports it; the best of RUNS runs per scenario (a run lasts 0.4-6 s:
one stall of the machine, or the cold caches of the first run after a build, halved a single
run's figure). Runs are sequential; one line of progress per scenario.
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

PLANAR = "intentional_contact"
RUNS = 3


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    sim, out = Path(sys.argv[1]) / "skin_sim", Path(sys.argv[2])
    names = [line.split()[0] for line in subprocess.run([sim, "list"], check=True, capture_output=True,
                                                         text=True).stdout.splitlines() if line.strip()]
    figures = {}
    with tempfile.TemporaryDirectory() as tmp:
        for k, name in enumerate(names, 1):
            factors, metrics = [], []
            for _ in range(RUNS):
                run = subprocess.run([sim, "run", name, "--out", f"{tmp}/{name}"], capture_output=True, text=True)
                if run.returncode not in (0, 1):  # 1: an outcome check failed, the speed still counts
                    print(run.stdout[-2000:], run.stderr[-2000:], file=sys.stderr)
                    raise SystemExit(f"bench_sim: skin_sim run {name} exited with {run.returncode}")
                metrics.append(json.loads(Path(f"{tmp}/{name}/metrics.json").read_text()))
                factors.append(metrics[-1]["realtime_factor"])
            rtf = max(factors)
            best = metrics[factors.index(rtf)]
            figures[f"sim_realtime_factor_{name}"] = round(rtf, 2)
            figures[f"sim_physics_bound_{name}"] = round(best["realtime_factor_physics_bound"], 2)
            for part, seconds in best["loop_time_s"].items():
                figures[f"sim_ms_per_s_{part.removesuffix('_s')}_{name}"] = round(1e3 * seconds / best["sim_duration_s"], 3)
            runs = ", ".join(f"{f:.1f}" for f in factors)
            print(f"[bench] sim {k}/{len(names)} {name}: realtime factor {rtf:.1f} (best of {runs})", flush=True)
    figures["sim_realtime_factor_planar"] = figures[f"sim_realtime_factor_{PLANAR}"]
    slowest = min((n for n in names if n != PLANAR), key=lambda n: figures[f"sim_realtime_factor_{n}"])
    figures["sim_realtime_factor_tomm"] = figures[f"sim_realtime_factor_{slowest}"]
    figures["sim_physics_bound_planar"] = figures[f"sim_physics_bound_{PLANAR}"]
    figures["sim_physics_bound_tomm"] = figures[f"sim_physics_bound_{slowest}"]
    summary = json.loads(out.read_text()) if out.is_file() else {}
    summary.update(figures)
    out.write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
