"""The normal slot's force through every solver that calls it, as bits: for tests/test_normal_bits.py (the normal
laws one module each — hooke, hertz, hls — and a generated switch on the law array's family column, issue 29
item 1).

* ``grid``: every seed normal model's law array (limit on and off) and every engine twin's law array of them (on a
  pair and on a wall), through the facade the solvers import (laws/normal_force.py: ``normal_force``,
  ``viscoelastic_force``, ``viscoelastic_contact_force``, ``viscoelastic_force_rate``, ``hls_unloading``), the 1-D
  adaptive solver's force and dF/dt events (``kernels._event_value``) and the 3-D adaptive solver's mode force
  (``adaptive3d._contact_force``), in the modes the solvers ask them in, on a grid of overlaps and rates (signs
  and zero included): float64 as hex.
* ``cases``: tests/damping_bits.py's digests of the case files (every variant through the reference's adaptive
  and verlet methods, 1-D where the case is and then through the 3-D solvers too, and every packing through 3000
  steps of the packing loop): the test's share, or with ``--all`` every case file.

The golden file tests/golden/normal_bits.json was written by this module run against main at 7b9469c (the code
before the change: hooke and hertz one module, the hand-written switch), a detached worktree of it first on the
path:

    git worktree add --detach /tmp/normal-old 7b9469c
    PYTHONPATH=/tmp/normal-old/src:/work/wt-normal /work/main/.venv/bin/python -m tests.normal_bits \\
        tests/golden/normal_bits.json --all

(only ``demcheck``'s public solvers, the normal force facade and the solvers' force functions are called).
"""

from __future__ import annotations

import json
import sys

import numpy as np

from .damping_bits import CASES, SEEDS, case_files, law_arrays, one_case

DELTAS = [-1e-4, -0.0, 0.0, 1e-12, 3.7e-7, 1e-5, 2.5e-4]
RATES = [-2.0, -1e-3, 0.0, 1e-3, 0.7, 3.0]


def twin_arrays() -> dict:
    """Every engine twin's law array of every seed normal model's example, on a pair and on a wall (an engine
    that refuses a model has none)."""
    from demcheck.engines import mapping, registry
    from demcheck.laws import normal
    from demcheck.laws.model import resolve
    from tests.helpers import glass_case

    out = {}
    for seed in SEEDS:
        for wall in (False, True):
            case = glass_case(seed, normal.REGISTRY[seed].example, wall=wall)
            model = resolve(case)
            for name in ("lammps", "liggghts", "yade", "kratos"):
                mp = mapping.map_model(model, name, dict(case.contact.params))
                if mp.native is None:
                    continue
                nl, _ = registry.get(name).twin(mp.native, model.pair.m_eff, model.pair.r_eff)
                out[f"{seed}-{'wall' if wall else 'pair'}-{name}"] = nl.array()
    return out


def values(law) -> list[float]:
    """The law's forces on the grid, through every function of the facade and the solvers' force functions."""
    from demcheck.laws import normal_force as N
    from demcheck.reference import adaptive3d as A3
    from demcheck.reference import kernels as K

    out = []
    branched = N.loads_and_unloads(law)
    for d in DELTAS:
        for r in RATES:
            dmax = max(d, 0.0) * 1.5
            dmax = dmax if dmax > 0.0 or not branched else 1e-6
            out.append(N.normal_force(law, d, r, dmax))
            if branched:
                out.extend(N.hls_unloading(law, dmax))
                modes = (K.M_LOAD, K.M_UNLOAD, K.M_FREE)
            else:  # (the solvers never ask the branched law for a viscoelastic force)
                out += [N.viscoelastic_force(law, d, r), N.viscoelastic_contact_force(law, d, r)]
                if d != 0.0:  # (δ^{a−1}, δ^{b−1} have no value at 0)
                    out.append(N.viscoelastic_force_rate(law, d, r, -7.3e3))
                modes = (K.M_VE, K.M_FREE)
            for mode in modes:
                # (the dF/dt event is the viscoelastic branch's, live in M_VE only)
                for event in ((1, 3) if d != 0.0 and not branched else (1,)):
                    out.append(K._event_value(law, np.int64(mode), np.int64(event), d, r, dmax, 2e-6, -9.81))
                out.append(A3._contact_force(law, float(mode), d, r, dmax))
    return out


def grid() -> dict:
    arrays = {**law_arrays(), **twin_arrays()}
    return {name: [float(v).hex() for v in values(law)] for name, law in arrays.items()}


def compute(every: bool = False) -> dict:
    return {"grid": grid(), "cases": {str(p.relative_to(CASES)): one_case(p) for p in case_files(every)}}


def compare(golden: dict, every: bool = False) -> dict:
    """(for a full check by hand) the number of case files, variants and solver runs compared, and the differing
    ones, against ``golden``."""
    now = compute(every)
    files = variants = runs = 0
    bad = [name for name, v in golden["grid"].items() if now["grid"].get(name) != v]
    for path, cases in now["cases"].items():
        files += 1
        for name, row in cases.items():
            variants += 1
            runs += len(row) if isinstance(row, dict) else 1
            if golden["cases"].get(path, {}).get(name) != row:
                bad.append(f"{path}:{name}")
    return {"files": files, "variants": variants, "solver_runs": runs,
            "grid_values": sum(len(v) for v in now["grid"].values()), "laws": len(now["grid"]), "differ": bad}


if __name__ == "__main__":  # OUT.json [--all] | --check GOLDEN.json [--all]
    every = "--all" in sys.argv[2:]
    if sys.argv[1] == "--check":
        with open(sys.argv[2]) as fh:
            print(json.dumps(compare(json.load(fh), "--all" in sys.argv[3:])))
    else:
        with open(sys.argv[1], "w") as fh:
            json.dump(compute(every), fh, indent=0, sort_keys=True)
