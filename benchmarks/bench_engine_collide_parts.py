"""Where an engine collision's time goes through `collide` with the engine's worker (issue 33, item 4: a collision
≤ 3× its engine loop): per collision, the engine's own loop (RunOutput.loop_time), the worker round trip beyond
it (RunOutput.wall_time − loop), reading the dump (dumps.read_dump) and everything else in collide + metrics (the
deck, the twin's states, the health rules, the metrics), median over N collisions; beside them, the same dump read
line by line (dumps._read_dump_lines: the reader before issue 33's, timed on the same file in the same run, not
counted in the total) (impact speeds 0.5 … 2 m/s) of
each engine and case, in one process, the engines one after another. The machine is shared: the load average is
printed, and the ratios are what to read.

Run: .venv/bin/python benchmarks/bench_engine_collide_parts.py [--n 20] \
     > benchmarks/results/bench_engine_collide_parts.txt
"""

import argparse
import os
import statistics
import time
from pathlib import Path

from demcheck import case as C
from demcheck.engines import dumps, run as runner
from demcheck.engines import collide as engine_collide

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ["lammps", "liggghts", "yade", "kratos"]
CASES = ["hertz-wall", "glass-pair", "oblique-lsd-wall"]


def measure(engine: str, name: str, n: int) -> dict | None:
    runs, reads, old_reads = [], [], []
    real_run, real_read = runner.run, dumps.read_dump

    def run(*a, **k):
        out = real_run(*a, **k)
        runs.append(out)
        return out

    def read(*a, **k):
        t0 = time.perf_counter()
        table = real_read(*a, **k)
        reads.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        dumps._read_dump_lines(Path(a[0]), k.get("columns"))
        old_reads.append(time.perf_counter() - t0)
        return table

    runner.run, dumps.read_dump = run, read
    try:
        cases = [C.load(ROOT / "cases" / f"{name}.toml", [f"impact.speed={0.5 + 1.5 * i / max(n - 1, 1)!r}"])
                 for i in range(n)]
        try:
            engine_collide.collide(cases[0], engine, worker=True).metrics()  # the worker's start: not marginal
        except Exception as e:  # an engine that cannot express the case
            return {"skip": type(e).__name__}
        rows = []
        for c in cases:
            runs.clear()
            reads.clear()
            old_reads.clear()
            t0 = time.perf_counter()
            engine_collide.collide(c, engine, worker=True).metrics()
            total = time.perf_counter() - t0 - sum(old_reads)
            loop = sum(r.loop_time or 0.0 for r in runs)
            trip = sum(r.wall_time for r in runs) - loop
            read = sum(reads)
            rows.append((total, loop, trip, read, total - loop - trip - read, sum(old_reads)))
        med = [statistics.median(r[k] for r in rows) for k in range(6)]
        return dict(zip(("total", "loop", "trip", "read", "rest", "old_read"), med))
    finally:
        runner.run, dumps.read_dump = real_run, real_read


def main(n: int) -> None:
    load0 = os.getloadavg()
    print(f"engine collision through collide(worker=True) + metrics: median of {n} collisions, ms "
          f"(load average at the start {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}; 2 cores, shared)")
    print(f"{'engine':9s} {'case':18s} {'loop':>7s} {'round trip':>10s} {'dump read':>9s} {'rest':>7s} "
          f"{'total':>7s} {'total/loop':>10s} {'read line by line':>17s} {'total/loop with it':>18s}")
    for engine in ENGINES:
        for name in CASES:
            m = measure(engine, name, n)
            if m is None or "skip" in m:
                print(f"{engine:9s} {name:18s} not run ({m and m['skip']})")
                continue
            print(f"{engine:9s} {name:18s} {m['loop'] * 1e3:7.2f} {m['trip'] * 1e3:10.2f} {m['read'] * 1e3:9.2f} "
                  f"{m['rest'] * 1e3:7.2f} {m['total'] * 1e3:7.2f} {m['total'] / m['loop']:10.2f} "
                  f"{m['old_read'] * 1e3:17.2f} {(m['total'] - m['read'] + m['old_read']) / m['loop']:18.2f}",
                  flush=True)
    load1 = os.getloadavg()
    print(f"load average at the end {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=20)
    main(ap.parse_args().n)
