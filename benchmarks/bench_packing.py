"""Packing speed: the N-body reference against the engines on the same poured packing, side by side in one run
(issue 16, item 4) — the default suite's 2000 spheres (cases/packing/poured.toml) over the whole pour, in
particle-steps per second:

* the reference on one thread and on two (numba threads over shares of the particles and the Verlet list's
  rows; docs/packing.md),
* LAMMPS on one MPI rank and on two (the mpich wheel's mpiexec, as `demcheck pack --mpi 2`),
* LIGGGHTS and Yade on one core each,

and the issue's targets, each printed as met or MISSED:

* one core: the reference at ≥ 1.0 × the faster engine on one core (LAMMPS or LIGGGHTS);
* two cores: the reference on two threads at ≥ 1.7 × itself on one, LAMMPS's two ranks against its one beside it.

The same initial state, the same model (LSDn + linear spring with sliding friction: exact in LAMMPS and
LIGGGHTS, approximate in Yade, whose spring alone is capped), the same dt and duration. The engines' times
include their start-up (a few tenths of a second); the runs are long enough for it not to matter much.

This machine is shared: the load average is printed with every run. Each source but Yade runs ROUNDS times (the
reference, whose runs are shortest, REFERENCE_ROUNDS),
the sources alternating (the order reversed every other round), and its fastest run counts — the one least
disturbed by other work; every run's time is listed. The ratios are read within this one run.

Run: .venv/bin/python benchmarks/bench_packing.py > benchmarks/results/bench_packing.txt
"""

import os
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from demcheck import case as C  # noqa: E402
from demcheck.comparisons import packing_metrics as PM  # noqa: E402
from demcheck.engines.packing import run_engine  # noqa: E402
from demcheck.reference import packing as P  # noqa: E402

CASE = ROOT / "cases" / "packing" / "poured.toml"
ROUNDS = 3
REFERENCE_ROUNDS = 5  # the reference's runs are the shortest: more of them, for a best run as little disturbed
# (label, source, ranks or threads, rounds)
SOURCES = [("reference, 1 thread", "reference", 1, REFERENCE_ROUNDS),
           ("reference, 2 threads", "reference", 2, REFERENCE_ROUNDS),
           ("lammps, 1 rank", "lammps", 1, ROUNDS),
           ("lammps, 2 MPI ranks", "lammps", 2, ROUNDS),
           ("liggghts, 1 rank", "liggghts", 1, ROUNDS),
           ("yade", "yade", 1, 1)]  # the slowest, and in no target: once
ONE_CORE_TARGET, TWO_CORE_TARGET = 1.0, 1.7


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def _head() -> str:
    def git(*args):
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True).stdout.strip()

    dirty = git("status", "--porcelain", "--untracked-files=no")
    return git("rev-parse", "--short", "HEAD") + (" with uncommitted changes" if dirty else "")


def _run(case, source, cores):
    """(wall s, metrics, version) of one settled pour."""
    t = time.perf_counter()
    if source == "reference":
        st = P.simulate(case, rest=0.0, threads=cores)
        wall = time.perf_counter() - t
        nc = min(st.n_contacts, len(st.contacts))
        return wall, PM.compute(st.x, st.rad, box=case.packing.box, margin=1.0, forces=st.contacts[:nc, 3]), ""
    run = run_engine(case, source, mpi=cores)
    wall = time.perf_counter() - t
    return wall, PM.compute(run.table[["x", "y", "z"]].to_numpy(), run.table["radius"].to_numpy(),
                            box=case.packing.box, margin=1.0, forces=run.contacts["fn"].to_numpy()), run.version


def main():
    import numba

    case = C.load(CASE)
    n = len(case.particles)
    dt = P.packing_dt(case)
    steps = round(case.packing.duration / dt)
    for threads in (1, 2):  # compile (or load) both kernels first
        P.simulate(case, duration=10 * dt, threads=threads)
    print(f"poured packing: {n} spheres, {steps} steps of {dt:.3g} s; {datetime.now(timezone.utc):%d %b %Y %H:%M} "
          f"UTC, git {_head()}; {os.cpu_count()} cores, numba {numba.__version__} ({numba.threading_layer()} layer)")
    print(f"load average (1, 5, 15 min) at the start: {_load()}")
    times = {label: [] for label, *_ in SOURCES}
    loads = {label: [] for label, *_ in SOURCES}
    results = {}
    for k in range(max(rounds for *_, rounds in SOURCES)):
        for label, source, cores, rounds in SOURCES if k % 2 == 0 else SOURCES[::-1]:
            if k < rounds:
                wall, metrics, version = _run(case, source, cores)
                times[label].append(wall)
                loads[label].append(os.getloadavg()[0])
                results[label] = (metrics, version)
    best = {label: min(t) for label, t in times.items()}
    print(f"\n{'source':22s} {'cores':>5s} {'best s':>7s} {'particle-steps/s':>17s} {'solid frac':>10s} {'coord':>6s}"
          "  runs, s [1-min load after each]")
    for label, _, cores, _ in SOURCES:
        metrics = results[label][0]
        runs = " ".join(f"{t:.2f} [{load:.1f}]" for t, load in zip(times[label], loads[label]))
        print(f"{label:22s} {cores:5d} {best[label]:7.2f} {n * steps / best[label]:17.3g} "
              f"{metrics['solid_fraction']:10.4f} {metrics['coordination_number']:6.2f}  {runs}")
    print(f"(engines: {'; '.join(sorted({v for _, v in results.values() if v}))})")
    print(f"load average at the end: {_load()}")

    faster = min(("lammps, 1 rank", "liggghts, 1 rank"), key=best.get)
    one_core = best[faster] / best["reference, 1 thread"]
    two_core = best["reference, 1 thread"] / best["reference, 2 threads"]
    lammps_two = best["lammps, 1 rank"] / best["lammps, 2 MPI ranks"]
    print(f"\none core: the reference at {one_core:.2f} x the faster engine on one core ({faster}); "
          f"target >= {ONE_CORE_TARGET}: {'met' if one_core >= ONE_CORE_TARGET else 'MISSED'}")
    print(f"two cores: the reference on 2 threads at {two_core:.2f} x itself on 1 (LAMMPS on 2 ranks: "
          f"{lammps_two:.2f} x itself on 1); target >= {TWO_CORE_TARGET}: "
          + ("met" if two_core >= TWO_CORE_TARGET else "MISSED"))


if __name__ == "__main__":
    main()
