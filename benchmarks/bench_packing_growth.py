"""What grows with N in the poured packing at scale (issue 33 item 2, the growth goal: the reference's run time as
N^≤1.05): bench_packing_scale.py's scaled case (box side 30 mm · √(N / 2000), the same bed height and duration) at
each N, the reference on one thread and LIGGGHTS on one rank, with the work each did counted beside its time:

* the time: wall and CPU. The machine's 2 cores are shared, so **CPU time is the measure** (the reference: its
  process's CPU over ``simulate``; LIGGGHTS: the user + sys of its process, from os.wait4, read_data to exit);
* the steps, the time-averaged touching pair contacts a sphere (each pair once; the reference also its wall
  contacts a sphere), the time-averaged neighbour-list entries a sphere and the list builds;
* the cost: CPU ns a sphere-step, a pair-contact-step and a list-entry-step;
* then the growth exponent of each (the slope of a least-squares line through log y against log N): of the time,
  of the contacts and list entries a sphere, and of the cost per sphere-, contact- and entry-step. If the cost per
  contact-step (or per entry-step) is flat in N while the time grows faster than N, the growth is the case's
  contact count (its work), not the solver's cost per unit of work.

How the counts are taken (nothing in src/ changed; the reference's loop exposes no time series of its counts):

* the reference, in a process of its own per N (compiled first, outside the timing), runs twice. First untimed,
  exactly as bench_packing_scale.py's one-thread run (``simulate(case, threads=1)``): the wall and CPU time. Then
  counted: the same case with the loop's clock (``clock=``, the phases' counter: its rebuild count) and an
  observation every OBSERVE steps (``observe=``, the run cut into chunks of OBSERVE steps), each observation
  reading the state the loop hands back: touching pairs (a list entry whose largest overlap is non-zero — the
  loop zeroes it when a contact ends), touching wall rows, and list entries (``start[-1]``: each pair j > i once).
  The averages are the trapezoid over those samples (every OBSERVE steps and the last step; the start has no
  list yet). The counted
  run is not the untimed run's trajectory to the bit: each chunk starts with a list build (``advance``'s setup),
  so it builds its list (steps / OBSERVE) times more and its later in-loop rebuilds fall elsewhere — its rebuild
  count is given as in-loop + at chunk starts. A pour is chaotic: the counted run is the same pour in its
  statistics, not particle by particle.
* LIGGGHTS runs its own deck (engines/liggghts/packing.py's, as bench_packing_scale.py runs it), written by this
  script with two changes for the counts: a ``compute contact/atom`` summed by ``compute reduce`` in its thermo
  output (evaluated at the thermo steps only: 50 in the run), and its ``run N`` cut into SEGMENTS runs with
  ``pre no`` (no list build at a segment's start; its setup computes the forces once without updating the
  contact histories), each ending with the engine's neighbour-list statistics ("Total # of neighbors", builds):
  the list entries are sampled at the segments' ends, the builds are the last segment's count (cumulative over
  segments run with ``pre no``: 69 in all at 2 000 spheres, as the plain deck's one run, checked once by hand) (LIGGGHTS's list is half, newton off: a pair across the
  periodic boundary is listed from both sides). Its loop time is the sum of the segments' "Loop time". Run as
  engines/run.py runs an engine (its environment: one thread), as a child of this script, its CPU from os.wait4.
  Its list's reach is 2 R + 0.5 R (the deck's skin), the reference's 2 R + 0.3 R.

Each N runs the reference, then LIGGGHTS, sizes in increasing order, a row printed as each finishes with the
1-minute load average.

Run (about 12 minutes at the default sizes on an idle machine, two thirds of it at 128 000 spheres):

    .venv/bin/python benchmarks/bench_packing_growth.py [N,N… [DURATION [reference|liggghts|both [ROUNDS]]]] \\
        > benchmarks/results/bench_packing_growth.txt

defaults N = 2000,8000,32000,128000, DURATION = 0.1 s (issue 33's table), both sources, ROUNDS = 1: the sizes up to
REPEAT_UP_TO run ROUNDS times (the reference's untimed run repeated in its process; LIGGGHTS's whole run), the least
CPU time kept — under load the small sizes' times spread most, and they weigh as much in the fit.

Besides the costs per sphere-, contact- and entry-step, the reference's cost per work unit-step: its force loop's
own cost model (packing.py's force-cut weights, in list entries: a row ROW_COST + WALL_TEST_COST a wall, an entry
1, a touching pair PAIR_COST, a wall contact WALL_COST) applied to the time-averaged counts.
"""

import json
import math
import os
import pickle
import re
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

SIZES = (2_000, 8_000, 32_000, 128_000)
DURATION = 0.1  # s of the pour: issue 33's table
REPEAT_UP_TO = 32_000  # sizes repeated ``rounds`` times (cheap; the small sizes' times spread most under load)
OBSERVE = 500  # steps between two counts of the reference's counted run
SEGMENTS = 10  # LIGGGHTS's run cut into this many, each ending with its list statistics


def trapezoid_mean(steps, values) -> float:
    """The time average of a quantity sampled at ``steps`` (increasing), by the trapezoid rule."""
    s, v = np.asarray(steps, float), np.asarray(values, float)
    if len(s) < 2 or s[-1] == s[0]:
        return float(v.mean())
    return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(s)) / (s[-1] - s[0]))


def counts(st, n_walls: int) -> tuple[int, int, int]:
    """(touching pairs, touching wall rows, list entries) of a packing state as the loop hands it back: a contact's
    largest overlap ``dmax`` is non-zero while it touches (the loop zeroes it when the contact ends); particle i's
    rows with the walls first (n · n_walls), then one per list entry."""
    n = len(st.x)
    base = n * n_walls
    return int(np.count_nonzero(st.dmax[base:])), int(np.count_nonzero(st.dmax[:base])), int(st.start[-1])


# the counted run's phases read off the loop's clock (row, column): the force loop, the kick and drift pass, the
# in-loop list rebuilds, the rest (the loop, the displacement test, after a rebuild)
PHASE_CPU = [("force", 0, P.F_WORK), ("kick", 0, P.K_WORK), ("rebuilds", -1, P.S_REBUILD), ("rest", -1, P.S_OTHER)]


def child(path: str, rounds: int = 1) -> None:
    """One size, the reference on one thread: untimed (wall, CPU; ``rounds`` times, the least CPU time kept), then
    counted (module notes). Prints JSON."""
    with open(path, "rb") as fh:
        case = pickle.load(fh)
    dt = P.packing_dt(case)
    P.simulate(case, duration=10 * dt, threads=1)  # compile (or load) outside the timing
    timings = []
    for _ in range(rounds):
        cpu, t = time.process_time(), time.perf_counter()
        st = P.simulate(case, threads=1)
        timings.append((time.process_time() - cpu, time.perf_counter() - t))
    cpu, wall = min(timings)
    steps = st.steps
    n_walls = len(case.walls)
    samples = []
    clock = np.zeros((2, 2 * P.PHASES))
    cpu2, t = time.process_time(), time.perf_counter()
    st2 = P.simulate(case, threads=1, clock=clock, chunk=OBSERVE,
                     observe=(list(range(OBSERVE, steps + 1, OBSERVE)) + [steps],
                              lambda s: samples.append((s.steps, *counts(s, n_walls)))))
    wall2, cpu2 = time.perf_counter() - t, time.process_time() - cpu2
    k = np.array(samples, float)
    print(json.dumps({"wall": wall, "cpu": cpu, "rounds": [list(x) for x in timings], "steps": steps,
                      "rows": len(case.particles) * (P.ROW_COST + P.WALL_TEST_COST * n_walls), "counted_wall": wall2, "counted_cpu": cpu2,
                      "pairs": trapezoid_mean(k[:, 0], k[:, 1]), "walls": trapezoid_mean(k[:, 0], k[:, 2]),
                      "entries": trapezoid_mean(k[:, 0], k[:, 3]), "pairs_end": int(k[-1, 1]),
                      "entries_start": int(k[0, 3]), "entries_end": int(k[-1, 3]),
                      "rebuilds": int(clock[-1, P.S_REBUILDS]), "chunk_builds": math.ceil(st2.steps / OBSERVE),
                      "samples": len(samples), "end_pairs_untimed": int(st.n_contacts),
                      # the counted run's phases, its thread's CPU ns a step (the loop's clock)
                      "phases": {name: float(clock[row, P.PHASES + k]) / steps for name, row, k in PHASE_CPU}}))


def _reference(path: Path, rounds: int) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", str(path), str(rounds)], capture_output=True, text=True)
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1][:200]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def liggghts_deck(case) -> tuple[str, dict, int]:
    """The LIGGGHTS packing deck of ``case`` with the two changes the counts need (module notes): (text, files, its
    steps)."""
    from demcheck.engines import registry

    dk = registry.get("liggghts").packing_deck(case, None, None)
    lines = dk.text.split("\n")
    i = lines.index("thermo_style custom step ke atoms")
    lines[i:i + 1] = ["compute growth_nc all contact/atom", "compute growth_ncsum all reduce sum c_growth_nc",
                      "thermo_style custom step ke atoms c_growth_ncsum"]
    runs = [k for k, line in enumerate(lines) if re.fullmatch(r"run \d+", line) and line != "run 0"]
    assert len(runs) == 1, runs
    steps = int(lines[runs[0]].split()[1])
    cuts = np.linspace(0, steps, SEGMENTS + 1).round().astype(int)
    lines[runs[0]:runs[0] + 1] = [f"run {b - a}" + (" pre no" if k else "")
                                  for k, (a, b) in enumerate(zip(cuts[:-1], cuts[1:]))]
    return "\n".join(lines), dk.files, steps


def liggghts(case) -> dict:
    """LIGGGHTS on one rank with the counting deck: its process's wall and CPU (os.wait4), loop time, contacts
    (thermo, c_growth_ncsum: a contact counted at both its atoms), list entries and builds (each segment's end)."""
    import shutil

    from demcheck.engines import discovery, registry

    info = discovery.require("liggghts")
    text, files, steps = liggghts_deck(case)
    wd = Path(tempfile.mkdtemp(prefix="growth-liggghts-"))
    try:
        for name, body in {"in.deck": text, **files}.items():
            (wd / name).write_text(body)
        argv = registry.get("liggghts").argv(info.executable, "in.deck")
        with open(wd / "output.txt", "wb") as out:
            t = time.perf_counter()
            proc = subprocess.Popen(argv, cwd=wd, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
                                    env=discovery.engine_env(), start_new_session=True)
            _, status, usage = os.wait4(proc.pid, 0)
            wall = time.perf_counter() - t
        proc.returncode = os.waitstatus_to_exitcode(status)
        log = (wd / "log.txt").read_text(errors="replace")
        if proc.returncode != 0 or "Loop time" not in log:
            return {"error": f"exit {proc.returncode}: " + " | ".join(log.strip().splitlines()[-3:])[:300]}
        contacts = (wd / "contacts.txt").read_text().split("ITEM: ENTRIES")[-1].strip().splitlines()
    finally:
        shutil.rmtree(wd, ignore_errors=True)
    loops = [(float(a), int(b)) for a, b in re.findall(r"Loop time of (\S+) on \d+ procs for (\d+) steps", log)]
    loop = sum(a for a, b in loops if b > 0)
    neighbours = [int(x) for x in re.findall(r"Total # of neighbors = (\d+)", log)]
    # the count is the run's since its last init: cumulative over the segments (``pre no`` does not reset it), so
    # the last segment's is the whole run's (the final ``run 0`` re-inits: its 0 is not counted)
    builds = [int(x) for x in re.findall(r"Neighbor list builds = (\d+)", log)]
    builds = builds[SEGMENTS - 1] if len(builds) >= SEGMENTS else -1
    rows = []  # (step, contacts counted at both atoms) from the thermo blocks
    for block in re.findall(r"^\s*Step .*?\n(.*?)^Loop time", log, re.M | re.S):
        for line in block.strip().splitlines():
            w = line.split()
            if len(w) == 4 and w[0].isdigit():
                rows.append((int(w[0]), float(w[3])))
    rows = sorted(dict(rows).items())
    k = np.array(rows, float)
    n = len(case.particles)
    seg = np.linspace(0, steps, SEGMENTS + 1).round()[1:]
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "user": usage.ru_utime, "sys": usage.ru_stime,
            "loop": loop, "steps": steps, "pairs": trapezoid_mean(k[:, 0], k[:, 1] / 2), "pairs_end": k[-1, 1] / 2,
            "pairs_dump": len(contacts),
            # the list at the segments' ends (the start's list is not printed: its first segment's end is the first)
            "entries": trapezoid_mean(seg[:len(neighbours[:SEGMENTS])], neighbours[:SEGMENTS]) if neighbours else math.nan,
            "entries_end": neighbours[SEGMENTS - 1] if len(neighbours) >= SEGMENTS else math.nan,
            "rebuilds": builds, "samples": len(rows), "n": n}


def _fit(ns, ys) -> float:
    ok = [(n, y) for n, y in zip(ns, ys) if y > 0 and math.isfinite(y)]
    if len(ok) < 2:
        return math.nan
    return float(np.polyfit(np.log([n for n, _ in ok]), np.log([y for _, y in ok]), 1)[0])


def work_units(r: dict) -> float:
    """The reference's force-loop work a step in its own cost model (packing.py's force-cut weights, in list
    entries: ROW_COST + WALL_TEST_COST a wall for each particle's row, 1 a list entry, PAIR_COST a touching pair,
    WALL_COST a wall contact — fitted on the force loop, bench_packing_phases.py --fit), with the time-averaged
    counts; NaN for LIGGGHTS (not its model)."""
    if "rows" not in r:
        return math.nan
    return r["rows"] + r["entries"] + P.PAIR_COST * r["pairs"] + P.WALL_COST * r["walls"]


def _costs(n: int, r: dict) -> dict:
    """CPU ns a sphere-step, a pair-contact-step, a list-entry-step, a work unit-step (:func:`work_units`)."""
    cpu = r["cpu"] * 1e9 / r["steps"]
    return {"sphere": cpu / n, "contact": cpu / r["pairs"] if r["pairs"] else math.nan, "entry": cpu / r["entries"],
            "unit": cpu / work_units(r)}


HEAD = (f"{'source':10s} {'N':>7s} {'wall s':>8s} {'CPU s':>8s} {'steps':>6s} {'pairs/sph':>9s} {'walls/sph':>9s} "
        f"{'entries/sph':>11s} {'builds':>11s} {'ns/sph-step':>11s} {'ns/contact-step':>15s} {'ns/entry-step':>13s}"
        f" {'ns/unit-step':>12s} {'load':>5s}")


def _row(source: str, n: int, r: dict, load: float) -> str:
    if "error" in r:
        return f"{source:10s} {n:7d}  failed: {r['error']}"
    c = _costs(n, r)
    walls = f"{r['walls'] / n:9.3f}" if "walls" in r else f"{'-':>9s}"
    builds = (f"{r['rebuilds']}+{r['chunk_builds']}" if "chunk_builds" in r else f"{r['rebuilds']}")
    return (f"{source:10s} {n:7d} {r['wall']:8.2f} {r['cpu']:8.2f} {r['steps']:6d} {r['pairs'] / n:9.3f} {walls} "
            f"{r['entries'] / n:11.3f} {builds:>11s} {c['sphere']:11.1f} {c['contact']:15.1f} {c['entry']:13.1f} "
            f"{c['unit']:12.2f} {load:5.2f}")


def _detail(source: str, n: int, r: dict) -> str:
    if "error" in r:
        return ""
    if source == "reference":
        times = ", ".join(f"{c:.2f}" for c, _ in r["rounds"])
        return (f"           untimed runs' CPU s: {times} (the least kept); work units a step (the cost model) "
                f"{work_units(r) / n:.1f} a sphere\n"
                f"           counted run: {r['counted_wall']:.2f} s wall, {r['counted_cpu']:.2f} s CPU (clock and "
                f"{r['samples']} observations); list entries a sphere {r['entries_start'] / n:.3f} at the first count, "
                f"{r['entries_end'] / n:.3f} at the end; pairs a sphere at the end {r['pairs_end'] / n:.3f} "
                f"(the untimed run's {r['end_pairs_untimed'] / n:.3f})\n"
                f"           counted run's phases, CPU ns a sphere-step (its clock): "
                + ", ".join(f"{k} {v / n:.1f}" for k, v in r["phases"].items())
                + f"; a rebuild {r['phases']['rebuilds'] * r['steps'] / max(r['rebuilds'], 1) / n:.0f} ns a sphere")
    return (f"           process CPU {r['user']:.2f} user + {r['sys']:.2f} sys; loop {r['loop']:.2f} s (its wall "
            f"timer); {r['samples']} contact samples; pairs a sphere at the end {r['pairs_end'] / n:.3f} (thermo) / "
            f"{r['pairs_dump'] / n:.3f} (its final contact dump); list entries a sphere at the end "
            f"{r['entries_end'] / n:.3f}")


def report(results: dict) -> None:
    print("\nAll rows (CPU time is the measure; costs are CPU ns):")
    print(HEAD)
    for source, by_n in results.items():
        for n, (r, load) in by_n.items():
            print(_row(source, n, r, load))
    print("\nGrowth exponents (slope of log y against log N over the sizes that ran):")
    print(f"{'source':10s} {'sizes':>26s} {'CPU':>6s} {'wall':>6s} {'pairs/sph':>9s} {'entries/sph':>11s} "
          f"{'builds':>6s} {'/sph-step':>9s} {'/contact-step':>13s} {'/entry-step':>11s} {'/unit-step':>10s} "
          f"{'units/sph':>9s}")
    for source, by_n in results.items():
        ok = {n: r for n, (r, _) in by_n.items() if "error" not in r}
        if len(ok) < 2:
            continue
        ns = list(ok)
        g = {"cpu": _fit(ns, [ok[n]["cpu"] for n in ns]), "wall": _fit(ns, [ok[n]["wall"] for n in ns]),
             "pairs": _fit(ns, [ok[n]["pairs"] / n for n in ns]), "entries": _fit(ns, [ok[n]["entries"] / n for n in ns]),
             "builds": _fit(ns, [ok[n]["rebuilds"] + ok[n].get("chunk_builds", 0) for n in ns])}
        for key in ("sphere", "contact", "entry", "unit"):
            g[key] = _fit(ns, [_costs(n, ok[n])[key] for n in ns])
        g["units"] = _fit(ns, [work_units(ok[n]) / n for n in ns])
        print(f"{source:10s} {','.join(map(str, ns)):>26s} {g['cpu']:6.3f} {g['wall']:6.3f} {g['pairs']:9.3f} "
              f"{g['entries']:11.3f} {g['builds']:6.3f} {g['sphere']:9.3f} {g['contact']:13.3f} {g['entry']:11.3f} "
              f"{g['unit']:10.3f} {g['units']:9.3f}")
        print(f"           time N^{g['cpu']:.3f} (CPU) = N^1 x the cost a sphere-step N^{g['sphere']:.3f}; that cost = "
              f"contacts a sphere N^{g['pairs']:.3f} x the cost a contact-step N^{g['contact']:.3f}, = list entries a "
              f"sphere N^{g['entries']:.3f} x the cost an entry-step N^{g['entry']:.3f}")
        if math.isfinite(g["unit"]):
            print(f"           in the reference's cost model: work units a sphere N^{g['units']:.3f} x the cost a "
                  f"unit-step N^{g['unit']:.3f}")
    ref = {n: r for n, (r, _) in results.get("reference", {}).items() if "error" not in r}
    if len(ref) >= 2:
        ns = list(ref)
        print("\nThe reference's counted run by phase (its loop's clock, thread CPU ns a sphere-step; the counted run, "
              "not the untimed one — its own load):")
        print(f"{'N':>7s} " + " ".join(f"{name:>9s}" for name, _, _ in PHASE_CPU) + f" {'sum':>9s} {'rebuilds':>8s}")
        for n in ns:
            ph = ref[n]["phases"]
            print(f"{n:7d} " + " ".join(f"{ph[name] / n:9.1f}" for name, _, _ in PHASE_CPU)
                  + f" {sum(ph.values()) / n:9.1f} {ref[n]['rebuilds']:8d}")
        print("exponent" + " ".join(f"{_fit(ns, [ref[n]['phases'][name] / n for n in ns]):9.3f}" for name, _, _ in PHASE_CPU)
              + f" {_fit(ns, [sum(ref[n]['phases'].values()) / n for n in ns]):9.3f}"
              + f" {_fit(ns, [ref[n]['rebuilds'] for n in ns]):8.3f}   (of each per sphere-step; of the rebuild count)")
    print("(a cost's exponent near 0 is a cost flat in N; the growth goal is the reference's time as N^<=1.05)")


def main(sizes: list[int], duration: float, sources: list[str], rounds: int = 1) -> None:
    import numba

    from demcheck.case import packing_run

    steps = packing_run(BS.scaled_case(BS.BASE_N, duration), duration, None)[2]
    print(f"what grows with N: the poured packing at scale (box side 30 mm x sqrt(N / 2000)), {duration:g} s of the "
          f"pour ({steps} steps), N = {', '.join(map(str, sizes))}; the reference on 1 thread, LIGGGHTS on 1 rank "
          f"({', '.join(sources)}); {datetime.now(timezone.utc):%d %b %Y %H:%M} UTC, git {BP._head()}; "
          f"{os.cpu_count()} cores, numba {numba.__version__}")
    print(f"load average (1, 5, 15 min) at the start: {BP._load()}")
    print(f"rounds: {rounds} at N <= {REPEAT_UP_TO} (the reference's untimed run repeated in its process, the least CPU "
          f"kept; LIGGGHTS run again, the round with the least CPU kept), 1 above")
    print("columns: pairs/sph = time-averaged touching pairs a sphere (each pair once; coordination = 2 x); walls/sph "
          "= the reference's wall contacts a sphere; entries/sph = time-averaged list entries a sphere (the reference: "
          f"every {OBSERVE} steps of its counted run; LIGGGHTS: at its {SEGMENTS} segments' ends); builds = list builds "
          "(the reference: in-loop rebuilds of its counted run + builds at its chunks' starts); ns = CPU ns; load = "
          "1-minute load average after the row\n")
    print(HEAD, flush=True)
    results = {s: {} for s in sources}
    with tempfile.TemporaryDirectory() as tmp:
        for n, path in BS.pickled_cases(tmp, sizes, duration):
            repeat = rounds if n <= REPEAT_UP_TO else 1
            for source in sources:
                if source == "reference":
                    r = _reference(path, repeat)
                    load = os.getloadavg()[0]
                else:
                    with open(path, "rb") as fh:
                        case = pickle.load(fh)
                    runs = []
                    for _ in range(repeat):
                        runs.append((liggghts(case), os.getloadavg()[0]))
                        if repeat > 1:
                            print(f"{'':10s} {n:7d}  LIGGGHTS round: " + (
                                f"{runs[-1][0]['wall']:.2f} s wall, {runs[-1][0]['cpu']:.2f} s CPU, load "
                                f"{runs[-1][1]:.2f}" if "error" not in runs[-1][0] else runs[-1][0]["error"]),
                                  flush=True)
                    good = [x for x in runs if "error" not in x[0]] or runs
                    r, load = min(good, key=lambda x: x[0].get("cpu", math.inf))
                results[source][n] = (r, load)
                print(_row(source, n, r, load), flush=True)
                detail = _detail(source, n, r)
                if detail:
                    print(detail, flush=True)
    print(f"\nload average at the end: {BP._load()}")
    report(results)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        child(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 1)
    else:
        a = sys.argv[1:]
        which = a[2] if len(a) > 2 else "both"
        main([int(x) for x in a[0].split(",")] if a else list(SIZES), float(a[1]) if len(a) > 1 else DURATION,
             ["reference", "liggghts"] if which == "both" else [which], int(a[3]) if len(a) > 3 else 1)
