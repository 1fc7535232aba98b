"""Cold start (issue 16, item 3): how much of a cold `demcheck verify` (the default suite) is numba compilation,
and what `demcheck warmup` buys. Targets: compilation ≤ 25 % of the suite once setup has run the warm-up; a fresh
clone's first run (the warm-up, then the suite, every cache empty: what `make run` does) within 2× of the suite on
compiled kernels with an empty run cache.

Each run is a fresh process with its own empty caches: NUMBA_CACHE_DIR (the kernels; empty = cold), DEMCHECK_CACHE
(the run cache: the engines' runs and the reference's packings) and XDG_CACHE_HOME. Compilation time is the union of
the top-level ``numba:compile`` events (numba's event API) inside the process — with --jobs 1 the cases run there;
on a Dask cluster (--jobs N > 1) the workers compile, out of the listener's sight, and only the process times
count. The runs, in one go:

1. the suite on an empty kernel cache (what a fresh clone without the warm-up paid);
2. `demcheck warmup` on another empty kernel cache (what setup pays once; by default in as many processes as
   the machine has cores, whose compiling the listener does not see: its process time is the measure), then the
   suite on that cache.

Run: .venv/bin/python benchmarks/bench_coldstart.py > benchmarks/results/bench_coldstart.txt (the reference alone,
     one process)
     .venv/bin/python benchmarks/bench_coldstart.py --engines lammps,liggghts,yade,kratos --jobs 2 \
         > benchmarks/results/bench_coldstart_engines.txt (`make run`'s suite)
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

TIMED = r"""
import json, sys, time
from numba.core import event
rec = event.RecordingListener()
event.register("numba:compile", rec)
t0 = time.perf_counter()
from demcheck import cli
code = 0
try:
    cli.main(sys.argv[1:])
except SystemExit as e:
    code = e.code
wall = time.perf_counter() - t0
depth, start, total = 0, 0.0, 0.0
for ts, ev in rec.buffer:
    if ev.is_start:
        start = ts if depth == 0 else start
        depth += 1
    else:
        depth -= 1
        total += (ts - start) if depth == 0 else 0.0
print("BENCH " + json.dumps({"wall": wall, "compile": total, "exit": code}), file=sys.stderr)
"""


def timed(args, tmp: Path, kernels: str, name: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp / kernels), DEMCHECK_CACHE=str(tmp / f"runs-{name}"),
               XDG_CACHE_HOME=str(tmp / f"xdg-{name}"), PYTHONPATH=str(ROOT / "src"))
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", TIMED, *args], cwd=ROOT, env=env, capture_output=True, text=True)
    line = [x for x in p.stderr.splitlines() if x.startswith("BENCH ")][-1]
    return {**json.loads(line[6:]), "process": time.perf_counter() - t}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--engines", default="none", help="verify's --engines (default: none, the reference alone)")
    ap.add_argument("--jobs", default="1", help="verify's --jobs (default 1: in one process, compile events seen)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        suite = ["verify", "--engines", args.engines, "--jobs", args.jobs, "--report", str(tmp / "reports"), "--json"]
        cold = timed(suite, tmp, "kernels-cold", "cold")
        warm_up = timed(["warmup"], tmp, "kernels-warm", "warmup")
        warm = timed(suite, tmp, "kernels-warm", "warm")
    rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    seen = args.jobs == "1"
    print(f"demcheck verify --engines {args.engines} --jobs {args.jobs} (the default suite), fresh processes, every "
          f"cache empty, one run each; git {rev.strip()}, {os.cpu_count()} cores, load average at the end "
          f"{os.getloadavg()[0]:.2f}")
    print(f"{'run':44s} {'process s':>10s} {'compile s':>10s} {'compile %':>10s} exit")
    for label, r, here in (("suite, empty kernel cache (cold)", cold, seen),
                           ("demcheck warmup, empty kernel cache", warm_up, False),
                           ("suite after the warm-up", warm, seen)):
        compiled = f"{r['compile']:10.1f} {100 * r['compile'] / r['process']:9.1f}%" if here else \
            f"{'(workers)':>10s} {'':>10s}"  # (the warm-up compiles in its own processes)
        print(f"{label:44s} {r['process']:10.1f} {compiled} {r['exit']}")
    first = (warm_up["process"] + warm["process"]) / warm["process"]
    if seen:
        share = warm["compile"] / warm["process"]
        print(f"\ncold suite: compilation {100 * cold['compile'] / cold['process']:.0f} % of it; after the warm-up "
              f"{100 * share:.0f} % (target ≤ 25 %: {'met' if share <= 0.25 else 'MISSED'}); the warm-up itself "
              f"{warm_up['process']:.0f} s")
    else:
        extra = cold["process"] - warm["process"]
        print(f"\ncold suite: {extra:.0f} s longer than on compiled kernels ({100 * extra / cold['process']:.0f} % of it: "
              f"the workers' compiling, beside the engines); the warm-up itself {warm_up['process']:.0f} s")
    print(f"a fresh clone's first run (warm-up + suite, every cache empty) / the suite on compiled kernels = {first:.2f} "
          f"(target ≤ 2: {'met' if first <= 2 else 'MISSED'}); without the warm-up, cold / compiled = "
          f"{cold['process'] / warm['process']:.2f}")


if __name__ == "__main__":
    main()
