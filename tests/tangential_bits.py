"""Every tangential seed model through the 3-D adaptive and verlet solvers and the packing loop on a small oblique
impact: the bits of the final state (float64 as hex), for tests/test_tangential_bits.py.

The golden file tests/data/tangential_bits.json was written by this module run against the code before the
tangential laws moved to one module each (commit 8f27648, a throw-away worktree of it on PYTHONPATH):

    PYTHONPATH=/tmp/old-tslot/src:/work/wt-tslot /work/main/.venv/bin/python -m tests.tangential_bits OUT.json

(only ``demcheck``'s public solvers are called: collision3d.collide, packing.advance).
"""

from __future__ import annotations

import json
import sys

import numpy as np

# (seed model, its [contact] parameters): every registered tangential model, the truncations of the spring
VARIANTS = [("none", {}), ("sliding", {}), ("viscous", {"eta_t": 2.0}),
            ("viscous_sliding", {"eta_t": 2.0}), ("spring_sliding", {}),
            ("lsd_sliding", {"truncation": "force", "tangential_restitution": 0.5}),
            ("lsd_sliding", {"truncation": "overlap", "tangential_restitution": 0.5}),
            ("lsd_sliding", {"truncation": "spring", "tangential_restitution": 0.5}),
            ("ddt", {}), ("ddt", {"eta_t": 0.05}), ("lth", {"eta_t": 0.5}), ("zzy", {"eta_1": 1e-4}),
            ("tti", {"truncation": "force"}), ("tti", {"truncation": "overlap"}), ("tti", {"truncation": "spring"}),
            ("walton", {})]


def _hex(a) -> list[str]:
    return [float(x).hex() for x in np.asarray(a, float).ravel()]


def _case(law, params, wall):
    from tests.helpers import oblique_case

    normal = "tti" if law == "tti" else "lsd"
    return oblique_case(law, params, normal=normal, normal_params={} if normal == "tti" else None, wall=wall,
                        angle=30.0, spin=500.0,
                        overrides=[] if normal == "tti" else ["contact.reference_velocity=1.0"])


def one(law, params, wall) -> dict:
    from demcheck.laws.model import resolve
    from demcheck.reference import collision3d
    from demcheck.reference import packing as P
    from demcheck.reference.collision import auto_dt

    case = _case(law, params, wall)
    model = resolve(case)
    out = {}
    for method in ("adaptive", "verlet"):
        res = collision3d.collide(case, model, method, dt=None if method == "adaptive" else auto_dt(case))
        cols = [c for c in res.contact.columns if c != "t"]
        out[method] = {"t": _hex(res.contact["t"].to_numpy()[-3:]), "contact": _hex(res.contact[cols].to_numpy()[-3:]),
                       "particles": _hex(res.particles.groupby("id").last().to_numpy()), "rows": len(res.contact)}
    dt = auto_dt(case)
    two = collision3d.collide(case, model, "verlet", dt=dt)
    steps = int(round(two.contact["t"].iloc[-1] / dt))
    st = P.PackState(case)
    P.advance(case, st, dt, steps, None, gravity=np.zeros(3), ke_every=steps)
    out["packing"] = {"x": _hex(st.x), "v": _hex(st.v), "w": _hex(st.w)}
    return out


def compute() -> dict:
    return {f"{law}{json.dumps(params, sort_keys=True)}{'-wall' if wall else '-pair'}": one(law, params, wall)
            for law, params in VARIANTS for wall in (False, True)}


if __name__ == "__main__":
    with open(sys.argv[1], "w") as fh:
        json.dump(compute(), fh, indent=0, sort_keys=True)
