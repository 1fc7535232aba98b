"""The toy engine's executable: ``-h`` prints its banner; ``-in DECK -log F -screen F`` runs the deck (the
reference verlet method) and writes ``dump.txt`` in LAMMPS's ``dump custom`` format."""

from __future__ import annotations

import json
import sys

import numpy as np


def main(argv: list[str]) -> int:
    if "-h" in argv:
        print("toy engine 1.0 (demcheck's reference verlet method in a subprocess)")
        return 0
    deck = argv[argv.index("-in") + 1]
    d = json.loads(open(deck).read())
    from demcheck import case as C
    from demcheck.engines.output import STATE_COLUMNS as DUMP_COLUMNS
    from demcheck.inputs.common import DUMP_FILE
    from demcheck.reference import collision3d
    from demcheck.laws.model import resolve

    case = C.from_dict(d["case"])
    res = collision3d.collide(case, resolve(case), "verlet", dt=d["dt"],
                              rules={"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "contact",
                                     "rotation": "rescale"})
    c, parts = res.contact, res.particles
    f0 = -c["fn"].to_numpy()[:, None] * c[["nx", "ny", "nz"]].to_numpy() + c[["ftx", "fty", "ftz"]].to_numpy()
    n = len(case.particles)
    with open(DUMP_FILE, "w") as out:
        for k, (_, row0) in enumerate(parts[parts["id"] == 0].iterrows()):
            step = round(row0["t"] / d["dt"])
            if step > d["steps"]:
                break
            out.write(f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{n}\nITEM: BOX BOUNDS ff ff ff\n"
                      "-1 1\n-1 1\n-1 1\n")
            out.write("ITEM: ATOMS " + " ".join(DUMP_COLUMNS) + "\n")
            for i in range(n):
                row = parts[(parts["id"] == i)].iloc[k]
                p = case.particles[i]
                # an engine's force on a body: the contact's, and its weight
                f = (f0[k] if i == 0 else -f0[k]) + case.mass(i) * np.asarray(case.run.gravity, float)
                vals = [i + 1, i + 1, 2 * p.radius, case.mass(i), row["x"], row["y"], row["z"], row["vx"], row["vy"],
                        row["vz"], row["wx"], row["wy"], row["wz"], *f, 0.0, 0.0, 0.0]
                out.write(" ".join(repr(float(v)) if j > 1 else str(int(v)) for j, v in enumerate(vals)) + "\n")
    print(f"toy engine: {k + 1} steps written")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
