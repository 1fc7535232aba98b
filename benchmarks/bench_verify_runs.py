"""Every engine run of ``demcheck verify`` on the default suite with all four engines, and what reads it (issue 33
item 5: "no engine run that a verdict does not need").

The suite runs in this process (``--jobs 1``, the default here) or on a local Dask cluster (``--jobs N``: each
task runs under its own spy on its worker, its records sent back with its entry) with an empty engine-run cache in a temporary directory (DEMCHECK_CACHE), so every run is real, under the spy of
tests/test_verify_engine_runs.py: every request of a case for an engine run (a collision, a scenario beyond sliding,
a packing), the cache's answer, every real run (through the engine's worker or as a process), and each request's
reader, the row of the results and the comparisons made of it. Printed: the runs by engine and kind, the runs per
case, each request with its reader, the runs a longer one replaced, the decks several cases share, and every needless
run (none expected). ``--src DIR``: run another tree's demcheck (PYTHONPATH=DIR; e.g. a worktree of main) under the
same spy.

Run: PYTHONPATH=src .venv/bin/python benchmarks/bench_verify_runs.py > benchmarks/results/bench_verify_runs.txt
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ("lammps", "liggghts", "kratos", "yade")


def spy_module():
    """The spy, imported by its name (a Dask worker unpickles its task function by it: the workers' sys.path is
    this process's)."""
    sys.path.insert(0, str(ROOT))
    import tests.test_verify_engine_runs as spy

    return spy


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--engines", default=",".join(ENGINES))
    ap.add_argument("--src", help="the src directory of another demcheck to run under the spy")
    ap.add_argument("--jobs", type=int, default=1, help="1: in this process; N: a local Dask cluster of N workers "
                                                        "(the command's default is 2), each task under the spy")
    a = ap.parse_args()
    if a.src and os.environ.get("BENCH_VERIFY_RUNS_CHILD") != "1":  # that tree's demcheck, in a process of its own
        env = dict(os.environ, PYTHONPATH=a.src, BENCH_VERIFY_RUNS_CHILD="1")
        sys.exit(subprocess.call([sys.executable, __file__, "--engines", a.engines, "--src", a.src, "--jobs",
                                  str(a.jobs)], env=env))
    engines = tuple(e for e in a.engines.split(",") if e)
    with tempfile.TemporaryDirectory(prefix="bench-verify-runs-") as tmp:
        os.environ["DEMCHECK_CACHE"] = str(Path(tmp) / "engine-runs")
        import demcheck
        from demcheck import resources
        from demcheck.engines import discovery

        spy = spy_module()
        files = resources.case_files([])
        load0 = os.getloadavg()
        started = time.perf_counter()
        summary, runs = spy.verify(files, Path(tmp) / "engine-runs", engines, jobs=a.jobs, report=True)
        wall = time.perf_counter() - started
        report(summary, runs, engines, wall, load0, os.getloadavg(), Path(demcheck.__file__).parent, discovery,
               a.jobs)


def report(summary, spy, engines, wall, load0, load1, src, discovery, jobs) -> None:
    commit = subprocess.run(["git", "-C", str(src), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    where = "in one process" if jobs == 1 else f"a local Dask cluster of {jobs} workers"
    print(f"demcheck verify, the default suite, engines {','.join(engines)}, --jobs {jobs} ({where}), an empty "
          f"engine-run cache; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} CPUs")
    print(f"demcheck from {src} (git {commit or '?'}); "
          + "; ".join(f"{e} {discovery.find(e).version}" for e in engines if discovery.find(e)))
    print(f"{len(summary.cases)} cases, {summary.failed} failing; suite wall {wall:.1f} s; load average "
          f"{' '.join(f'{x:.2f}' for x in load0)} -> {' '.join(f'{x:.2f}' for x in load1)}")
    ran = [r for r in spy.requests if r.ran]
    refused = [r for r in spy.requests if not r.ran]
    print()
    print("## engine runs by engine and kind (a request: a case asking an engine for a run; real: engines.run.run; "
          "hit: the run cache answered)")
    print(f"{'engine':9s} {'kind':10s} {'requests':>8s} {'real runs':>9s} {'hits':>5s} {'refused':>7s} "
          f"{'via worker':>10s} {'as process':>10s} {'engine s':>9s}")
    kinds = ("collision", "scenario", "packing")
    tot = collections.Counter()
    for e in engines:
        for k in kinds:
            rq = [r for r in ran if r.engine == e and r.kind == k]
            rr = [r for r in spy.runs if r.engine == e and r.kind == k]
            hits = sum(1 for r in rq if r.hit)
            nref = sum(1 for r in refused if r.engine == e and r.kind == k)
            worker = sum(1 for r in rr if r.worker != "process")
            secs = sum(r.seconds for r in rr)
            if not (rq or rr or nref):
                continue
            tot.update(requests=len(rq), runs=len(rr), hits=hits, refused=nref, worker=worker,
                       process=len(rr) - worker)
            tot["seconds"] += secs
            print(f"{e:9s} {k:10s} {len(rq):8d} {len(rr):9d} {hits:5d} {nref:7d} {worker:10d} {len(rr) - worker:10d} "
                  f"{secs:9.1f}")
    print(f"{'all':9s} {'':10s} {tot['requests']:8d} {tot['runs']:9d} {tot['hits']:5d} {tot['refused']:7d} "
          f"{tot['worker']:10d} {tot['process']:10d} {tot['seconds']:9.1f}")
    print("(refused: the engine's package refused the case before any run — a packing deck it does not write — and "
          "its row says so; not a run)")
    print(f"besides the runs: {len(spy.workers)} engine worker(s) started ("
          + ", ".join(f"{e} {spy.workers.count(e)}" for e in engines if e in spy.workers)
          + f"); {len(spy.probes)} discovery question(s) to an executable (its banner, for the version the cache "
            "keys and the report name): " + "; ".join(spy.probes))

    print()
    print("## runs per case (requests that ran or hit)")
    per = collections.Counter(r.case for r in ran)
    dist = collections.Counter(per.get(c.case, 0) for c in summary.cases)
    print("  " + ", ".join(f"{n} run(s): {dist[n]} case(s)" for n in sorted(dist)))
    rows = sum(1 for c in summary.cases for s, row in c.sources.items() if s in engines
               and row.status not in ("not expressible", "engine missing"))
    print(f"  engine rows in the results that are not 'not expressible' or 'engine missing': {rows}; requests that "
          f"ran or hit: {len(ran)}")

    print()
    hits = [r for r in ran if r.hit and not r.runs]
    print(f"## decks several cases share: {len(hits)} request(s) answered by the cache from a run another case of this "
          "verify made (the same deck's commands; only the comments naming the case differ)")
    for r in hits:
        print(f"  {r.engine:9s} {r.kind:10s} {r.case}")

    print()
    ext = spy.extended()
    print(f"## shorter runs a longer one replaced (a collision whose contact had not ended): {len(ext)}")
    for r in ext:
        print(f"  {r.engine:9s} {r.case}")

    print()
    bad = spy.needless()
    print(f"## needless runs (no row reads them, or a repeat of the same engine and deck): {len(bad)}")
    for line in bad:
        print("  " + line)

    print()
    print("## every request and its reader (results.json: the case's row of the engine and its comparisons)")
    for r in spy.requests:
        how = ("refused: " + r.error) if not r.ran else ("hit" if r.hit and not r.runs else
                                                         f"{len(r.runs)} real run(s)")
        print(f"  {r.case} / {r.engine} ({r.kind}, {how}): {r.reader or r.needless or '-'}")


if __name__ == "__main__":
    main()
