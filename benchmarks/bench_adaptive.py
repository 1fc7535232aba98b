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
5. With --before PATH (a tree's root, e.g. `git worktree add /tmp/before BASE`): the suite's oblique cases, every
   variant, at their default tolerance (rtol 1e-13), the tree before a change and this one side by side in one run
   (each in a child process: adaptive3d_suite_child.py), with each variant's accuracy against the converged verlet
   answer (the verlet method at 20 000 steps per contact) beside the time, and whether the two trees' metrics are
   identical. The machine's load average is recorded; read the ratios.

Run: .venv/bin/python benchmarks/bench_adaptive.py [--before PATH [--rounds N]] [--only-suite]
"""

import argparse
import json
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


def _child(src: Path, repeat: int, name: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(src)}  # (numba caches each tree's kernels beside its sources)
    out = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "adaptive3d_suite_child.py"), str(repeat), name],
                         env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _both(before: Path, repeat: int, rounds: int = 1) -> tuple[dict, dict, list]:
    """Both trees, one suite file at a time, taking turns at going first (the load shifts during the run), ``rounds``
    times over (the next round starts with the other tree); each variant's times are the median over the rounds of
    each round's median. Returns the two trees' results and the load average after each round."""
    runs = {"old": [], "new": []}
    loads = []
    names = sorted(p.stem for p in (ROOT / "src" / "demcheck" / "cases" / "suite").glob("oblique-*.toml"))
    for r in range(rounds):
        old, new = {}, {}
        for k, name in enumerate(names):
            first, second = (before / "src", old), (ROOT / "src", new)
            for src, into in ((first, second) if (k + r) % 2 == 0 else (second, first)):
                into.update(_child(src, repeat, name))
        runs["old"].append(old)
        runs["new"].append(new)
        loads.append(os.getloadavg())
        print(f"round {r + 1} of {rounds} done, load {loads[-1][0]:.2f}", file=sys.stderr, flush=True)
    merged = []
    for tree in ("old", "new"):
        out = {}
        for label, first in runs[tree][0].items():
            out[label] = dict(first, kernel=statistics.median(run[label]["kernel"] for run in runs[tree]),
                              collide=statistics.median(run[label]["collide"] for run in runs[tree]),
                              kernels=[run[label]["kernel"] for run in runs[tree]])
            if any(run[label]["metrics"] != first["metrics"] or run[label]["points"] != first["points"]
                   for run in runs[tree]):
                out[label]["metrics"] = None  # a tree that does not repeat its own answer: reported as DIFFER
        merged.append(out)
    return merged[0], merged[1], loads


def _verlet_error(label: str, metrics: dict) -> float:
    """The largest relative difference of the adaptive answer from the verlet method's at 20 000 steps per
    contact, over restitution, tangential restitution, contact time and rebound spin."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from adaptive3d_suite_child import variants

    raw = dict(variants())[label]
    from demcheck import case as C

    case = C.from_dict(raw)
    model = resolve(case)
    v = collision3d.collide(case, model, "verlet", dt=characteristic_time(model) / 20_000).metrics()
    keys = ("restitution", "tangential_restitution", "contact_time", "rebound_angular_velocity")
    return max(abs(metrics[k] / v[k] - 1.0) for k in keys if metrics.get(k) and v.get(k))


def suite_section(before: Path, rounds: int = 1) -> list[str]:
    load0 = os.getloadavg()
    old, new, loads = _both(before, 5, rounds)
    load1 = os.getloadavg()
    lines = ["", f"5. the suite's oblique cases at their default tolerance (rtol 1e-13), before ({before}) and after, "
             f"one run, the two trees taking turns case file by case file, median CPU time of 5 (1 for a solve over "
             f"0.3 s)" + (f"; {rounds} rounds, each starting with the other tree: a variant's time is the median of "
                          "its rounds' medians" if rounds > 1 else ""),
             f"load average (1, 5, 15 min) at the start {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, "
             f"at the end {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f} (2 cores, shared)"
             + (", 1 min after each round " + " ".join(f"{ld[0]:.2f}" for ld in loads) if rounds > 1 else ""),
             f"{'variant':36s} {'points':>6s} {'kernel before':>13s} {'after (ms)':>10s} {'ratio':>6s} "
             f"{'collide() after':>15s} {'vs verlet':>9s} {'metrics':>9s}"]
    ratios, kern, same_all = [], [], True
    for label, b in old.items():
        a = new[label]
        same = a["metrics"] == b["metrics"] and a["points"] == b["points"]
        same_all &= same
        err = _verlet_error(label, a["metrics"]) if a["metrics"] is not None else float("nan")
        ratios.append(b["kernel"] / a["kernel"])
        kern.append(a["kernel"])
        lines.append(f"{label:36s} {a['points']:6d} {b['kernel'] * 1e3:13.2f} {a['kernel'] * 1e3:10.2f} "
                     f"{ratios[-1]:6.2f} {a['collide'] * 1e3:15.2f} {err:9.1e} {'same' if same else 'DIFFER':>9s}")
    lines += [f"{len(ratios)} variants: kernel after, median {statistics.median(kern) * 1e3:.2f} ms, "
              f"least {min(kern) * 1e3:.2f} ms, most {max(kern) * 1e3:.1f} ms; speed-up before/after median "
              f"{statistics.median(ratios):.2f}x (least {min(ratios):.2f}x, most {max(ratios):.2f}x); metrics and "
              f"points of every variant {'identical' if same_all else 'NOT identical'}"]
    if rounds > 1:
        per_round = [statistics.median(b["kernels"][r] / new[label]["kernels"][r] for label, b in old.items())
                     for r in range(rounds)]
        lines.append("speed-up before/after, median over the variants, each round alone: "
                     + " ".join(f"{x:.2f}x" for x in per_round))
    return lines


def main(before: Path | None = None, only_suite: bool = False, rounds: int = 1):
    if only_suite:
        text = "\n".join(suite_section(before, rounds)) + "\n"
        print(text)
        out = ROOT / "benchmarks" / "results" / "bench_adaptive.txt"
        kept = out.read_text().split("\n5. the suite's oblique cases")[0].rstrip("\n") + "\n"
        out.write_text(kept + text)
        return
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
    if before is not None:
        lines += suite_section(before, rounds)
    text = "\n".join(lines) + "\n"
    print(text)
    out = ROOT / "benchmarks" / "results" / "bench_adaptive.txt"
    out.write_text(text)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", type=Path, help="a tree (its root) to time side by side with this one (section 5)")
    ap.add_argument("--only-suite", action="store_true", help="run section 5 only (replacing it in the results)")
    ap.add_argument("--rounds", type=int, default=1, help="section 5: run both trees this many times over")
    args = ap.parse_args()
    main(args.before, args.only_suite, args.rounds)
