"""The 3-D adaptive solve per collision for every tangential seed model, two trees side by side.

The 32 oblique impacts of tests/tangential_bits.py (every seed model and the spring's truncations, on a wall and
of a pair): the kernel's time (``Result.wall_time``), best of ``--repeat`` in one process, each tree in its own
child process with its ``src`` first on the path, the trees alternated ``--rounds`` times (best per case over
rounds). Warm kernel caches (a first untimed collision per case). Prints one line per case and the ratios.

Run: python benchmarks/bench_tangential_laws.py --before /tmp/old-tree [--rounds 3] [--repeat 7] [--only overlap,…]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r'''
import json, sys
from demcheck.laws.model import resolve
from demcheck.reference import collision3d
from tests.tangential_bits import VARIANTS, _case
repeat = int(sys.argv[1])
only = [w for w in sys.argv[2].split(",") if w]
out = {}
for law, params in VARIANTS:
    for wall in (False, True):
        key = f"{law}{json.dumps(params, sort_keys=True)}{'-wall' if wall else '-pair'}"
        if only and not any(w in key for w in only):
            continue
        case = _case(law, params, wall)
        model = resolve(case)
        collision3d.collide(case, model, "adaptive")
        best = min(collision3d.collide(case, model, "adaptive").wall_time for _ in range(repeat))
        out[key] = best
print(json.dumps(out))
'''


def _run(tree: Path, repeat: int, only: str) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree / "src"), str(tree)]))
    p = subprocess.run([sys.executable, "-c", CHILD, str(repeat), only], cwd=tree, env=env, capture_output=True,
                       text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--before", type=Path, required=True, help="the tree before the change (its root)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--only", default="", help="comma-separated parts of the case keys to time (default: all)")
    args = ap.parse_args()
    best: dict[str, dict[str, float]] = {"before": {}, "after": {}}
    for _ in range(args.rounds):
        for side, tree in (("before", args.before), ("after", ROOT)):
            for key, t in _run(tree, args.repeat, args.only).items():
                best[side][key] = min(best[side].get(key, t), t)
    ratios = []
    for key in best["after"]:
        b, a = best["before"][key], best["after"][key]
        ratios.append(a / b)
        print(f"{key:60s} before {b * 1e3:8.3f} ms  after {a * 1e3:8.3f} ms  {a / b:6.3f}")
    print(f"total before {sum(best['before'].values()):.3f} s, after {sum(best['after'].values()):.3f} s; "
          f"median ratio {statistics.median(ratios):.3f}, max {max(ratios):.3f}; load {os.getloadavg()}")


if __name__ == "__main__":
    main()
