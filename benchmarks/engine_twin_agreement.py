"""Engine vs twin: the largest relative difference per metric over the engine tests' cases.

Run: .venv/bin/python benchmarks/engine_twin_agreement.py > benchmarks/results/engine_twin_agreement.txt
Also measures the four engine traps (docs/models.md, "Engine mapping").
"""

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from demcheck.engines import discovery  # noqa: E402
from demcheck.engines.collide import collide, twin_states  # noqa: E402
from demcheck.engines.mapping import Native  # noqa: E402
from demcheck.engines.registry import names as engine_names  # noqa: E402
from tests.helpers import glass_case  # noqa: E402
from tests.test_engines import (NORMAL_CASES, OBLIQUE_CASES, _expressible, _normal_case,  # noqa: E402
                                _oblique_case)

KEYS = ("peak_force", "restitution", "contact_time", "max_overlap", "tangential_restitution",
        "rebound_angular_velocity", "energy_dissipated")


def main():
    for e in engine_names():
        print(f"{e}: {discovery.find(e).version}")
    worst = {(e, k): (0.0, "") for e in engine_names() for k in KEYS}
    runs = 0
    for make, n in ((_normal_case, len(NORMAL_CASES)), (_oblique_case, len(OBLIQUE_CASES))):
        for p in _expressible(make, n):
            i, wall, engine = p.values
            case = make(i, wall)
            res = collide(case, engine)
            a, b = res.metrics(), twin_states(case, engine, res.dt).metrics()
            runs += 1
            for k in KEYS:
                if math.isfinite(a[k]) and math.isfinite(b[k]) and b[k] != 0:
                    d = abs(a[k] - b[k]) / abs(b[k])
                    if d >= worst[(engine, k)][0]:
                        worst[(engine, k)] = (d, p.id + ("-oblique" if make is _oblique_case else "-normal"))
    print(f"\n{runs} engine runs; largest |engine − twin| / |twin| per metric:")
    print(f"{'engine':9s} {'metric':26s} {'worst':>10s}  case")
    for (e, k), (d, where) in worst.items():
        print(f"{e:9s} {k:26s} {d:10.2e}  {where}")

    print("\nengine traps:")
    case = glass_case("hertz", {}, restitution=0.5)
    k = 4.0 / 3.0 * 71e9 / (2.0 * (1.0 - 0.22**2))
    for style in ("tsuji", "coeff_restitution"):
        nat = Native("lammps", "hertz", (k,), damping=style, damping_coeff=0.5, tangential="linear_nohistory",
                     tangential_args=(0.0, 0.0))
        print(f"  LAMMPS damping {style:17s} e_in 0.5 -> e = {collide(case, 'lammps', native=nat).metrics()['restitution']:.4f}")
    wall = glass_case("hertz", {}, wall=True, restitution=0.5)
    for limit in (False, True):
        nat = Native("liggghts", "hertz", limit=limit, tangential="off",
                     props={"restitution": 0.5, "youngs_eff": 71e9 / (1 - 0.22**2), "shear_eff": 71e9 / (2 * 1.22 * 1.78)})
        print(f"  LIGGGHTS hertz limitForce {'on ' if limit else 'off'}        e_in 0.5 -> e = "
              f"{collide(wall, 'liggghts', native=nat).metrics()['restitution']:.4f}")


if __name__ == "__main__":
    main()
