"""A heap benchmark's verdict as `demcheck validate ai2011-sandpile-*` reported it, written as a recorded result
(docs/benchmarks.md, "Rolling: Ai et al.'s sandpile"): the check (verdict, largest relative deviation and where,
the signed mean), the run's heights at each of the digitised curve's times beside the paper's, and the run's own
height every 0.02 s up to the curve's first time plus 1 s (where a grain still draining through the hopper would
show as a height far above the pile). It reads the report's results.json; it computes nothing the report did not.

Run: .venv/bin/python benchmarks/record_validate_heap.py REPORT_DIR > benchmarks/results/validate_<name>.txt
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    report = Path(sys.argv[1])
    data = json.loads((report / "results.json").read_text())
    val = data["validation"]
    print(f"report {report.name}; demcheck {data['demcheck']}; command: {' '.join(data['command'])}")
    print(f"started {data['started']}, wall time {data.get('wall_time')} s, partial {data['partial']}, "
          f"failed {data['failed']}")
    print(f"(recorded by benchmarks/record_validate_heap.py at git "
          f"{subprocess.run(['git', 'describe', '--always', '--dirty'], capture_output=True, text=True).stdout.strip()})")
    for check, series in zip(val["checks"], val["series"]):
        print()
        print(f"{check['benchmark']}: {check['verdict']}; largest relative deviation "
              f"{check.get('deviation') if check.get('deviation') is not None else '- (not judged)'} at "
              f"t = {check.get('at')} s over {check.get('points')} points; signed mean "
              f"{check.get('mean_deviation', check.get('extra', {}).get('mean_deviation'))}; tolerance "
              f"{check['tolerance']}")
        if "failed" in json.dumps(check):
            print(f"  failed: {check.get('failed', check.get('extra', {}).get('failed'))}")
        paper = np.asarray(series["paper"], float)
        run = series["sources"].get("reference")
        if run is None:
            print("  no heights")
            continue
        t, h = np.asarray(run["x"], float), np.asarray(run["y"], float)
        print(f"  run: {len(t)} heights, t = {t[0]:.4g}-{t[-1]:.4g} s")
        print(f"  {'t (s)':>9s} {'paper (m)':>10s} {'run (m)':>10s} {'run/paper-1':>12s}")
        for tp, hp in paper:
            if not t[0] <= tp <= t[-1]:  # past an interrupted run's end: no height (never the last one carried on)
                print(f"  {tp:9.4f} {hp:10.6f} {'-':>10s} {'-':>12s}")
                continue
            hr = float(np.interp(tp, t, h))
            print(f"  {tp:9.4f} {hp:10.6f} {hr:10.6f} {hr / hp - 1:+12.4f}")
        print(f"  the run's heights up to {paper[0, 0] + 1:.2f} s:")
        for ti, hi in zip(t, h):
            if ti <= paper[0, 0] + 1.0:
                print(f"  {ti:9.4f} {hi:10.6f}")


if __name__ == "__main__":
    main()
