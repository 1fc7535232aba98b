"""The packing loop of this tree against that of another copy (OLD_SRC), to judge a change to the loop by its
cost: written for the verlet history rules shared between the two-body verlet kernel and the packing loop
(kernels3d.wall_arm, walton_reverses, turn_history, project_history, spring_slip; issue "Engines as plug-ins",
item 4: at most 5 % on the packing loop).

Run: .venv/bin/python benchmarks/bench_packing_loop.py OLD_SRC [OLD_LABEL [OUT]]
     (writes benchmarks/results/OUT, bench_packing_loop.txt by default; OLD_LABEL, e.g. the old copy's commit, is
     printed beside this tree's git head)

OLD_SRC is the ``src`` directory of a copy of demcheck from before the change, kept outside the project, e.g.
``git archive <commit> src/demcheck | tar -x -C /tmp/old`` → OLD_SRC = /tmp/old/src.

Each measurement is a fresh process (its own numba cache directory per tree, compiled before timing): the
default suite's 2000-sphere poured packing (cases/packing/poured.toml) over its whole duration (the pour
and the dense settled bed, where the contact law runs most), timed warm; old and new alternate, ROUNDS times each, and the ratio of the medians is read
within the one run (the machine may be shared). The two trees' states after the run are compared too (the
same law and rules: they should agree to round-off, or exactly).
"""

import os
import statistics
import subprocess
import sys
import tempfile
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASE = ROOT / "cases" / "packing" / "poured.toml"
ROUNDS = 5

CHILD = r"""
import sys, time
import numpy as np
from demcheck import case as C
from demcheck.reference import packing as P
case = C.load(sys.argv[1])
dt = P.packing_dt(case)
P.simulate(case, duration=20 * dt)  # compile
t = time.perf_counter()
st = P.simulate(case, rest=0.0)
elapsed = time.perf_counter() - t
print(elapsed, float(np.abs(st.x).sum()), float(np.abs(st.v).sum()))
"""


def run(src: Path, cache: Path) -> tuple[float, float, float]:
    env = {"PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache), "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", CHILD, str(CASE)], env=env, capture_output=True,
                         text=True, check=True)
    a, b, c = out.stdout.split()
    return float(a), float(b), float(c)


def main():
    if not 2 <= len(sys.argv) <= 4:
        sys.exit(__doc__)
    old_src, new_src = Path(sys.argv[1]).resolve(), ROOT / "src"
    old_label = sys.argv[2] if len(sys.argv) > 2 else str(old_src)
    name = sys.argv[3] if len(sys.argv) > 3 else "bench_packing_loop.txt"
    if "/" in name or not name.endswith(".txt"):
        sys.exit(f"OUT: {name!r}: must be a file name ending in .txt (written in benchmarks/results/)")
    head = subprocess.run(["git", "-C", str(ROOT), "describe", "--always", "--dirty"], capture_output=True,
                          text=True).stdout.strip() or "unknown"
    times = {"old": [], "new": []}
    states = {}
    load0 = f"{os.getloadavg()[0]:.2f}"
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(ROUNDS):
            for label, src in (("old", old_src), ("new", new_src)) if k % 2 == 0 else (("new", new_src), ("old", old_src)):
                t, sx, sv = run(src, Path(tmp) / label)
                times[label].append(t)
                states[label] = (sx, sv)
    old, new = statistics.median(times["old"]), statistics.median(times["new"])
    dx = abs(states["new"][0] - states["old"][0]) / states["old"][0]
    dv = abs(states["new"][1] - states["old"][1]) / max(states["old"][1], 1e-300)
    lines = [f"{datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC; new: this tree (git {head}), old: {old_label}; "
             f"load average before/after: {load0} / {os.getloadavg()[0]:.2f}",
             f"packing loop: {CASE.relative_to(ROOT)} (2000 spheres), its whole duration, warm; median of {ROUNDS} fresh "
             "processes each, old and new alternated",
             f"{'':8s}{'median s':>10s}  runs",
             f"{'old':8s}{old:10.3f}  " + " ".join(f"{t:.3f}" for t in times["old"]),
             f"{'new':8s}{new:10.3f}  " + " ".join(f"{t:.3f}" for t in times["new"]),
             f"new/old {new / old:.3f} (limit 1.05)",
             f"state after the run, new against old: sum|x| relative {dx:.2g}, sum|v| relative {dv:.2g}"]
    text = "\n".join(lines) + "\n"
    print(text, end="")
    (ROOT / "benchmarks" / "results" / name).write_text(text)


if __name__ == "__main__":
    main()
