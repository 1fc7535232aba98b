"""Where a cold `demcheck verify` with all four engines spends its time (issue 33 item 5: cold ≤ 5 min on 2 cores).

One run in this process, ``--jobs 1`` (the cases one after another, so each part's wall time is its own), an empty
engine-run cache (a temporary DEMCHECK_CACHE), the compiled kernels already on disk, under cProfile. Printed:
* the process's wall and CPU time, and the CPU time of every child process it waited for (the engines' runs as
  processes and their long-lived workers) — their sum over the 2 cores is the least wall time a ``--jobs 2`` run
  could take if nothing were serial;
* each source's rows summed (results.json's wall_time: a collision's or scenario's solve or engine run, a packing's
  run), by the case's kind;
* the profile's cumulative wall time of the parts named below (each a function; a part inside another is listed
  under it), and of the report.

Run: .venv/bin/python benchmarks/profile_verify_cold.py > benchmarks/results/profile_verify_cold.txt
"""

import cProfile
import json
import os
import pstats
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENGINES = "lammps,liggghts,kratos,yade"

# (label, file suffix, function name): cumulative wall time from the profile
PARTS = [
    ("the cases (run_case)", "comparisons/suite.py", "run_case"),
    ("  packings (run_packing)", "comparisons/packing_suite.py", "run_packing"),
    ("    the reference's packings (reference_packing)", "comparisons/packing_suite.py", "reference_packing"),
    ("    the engines' packings (engines.packing.run_engine)", "engines/packing.py", "run_engine"),
    ("  scenarios beyond sliding (run_scenario)", "comparisons/suite.py", "run_scenario"),
    ("    their engine runs (engines.scenario.run)", "engines/scenario.py", "run"),
    ("  collisions' reference sources (_reference_sources)", "comparisons/suite.py", "_reference_sources"),
    ("    the adaptive 3-D kernel (adaptive_3d)", "reference/adaptive3d.py", "adaptive_3d"),
    ("  collisions' engine sources (_engine_source)", "comparisons/suite.py", "_engine_source"),
    ("    their engine runs (engines.collide.collide)", "engines/collide.py", "collide"),
    ("engine runs, all (engines.run.run)", "engines/run.py", "run"),
    ("  through an engine's worker (_run_in_worker)", "engines/run.py", "_run_in_worker"),
    ("  as a process (_run_process)", "engines/run.py", "_run_process"),
    ("the report (write_all)", "comparisons/report/__init__.py", "write_all"),
    ("  the case panels (case_panels)", "comparisons/report/figures.py", "case_panels"),
    ("  the suite's plots (suite_plots)", "comparisons/report/figures.py", "suite_plots"),
    ("  the packings' panels (packing_plots)", "comparisons/report/figures.py", "packing_plots"),
    ("  matplotlib's savefig, all", "matplotlib/figure.py", "savefig"),
]


def main() -> None:
    cache = tempfile.mkdtemp(prefix="demcheck-cold-")
    os.environ["DEMCHECK_CACHE"] = cache
    load0 = " ".join(f"{x:.2f}" for x in os.getloadavg())
    git = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout
    from demcheck.cli import main as cli

    report = Path(cache) / "report"
    prof = cProfile.Profile()
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0, p0 = time.perf_counter(), time.process_time()
    prof.enable()
    try:
        with open(Path(cache) / "out.json", "w") as out:
            sys.stdout, saved = out, sys.stdout
            try:
                cli(["verify", "--engines", ENGINES, "--jobs", "1", "--report", str(report), "--json"])
            finally:
                sys.stdout = saved
    except SystemExit as exc:
        code = exc.code
    else:
        code = 0
    prof.disable()
    wall, cpu = time.perf_counter() - t0, time.process_time() - p0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    children = (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
    res = json.loads((Path(cache) / "out.json").read_text())
    print(f"cold `demcheck verify --engines {ENGINES} --jobs 1` under cProfile, git {git.strip()}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} CPUs; exit {code}, "
          f"{len(res['cases'])} cases, {res['failed']} failing; load average {load0} → "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    print(f"process wall {wall:.1f} s (the suite's own wall_time {res['wall_time']:.1f} s); CPU: this process "
          f"{cpu:.1f} s, its children (engine processes and workers) {children:.1f} s, together {cpu + children:.1f} s "
          f"→ at least {(cpu + children) / 2:.1f} s of wall on 2 cores if nothing were serial")
    print("\nrows' wall_time summed (results.json), s, by source and the case's kind:")
    sums: dict = {}
    for c in res["cases"]:
        for src, row in c.get("sources", {}).items():
            w = row.get("wall_time")
            if w:
                k = (src, c["kind"])  # a scenario beyond sliding is a collision case
                sums[k] = sums.get(k, 0.0) + w
    for (src, kind), w in sorted(sums.items(), key=lambda kv: -kv[1]):
        print(f"  {src:18s} {kind:10s} {w:8.1f}")
    print(f"  {'all':29s} {sum(sums.values()):8.1f}")
    stats = pstats.Stats(prof)
    print("\nthe profile's cumulative wall time, s (calls):")
    for label, suffix, name in PARTS:
        hits = [(v[3], v[1]) for (f, _, fn), v in stats.stats.items() if f.endswith(suffix) and fn == name]
        if hits:
            print(f"  {label:60s} {sum(h[0] for h in hits):8.1f} ({sum(h[1] for h in hits)})")


if __name__ == "__main__":
    main()
