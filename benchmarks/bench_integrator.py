"""The adaptive solvers of this tree against those of another copy (OLD_SRC): written to judge a shared
integrator core (issue "Engines as plug-ins", item 4) against the two hand-written solvers — limits: the 1-D
solver ≤ 1.10x per collision, a cold-cache compile ≤ 1.20x. The recorded result is of the core in
reference/integrator.py (met); a first attempt, 3c73b35, missed both and was reverted.

Run: .venv/bin/python benchmarks/bench_integrator.py OLD_SRC
     (writes benchmarks/results/bench_integrator.txt)

OLD_SRC is the ``src`` directory of a copy of demcheck from before the change, kept outside the project, e.g.
``git archive <commit> src/demcheck | tar -x -C /tmp/old`` → OLD_SRC = /tmp/old/src.

1. The 1-D adaptive solver per collision, warm (cases/hertz-wall.toml, cases/glass-pair.toml, rtol of the case):
   the old kernels.py (loaded as a stand-alone module under another name) and the new one side by side in one
   process, interleaved; median of repeated calls; the two answers compared bit for bit.
2. Numba compile time on a cold cache (an empty NUMBA_CACHE_DIR), old and new, in fresh processes, alternated:
   the 1-D solver (collide hertz-wall), then the 3-D solver (collide an oblique case); and the 3-D solver's warm
   time per collision in the same process.
The machine may be shared: read the ratios within one run.
"""

import importlib.util
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NEW_SRC = ROOT / "src"
sys.path.insert(0, str(NEW_SRC))

import numpy as np  # noqa: E402

CASES_1D = ["cases/hertz-wall.toml", "cases/glass-pair.toml"]
CASE_3D = "cases/oblique-lsd-wall.toml"
REPEAT = 400
COLD_RUNS = 2

CHILD = r"""
import sys, time, statistics
t0 = time.perf_counter()
from demcheck.case import expand
from demcheck.reference.collision import collide
t1 = time.perf_counter()
collide(expand(sys.argv[1])[0], method="adaptive")
t2 = time.perf_counter()
c3 = expand(sys.argv[2])[0]
r = collide(c3, method="adaptive")
t3 = time.perf_counter()
warm = []
for _ in range(5):
    s = time.perf_counter(); collide(c3, method="adaptive"); warm.append(time.perf_counter() - s)
print(t2 - t1, t3 - t2, statistics.median(warm), r.meta.get("solver"))
"""


def load_old_kernels(old_src: Path):
    path = old_src / "demcheck" / "reference" / "kernels.py"
    spec = importlib.util.spec_from_file_location("kernels_before_integrator", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def one_d_inputs(path):
    from demcheck.case import expand
    from demcheck.reference.collision import Geometry1D, characteristic_time
    from demcheck.laws.model import resolve
    from demcheck.reference.outcome import time_to_contact

    case = expand(ROOT / path)[0]
    model = resolve(case)
    geo = Geometry1D(case)
    t_c, v = characteristic_time(model), model.pair.impact_speed
    return (model.normal_law.array(), model.pair.m_eff, geo.an, geo.delta0, geo.rate0, case.run.rtol, t_c, v * t_c,
            v, time_to_contact(case) + 200.0 * t_c, 1_000_000)


def per_collision(old, new, args):
    fo, fn = (lambda: old.adaptive_normal(*args)), (lambda: new.adaptive_normal(*args))
    a, b = fo(), fn()
    same = all(np.array_equal(x, y) if isinstance(x, np.ndarray) else x == y for x, y in zip(a, b))
    to, tn = [], []
    for _ in range(REPEAT):
        for f, acc in ((fo, to), (fn, tn)):
            s = time.perf_counter()
            f()
            acc.append(time.perf_counter() - s)
    return statistics.median(to), statistics.median(tn), int(b[1]), same


def cold(src: Path):
    with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(src))
        out = subprocess.run([sys.executable, "-c", CHILD, str(ROOT / CASES_1D[0]), str(ROOT / CASE_3D)],
                             env=env, capture_output=True, text=True, check=True, cwd=ROOT).stdout.split()
    return float(out[0]), float(out[1]), float(out[2]), out[3]


def main():
    old_src = Path(sys.argv[1]).resolve()
    from demcheck.reference import kernels as new

    old = load_old_kernels(old_src)
    lines = [f"1-D adaptive solver per collision, warm (median of {REPEAT}, old and new interleaved)",
             f"{'case':22s} {'old (µs)':>9s} {'new (µs)':>9s} {'new/old':>8s} {'points':>7s}  identical"]
    for path in CASES_1D:
        to, tn, n, same = per_collision(old, new, one_d_inputs(path))
        lines.append(f"{Path(path).stem:22s} {to * 1e6:9.1f} {tn * 1e6:9.1f} {tn / to:8.3f} {n:7d}  {same}")
    lines += ["", f"numba compile on a cold cache (fresh process, empty NUMBA_CACHE_DIR; {COLD_RUNS} runs each, "
              "alternated; median)",
              f"{'':6s} {'1-D (s)':>8s} {'3-D (s)':>8s} {'total (s)':>9s} {'3-D warm (ms)':>14s}"]
    runs = {"old": [], "new": []}
    for _ in range(COLD_RUNS):
        for name, src in (("old", old_src), ("new", NEW_SRC)):
            runs[name].append(cold(src))
    med = {}
    for name, rs in runs.items():
        c1 = statistics.median(r[0] for r in rs)
        c3 = statistics.median(r[1] for r in rs)
        w3 = statistics.median(r[2] for r in rs)
        med[name] = (c1, c3, w3)
        lines.append(f"{name:6s} {c1:8.2f} {c3:8.2f} {c1 + c3:9.2f} {w3 * 1e3:14.2f}   ({rs[0][3]})")
    (o1, o3, ow), (n1, n3, nw) = med["old"], med["new"]
    lines.append(f"{'ratio':6s} {n1 / o1:8.3f} {n3 / o3:8.3f} {(n1 + n3) / (o1 + o3):9.3f} {nw / ow:14.3f}")
    text = "\n".join(lines) + "\n"
    print(text, end="")
    out = ROOT / "benchmarks" / "results" / "bench_integrator.txt"
    out.write_text(text)


if __name__ == "__main__":
    main()
