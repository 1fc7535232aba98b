"""Building the scaled poured packing (bench_packing_scale.py's case) at N = 2 000 … 128 000 spheres: the case's
load, which checks the initial layout for overlaps (issue 33 item 1's blocker: all pairs, O(N²), before; a k-d tree
past case.PAIRWISE_MAX particles now). This tree, and with --before PATH a tree before the change (its src on
PYTHONPATH, in a child process per N, up to --before-max spheres: the all-pairs check grows as N²), side by side.

Run: .venv/bin/python benchmarks/bench_case_build.py [--before PATH] > benchmarks/results/bench_case_build.txt
"""

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SIZES = (2_000, 8_000, 32_000, 128_000)
CHILD = r"""
import json, sys, time
sys.path.insert(0, sys.argv[2])
import bench_packing_scale as S
t0 = time.perf_counter()
case = S.scaled_case(int(sys.argv[1]), 0.02)
print(json.dumps({"n": len(case.particles), "s": time.perf_counter() - t0}))
"""


def build(src: Path, n: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run([sys.executable, "-c", CHILD, str(n), str(ROOT / "benchmarks")], env=env,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(before: Path | None, before_max: int) -> None:
    load = os.getloadavg()
    print(f"the scaled poured packing's case built (C.load), seconds; load average at the start {load[0]:.2f} "
          f"{load[1]:.2f} {load[2]:.2f} (2 cores, shared)")
    print(f"{'N':>8s} {'after s':>8s}" + (f" {'before s':>9s} {'before/after':>12s}" if before else ""))
    for n in SIZES:
        a = build(ROOT / "src", n)
        assert a["n"] == n
        line = f"{n:8d} {a['s']:8.2f}"
        if before and n <= before_max:
            b = build(before / "src", n)
            line += f" {b['s']:9.2f} {b['s'] / a['s']:12.1f}"
        elif before:
            line += f" {'not run':>9s}"
        print(line, flush=True)
    load = os.getloadavg()
    print(f"load average at the end {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", type=Path)
    ap.add_argument("--before-max", type=int, default=32_000)
    a = ap.parse_args()
    main(a.before, a.before_max)
