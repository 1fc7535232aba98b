"""Speed of the reference's adaptive method, and the cost of compiling it.

Run: .venv/bin/python benchmarks/bench_adaptive.py  (writes benchmarks/results/bench_adaptive.txt)

1. Per model: an adaptive collision at rtol = 1e-10, warm: the compiled kernel alone and the whole
   `collide()` (tables, metrics). Median of repeated runs; the machine is shared, so the numbers to read
   are the ratios within one run.
2. The 3-D solver (oblique impact at a wall, 45°, spin) per tangential law: adaptive (rtol 1e-10) and
   verlet at t_c/200, warm.
3. The 1-D skip: one frictionless oblique wall impact solved along the normal (what demcheck does) and by
   the full 3-D solver, side by side, and the two answers' agreement.
4. A command-line call with the on-disk compilation cache warm, against one with an empty cache (what every
   call would cost without numba's cache=True).
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from demcheck.reference import kernels  # noqa: E402
from demcheck.reference.collision import Geometry1D, characteristic_time, collide  # noqa: E402
from demcheck.laws.model import resolve  # noqa: E402
from demcheck.reference import collision3d  # noqa: E402
from tests.helpers import glass_case, oblique_case  # noqa: E402

TANGENTIAL = ["sliding", "viscous_sliding", "lsd_sliding", "ddt", "lth", "walton"]

MODELS = {
    "lsd": {"stiffness_method": "energy"}, "hertz": {}, "bshp": {"dissipative_constant": 1e-7},
    "kk": {"eta_n": 20.0}, "tti": {}, "hls": {"stiffness_method": "overlap"},
}


def median_time(fn, repeat=200):
    fn()
    samples = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


def main():
    lines = ["adaptive collision, rtol = 1e-10, warm (median of 200)",
             f"{'model':8s} {'kernel (ms)':>12s} {'collide() (ms)':>15s} {'steps':>6s}"]
    for name, params in MODELS.items():
        case = glass_case(name, params)
        model = resolve(case)
        geo = Geometry1D(case)
        law = model.normal_law.array()
        t_c, v = characteristic_time(model), model.pair.impact_speed

        def kernel():
            return kernels.adaptive_normal(law, model.pair.m_eff, geo.an, geo.delta0, geo.rate0, 1e-10, t_c,
                                           v * t_c, v, 300 * t_c, 100_000)

        k = median_time(kernel)
        full = median_time(lambda: collide(case, "adaptive", rtol=1e-10))
        steps = kernel()[1]
        lines.append(f"{name:8s} {k * 1e3:12.3f} {full * 1e3:15.3f} {steps:6d}")

    lines += ["", "3-D solver, oblique wall impact 45°, spin 500 rad/s, LSDn normal (median of 20)",
              f"{'tangential':16s} {'adaptive (ms)':>14s} {'verlet (ms)':>12s}"]
    for law in TANGENTIAL:
        case = oblique_case(law, angle=45.0, spin=500.0)
        a = median_time(lambda: collide(case, "adaptive", rtol=1e-10), repeat=20)
        v = median_time(lambda: collide(case, "verlet"), repeat=20)
        lines.append(f"{law:16s} {a * 1e3:14.2f} {v * 1e3:12.2f}")

    case = oblique_case("none", {}, angle=40.0)
    model = resolve(case)
    one = median_time(lambda: collide(case, "adaptive", rtol=1e-10), repeat=50)
    three = median_time(lambda: collision3d.collide(case, model, "adaptive", rtol=1e-10), repeat=50)
    m1 = collide(case, "adaptive").metrics()
    m3 = collision3d.collide(case, model, "adaptive").metrics()
    worst = max(abs(m1[k] / m3[k] - 1) for k in ("restitution", "contact_time", "max_overlap", "peak_force"))
    lines += ["", "the 1-D skip: frictionless oblique wall impact (40°), adaptive rtol 1e-10, median of 50",
              f"1-D normal solve: {one * 1e3:.3f} ms   3-D solver: {three * 1e3:.3f} ms   "
              f"ratio 3-D/1-D: {three / one:.1f}x   largest relative difference of the normal metrics: {worst:.1e}"]

    cmd = [sys.executable, "-m", "demcheck", "collide", str(ROOT / "cases" / "glass-pair.toml"), "--json"]
    def cli(env):
        t0 = time.perf_counter()
        subprocess.run(cmd, env=env, capture_output=True, check=True)
        return time.perf_counter() - t0

    env = dict(os.environ)
    cli(env)
    warm = statistics.median(cli(env) for _ in range(3))
    cold = []
    for _ in range(3):
        with tempfile.TemporaryDirectory() as d:
            cold.append(cli({**env, "NUMBA_CACHE_DIR": d}))
    cold = statistics.median(cold)
    lines += ["", "command-line call (`demcheck collide glass-pair --json`), median of 3",
              f"compilation cache warm: {warm:.2f} s", f"empty cache (compiles): {cold:.2f} s",
              f"ratio empty/warm: {cold / warm:.1f}x"]
    text = "\n".join(lines) + "\n"
    print(text)
    out = ROOT / "benchmarks" / "results" / "bench_adaptive.txt"
    out.write_text(text)


if __name__ == "__main__":
    main()
