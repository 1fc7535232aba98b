"""Where a step of the threaded packing loop goes (issue 33, the two-thread goal): the default suite's poured packing
at N spheres (bench_packing_scale.py's scaled case: box side 30 mm · √(N / 2000)), the first DURATION seconds of the
pour, on one thread (reference/packing.py's ``run``) and on two (``run_threaded``), each phase timed inside the loop
(packing.py's clock: ``simulate(..., clock=array)``) by the processor's time-stamp counter (wall time, ~7 ns a
reading) and by the CPU clock of the thread that ran it (~0.6 µs a reading; a few readings a step):

* the force region: each share's launch (the region's start to the share's start), work (its contacts' forces)
  and wait (its end to the region's end: the barrier and the other share's lag);
* the kick region likewise, its work split into the far buffers' gather and the kick-and-drift;
* the calling thread's serial parts: the neighbour-list rebuilds (threaded inside on two threads), what follows a
  rebuild (positions kept, shares cut again, far ends), the recut every 50 steps, the rest (the energy's sum, the
  displacement test, the loop).

Three configurations (CONFIGS, as shares/threads): one thread (1/1); the threaded loop's two shares run one after
the other on one thread (2/1: what cutting the work costs — far buffers, gather, recuts, the threaded rebuild —
with nothing running concurrently); two threads (2/2: that, and what running concurrently costs — the regions'
launches and barriers, the shares' imbalance, the cores' contention). Each (N, configuration) runs in a fresh
process (compiled first, outside the timing), twice: untimed (its wall and CPU time, as bench_packing_scale.py
--threads measures) and timed (the phases, in microseconds a step; the timed run's wall time against the untimed
one's is the clock's own cost). The counter's rate is calibrated against the timed run's wall time. The
configurations alternate, ROUNDS each; the tables give the medians.

This machine is shared: the load average is printed with every run. Under load the CPU columns of one-thread runs
(1/1, 2/1) still measure the work; wall times, and anything of a two-thread run (its threads wait for each other at
every region's end, so another process taking a core stretches every wait), are meaningful only on an idle machine
(load < 1).

Run (about 1 minute a round on an idle machine at the default sizes):

    .venv/bin/python benchmarks/bench_packing_phases.py [DURATION [N,N… [ROUNDS [CONFIGS]]]] \
        > benchmarks/results/bench_packing_phases.txt

defaults DURATION = 0.02 s (the scale benchmark's), N = 32000,128000, ROUNDS = 2, CONFIGS = 1/1,2/1,2/2 (shares /
numba threads: one thread; two shares run one after the other on one thread — what cutting the work costs, with
nothing concurrent, meaningful under load; two threads — meaningful on an idle machine only). On an idle machine:

    .venv/bin/python benchmarks/bench_packing_phases.py 0.02 32000,128000 2 > benchmarks/results/bench_packing_phases_idle.txt

The engine's own breakdown of the same case on one rank (its log's Pair / Neigh / Other lines, per step), which
the one-core goal's limit is read against:

    .venv/bin/python benchmarks/bench_packing_phases.py --engine N DURATION [liggghts|lammps] >> …

Its timers are wall time, where the reference's phases are its thread's CPU time: beside them the mode prints the
engine process's own CPU time (user + sys, from getrusage(RUSAGE_CHILDREN) around the run: the process is this
script's child, reaped by engines/run.py) against the process's wall time, and each timer scaled by the loop's CPU /
wall ratio — an approximation: that ratio is not measured over the loop alone, only bounded (low: the process's CPU
less its wall time outside the loop, as if the rest had a whole core; high: all its CPU in the loop), and the phases
are taken to share it alike — so that a µs a step of both sources can be read in CPU time.

The two-thread speed-up alone, idle: bench_packing_scale.py --threads 0.02 32000,128000 3. The force cut's
weights (packing.py's ROW_COST …) from a fit of the force loop's CPU time by parts, on one thread:

    .venv/bin/python benchmarks/bench_packing_phases.py --fit 32000 0.02 >> benchmarks/results/bench_packing_phases.txt
"""

import json
import math
import os
import pickle
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_packing as BP  # noqa: E402  (its ROOT on sys.path, then demcheck)
import bench_packing_scale as BS  # noqa: E402
import numpy as np  # noqa: E402

from demcheck.reference import packing as P  # noqa: E402

ROUNDS, SIZES = 2, (32_000, 128_000)
SHARE = [("force: launch", P.F_LAUNCH), ("force: work", P.F_WORK), ("force: wait", P.F_WAIT),
         ("kick: launch", P.K_LAUNCH), ("kick: gather", P.K_GATHER), ("kick: work", P.K_WORK),
         ("kick: wait", P.K_WAIT)]
SERIAL = [("rebuilds", P.S_REBUILD), ("after a rebuild", P.S_AFTER), ("recut / 50 steps", P.S_BALANCE),
          ("serial rest", P.S_OTHER)]


def child(path: str, threads: int, cores: int) -> None:
    """One size, ``threads`` shares on ``cores`` of numba's threads, untimed then timed: prints JSON (walls, CPU,
    steps, phases in µs a step). Two shares on one thread: numba's thread count held at one (advance's setting it
    to the shares' number disabled), so that the parallel regions run their two shares one after the other on the
    calling thread — the threaded loop's work with no second thread: what cutting the work costs, apart from what
    running it concurrently costs."""
    import numba

    with open(path, "rb") as fh:
        case = pickle.load(fh)
    if cores < threads:
        numba.set_num_threads(cores)
        numba.set_num_threads = lambda n: None
    dt = P.packing_dt(case)
    P.simulate(case, duration=10 * dt, threads=threads, clock=np.zeros((threads + 1, 2 * P.PHASES)))  # compile
    cpu, t = time.process_time(), time.perf_counter()
    st = P.simulate(case, threads=threads)
    wall, cpu = time.perf_counter() - t, time.process_time() - cpu
    steps = round(st.time / dt)
    clock = np.zeros((threads + 1, 2 * P.PHASES))
    ticks, t = P.clock_ticks(), time.perf_counter()
    P.simulate(case, threads=threads, clock=clock)
    timed = time.perf_counter() - t
    hz = (P.clock_ticks() - ticks) / timed
    us = clock[:, :P.PHASES] / hz / steps * 1e6  # wall
    us[-1, P.S_REBUILDS] = clock[-1, P.S_REBUILDS]  # a count
    cpu_us = clock[:, P.PHASES:] / 1e3 / steps
    print(json.dumps({"wall": wall, "cpu": cpu, "timed": timed, "steps": steps, "ghz": hz / 1e9,
                      "us": us.tolist(), "cpu_us": cpu_us.tolist()}))


def _one(path: Path, threads: int, cores: int) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", str(path), str(threads), str(cores)],
                         capture_output=True, text=True)
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1][:200]}
    return json.loads(out.stdout.strip().splitlines()[-1])


# (label, shares, numba threads)
CONFIGS = [("1 thread", 1, 1), ("2 shares, 1 thread", 2, 1), ("2 threads", 2, 2)]
WORK = [P.F_WORK, P.K_GATHER, P.K_WORK]


def _table(n: int, runs: dict) -> None:
    """The medians of each phase (µs a step), wall and CPU, per configuration and share."""
    med = {k: np.median([r["us"] for r in rs], axis=0) for k, rs in runs.items() if rs}
    cpu = {k: np.median([r["cpu_us"] for r in rs], axis=0) for k, rs in runs.items() if rs}
    steps = next(rs for rs in runs.values() if rs)[0]["steps"]
    print(f"\nN = {n}: µs a step, wall (the counter) / CPU of the thread that ran it (medians; {steps} steps; a "
          f"region's launch and wait span two threads: no CPU)")
    print(f"  {'phase':18s} " + " ".join(f"{label:>16s}" + ("" if shares == 1 else f" {'(share 1)':>15s}")
                                         for label, shares, _ in CONFIGS if label in med))
    for label, k in SHARE + SERIAL:
        row = -1 if k >= P.S_REBUILD else 0
        cells = []
        for cfg, shares, _ in CONFIGS:
            if cfg in med:
                cells.append(f"{med[cfg][row, k]:8.1f} / {cpu[cfg][row, k]:5.1f}")
                if shares > 1:
                    cells.append(f"{med[cfg][1, k]:7.1f} / {cpu[cfg][1, k]:5.1f}" if row == 0 else " " * 15)
        print(f"  {label:18s} " + " ".join(cells))
    print(f"  {'rebuilds (count)':18s} " + " ".join(f"{med[c][-1, P.S_REBUILDS]:16.0f}" + ("" if s == 1 else " " * 16)
                                                    for c, s, _ in CONFIGS if c in med))
    for cfg, shares, cores in CONFIGS:
        if cfg not in med:
            continue
        wall_cfg = float(np.median([r["wall"] for r in runs[cfg]]))
        work = float(cpu[cfg][:shares, WORK].sum() + cpu[cfg][-1, P.S_REBUILD:P.S_REBUILDS].sum())
        print(f"  {cfg:18s}: untimed {wall_cfg:6.2f} s wall ({wall_cfg / steps * 1e6:7.1f} µs a step), "
              f"{float(np.median([r['cpu'] for r in runs[cfg]])):6.2f} s CPU (spinning included); timed "
              f"{float(np.median([r['timed'] for r in runs[cfg]])):6.2f} s; CPU of the work and the serial phases "
              f"{work:7.1f} µs a step (force {cpu[cfg][:shares, P.F_WORK].sum():6.1f}, kick and gather "
              f"{cpu[cfg][:shares, [P.K_GATHER, P.K_WORK]].sum():6.1f}, rebuilds {cpu[cfg][-1, P.S_REBUILD]:5.1f})")
    if "1 thread" in med and "2 threads" in med:
        _excess(med["1 thread"], med["2 threads"])


def _excess(one: np.ndarray, two: np.ndarray) -> None:
    """The two-thread step against half the one-thread step, phase by phase (wall: the counter)."""
    t1 = float(one[-1, :P.S_REBUILDS].sum() + one[0, :P.S_REBUILD].sum())
    t2 = float(two[-1, :P.S_REBUILDS].sum() + two[0, :P.S_REBUILD].sum())
    kick = two[:2, P.K_WORK] + two[:2, P.K_GATHER]
    region = {"force": (two[:2, P.F_LAUNCH] + two[:2, P.F_WORK] + two[:2, P.F_WAIT]).mean(),
              "kick": (two[:2, P.K_LAUNCH] + kick + two[:2, P.K_WAIT]).mean()}
    parts = [
        ("force work beyond half (split cost)", two[:2, P.F_WORK].mean() - one[0, P.F_WORK] / 2),
        ("force imbalance (max - mean work)", two[:2, P.F_WORK].max() - two[:2, P.F_WORK].mean()),
        ("force launch + barrier", region["force"] - two[:2, P.F_WORK].max()),
        ("kick and gather beyond half", kick.mean() - one[0, P.K_WORK] / 2),
        ("kick imbalance", kick.max() - kick.mean()),
        ("kick launch + barrier", region["kick"] - kick.max()),
        ("rebuilds beyond half", two[-1, P.S_REBUILD] - one[-1, P.S_REBUILD] / 2),
        ("serial: after a rebuild, recut, rest", sum(two[-1, k] - one[-1, k] / 2
                                                     for k in (P.S_AFTER, P.S_BALANCE, P.S_OTHER))),
    ]
    print(f"  two threads' step {t2:.1f} µs (wall) against half of one's {t1 / 2:.1f}: {t2 - t1 / 2:+.1f} µs "
          f"({t1 / t2:.2f} x by the counter), of which")
    for label, v in parts:
        print(f"    {label:38s} {v:+8.1f} µs  ({100 * v / t2:+5.1f} % of the two-thread step)")


def fit(n: int, duration: float) -> None:
    """The force loop's cost by parts, for the force cut's weights (packing.py's ROW_COST …): the pour of n spheres
    run ``duration`` on one thread, then the force loop over blocks of 1/32 of the rows (each the best of 7 runs of
    its CPU time, on copies of the contact states), and a least-squares fit of the blocks' times against their rows,
    list entries, touching pairs and wall contacts."""
    from demcheck.reference.collision3d import rules_array

    case = BS.scaled_case(n, duration)
    st = P.simulate(case, threads=1)
    sp, laws_n, laws_t, wall_n, wall_t = P.resolve_laws(case)
    walls = np.array([[*w.point, *w.normal] for w in case.walls], float).reshape(-1, 6)
    lo, hi, periodic = P.box_of(case, st.x, st.rad)
    table = P.law_table(laws_n, laws_t, wall_n, wall_t)
    n_w, f, tq = walls.shape[0], np.zeros((n, 3)), np.zeros((n, 3))
    blocks = np.linspace(0, n, 33).astype(np.int64)
    rows, times = [], []
    for a, e in zip(blocks[:-1], blocks[1:]):
        hist, dmax = st.hist.copy(), st.dmax.copy()
        best = math.inf
        for _ in range(7):
            t = time.thread_time()
            P._contact_forces(a, e, st.x, st.v, st.w, st.rad, sp, laws_n.shape[0], *table, walls,
                              P._period(lo, hi, periodic), st.start, st.nbj, hist, dmax, f, tq, f, tq,
                              np.zeros((0, 3)), 1e-6, np.bool_(True), rules_array(None), *P.NO_ROLLING)
            best = min(best, time.thread_time() - t)
        base = n * n_w + st.start[a], n * n_w + st.start[e]
        rows.append([e - a, st.start[e] - st.start[a], int((dmax[base[0]:base[1]] != 0).sum()),
                     int((dmax[a * n_w:e * n_w] != 0).sum())])
        times.append(best)
    coef = np.linalg.lstsq(np.array(rows, float), np.array(times), rcond=None)[0] * 1e9
    worst = np.abs(np.array(rows, float) @ coef / 1e9 / np.array(times) - 1).max()
    print(f"the force loop by parts: the pour of {n} spheres at {duration:g} s, 32 blocks of rows, {n_w} wall(s); "
          f"load {BP._load()}")
    print(f"  ns a row {coef[0]:.2f}, a list entry {coef[1]:.2f}, a touching pair {coef[2]:.2f}, a wall contact "
          f"{coef[3]:.2f} (in entries: row {coef[0] / coef[1]:.1f}, pair {coef[2] / coef[1]:.1f}, wall contact "
          f"{coef[3] / coef[1]:.1f}); the fit's worst block {100 * worst:.0f} % off")


def main(duration: float, sizes: list[int], rounds: int, configs: list[str]) -> None:
    import numba

    print(f"the packing loop's phases on 1 and 2 threads: the poured packing, {duration:g} s of the pour, N = "
          f"{', '.join(map(str, sizes))}, {rounds} rounds; {datetime.now(timezone.utc):%d %b %Y %H:%M} UTC, git "
          f"{BP._head()}; {os.cpu_count()} cores, numba {numba.__version__}, threading layer: OpenMP first")
    print(f"load average (1, 5, 15 min) at the start: {BP._load()}")
    with tempfile.TemporaryDirectory() as tmp:
        for n, path in BS.pickled_cases(tmp, sizes, duration):
            runs = {label: [] for label, _, _ in CONFIGS}
            chosen = [c for c in CONFIGS if f"{c[1]}/{c[2]}" in configs]
            for k in range(rounds):
                for label, shares, cores in chosen if k % 2 == 0 else chosen[::-1]:
                    r = _one(path, shares, cores)
                    if "error" in r:
                        print(f"{n:7d}  {label}: failed: {r['error']}")
                        continue
                    runs[label].append(r)
                    print(f"{n:7d}  {label:18s} untimed {r['wall']:7.2f} s wall {r['cpu']:7.2f} s cpu, timed "
                          f"{r['timed']:7.2f} s ({r['ghz']:.3f} GHz counter)  load {os.getloadavg()[0]:.2f}",
                          flush=True)
            _table(n, runs)
    print(f"\nload average at the end: {BP._load()}")


ENGINE_PHASES = ("Pair", "Neigh", "Comm", "Modify", "Outpt", "Other")


def engine(n: int, duration: float, name: str = "liggghts") -> None:
    """The engine's own timing breakdown of the same scaled case on one rank (its log's "Loop time" and
    "<phase> time (%)" lines, and its neighbour-list builds), per step, beside which the reference's phases above
    are read: what the one-core goal's limit is measured against (bench_packing_scale.py's engine run, its work
    directory kept until its log is read)."""
    import re
    import resource
    import shutil

    from demcheck.engines import discovery, run as runner
    from demcheck.engines.packing import run_engine

    case = BS.scaled_case(n, duration)
    steps = round(duration / P.packing_dt(case))
    work = Path(tempfile.mkdtemp(prefix="phases-engine-"))
    discovery.require(name)  # any probe of the executable before the CPU baseline below
    outs, plain_run = [], runner.run

    def kept_run(*args, **kwargs):  # run_engine's engines/run.run, its RunOutput kept (the process's own wall time)
        outs.append(plain_run(*args, **kwargs))
        return outs[-1]

    runner.run = kept_run
    try:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        run_engine(case, name, mpi=1, workdir=work)
        wall = time.perf_counter() - t
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        log = (work / "log.txt").read_text(errors="replace")
    finally:
        runner.run = plain_run
        shutil.rmtree(work, ignore_errors=True)
    user, system = after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime
    process_wall = outs[-1].wall_time if outs else math.nan
    loop = re.search(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms", log)
    if loop is None:
        print(f"{n:7d}  {name}: no 'Loop time' line in its log (load {os.getloadavg()[0]:.2f})")
        return
    seconds, nsteps = float(loop.group(1)), int(loop.group(3))
    builds = re.search(r"Neighbor list builds = (\d+)", log)
    print(f"\n{name} on 1 rank, the same case (N = {n}, {duration} s of the pour, {nsteps} steps; the reference's "
          f"{steps}): loop {seconds:.2f} s, {wall:.2f} s of wall in all, "
          f"{builds.group(1) if builds else '?'} neighbour-list builds; load {os.getloadavg()[0]:.2f}")
    print(f"  {'phase':8s} {'s':>9s} {'%':>6s} {'us a step':>10s}")
    for phase in ENGINE_PHASES:
        m = re.search(rf"^{phase}\s+time \(%\) = (\S+) \((\S+)\)", log, re.M)
        if m:
            print(f"  {phase:8s} {float(m.group(1)):9.3f} {float(m.group(2)):6.1f} "
                  f"{1e6 * float(m.group(1)) / nsteps:10.1f}")
    print(f"  the one-core goal (the reference >= 1.5 x this loop): the reference's whole step must be <= "
          f"{1e6 * seconds / nsteps / 1.5:.1f} us")
    cpu = user + system
    ratio = cpu / process_wall
    # the loop's share of the process's CPU: at most all of it (and at most its wall time), at least what is left
    # after the rest of the process (its wall time outside the loop) had a whole core
    low = max(0.0, cpu - (process_wall - seconds)) / seconds
    high = min(cpu, seconds) / seconds
    print(f"  the engine process's own CPU time (getrusage of the child, user + sys): {cpu:.2f} s ({user:.2f} + "
          f"{system:.2f}) over {process_wall:.2f} s of its wall time (start to exit; its loop {seconds:.2f} s of "
          f"it): CPU / wall {ratio:.3f}; {1e6 * cpu / nsteps:.1f} us of CPU a step over the whole process (an upper "
          f"bound of the loop's)")
    print(f"  its timers in CPU time, an APPROXIMATION: each timer x the loop's CPU / wall ratio, which is not measured "
          f"over the loop alone but bounded, {low:.3f} to {high:.3f} (low: the process's CPU less its wall time "
          f"outside the loop; high: all its CPU in the loop); the phases assumed to share that ratio alike")
    print(f"  {'phase':8s} {'us CPU a step, low':>19s} {'high':>8s}")
    for phase in ENGINE_PHASES:
        m = re.search(rf"^{phase}\s+time \(%\) = (\S+) \((\S+)\)", log, re.M)
        if m:
            us = 1e6 * float(m.group(1)) / nsteps
            print(f"  {phase:8s} {low * us:19.1f} {high * us:8.1f}")
    us = 1e6 * seconds / nsteps
    print(f"  {'loop':8s} {low * us:19.1f} {high * us:8.1f}   (the one-core goal in CPU time: the reference's whole "
          f"step, its thread's CPU, <= {low * us / 1.5:.1f} to {high * us / 1.5:.1f} us)")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--engine"]:  # --engine N DURATION [NAME]
        engine(int(sys.argv[2]), float(sys.argv[3]), sys.argv[4] if len(sys.argv) > 4 else "liggghts")
    elif sys.argv[1:2] == ["--child"]:
        child(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    elif sys.argv[1:2] == ["--fit"]:  # --fit N DURATION
        fit(int(sys.argv[2]), float(sys.argv[3]))
    else:
        a = sys.argv[1:]
        main(float(a[0]) if a else BS.DURATION, [int(x) for x in a[1].split(",")] if len(a) > 1 else list(SIZES),
             int(a[2]) if len(a) > 2 else ROUNDS, a[3].split(",") if len(a) > 3 else ["1/1", "2/1", "2/2"])
