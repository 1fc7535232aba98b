"""The default suite's run time with all four engines: engine-run cache cold, then warm (issue 33 item 5: cold ≤ 5 min,
warm ≤ 20 s on this 2-core machine), for two versions of demcheck side by side in one run — "before" (a source tree
given with --before, e.g. a ``git worktree add /tmp/speed-old b2b60bb``, run with PYTHONPATH=its src) and "after"
(this tree). Each run is ``demcheck verify --engines lammps,liggghts,kratos,yade --jobs 2`` in a fresh process,
the compiled kernels already on disk (each version's ``demcheck warmup`` first, untimed). The order interleaves
the versions (before cold, after cold, before warm, after warm) and the load average is printed beside each run:
the machine is shared, so the ratios within one run are the result, not the absolute times.

Run: .venv/bin/python benchmarks/bench_verify.py --before /tmp/speed-old/src > benchmarks/results/bench_verify.txt
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMCHECK = [sys.executable, "-m", "demcheck"]
ENGINES = "lammps,liggghts,kratos,yade"


def run(args, env):
    """The run's wall time and its process tree's CPU time (verify, its Dask workers, the engines' processes and
    workers: every descendant reaped by the time it ends)."""
    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    p = subprocess.run(DEMCHECK + args, cwd=ROOT, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - t
    d = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU[id(p)] = (d.ru_utime - c.ru_utime) + (d.ru_stime - c.ru_stime)
    return seconds, p


CPU: dict = {}


def source_sums(out: dict) -> dict:
    """Each source's rows' wall_time summed (collisions, scenarios and packings alike), s."""
    sums: dict = {}
    for case in out["cases"]:
        for src, row in case.get("sources", {}).items():
            if row.get("wall_time"):
                sums[src] = sums.get(src, 0.0) + row["wall_time"]
    return sums


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", help="the src directory of the version to compare against (PYTHONPATH)")
    ap.add_argument("--jobs", default="2")
    ap.add_argument("--engines", default=ENGINES, help="the engines verify runs (default all four; none: the "
                                                      "reference alone)")
    ap.add_argument("--write-baseline", help="the 'after' tree's cold run also writes its results here "
                                           "(verify --write-baseline: the golden run tests/test_suite_identity.py "
                                           "compares with, made by the timed run itself)")
    a = ap.parse_args()
    versions = [("after", str(ROOT / "src"))] + ([("before", a.before)] if a.before else [])
    versions.reverse()
    rows, cpus = [], []
    with tempfile.TemporaryDirectory() as tmp:
        envs = {}
        for name, src in versions:
            env = dict(os.environ, DEMCHECK_CACHE=str(Path(tmp) / f"engine-runs-{name}"), PYTHONPATH=src)
            envs[name] = env
            run(["warmup"], env)  # compile (or load) the kernels, so that no timed run pays for it
        for label in ("cold", "warm"):
            for name, _ in versions:
                report = str(Path(tmp) / f"reports-{name}")
                before_load = load()
                extra = (["--write-baseline", a.write_baseline]
                         if a.write_baseline and (name, label) == ("after", "cold") else [])
                seconds, p = run(["verify", "--engines", a.engines, "--jobs", a.jobs, "--report", report, "--json"]
                                 + extra, envs[name])
                try:
                    out = json.loads(p.stdout)
                except ValueError:
                    print(f"{name} {label}: exit {p.returncode}\n{p.stderr[-3000:]}", file=sys.stderr)
                    raise
                per_engine = {}
                for case in out["cases"]:
                    for src, s in case.get("sources", {}).items():
                        if src in a.engines.split(","):
                            per_engine[src] = per_engine.get(src, 0) + 1
                rows.append((name, label, seconds, out["wall_time"], len(out["cases"]), out["cache"], p.returncode,
                             before_load, load(), out["failed"]))
                cpus.append((name, label, CPU.pop(id(p)), source_sums(out)))
                print(f"# {name} {label}: {seconds:.1f} s, load {before_load} → {load()}", file=sys.stderr,
                      flush=True)
    print(f"demcheck verify, the default suite (cases/), engines {a.engines}, --jobs {a.jobs}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} CPUs")
    print(f"{'version':8s} {'run':5s} {'process s':>10s} {'suite s':>8s} {'cases':>6s} {'hits/misses':>14s} "
          f"{'failed':>6s} exit  load average (1, 5, 15 min) before → after")
    for name, label, seconds, wall, n, cache, rc, l0, l1, failed in rows:
        print(f"{name:8s} {label:5s} {seconds:10.1f} {wall:8.1f} {n:6d} {cache['hits']:>6d}/{cache['misses']:<7d} "
              f"{failed:6d} {rc:4d}  {l0} → {l1}")
    print("CPU time of each run's process tree (verify, its workers, the engines), and its rows' wall_time summed "
          "by source (each row's solve or engine run; a packing's engine rows since 7edd32e):")
    for name, label, cpu, sums in cpus:
        print(f"{name:8s} {label:5s} CPU {cpu:7.1f} s (÷ {os.cpu_count()} cores: {cpu / os.cpu_count():6.1f} s)  rows: "
              + ", ".join(f"{k} {v:.1f}" for k, v in sorted(sums.items(), key=lambda kv: -kv[1])))
    t = {(r[0], r[1]): r[2] for r in rows}
    for label in ("cold", "warm"):
        if ("before", label) in t:
            print(f"{label}: after ÷ before = {t[('after', label)] / t[('before', label)]:.2f} "
                  f"({t[('before', label)] / t[('after', label)]:.2f}× faster)")
    cold, warm = t[("after", "cold")], t[("after", "warm")]
    print(f"targets (after): cold ≤ 300 s ({'met' if cold <= 300 else 'MISSED'}: {cold:.0f} s), warm ≤ 20 s "
          f"({'met' if warm <= 20 else 'MISSED'}: {warm:.1f} s); warm/cold = {warm / cold:.2f}")


if __name__ == "__main__":
    main()
