"""Packings at scale (issue 33, item 1): the default suite's poured packing (cases/packing/poured.toml) at
N = 2 000, 8 000, 32 000 and 128 000 spheres — the periodic box scaled laterally (side 30 mm · √(N / 2000): the
same area per sphere, so the same bed height), the same lattice height, the same time step and duration — in every
source side by side:

* on one core: the reference on one thread, LAMMPS on one rank, LIGGGHTS;
* on two: the reference on two threads, LAMMPS on two MPI ranks;

wall time, particle-steps per second, the process's CPU time, peak memory, memory per particle (the slope of the
peak against N, fitted over the sizes: a baseline such as the interpreter's or the engine's own falls out), and
each source's growth exponent (the slope of a least-squares line through log wall time against log N). The issue's
targets are printed, each met or MISSED:

* one core: the reference on one thread ≥ 1.5 × the fastest engine on one core, at every N;
* growth: the reference's exponent ≤ 1.05;
* two cores: the reference on two threads ≥ 1.8 × itself on one, at N ≥ 32 000.

How the runs are made — bench_packing.py's pieces, reused: its ``_run`` (one settled pour, timed around the
solver's call or the engine's whole run, deck writing, start-up and dump reading included, as there), its load
and git-head lines. Each run is a fresh process of this script (``--child``), so that its peak memory is its own
(the reference: the process's peak over its resident size before the pour, i.e. what the solver added; an
engine: the peak of the engine's process, per rank under MPI); the scaled case is built once per N (its load
checks every pair for overlaps) and handed to the children pickled.

This machine is shared (2 cores, other work running): the 1-minute load average is printed with every run,
each source runs once per N, the sources alternate (their order reversed at every other N), and the ratios are
read within this one run. The time budget: the whole pour (0.3 s) at 128 000 spheres in every source would take
hours here, so every source at every N runs the same first DURATION seconds of the pour (a command-line
argument; the default is printed in the header).

Run: .venv/bin/python benchmarks/bench_packing_scale.py [DURATION [N,N…]] > benchmarks/results/bench_packing_scale.txt
(the sizes default to all four)
The memory order alone (the case's order against sorted once by linked cells, one thread, alternating, medians):
     .venv/bin/python benchmarks/bench_packing_scale.py --order DURATION N[,N…] ROUNDS [together]
(``together``: each round's two runs at once, one a core, so that other load slows both alike)
The two-thread goal alone (the reference on 1 and 2 threads, alternating, ROUNDS each, medians):
     .venv/bin/python benchmarks/bench_packing_scale.py --threads DURATION 32000,128000 ROUNDS
"""

import json
import math
import os
import pickle
import resource
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_packing as BP  # noqa: E402  (its ROOT on sys.path, then demcheck)
import numpy as np  # noqa: E402

from demcheck import case as C  # noqa: E402
from demcheck.reference import packing as P  # noqa: E402

SIZES = (2_000, 8_000, 32_000, 128_000)
BASE_N, BASE_SIDE = 2000, 0.03  # poured.toml's count and box side
DURATION = 0.02  # s of the pour: see the module's notes
# (label, source, threads or ranks)
SOURCES = [("reference, 1 thread", "reference", 1),
           ("liggghts, 1 rank", "liggghts", 1),
           ("lammps, 1 rank", "lammps", 1),
           ("reference, 2 threads", "reference", 2),
           ("lammps, 2 MPI ranks", "lammps", 2)]
ONE_CORE, GROWTH, TWO_CORE, TWO_CORE_FROM = 1.5, 1.05, 1.8, 32_000


def scaled_case(n: int, duration: float):
    """poured.toml with n spheres in a box of side 30 mm · √(n / 2000), for ``duration`` seconds."""
    side = BASE_SIDE * math.sqrt(n / BASE_N)
    return C.load(BP.CASE, [f"packing.count={n}", f"packing.box=[{side!r}, {side!r}]",
                            f"packing.duration={duration!r}"])


def pickled_cases(tmp: str, sizes: list[int], duration: float):
    """(n, the path of the scaled case pickled into ``tmp``) for each size, each written when its turn comes."""
    for n in sizes:
        path = Path(tmp) / f"case-{n}.pickle"
        with open(path, "wb") as fh:
            pickle.dump(scaled_case(n, duration), fh)
        yield n, path


def _rss_kb() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024


def child(path: str, source: str, cores: int) -> None:
    """One run (in a process of its own): prints its wall and CPU time, peak memory and metrics as JSON."""
    with open(path, "rb") as fh:
        case = pickle.load(fh)
    if source == "reference":  # load (or compile) the kernel outside the timing, as bench_packing does
        P.simulate(case, duration=10 * P.packing_dt(case), threads=cores)
    before = _rss_kb()
    cpu = time.process_time(), resource.getrusage(resource.RUSAGE_CHILDREN)
    wall, metrics, version = BP._run(case, source, cores)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    if source == "reference":
        cpu_s = time.process_time() - cpu[0]  # (metrics included: a small part)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    else:
        cpu_s = kids.ru_utime + kids.ru_stime - cpu[1].ru_utime - cpu[1].ru_stime
        peak = kids.ru_maxrss
    print(json.dumps({"wall": wall, "cpu": cpu_s, "peak_kb": peak, "version": version,
                      "solid_fraction": metrics["solid_fraction"], "coordination": metrics["coordination_number"]}))


def _one(path: Path, source: str, cores: int) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", str(path), source, str(cores)],
                         capture_output=True, text=True)
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1][:200]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def _fit(xs, ys) -> float:
    """The slope of a least-squares line through (xs, ys)."""
    return float(np.polyfit(np.asarray(xs, float), np.asarray(ys, float), 1)[0])


def _report(results: dict, steps: int) -> None:
    print(f"\n{'source':22s} {'N':>7s} {'wall s':>8s} {'cpu s':>8s} {'particle-steps/s':>17s} {'peak MB':>8s} "
          f"{'solid frac':>10s} {'coord':>6s}")
    for label, _, _ in SOURCES:
        for n in SIZES:
            r = results[label].get(n)
            if r is None or "error" in r:
                print(f"{label:22s} {n:7d}  failed: {r and r['error']}")
                continue
            print(f"{label:22s} {n:7d} {r['wall']:8.2f} {r['cpu']:8.2f} {n * steps / r['wall']:17.3g} "
                  f"{r['peak_kb'] / 1024:8.1f} {r['solid_fraction']:10.4f} {r['coordination']:6.2f}")
    print(f"\n{'source':22s} {'growth exponent':>16s} {'memory B/particle':>18s}   (fits over N = "
          f"{', '.join(map(str, SIZES))})")
    growth = {}
    for label, _, _ in SOURCES:
        ok = [(n, r) for n, r in results[label].items() if "error" not in r]
        if len(ok) < 2:
            continue
        growth[label] = _fit([math.log(n) for n, _ in ok], [math.log(r["wall"]) for _, r in ok])
        by_cpu = _fit([math.log(n) for n, _ in ok], [math.log(r["cpu"]) for _, r in ok])
        mem = _fit([n for n, _ in ok], [r["peak_kb"] * 1024 for _, r in ok])
        print(f"{label:22s} {growth[label]:16.3f} {mem:18.0f}   (by CPU time: {by_cpu:.3f})")
    _targets(results, growth)


def _targets(results: dict, growth: dict) -> None:
    def wall(label, n):
        r = results[label].get(n)
        return r["wall"] if r and "error" not in r else math.nan

    print()
    for n in SIZES:
        engines = {lab: wall(lab, n) for lab in ("liggghts, 1 rank", "lammps, 1 rank")}
        fastest = min(engines, key=lambda k: engines[k] if engines[k] == engines[k] else math.inf)
        ratio = engines[fastest] / wall("reference, 1 thread", n)
        cpu = {lab: results[lab].get(n, {}).get("cpu", math.nan) for lab in (*engines, "reference, 1 thread")}
        by_cpu = min(cpu[lab] for lab in engines) / cpu["reference, 1 thread"]
        line = (f"N = {n:7d}: one core, the reference at {ratio:.2f} x the fastest engine ({fastest}); "
                f"target >= {ONE_CORE}: {'met' if ratio >= ONE_CORE else 'MISSED'} (by CPU time {by_cpu:.2f} x)")
        two = wall("reference, 1 thread", n) / wall("reference, 2 threads", n)
        lammps = wall("lammps, 1 rank", n) / wall("lammps, 2 MPI ranks", n)
        line += f"; two threads at {two:.2f} x one (LAMMPS 2 ranks: {lammps:.2f} x 1)"
        if n >= TWO_CORE_FROM:
            line += f", target >= {TWO_CORE}: {'met' if two >= TWO_CORE else 'MISSED'}"
        print(line)
    g = growth.get("reference, 1 thread", math.nan)
    print(f"growth: the reference (1 thread) as N^{g:.3f}; target <= {GROWTH}: {'met' if g <= GROWTH else 'MISSED'}"
          f" (LIGGGHTS N^{growth.get('liggghts, 1 rank', math.nan):.3f}, LAMMPS "
          f"N^{growth.get('lammps, 1 rank', math.nan):.3f})")


def main(duration: float) -> None:
    import numba

    results = {label: {} for label, _, _ in SOURCES}
    steps = round(duration / P.packing_dt(scaled_case(BASE_N, duration)))
    print(f"poured packing at scale: N = {', '.join(map(str, SIZES))}, box side 30 mm x sqrt(N / 2000), "
          f"{duration:g} s of the pour ({steps} steps) in every source; {datetime.now(timezone.utc):%d %b %Y %H:%M} "
          f"UTC, git {BP._head()}; {os.cpu_count()} cores, numba {numba.__version__}")
    print(f"load average (1, 5, 15 min) at the start: {BP._load()}")
    print(f"\n{'N':>7s}  {'source':22s} {'wall s':>8s} {'cpu s':>8s}  load after", flush=True)
    versions = set()
    with tempfile.TemporaryDirectory() as tmp:
        for k, n in enumerate(SIZES):
            path = Path(tmp) / f"case-{n}.pickle"
            with open(path, "wb") as fh:
                pickle.dump(scaled_case(n, duration), fh)
            for label, source, cores in SOURCES if k % 2 == 0 else SOURCES[::-1]:
                r = _one(path, source, cores)
                results[label][n] = r
                versions.add(r.get("version") or "")
                shown = (f"{r['wall']:8.2f} {r['cpu']:8.2f}" if "error" not in r else f"failed: {r['error']}")
                print(f"{n:7d}  {label:22s} {shown}  {os.getloadavg()[0]:.2f}", flush=True)
    print(f"(engines: {'; '.join(sorted(v for v in versions if v))})")
    print(f"load average at the end: {BP._load()}")
    _report(results, steps)


def _two_at_once(path: Path) -> list[dict]:
    """Two one-thread reference runs started together, one on each core: what the two cores cost each other."""
    procs = [subprocess.Popen([sys.executable, __file__, "--child", str(path), "reference", "1"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate() for p in procs]
    return [json.loads(o.strip().splitlines()[-1]) if p.returncode == 0 else {"error": e.strip()[-200:]}
            for p, (o, e) in zip(procs, outs)]


def threads(duration: float, sizes: list[int], rounds: int) -> None:
    """The two-thread goal alone: the reference on one and on two threads at each size, ``rounds`` times each,
    alternating (1, 2, 2, 1, …), each run a fresh process as in :func:`main`; the median wall time of each and their
    ratio. Two threads meet at a barrier twice a step, so any other process on the two cores stretches their
    waits: the load average is printed with every run, and only a run on an idle machine measures the loop.
    Beside them, two independent one-thread runs at once (one a core): how much the cores slow each other down
    with no barrier and nothing shared but the machine (caches, memory) — the bound that sharing puts on two
    threads."""
    import numba

    print(f"the reference on 1 and 2 threads: the poured packing, {duration:g} s of the pour, N = "
          f"{', '.join(map(str, sizes))}, {rounds} rounds; {datetime.now(timezone.utc):%d %b %Y %H:%M} UTC, git "
          f"{BP._head()}; {os.cpu_count()} cores, numba {numba.__version__}")
    print(f"load average (1, 5, 15 min) at the start: {BP._load()}")
    with tempfile.TemporaryDirectory() as tmp:
        for n, path in pickled_cases(tmp, sizes, duration):
            walls, cpus = {1: [], 2: []}, {1: [], 2: []}
            for k in range(rounds):
                for cores in ((1, 2) if k % 2 == 0 else (2, 1)):
                    r = _one(path, "reference", cores)
                    if "error" in r:
                        print(f"{n:7d}  {cores} thread(s) failed: {r['error']}")
                        continue
                    walls[cores].append(r["wall"])
                    cpus[cores].append(r["cpu"])
                    print(f"{n:7d}  {cores} thread(s) {r['wall']:8.2f} s wall {r['cpu']:8.2f} s cpu  load "
                          f"{os.getloadavg()[0]:.2f}", flush=True)
            together = []
            for _ in range(rounds):
                pair = _two_at_once(path)
                together += [r["cpu"] for r in pair if "error" not in r]
                print(f"{n:7d}  two 1-thread runs at once: " + ", ".join(
                    f"{r['wall']:.2f} s wall {r['cpu']:.2f} s cpu" if "error" not in r else f"failed: {r['error']}"
                    for r in pair) + f"  load {os.getloadavg()[0]:.2f}", flush=True)
            one, two = float(np.median(walls[1])), float(np.median(walls[2]))
            print(f"N = {n:7d}: median 1 thread {one:.2f} s, 2 threads {two:.2f} s: two threads at {one / two:.2f} x "
                  f"one; target >= {TWO_CORE}: {'met' if one / two >= TWO_CORE else 'MISSED'}")
            if together:
                alone = float(np.median(cpus[1]))
                print(f"             one run's CPU alone {alone:.2f} s, beside another {float(np.median(together)):.2f}"
                      f" s: the cores slow each other {float(np.median(together)) / alone:.2f} x; two threads "
                      f"spend {float(np.median(cpus[2])) / alone:.2f} x one thread's CPU")
    print(f"load average at the end: {BP._load()}")


def sorted_case(case):
    """The case with its particles in the engines' memory order (LAMMPS's ``atom_modify sort``: by linked cells —
    slabs along x, in each slab rows up z, each row along y — of side 2 R_max + the reference's skin, 0.3 R_max):
    the same spheres, the same physics, only their order, so a sphere's neighbours sit near it in memory (the case's
    own order is the pour's lattice layer by layer: the spheres below and above a sphere are a layer away). Sorted
    once, at the start: the pour's spheres fall mostly straight down, so their columns stay together."""
    from dataclasses import replace

    cell = 2.3 * max(p.radius for p in case.particles)
    key = [(math.floor(p.position[0] / cell), math.floor(p.position[2] / cell), p.position[1]) for p in case.particles]
    order = sorted(range(len(key)), key=key.__getitem__)
    return replace(case, particles=tuple(case.particles[i] for i in order))


def order(duration: float, sizes: list[int], rounds: int, together: bool = False) -> None:
    """The memory order alone (issue 33 item 2: the engines sort their atoms spatially): the reference on one
    thread, the case's order against the same case sorted once by linked cells (:func:`sorted_case`), alternating,
    ``rounds`` times each, each run a fresh process; medians, wall and CPU, and the packing's metrics (the same
    packing in its statistics: the order changes a pour's last bits, as threads do). ``together``: the two runs of
    a round start at once, one a core — on a machine that other work loads, both then share its load alike."""
    import numba

    print(f"the reference on 1 thread, the case's particle order against sorted by linked cells: the poured packing, "
          f"{duration:g} s of the pour, N = {', '.join(map(str, sizes))}, {rounds} rounds; "
          f"{datetime.now(timezone.utc):%d %b %Y %H:%M} UTC, git {BP._head()}; {os.cpu_count()} cores, numba "
          f"{numba.__version__}")
    print(f"load average (1, 5, 15 min) at the start: {BP._load()}")
    with tempfile.TemporaryDirectory() as tmp:
        for n, path in pickled_cases(tmp, sizes, duration):
            with open(path, "rb") as fh:
                case = pickle.load(fh)
            sorted_path = Path(tmp) / f"case-{n}-sorted.pickle"
            with open(sorted_path, "wb") as fh:
                pickle.dump(sorted_case(case), fh)
            runs = {"case order": [], "sorted": []}
            if together:  # both at once, one a core: whatever else runs on the machine slows both alike
                for _ in range(rounds):
                    procs = {label: subprocess.Popen(
                        [sys.executable, __file__, "--child", str(p), "reference", "1"], stdout=subprocess.PIPE,
                        stderr=subprocess.PIPE, text=True) for label, p in (("case order", path),
                                                                            ("sorted", sorted_path))}
                    for label, proc in procs.items():
                        out, err = proc.communicate()
                        r = (json.loads(out.strip().splitlines()[-1]) if proc.returncode == 0
                             else {"error": err.strip()[-200:]})
                        if "error" in r:
                            print(f"{n:7d}  {label}: failed: {r['error']}")
                            continue
                        runs[label].append(r)
                        print(f"{n:7d}  {label:10s} {r['wall']:8.2f} s wall {r['cpu']:8.2f} s cpu  solid fraction "
                              f"{r['solid_fraction']:.4f}, coordination {r['coordination']:.2f}  (together)  load "
                              f"{os.getloadavg()[0]:.2f}", flush=True)
            for k in range(0 if together else rounds):
                for label in (("case order", "sorted") if k % 2 == 0 else ("sorted", "case order")):
                    r = _one(path if label == "case order" else sorted_path, "reference", 1)
                    if "error" in r:
                        print(f"{n:7d}  {label}: failed: {r['error']}")
                        continue
                    runs[label].append(r)
                    print(f"{n:7d}  {label:10s} {r['wall']:8.2f} s wall {r['cpu']:8.2f} s cpu  solid fraction "
                          f"{r['solid_fraction']:.4f}, coordination {r['coordination']:.2f}  load "
                          f"{os.getloadavg()[0]:.2f}", flush=True)
            if runs["case order"] and runs["sorted"]:
                a = {m: float(np.median([r[m] for r in runs["case order"]])) for m in ("wall", "cpu")}
                b = {m: float(np.median([r[m] for r in runs["sorted"]])) for m in ("wall", "cpu")}
                print(f"N = {n:7d}: median case order {a['wall']:.2f} s wall / {a['cpu']:.2f} s cpu, sorted "
                      f"{b['wall']:.2f} / {b['cpu']:.2f}: sorted at {a['wall'] / b['wall']:.2f} x (wall), "
                      f"{a['cpu'] / b['cpu']:.2f} x (CPU)")
    print(f"load average at the end: {BP._load()}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--order"]:  # --order DURATION N[,N…] ROUNDS
        order(float(sys.argv[2]), [int(x) for x in sys.argv[3].split(",")], int(sys.argv[4]),
              sys.argv[5:6] == ["together"])
    elif sys.argv[1:2] == ["--child"]:
        child(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    elif sys.argv[1:2] == ["--threads"]:  # --threads DURATION N[,N…] ROUNDS
        threads(float(sys.argv[2]), [int(x) for x in sys.argv[3].split(",")], int(sys.argv[4]))
    else:
        if len(sys.argv) > 2:  # DURATION N[,N…]: these sizes only
            SIZES = tuple(int(x) for x in sys.argv[2].split(","))
        main(float(sys.argv[1]) if len(sys.argv) > 1 else DURATION)
