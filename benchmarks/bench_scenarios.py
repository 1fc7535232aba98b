"""`demcheck verify` on the eight scenario cases beyond sliding (cases/suite/beyond-*.toml), two versions side by
side in one run: "before" (a source tree given with --before, e.g. ``git archive a935632 src | tar -x -C
/tmp/old-beyond4``, run with PYTHONPATH=its src) and "after" (this tree). All runs share one fresh engine-run cache
(a temporary $DEMCHECK_CACHE): the first run fills it with the engine runs (cold), so every later run is warm in
its engine runs; "after" then runs twice, the first computing its twins and seed runs (and caching them:
engines/scenario.cached_metrics), the second reading them. Each run is a fresh process with --jobs 2; the compiled
kernels are on disk already (each version's ``demcheck warmup`` first, untimed). The load average is printed beside
each run: the machine is shared, so the ratios within one run are the result, not the absolute times.

Every engine's, twin's and seed run's metric and every comparison of the last "before" and "after" runs are
compared (results.json, times left out): "numbers equal" says they are the same to the bit.

Run: .venv/bin/python benchmarks/bench_scenarios.py --before /tmp/old-beyond4/src > benchmarks/results/bench_scenarios.txt
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = sorted(str(p) for p in (ROOT / "src/demcheck/cases/suite").glob("beyond-*.toml"))


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def numbers(results: Path) -> dict:
    """Every metric and comparison of a results.json, without times."""
    d = json.loads(results.read_text())
    out = {}
    for c in d["cases"]:
        for name, s in c["sources"].items():
            for k in ("metrics", "twin_metrics", "seed_verlet_metrics"):
                if k in s:
                    out[(c["case"], name, k)] = s[k]
        for i, comp in enumerate(c["comparisons"]):
            out[(c["case"], i)] = {k: v for k, v in comp.items() if "time" not in k}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", required=True, help="the src directory of the version to compare against")
    a = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench-scenarios-"))
    base = {**os.environ, "DEMCHECK_CACHE": str(tmp / "cache")}
    versions = {"before": {**base, "PYTHONPATH": a.before}, "after": {**base, "PYTHONPATH": str(ROOT / "src")}}
    for env in versions.values():
        subprocess.run([sys.executable, "-m", "demcheck", "warmup"], env=env, capture_output=True, check=True)
    rows, last, times = [], {}, []
    plan = [("before", "engines cold"), ("before", "warm"), ("after", "twins computed"), ("after", "warm")]
    for i, (version, label) in enumerate(plan):
        report = tmp / f"r{i}"
        lb = load()
        t = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "demcheck", "verify", "--jobs", "2", "--report", str(report),
                            *CASES], env=versions[version], cwd=tmp, capture_output=True, text=True)
        secs = time.perf_counter() - t
        times.append(secs)
        res = report / "latest" / "results.json"
        last[version] = res
        rows.append(f"{version:7s} {label:15s} {secs:9.1f} {p.returncode:4d}  {lb} → {load()}")
        if p.returncode:
            rows.append("# " + p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "# (no stderr)")
    print(f"demcheck verify --jobs 2, the 8 beyond cases; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"{os.cpu_count()} CPUs")
    print("version run             process s exit  load average (1, 5, 15 min) before → after")
    print("\n".join(rows))
    before_warm, after_warm = times[1], times[3]
    print(f"warm: after ÷ before = {after_warm / before_warm:.2f} ({before_warm / after_warm:.1f}× faster)")
    same = numbers(last["before"]) == numbers(last["after"])
    shutil.rmtree(tmp, ignore_errors=True)
    print(f"numbers equal (every metric, twin, seed run and comparison): {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
