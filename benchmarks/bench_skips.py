"""What each skip saves (docs/performance.md), measured side by side in one run.

Ratios of best-of-N wall times on this shared, noisy machine; absolute seconds are printed for context only.

* the 1-D normal solve against the full 3-D solver, same head-on collision (adaptive and verlet);
* no tangential history for a history-free law: the 3-D solver with tangential 'none' against the same
  collision with a spring law at μ = 0 (identical physics: it slips from the first instant with zero force);
* early stop at separation: the verlet method stopping at the first step after contact against running as
  long as an engine deck does (free flight to contact plus six contact times);
* the engine-run cache and batching: see bench_verify.txt (cold vs warm suite) and `demcheck bench`
  (per process vs per batched collision), recorded in engine_batching below;
* no neighbour search for two bodies: the reference's two-body solvers never build a neighbour list, and
  there is no N-body reference solver yet (packings) to compare against — not measured.

Run: .venv/bin/python benchmarks/bench_skips.py > benchmarks/results/bench_skips.txt
"""

import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from demcheck.reference import collision3d, kernels  # noqa: E402
from demcheck.reference.collision import Geometry1D, auto_dt, characteristic_time, collide  # noqa: E402
from demcheck.laws.model import resolve  # noqa: E402
from tests.helpers import glass_case, oblique_case  # noqa: E402


def best(fn, n=7):
    t = math.inf
    for _ in range(n):
        s = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - s)
    return t


def main():
    rows = []
    for normal, params in (("hertz", {}), ("tti", {}), ("lsd", {"stiffness_method": "energy"})):
        case = glass_case(normal, params, wall=True, restitution=0.7)
        model = resolve(case)
        for method in ("adaptive", "verlet"):
            one = best(lambda: collide(case, method))
            three = best(lambda: collision3d.collide(case, model, method))
            rows.append((f"1-D normal solve vs 3-D ({normal}, {method})", one, three))
    case = oblique_case("none", {}, normal="lsd", normal_params=None, angle=40.0, spin=500.0)
    nohist = best(lambda: collision3d.collide(case, resolve(case), "adaptive"))
    zero = oblique_case("spring_sliding", None, normal="lsd", normal_params=None, angle=40.0, spin=500.0,
                        friction=0.0)
    hist = best(lambda: collision3d.collide(zero, resolve(zero), "adaptive"))
    a, b = collision3d.collide(case, resolve(case), "adaptive").metrics(), \
        collision3d.collide(zero, resolve(zero), "adaptive").metrics()
    same = max(abs(a[k] - b[k]) / max(abs(a[k]), 1e-30) for k in ("restitution", "tangential_restitution"))
    rows.append((f"no history for a history-free law (3-D adaptive; same result to {same:.1e})", nohist, hist))
    for normal in ("hertz", "lsd"):
        case = glass_case(normal, {} if normal == "hertz" else {"stiffness_method": "energy"}, wall=True)
        model = resolve(case)
        geo = Geometry1D(case)
        law = model.normal_law.array()
        t_c = characteristic_time(model)
        dt = auto_dt(case, model)
        t_engine = 6.0 * t_c + max(-geo.delta0, 0.0) / model.pair.impact_speed
        cap = int(t_engine / dt) + 10
        stop = best(lambda: kernels.verlet_normal(law, model.pair.m_eff, geo.an, geo.delta0, geo.rate0, dt,
                                                  t_engine, cap, True), n=20)
        full = best(lambda: kernels.verlet_normal(law, model.pair.m_eff, geo.an, geo.delta0, geo.rate0, dt,
                                                  t_engine, cap, False), n=20)
        rows.append((f"early stop at separation (verlet kernel, {normal}, engine-length run)", stop, full))
    print("what each skip saves: best-of-N wall time with the skip, without it, and the ratio")
    print(f"{'skip':80s} {'with s':>10s} {'without s':>10s} {'saved ×':>8s}")
    for name, w, wo in rows:
        print(f"{name:80s} {w:10.2e} {wo:10.2e} {wo / w:8.2f}")


if __name__ == "__main__":
    main()
