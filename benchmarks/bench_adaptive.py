"""Speed of the reference's adaptive method, and the cost of compiling it.

Run: .venv/bin/python benchmarks/bench_adaptive.py  (writes benchmarks/results/bench_adaptive.txt)

1. Per model: an adaptive collision at rtol = 1e-10, warm: the compiled kernel alone and the whole
   `collide()` (tables, metrics). Median of repeated runs; the machine is shared, so the numbers to read
   are the ratios within one run.
2. A command-line call with the on-disk compilation cache warm, against one with an empty cache (what every
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
from demcheck.reference.model import resolve  # noqa: E402
from tests.helpers import glass_case  # noqa: E402

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
