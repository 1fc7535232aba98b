"""An engine collision's marginal cost through a process per run and through the engine's long-lived worker,
against the engine's own loop time, for every engine side by side (issue 16, item 2: engines without start-up).
Target: the worker's engine cost per collision ≤ 10× the engine's loop time.

For each engine and each of its cases (those of CASES it can express), N collisions (impact speeds 0.5 … 2 m/s),
each run once through each path, interleaved point by point (the two paths share the machine's load), in one
process; best of ``--passes`` passes (the pass with the lowest mean). Per collision:

* loop: the engine's own stepping loop (``RunOutput.loop_time`` of the worker's runs): LAMMPS's and LIGGGHTS's
  "Loop time of …" (the loop, dump output included); Yade's script as its worker times it (the loop of O.step()
  and the dump, after a few lines that build the two bodies); Kratos's solution loop as its worker times it
  (the stage's RunSolutionLoop: steps and dump, not the stage's Initialize); summed over the runs of the
  collision (one here: every case's contact ends within its first run);
* engine: ``RunOutput.wall_time`` — for a process, its start to its exit; for the worker, the request sent to
  the answer read;
* collision: ``engines.collide.collide`` + ``metrics()`` (deck, run, dump read, health rules, metrics).

Each worker's start (loading its engine once, a one-off per job) is printed apart: it is not marginal.

Run: .venv/bin/python benchmarks/bench_engine_startup.py > benchmarks/results/bench_engine_startup.txt
"""

import argparse
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ["lammps", "liggghts", "yade", "kratos"]
CASES = ["cases/glass-pair.toml", "cases/oblique-lsd-wall.toml", "cases/hertz-wall.toml"]
TARGET = 10.0  # worker engine cost ≤ 10× loop time


def record_runs() -> list:
    """Every RunOutput engines.run.run returns from now on, appended to the list returned (collide runs its decks
    through that module attribute)."""
    from demcheck.engines import run as runner

    outputs = []
    original = runner.run

    def recording(*args, **kwargs):
        out = original(*args, **kwargs)
        outputs.append(out)
        return out

    runner.run = recording
    return outputs


def one(case, engine: str, worker: bool, workdir: Path, outputs: list) -> tuple[float, float, float]:
    """(collision s, engine s, loop s; NaN where the run reports none) of one collision."""
    from demcheck.engines.collide import collide

    first = len(outputs)
    t = time.perf_counter()
    r = collide(case, engine, workdir=workdir, worker=worker)
    r.metrics()
    total = time.perf_counter() - t
    assert r.status == "ok", r.message
    runs = outputs[first:]
    loops = [o.loop_time for o in runs]
    loop = float("nan") if None in loops else sum(loops)
    out = (total, sum(o.wall_time for o in runs), loop)
    shutil.rmtree(workdir)
    return out


def worker_start(engine: str, case, tmp: Path) -> float:
    """A fresh worker's first run (started, then run) less a warm one's."""
    from demcheck.engines import collide as collisions, run as runner

    deck = collisions.deck(case, engine)
    runner.shutdown_workers()
    spent = []
    for label in ("first", "warm"):
        t = time.perf_counter()
        runner.run(engine, deck.text, files=deck.files, workdir=tmp / f"{engine}-{label}", worker=True)
        spent.append(time.perf_counter() - t)
    return spent[0] - spent[1]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=30, help="collisions per case and path in a pass")
    ap.add_argument("--passes", type=int, default=3)
    ap.add_argument("--engines", default=",".join(ENGINES))
    args = ap.parse_args()

    from demcheck.case import load
    from demcheck.engines import collide as collisions, discovery, run as runner

    engines = [e for e in args.engines.split(",") if e]
    missing = [e for e in engines if discovery.find(e) is None]
    assert not missing, f"not installed: {', '.join(missing)} (make engines)"
    outputs = record_runs()
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    rows, starts, skipped = [], {}, []
    loads = [os.getloadavg()[0]]
    with tempfile.TemporaryDirectory(prefix="bench-engine-startup-") as tmp:
        tmp = Path(tmp)
        for engine in engines:
            for case_path in CASES:
                base = load(ROOT / case_path)
                try:
                    collisions.deck(base, engine)
                except Exception as exc:  # noqa: BLE001 - a case the engine cannot express: named, not run
                    skipped.append(f"{engine} {Path(case_path).stem} ({type(exc).__name__})")
                    continue
                points = [load(ROOT / case_path, [f"impact.speed={float(v)!r}"]) for v in np.linspace(0.5, 2.0, args.n)]
                starts.setdefault(engine, []).append(worker_start(engine, points[0], tmp))
                one(points[0], engine, False, tmp / "warm-process", outputs)
                best = {}
                for _ in range(args.passes):
                    got = {False: [], True: []}
                    for i, case in enumerate(points):
                        for worker in (False, True):
                            got[worker].append(one(case, engine, worker, tmp / f"{i}-{worker}", outputs))
                    for worker, runs in got.items():
                        mean = np.mean(np.array(runs), axis=0)
                        if worker not in best or mean[0] < best[worker][0]:
                            best[worker] = mean
                rows.append((engine, Path(case_path).stem, best))
                loads.append(os.getloadavg()[0])
            runner.shutdown_workers()

    versions = "; ".join(f"{e} {discovery.find(e).version}" for e in engines)
    print(f"Engine collision cost: a process per run against the engine's long-lived worker (HEAD {head.strip()}; "
          f"{versions}; {args.n} collisions per case and path, interleaved, best of {args.passes} passes; load "
          f"average (1 min) {min(loads):.1f}–{max(loads):.1f} during the run on {os.cpu_count()} cores; ms per "
          f"collision)")
    print()
    print(f"{'engine':9s} {'case':18s} {'loop ms':>8s} {'engine: process':>16s} {'worker':>8s} "
          f"{'collision: process':>19s} {'worker':>8s} {'process/loop':>13s} {'worker/loop':>12s} {'speed-up':>9s}")
    verdicts = []
    for engine, name, best in rows:
        proc, work = best[False], best[True]
        loop = work[2]
        print(f"{engine:9s} {name:18s} {loop * 1e3:8.2f} {proc[1] * 1e3:16.1f} {work[1] * 1e3:8.1f} "
              f"{proc[0] * 1e3:19.1f} {work[0] * 1e3:8.1f} {proc[1] / loop:13.1f} {work[1] / loop:12.2f} "
              f"{proc[1] / work[1]:8.1f}×")
        verdicts.append(f"{engine} {name} {work[1] / loop:.2f}× ({'met' if work[1] / loop <= TARGET else 'MISSED'})")
    print()
    print("worker start (once per job, not marginal; median over its cases): "
          + ", ".join(f"{e} {np.median(s) * 1e3:.0f} ms" for e, s in starts.items()))
    if skipped:
        print("not run (the engine cannot express the case): " + ", ".join(skipped))
    print(f"target: worker engine cost per collision ≤ {TARGET:g}× the loop time:")
    for v in verdicts:
        print(f"  {v}")
    print("collision/loop through the worker: "
          + ", ".join(f"{e} {n} {b[True][0] / b[True][2]:.1f}×" for e, n, b in rows))


if __name__ == "__main__":
    main()
