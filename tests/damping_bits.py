"""The normal force of every seed normal model, through every solver that calls it: bit digests, for
tests/test_damping_bits.py.

* ``cases``: the collision cases of src/demcheck/cases — the top-level ones, the suite's normal impacts and the
  packings, or with ``--all`` every file in every sub-folder; variants expanded; the scenarios beyond sliding
  compute no normal law of the kernels and are left out — through the reference's adaptive and verlet methods
  (1-D where the case is, else 3-D) and, for a 1-D case, through the 3-D solvers too; every packing case through
  a short run of the packing loop. A digest (sha256) of the float64 bytes of
  every column of the contact table, the particles table and the events.
* ``grid``: the compiled normal force (laws/normal_force.py: normal_force, viscoelastic_force) and the 1-D
  adaptive solver's force and dF/dt events (kernels._event_value, events 1 and 3) of every seed normal model's
  law array, limit on and off, in the modes the solvers ask them in, on a grid of overlaps and rates (signs and
  zero included), as float64 hex.

The golden file tests/data/damping_bits.json was written by this module run against the code before the damping
slot got its own compiled functions (main at 215e3c3, a throw-away export of it on PYTHONPATH):

    PYTHONPATH=/tmp/old-damp/src:/work/wt-damp /work/main/.venv/bin/python -m tests.damping_bits OUT.json

(only ``demcheck``'s public solvers and the normal force facade are called).
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

CASES = Path(__file__).resolve().parents[1] / "src" / "demcheck" / "cases"
PACK_STEPS = 3000
# every seed normal model with the parameters of a typical use (each one's example, on a glass pair)
SEEDS = ("lsd", "hertz", "bshp", "kk", "tti", "hls")


def _digest(table) -> str:
    h = hashlib.sha256()
    if table is None:
        return ""
    items = table.items() if isinstance(table, dict) else ((c, table[c]) for c in table.columns)
    for name, col in items:
        h.update(str(name).encode())
        a = np.asarray(col)
        h.update(a.astype(float).tobytes() if a.dtype != object else "|".join(map(str, a)).encode())
    return h.hexdigest()[:24]


def _result(res) -> list:
    return [_digest(res.contact), _digest(res.particles), _digest(res.events), res.status, len(res.contact["t"])]


def case_files(every: bool = False) -> list[Path]:
    """Every case file (``every``), or the test's share: the top-level cases, the suite's normal impacts (every
    seed normal model, on a wall and of a pair) and the packings (the packing loop on kk and lsd)."""
    if every:
        return sorted(CASES.rglob("*.toml"))
    return sorted([*CASES.glob("*.toml"), *CASES.glob("suite/normal-*.toml"), *CASES.glob("packing/*.toml")])


def one_case(path: Path) -> dict:
    from demcheck import case as C
    from demcheck.laws.model import resolve
    from demcheck.reference import collision, collision3d
    from demcheck.reference import packing as P

    out = {}
    for case in C.expand(path):
        if getattr(case.run, "scenario", "collision") != "collision":
            continue
        if case.kind == "packing":
            st = P.PackState(case)
            ke, nc, flags = P.advance(case, st, P.packing_dt(case), PACK_STEPS, ke_every=PACK_STEPS)
            out[case.name] = [_digest({"x": st.x, "v": st.v, "w": st.w, "hist": st.hist, "ke": ke}), int(nc)]
            continue
        model = resolve(case)
        row = {m: _result(collision.collide(case, m)) for m in ("adaptive", "verlet")}
        if collision.is_one_dimensional(case, model):
            dt = collision.auto_dt(case)
            row.update({f"3d-{m}": _result(collision3d.collide(case, model, m, dt=None if m == "adaptive" else dt))
                        for m in ("adaptive", "verlet")})
        out[case.name] = row
    return out


def law_arrays() -> dict:
    import dataclasses

    from demcheck.laws import normal
    from demcheck.laws.model import resolve
    from tests.helpers import glass_case

    out = {}
    for seed in SEEDS:
        law = resolve(glass_case(seed, normal.REGISTRY[seed].example)).normal_law
        for limit in (False, True):
            out[f"{seed}{'-limited' if limit else ''}"] = dataclasses.replace(law, limit=limit).array()
    return out


def grid() -> dict:
    from demcheck.laws import normal_force as N
    from demcheck.reference import kernels as K

    deltas = [-1e-4, -0.0, 0.0, 1e-12, 3.7e-7, 1e-5, 2.5e-4]
    rates = [-2.0, -1e-3, 0.0, 1e-3, 0.7, 3.0]
    out = {}
    for name, law in law_arrays().items():
        vals = []
        for d in deltas:
            for r in rates:
                dmax = max(d, 0.0) * 1.5
                hls = N.loads_and_unloads(law)
                dmax = dmax if dmax > 0.0 or not hls else 1e-6
                vals.append(N.normal_force(law, d, r, dmax))
                if not hls:  # (the solvers never ask the hysteretic law for a viscoelastic force)
                    vals.append(N.viscoelastic_force(law, d, r))
                for mode in (K.M_LOAD, K.M_UNLOAD, K.M_FREE) if hls else (K.M_VE, K.M_FREE):
                    # (the dF/dt event is the viscoelastic branch's, live in M_VE only; δ^{b−1} has no value at 0)
                    for event in ((1, 3) if d != 0.0 and not hls else (1,)):
                        vals.append(K._event_value(law, np.int64(mode), np.int64(event), d, r, dmax, 2e-6, -9.81))
        out[name] = [float(v).hex() for v in vals]
    return out


def compute(every: bool = False) -> dict:
    return {"grid": grid(), "cases": {str(p.relative_to(CASES)): one_case(p) for p in case_files(every)}}


if __name__ == "__main__":  # OUT.json [--all: every case file, not only the test's share]
    with open(sys.argv[1], "w") as fh:
        json.dump(compute("--all" in sys.argv[2:]), fh, indent=0, sort_keys=True)
