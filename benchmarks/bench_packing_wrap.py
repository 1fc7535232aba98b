"""The reference's Verlet-list rebuilds at a periodic crossing (branch ``wrap``): the poured packing at scale
(bench_packing_scale.py's scaled case: box side 30 mm · √(N / 2000), the same bed height and duration), the
reference on one thread, with two source trees — BEFORE (its rebuild trigger the wrapped position's difference from
the positions at the last rebuild: every crossing of the periodic boundary rebuilt the list) and AFTER (the
minimum-image displacement: packing.py's ``_drift``) — alternating, each run in a process of its own with
PYTHONPATH at its tree's src (the kernels compiled or loaded first, outside the timing).

Each run: ``simulate(case, threads=1, clock=...)`` — the default chunks (2 000 steps, each starting with a list
build in its setup), the loop's clock (its counter of in-loop rebuilds, S_REBUILDS, and its phases' CPU: the force
loop, the rebuilds). The time is the process's CPU over the run (the machine's 2 cores are shared: CPU time is the
measure); the clock's reads add ~5 µs a step. The end state's solid fraction and coordination (the case's metrics)
beside it: the two trees' pours differ from the first rebuild the old rule added on (a different list, a
different summation order, then chaos), the same pour in its statistics.

Run:

    .venv/bin/python benchmarks/bench_packing_wrap.py [N,N… [DURATION [ROUNDS [BEFORE_SRC]]]] \\
        > benchmarks/results/bench_packing_wrap.txt

defaults N = 2000,8000,32000, DURATION = 0.1 s, ROUNDS = 2 (before, after, before, after …; the least CPU of each
kept), BEFORE_SRC = a tree of git 5025729's src (``git archive 5025729 src``, made in a temporary directory unless
given). AFTER is this checkout's src.
"""

import json
import os
import pickle
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BEFORE_REV = "5025729"
SIZES = (2_000, 8_000, 32_000)
DURATION = 0.1
ROUNDS = 2


def child(path: str) -> None:
    """One run of the pickled case with this process's demcheck: prints JSON."""
    import numpy as np

    from demcheck.comparisons import packing_metrics as PM
    from demcheck.reference import packing as P

    with open(path, "rb") as fh:
        case = pickle.load(fh)
    P.simulate(case, duration=10 * P.packing_dt(case), threads=1)  # compile (or load) outside the timing
    clock = np.zeros((2, 2 * P.PHASES))
    cpu, wall = time.process_time(), time.perf_counter()
    st = P.simulate(case, threads=1, clock=clock)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    m = PM.compute(st.x, st.rad, box=case.packing.box, margin=1.0)
    print(json.dumps({"cpu": cpu, "wall": wall, "steps": st.steps, "rebuilds": int(clock[-1, P.S_REBUILDS]),
                      "chunks": -(-st.steps // 2000), "force_cpu": float(clock[0, P.PHASES + P.F_WORK]) * 1e-9,
                      "rebuild_cpu": float(clock[-1, P.PHASES + P.S_REBUILD]) * 1e-9,
                      "contacts": int(st.n_contacts), "source": P.__file__,
                      "phi": m["solid_fraction"], "z": m["coordination_number"]}))


def _run(path: Path, src: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src))
    out = subprocess.run([sys.executable, __file__, "--child", str(path)], capture_output=True, text=True, env=env)
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["?"])[-1][:200]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def _before_tree(tmp: str) -> Path:
    dest = Path(tmp) / "before"
    dest.mkdir()
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", BEFORE_REV, "src"], check=True, capture_output=True)
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)
    return dest / "src"


def main(sizes, duration: float, rounds: int, before: Path | None) -> None:
    sys.path.insert(0, str(HERE))
    import bench_packing_scale as BS  # noqa: E402  (this process's demcheck: the case only)

    after = ROOT / "src"
    with tempfile.TemporaryDirectory() as tmp:
        before = before or _before_tree(tmp)
        git = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True).stdout.strip()
        print(f"rebuilds at a periodic crossing: the poured packing at scale, {duration} s, the reference on 1 thread; "
              f"{datetime.now(timezone.utc):%d %b %Y %H:%M} UTC, git {git}; before = {before}, after = {after}; "
              f"rounds {rounds}, alternating, the least CPU kept")
        print("columns: rebuilds = in-loop rebuilds (the loop's clock) + builds at the chunks' starts; CPU s = the run's "
              "process CPU; force/rebuild s = the loop's clock, CPU; load = 1-minute load average after the row")
        print(f"{'tree':7s} {'N':>7s} {'steps':>6s} {'rebuilds':>9s} {'CPU s':>8s} {'force s':>8s} {'rebuild s':>9s}"
              f" {'contacts':>8s} {'phi':>7s} {'Z':>5s} {'CPU s, each round':>24s} {'load':>5s}")
        for n, path in BS.pickled_cases(tmp, list(sizes), duration):
            runs = {"before": [], "after": []}
            for _ in range(rounds):
                for tree, src in (("before", before), ("after", after)):
                    runs[tree].append(_run(path, src))
            for tree in ("before", "after"):
                ok = [r for r in runs[tree] if "error" not in r]
                load = os.getloadavg()[0]
                if not ok:
                    print(f"{tree:7s} {n:7d}  failed: {runs[tree][0]['error']}")
                    continue
                r = min(ok, key=lambda r: r["cpu"])
                each = ", ".join(f"{x['cpu']:.2f}" for x in ok)
                print(f"{tree:7s} {n:7d} {r['steps']:6d} {r['rebuilds']:>5d}+{r['chunks']:<3d} {r['cpu']:8.2f} "
                      f"{r['force_cpu']:8.2f} {r['rebuild_cpu']:9.2f} {r['contacts']:8d} {r['phi']:7.4f} {r['z']:5.2f} {each:>24s} {load:5.2f}",
                      flush=True)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        child(sys.argv[2])
    else:
        a = sys.argv[1:]
        main([int(x) for x in a[0].split(",")] if a else SIZES, float(a[1]) if len(a) > 1 else DURATION,
             int(a[2]) if len(a) > 2 else ROUNDS, Path(a[3]) if len(a) > 3 else None)
