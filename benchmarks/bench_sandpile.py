"""Ai, Chen, Rotter & Ooi (2011)'s sandpile by the reference (cases/optin/ai2011-sandpile-MODEL.toml,
reference/sandpile.height_curve): its height curve and what the run cost — wall time, particle-steps (each step's
particles present: the batches come in one by one) and particle-steps per second on THREADS threads.

A full run is 2.5 million steps of up to 3000 spheres (~7.4e9 particle-steps): minutes to tens of minutes. A short
``--duration`` (e.g. 1 s: the first five batches falling into the hopper) is a size check of the cost.

Run: .venv/bin/python benchmarks/bench_sandpile.py constant [--duration S] [--threads N] \
         > benchmarks/results/bench_sandpile_constant.txt
(one thread by default: at a few thousand spheres two threads' barriers cost more than they share: 7× the wall
time on a loaded machine; bench_sandpile_MODEL.partial.csv holds each measure as it comes, with the wall time)
The curve (every measure: t, height) goes to benchmarks/results/bench_sandpile_MODEL.csv when the run reaches the
measures' start (10 s); the digitised curves are the validate catalogue's to judge against (docs/benchmarks.md).
"""

import argparse
import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import numpy as np  # noqa: E402

from demcheck import case as C  # noqa: E402
from demcheck.reference import packing as P  # noqa: E402
from demcheck.reference import sandpile as S  # noqa: E402


def particle_steps(case, total: int, dt: float) -> int:
    """Σ over steps of the particles present: each batch from its insertion step to the end."""
    ins = case.packing.insertion
    return sum(ins.batch * max(0, total - P.step_at(b * ins.every, dt)) for b in range(ins.batches))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", choices=["constant", "epsd"])
    parser.add_argument("--duration", type=float, default=None, help="s (default: the case's 50 s)")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    path = ROOT / "src" / "demcheck" / "cases" / "optin" / f"ai2011-sandpile-{args.model}.toml"
    case = C.load(path)
    dt, duration, total = C.packing_run(case, args.duration)
    work = particle_steps(case, total, dt)
    print(f"# bench_sandpile {args.model}: {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, load {os.getloadavg()}")
    print(f"# case {path.relative_to(ROOT)}; {duration:g} s at dt {dt:g} s = {total} steps; {work:.4g} particle-steps;"
          f" {args.threads} thread(s)")
    t0 = time.perf_counter()
    partial = ROOT / "benchmarks" / "results" / f"bench_sandpile_{args.model}.partial.csv"
    with open(partial, "w") as log:  # every measure as it comes: a long run's progress, kept if it is stopped
        log.write("t_s,height_m,wall_s\n")

        def progress(t, h):
            log.write(f"{t:.10g},{h:.10g},{time.perf_counter() - t0:.1f}\n")
            log.flush()

        times, heights = S.height_curve(case, threads=args.threads, duration=args.duration, progress=progress)
    wall = time.perf_counter() - t0
    print(f"wall time {wall:.1f} s (compilation included); {work / wall:.4g} particle-steps/s; "
          f"load after {os.getloadavg()}")
    if len(times):
        out = ROOT / "benchmarks" / "results" / f"bench_sandpile_{args.model}.csv"
        np.savetxt(out, np.column_stack([times, heights]), delimiter=",", header="t_s,height_m", comments="",
                   fmt="%.10g")
        print(f"height: {len(times)} measures from {times[0]:g} to {times[-1]:g} s, first {heights[0]:.4f} m, last "
              f"{heights[-1]:.4f} m, mean over the last half {heights[len(heights) // 2:].mean():.4f} m -> {out.name}")
    else:
        print("height: no measure (the run ends before the measures' start)")


if __name__ == "__main__":
    main()
