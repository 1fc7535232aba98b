"""Writes tests/data/packing_golden.npz: the final state (x, v, ω) of three short pours by the packing solver as it was
before its rolling slot and segment walls (main at 7b9469c), each with its case text — the golden that
tests/test_packing_rolling.py holds the solver to, bit for bit, where a case names no rolling law and only plane walls.

    git archive 7b9469c src | tar -x -C /tmp/golden
    PYTHONPATH=/tmp/golden/src python tests/data/make_packing_golden.py tests/data/packing_golden.npz

Never run it against the code under test: the golden is the old solver's answer."""

import sys

import numpy as np

from demcheck import case as C
from demcheck.reference import packing as P

BASE = """
name = "golden-pour"
kind = "packing"
[materials.glass]
density = 2500.0
youngs_modulus = 1e8
poisson_ratio = 0.3
restitution = 0.3
friction = 0.5
[packing]
layout = "poured"
count = 150
material = "glass"
radii = [0.8e-3, 1.0e-3, 1.2e-3]
box = [0.011, 0.011]
seed = 3
duration = 0.03
[[walls]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[contact]
{contact}
[run]
gravity = [0.0, 0.0, -9.81]
steps_per_contact = 40
"""
CASES = {  # name → (contact table, threads)
    "spring_1": ('normal = "lsd"\nkn = 2000.0\ntangential = "spring_sliding"', 1),
    "spring_2": ('normal = "lsd"\nkn = 2000.0\ntangential = "spring_sliding"', 2),
    "tti_1": ('normal = "tti"\ntangential = "tti"', 1),
}


def main(out):
    arrays = {}
    for name, (contact, threads) in CASES.items():
        text = BASE.format(contact=contact)
        st = P.simulate(C.loads(text), rest=0.0, threads=threads)
        arrays[f"{name}_case"] = np.array(text)
        arrays[f"{name}_threads"] = np.array(threads)
        for key in ("x", "v", "w"):
            arrays[f"{name}_{key}"] = getattr(st, key)
        print(name, st.n_contacts, st.time)
    np.savez_compressed(out, **arrays)


if __name__ == "__main__":
    main(sys.argv[1])
