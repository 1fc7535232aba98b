"""Why the reference's Hertz–Mindlin packing keeps more residual motion than the engines (docs/packing.md):
the seed's TTIt under its min() cap (truncation "force") against the same packing with LAMMPS's law
(truncation "overlap", LAMMPS's kinematic rules), both in the reference, same initial state. Prints the
translational kinetic energy at the end, the rotational one, and the largest tangential spring extension.

Run: .venv/bin/python benchmarks/packing_residual_motion.py > benchmarks/results/packing_residual_motion.txt
"""

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from demcheck.case import load  # noqa: E402
from demcheck.engines.registry import get as engine  # noqa: E402
from demcheck.reference import packing as P  # noqa: E402

CASE = ROOT / "cases" / "optin" / "poured-hertz.toml"


def main():
    print(f"{CASE.name}: 2000 spheres, TTIn × TTIt, settled for 0.3 s in the reference")
    print(f"{'tangential law':44s} {'KE transl. (J)':>14s} {'KE rot. (J)':>12s} {'max |ξ| (m)':>12s} {'max δ (m)':>10s}")
    for label, over, rules in (("seed TTIt, min() cap (truncation force)", [], None),
                               ("LAMMPS's: Maw limit, LAMMPS rules", ["contact.truncation=overlap"], engine("lammps").rules)):
        case = load(CASE, over)
        st = P.simulate(case, rest=0.0, rules=rules)
        rot = 0.5 * float((0.4 * st.mass * st.rad**2 * (st.w**2).sum(1)).sum())
        ext = float(np.linalg.norm(st.hist[:, :3], axis=1).max()) if len(st.hist) else 0.0
        nc = min(st.n_contacts, len(st.contacts))
        print(f"{label:44s} {st.ke[-1][1]:14.3g} {rot:12.3g} {ext:12.3g} {st.contacts[:nc, 2].max():10.3g}")


if __name__ == "__main__":
    main()
