#!/usr/bin/env python3
"""Collects criterion's median estimates into one flat JSON object.

usage: bench_summary.py CRITERION_DIR OUT_JSON

Every benchmark `<group>/<name>` (or `<name>`) becomes the key `<name>_ns` with its median time in
nanoseconds; benchmarks whose id already ends in `_ns` keep it. Other figures already in OUT_JSON
(written by other bench commands) are kept."""
import json
import sys
from pathlib import Path


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    crit, out = Path(sys.argv[1]), Path(sys.argv[2])
    summary = json.loads(out.read_text()) if out.is_file() else {}
    found = 0
    for est in sorted(crit.glob("**/new/estimates.json")):
        bench = json.loads((est.parent / "benchmark.json").read_text())
        name = bench.get("function_id") or bench["group_id"]
        key = name if name.endswith("_ns") else f"{name}_ns"
        summary[key] = round(json.loads(est.read_text())["median"]["point_estimate"], 1)
        found += 1
    if found == 0:
        print(f"bench_summary: no criterion results under {crit}", file=sys.stderr)
        return 1
    out.write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
    print(f"[bench] {found} figures -> {out}")
    for k, v in sorted(summary.items()):
        print(f"  {k:40s} {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
