"""The N-body reference against LAMMPS (and LIGGGHTS) on the same poured packing, one core each, measured
side by side in one run: particle-steps per second (the issue's goal: the reference at least half of
LAMMPS's rate), and Yade beside them. The same initial state, the same model (LSDn + linear spring with
sliding friction: exact in LAMMPS and LIGGGHTS, approximate in Yade, whose spring alone is capped), the same
dt and duration; the engines' times include their start-up (a few tenths of a
second), so the runs are long enough for it not to matter much.

Run: .venv/bin/python benchmarks/bench_packing.py > benchmarks/results/bench_packing.txt
"""

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from demcheck import case as C  # noqa: E402
from demcheck.comparisons import packing_metrics as PM  # noqa: E402
from demcheck.engines.packing import run_engine  # noqa: E402
from demcheck.reference import packing as P  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "cases" / "packing" / "poured.toml"
ENGINES = ("lammps", "liggghts", "yade")  # the engines that pour packings (Kratos writes no packing decks)  # the default suite's, 2000 spheres


def main():
    case = C.load(CASE)
    n = len(case.particles)
    dt = P.packing_dt(case)
    duration = case.packing.duration
    steps = duration / dt
    P.simulate(case, duration=10 * dt)  # compile once
    rows = []
    t = time.perf_counter()
    st = P.simulate(case, rest=0.0)
    ref_time = time.perf_counter() - t
    nc = min(st.n_contacts, len(st.contacts))
    rows.append(("reference", ref_time, PM.compute(st.x, st.rad, box=case.packing.box, margin=1.0,
                                                   forces=st.contacts[:nc, 3])))
    for engine in ENGINES:
        t = time.perf_counter()
        run = run_engine(case, engine)
        rows.append((f"{engine} ({run.version})", time.perf_counter() - t,
                     PM.compute(run.table[["x", "y", "z"]].to_numpy(), run.table["radius"].to_numpy(),
                                box=case.packing.box, margin=1.0,
                                forces=run.contacts["fn"].to_numpy())))
    print(f"poured packing: {n} spheres, {steps:.0f} steps of {dt:.3g} s, one core each")
    print(f"{'source':36s} {'wall s':>8s} {'particle-steps/s':>17s} {'vs LAMMPS':>9s} {'solid frac':>10s} {'coord':>6s}")
    lam = rows[1][1]
    for name, wall, m in rows:
        print(f"{name:36s} {wall:8.2f} {n * steps / wall:17.3g} {lam / wall:9.2f} {m['solid_fraction']:10.4f} "
              f"{m['coordination_number']:6.2f}")
    print("\ngoal: the reference at ≥ 0.5 × LAMMPS's particle-steps per second: "
          + ("met" if lam / rows[0][1] >= 0.5 else "MISSED"))


if __name__ == "__main__":
    main()
