"""Which tolerance do the oblique metrics need? (issue 33, item 3: "a tolerance that the metrics need, not more")

The adaptive 3-D method is the suite's converged answer for an oblique case: a verdict measures an engine's
difference from it in units of each metric's scale (comparisons/verdicts.scale), against the engine tolerance
(1e-6, data/tolerances.toml) plus the time step's own error (the verlet method at the engine's dt against this same
adaptive answer). The adaptive answer's own error therefore has to be small beside 1e-6; the closed-form checks
hold the adaptive method to 1e-8 against exact solutions (tolerances.toml [closed_form]).

For every variant of the suite's oblique cases (cases/suite/oblique-*.toml, adaptive3d_suite_child.variants) at
run.rtol = 1e-13 (the default), 1e-12, 1e-11, 1e-10, 1e-9 and 1e-8: the compiled kernel's CPU time (median of
REPEAT; one run for a solve over 0.3 s), the output points, whether it completed, and the largest scaled
difference of its metrics (restitution, tangential restitution, contact time, rebound angle, rebound spin, peak
forces, energy dissipated: every metric both runs report) from the same variant at 1e-13 and from the verlet
method at 20 000 steps per contact (an independent path, but first order in dt for the damped laws: up to ~1e-3
itself, shrinking with its step — it bounds the adaptive answer only loosely). Printed: per
variant and rtol, then per rtol the worst difference over all variants and the median and total kernel time.

Run: .venv/bin/python benchmarks/bench_adaptive_rtol.py [REPEAT] > benchmarks/results/bench_adaptive_rtol.txt
"""

import json
import os
import statistics
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from adaptive3d_suite_child import variants  # noqa: E402

from demcheck import case as C  # noqa: E402
from demcheck.comparisons.verdicts import scaled  # noqa: E402
from demcheck.laws.model import resolve  # noqa: E402
from demcheck.reference import adaptive3d, collision3d  # noqa: E402
from demcheck.reference.collision import characteristic_time  # noqa: E402
from demcheck.reference.health import impact_scales  # noqa: E402

RTOLS = (1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8)


def solve(raw: dict, rtol: float, repeat: int):
    raw = json.loads(json.dumps(raw))
    raw.setdefault("run", {})["rtol"] = rtol
    case = C.from_dict(raw)
    model = resolve(case)
    orig, kernel = adaptive3d.adaptive_3d, []

    def timed(*a):
        t0 = time.process_time()
        r = orig(*a)
        kernel.append(time.process_time() - t0)
        return r

    collision3d.adaptive3d.adaptive_3d = timed
    try:
        r = collision3d.collide(case, model, "adaptive")  # warm (compiled on the first variant)
        if kernel[-1] < 0.3:
            kernel.clear()
            for _ in range(repeat):
                r = collision3d.collide(case, model, "adaptive")
    finally:
        collision3d.adaptive3d.adaptive_3d = orig
    return case, model, r, statistics.median(kernel)


def worst(a: dict, b: dict, scales: dict) -> tuple[float, str]:
    """The largest scaled difference over the metrics both report (finite), and its metric."""
    out = (0.0, "-")
    for k, v in a.items():
        w = b.get(k)
        if v is None or w is None or not np.isfinite(v) or not np.isfinite(w):
            continue
        d = scaled(v, w, k, scales)
        if np.isfinite(d) and d > out[0]:
            out = (d, k)
    return out


def main(repeat: int) -> None:
    load0 = os.getloadavg()
    print(f"adaptive 3-D tolerance against the metrics: {datetime.now(timezone.utc):%d %b %Y %H:%M} UTC, "
          f"load {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f} (2 cores, shared); kernel CPU time, median of {repeat}")
    print(f"{'variant':36s} {'rtol':>6s} {'status':>10s} {'points':>6s} {'kernel ms':>10s} "
          f"{'vs 1e-13':>9s} {'metric':>24s} {'vs verlet':>9s}")
    table = {rt: [] for rt in RTOLS}
    for label, raw in variants():
        base = None
        ver = None
        for rt in RTOLS:
            case, model, r, k = solve(raw, rt, repeat)
            m = {key: float(v) for key, v in r.metrics().items()}
            scales = impact_scales(case, model)
            if ver is None:
                dt = characteristic_time(model) / 20_000
                ver = {key: float(v) for key, v in collision3d.collide(case, model, "verlet", dt=dt).metrics().items()}
            if base is None:
                base = m
            d13, which = worst(m, base, scales)
            dv, _ = worst(m, ver, scales)
            ok = r.status == "ok"
            table[rt].append((label, ok, k, d13, dv, int(r.meta["steps"])))
            print(f"{label:36s} {rt:6.0e} {r.status:>10s} {int(r.meta['steps']):6d} {k * 1e3:10.2f} "
                  f"{d13:9.1e} {which:>24s} {dv:9.1e}", flush=True)
    print()
    print(f"{'rtol':>6s} {'completed':>9s} {'worst vs 1e-13':>14s} {'worst vs verlet':>15s} "
          f"{'median kernel ms':>16s} {'total kernel s':>14s} {'median points':>13s}")
    for rt, rows in table.items():
        done = [x for x in rows if x[1]]
        print(f"{rt:6.0e} {len(done):4d}/{len(rows):<4d} {max(x[3] for x in done):14.1e} "
              f"{max(x[4] for x in done):15.1e} {statistics.median(x[2] for x in rows) * 1e3:16.2f} "
              f"{sum(x[2] for x in rows):14.2f} {statistics.median(x[5] for x in rows):13.0f}")
    load1 = os.getloadavg()
    print(f"load at the end {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
