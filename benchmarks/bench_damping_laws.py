"""The normal force's cost per collision for every seed normal model, two trees side by side (the damping slot's
laws in one module each, issue 29 item 1).

Every seed normal model (its registry example, on a glass pair and on a wall), each through the 1-D adaptive
and verlet solvers and the 3-D adaptive solver (the kernel's time, ``Result.wall_time``, best of ``--repeat``);
and the packing loop on the two packings whose wall contacts carry a damped law (cases/packing/layer-kk.toml,
column-lsd.toml; ``--pack-steps`` steps timed, in CPU seconds, after as many untimed ones). Each tree in its own child process
with its ``src`` first on the path and a kernel cache of its own (warm: a first untimed run per case); the trees
alternated ``--rounds`` times, the best per case over rounds. Prints one line per case and the ratios.

With ``--compile``: the cold compile instead — `demcheck warmup -j 1` on an empty kernel cache, each tree in turn,
``--rounds`` times; the user CPU seconds of the process (wall seconds swing with the machine's load).

Run: python benchmarks/bench_damping_laws.py --before /tmp/old-tree [--rounds 3] [--repeat 7] [--pack-steps N]
     [--packing-only] [--compile]
"""

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r'''
import json, sys, time
from demcheck import case as C
from demcheck.laws import normal
from demcheck.laws.model import resolve
from demcheck.reference import collision, collision3d
from demcheck.reference import packing as P
from tests.helpers import glass_case
repeat, steps, packing_only = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3] == "1"
out = {}
for seed in [] if packing_only else sorted(normal.REGISTRY):
    for wall in (False, True):
        case = glass_case(seed, normal.REGISTRY[seed].example, wall=wall)
        model = resolve(case)
        runs = {"1d-adaptive": lambda: collision.collide(case, "adaptive"),
                "1d-verlet": lambda: collision.collide(case, "verlet"),
                "3d-adaptive": lambda: collision3d.collide(case, model, "adaptive")}
        for name, run in runs.items():
            run()
            out[f"{seed}-{'wall' if wall else 'pair'}-{name}"] = min(run().wall_time for _ in range(repeat))
for path in ("src/demcheck/cases/packing/layer-kk.toml", "src/demcheck/cases/packing/column-lsd.toml"):
    case = C.load(path)
    dt = P.packing_dt(case)
    best = None
    for _ in range(max(1, repeat // 3)):
        st = P.PackState(case)
        P.advance(case, st, dt, steps, ke_every=steps)
        t = time.process_time()  # (the CPU time of this process: the machine is shared)
        P.advance(case, st, dt, steps, ke_every=steps)
        took = time.process_time() - t
        best = took if best is None else min(best, took)
    out[f"packing-{case.name}"] = best
print(json.dumps(out))
'''


def _run(tree: Path, repeat: int, steps: int, packing_only: bool) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree / "src"), str(ROOT)]))
    env.pop("NUMBA_CACHE_DIR", None)  # each tree's own cache, named by its fingerprint
    p = subprocess.run([sys.executable, "-c", CHILD, str(repeat), str(steps), str(int(packing_only))], cwd=ROOT, env=env,
                       capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def _compile(tree: Path) -> tuple[float, float]:
    """(user CPU s, wall s) of `demcheck warmup -j 1` of ``tree`` on an empty kernel cache."""
    import time

    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, PYTHONPATH=str(tree / "src"), NUMBA_CACHE_DIR=str(Path(tmp) / "kernels"),
                   XDG_CACHE_HOME=str(Path(tmp) / "xdg"), DEMCHECK_CACHE=str(Path(tmp) / "runs"))
        before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "demcheck", "warmup", "-j", "1"], cwd=tmp, env=env, check=True,
                       capture_output=True)
        return resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before, time.perf_counter() - t


def compile_times(before: Path, rounds: int) -> None:
    user: dict[str, list[float]] = {"before": [], "after": []}
    for r in range(rounds):
        for side, tree in (("before", before), ("after", ROOT)):
            u, w = _compile(tree)
            user[side].append(u)
            print(f"{side} round {r + 1}: user {u:.1f} s, wall {w:.1f} s; load {os.getloadavg()}", flush=True)
    b, a = statistics.mean(user["before"]), statistics.mean(user["after"])
    print(f"cold compile, mean user CPU: before {b:.1f} s, after {a:.1f} s ({a / b - 1:+.1%})")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", type=Path, required=True, help="the tree before the change (its root, with src/)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--pack-steps", type=int, default=20000)
    ap.add_argument("--compile", action="store_true", help="time the cold compile instead")
    ap.add_argument("--packing-only", action="store_true", help="time the packing loop alone")
    args = ap.parse_args()
    if args.compile:
        compile_times(args.before, args.rounds)
        return
    best: dict[str, dict[str, float]] = {"before": {}, "after": {}}
    for _ in range(args.rounds):
        for side, tree in (("before", args.before), ("after", ROOT)):
            for key, t in _run(tree, args.repeat, args.pack_steps, args.packing_only).items():
                best[side][key] = min(best[side].get(key, t), t)
    ratios = {}
    for key in best["after"]:
        b, a = best["before"][key], best["after"][key]
        ratios[key] = a / b
        print(f"{key:32s} before {b * 1e3:9.3f} ms  after {a * 1e3:9.3f} ms  {a / b:6.3f}")
    for group in ("1d-adaptive", "1d-verlet", "3d-adaptive", "packing"):
        sel = [k for k in ratios if group in k]
        if not sel:
            continue
        tb, ta = sum(best["before"][k] for k in sel), sum(best["after"][k] for k in sel)
        print(f"{group}: total before {tb:.4f} s, after {ta:.4f} s ({ta / tb:.3f}); median ratio "
              f"{statistics.median(ratios[k] for k in sel):.3f}, max {max(ratios[k] for k in sel):.3f}")
    print(f"load {os.getloadavg()}")


if __name__ == "__main__":
    main()
