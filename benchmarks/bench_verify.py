"""The default suite's run time: engine-run cache cold, then warm (issue: ≤ 3 min cold, ≤ 15 s warm, on
this 2-core machine, both engines). Each run is the README's main command in a fresh process; the
compiled kernels are already on disk (they are compiled once at install or by the first run).

Run: .venv/bin/python benchmarks/bench_verify.py > benchmarks/results/bench_verify.txt
"""

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMCHECK = [sys.executable, "-m", "demcheck"]


def run(args, env):
    t = time.perf_counter()
    p = subprocess.run(DEMCHECK + args, cwd=ROOT, env=env, capture_output=True, text=True)
    return time.perf_counter() - t, p


def main():
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, DEMCHECK_CACHE=str(Path(tmp) / "engine-runs"))
        report = str(Path(tmp) / "reports")
        # compile (or load) the kernels once, so that neither timed run pays for it
        run(["verify", "cases/glass-pair.toml", "cases/oblique-lsd-wall.toml", "--engines", "none", "--report", report],
            env)
        rows = []
        for label in ("cold (empty engine-run cache)", "warm (every deck cached)"):
            seconds, p = run(["verify", "--jobs", "2", "--report", report, "--json"], env)
            import json

            out = json.loads(p.stdout)
            rows.append((label, seconds, out["wall_time"], len(out["cases"]), out["cache"], p.returncode))
    print("demcheck verify, the default suite (cases/), both engines, --jobs 2")
    print(f"{'run':32s} {'process s':>10s} {'suite s':>8s} {'cases':>6s} {'cache hits/misses':>18s} exit")
    for label, seconds, wall, n, cache, rc in rows:
        print(f"{label:32s} {seconds:10.1f} {wall:8.1f} {n:6d} {cache['hits']:>8d}/{cache['misses']:<9d} {rc}")
    cold, warm = rows[0][1], rows[1][1]
    print(f"\ntargets: cold ≤ 180 s ({'met' if cold <= 180 else 'MISSED'}), warm ≤ 15 s "
          f"({'met' if warm <= 15 else 'MISSED'}); warm/cold = {warm / cold:.2f}")


if __name__ == "__main__":
    main()
