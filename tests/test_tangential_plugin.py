"""Adding a tangential law touches that law's module only (issue 29 item 1): a law written as one module outside
demcheck's source — its record, family id, compiled force and users' name — is named in $DEMCHECK_LAW_PLUGINS
and then collides in the reference's 3-D adaptive and verlet solvers (against its closed form) and is refused by
every engine's vocabulary with a reason, with no other file edited; and the solvers' switch names no law."""

from pathlib import Path

import numpy as np

from .helpers import with_plugin_law

ROOT = Path(__file__).resolve().parents[1]

TOY = '''
"""A toy tangential law: a drag of constant magnitude F0 against the slip, F = −F0 t̂ (none at zero slip)."""
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from demcheck import KERNEL_CACHE
from demcheck.laws.normal import Param
from demcheck.laws.tangential import TangentialLaw, TangentialModel, register
from demcheck.laws.tangential_laws.common import _norm
from demcheck.laws.tangential_slot import T_P0, TangentialSubModel, compiled


@dataclass(frozen=True)
class ConstantDrag(TangentialSubModel):
    id: ClassVar[str] = "constant_drag"
    family: ClassVar[int] = 40
    title: ClassVar[str] = "constant drag"
    drag: float = 0.0


@njit(cache=KERNEL_CACHE)
def constant_drag_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    vn = _norm(vt)
    if vn == 0.0:
        return np.zeros(3)
    return -(tl[T_P0] / vn) * vt


compiled(ConstantDrag, force=constant_drag_tangential_force)


def _resolve(pair, params, normal):
    drag = float(params["drag"])
    return TangentialLaw.from_slot(ConstantDrag(drag=drag)), {"drag": drag}


register(TangentialModel(id="constant_drag", seed_name="toy", title="Constant drag", formula="Ft = -F0 t",
                         source="tests/test_tangential_plugin.py", params=(Param("drag", "F0 (N)"),),
                         resolve=_resolve, example={"drag": 1e-3}))
'''

RUN = r'''
import json, math
import numpy as np
from demcheck.engines import mapping, registry
from demcheck.laws.model import resolve
from demcheck.reference import collision3d
from demcheck.reference.collision import auto_dt
from tests.helpers import oblique_case

ARMS = {"slip_arm": "radius", "torque_arm": "radius", "wall_torque_arm": "radius"}
free = oblique_case("none", {}, angle=45.0)
tc = collision3d.collide(free, resolve(free), "adaptive", rules=ARMS).metrics()["contact_time"]
p = free.particles[0]
r = p.radius
m = free.materials[p.material].density * 4.0 / 3.0 * math.pi * r ** 3
drag = 0.1 * m * math.sqrt(0.5) / tc  # a tenth of the tangential momentum: the slip never stops
case = oblique_case("constant_drag", {"drag": drag}, angle=45.0)
model = resolve(case)
out = {"family": float(model.tangential_law.array()[0]), "tc": tc, "drag": drag, "m": m, "r": r,
       "inertia": 0.4 * m * r * r, "v0": [float(x) for x in case.particles[0].velocity]}
for method in ("adaptive", "verlet"):
    res = collision3d.collide(case, model, method, rules=ARMS, dt=None if method == "adaptive" else auto_dt(case))
    last = res.particles.groupby("id").last()
    out[method] = {"v": last.loc[0, ["vx", "vy", "vz"]].tolist(), "w": last.loc[0, ["wx", "wy", "wz"]].tolist(),
                   "tc": res.metrics()["contact_time"]}
out["engines"] = {}
for name in registry.names():
    mp = mapping.map_model(model, name, dict(case.contact.params))
    out["engines"][name] = [mp.fidelity, mp.reasons]
print(json.dumps(out))
'''


def test_a_tangential_law_in_one_module_runs_in_the_reference_and_is_refused_by_every_engine(tmp_path):
    out = with_plugin_law(tmp_path, "toy_drag_law", TOY, RUN)
    assert out["family"] == 40.0
    # a constant drag F0 opposite the slip for the whole contact (the slip keeps its direction: a tenth of the
    # momentum is taken): m Δv_t = −F0 tc, I Δω = F0 R tc (radius arms), the normal motion as without friction
    t_hat = np.array(out["v0"]) - np.dot(out["v0"], [0, 0, 1.0]) * np.array([0, 0, 1.0])
    t_hat /= np.linalg.norm(t_hat)
    impulse = out["drag"] * out["tc"]
    for method, rtol in (("adaptive", 1e-6), ("verlet", 2e-3)):
        got = out[method]
        assert abs(got["tc"] - out["tc"]) <= rtol * out["tc"]
        dv = np.array(got["v"]) - np.array(out["v0"])
        np.testing.assert_allclose(out["m"] * np.dot(dv, t_hat), -impulse, rtol=rtol)
        assert np.linalg.norm(np.array(got["w"])) == pytest_approx(impulse * out["r"] / out["inertia"], rtol)
    for name, (fidelity, reasons) in out["engines"].items():
        assert fidelity == "none" and reasons and all(r.strip() for r in reasons), (name, fidelity, reasons)


def pytest_approx(x, rtol):
    import pytest

    return pytest.approx(x, rel=rtol)


def test_the_solvers_switch_names_no_tangential_law():
    """The dispatch on the family id is assembled from the registered laws: its facade and its generator name
    none of them; each built-in law's compiled force is in its own module and nowhere else."""
    from demcheck.laws import tangential_dispatch, tangential_force, tangential_slot  # noqa: F401 (the laws registered)

    import re

    laws = ROOT / "src" / "demcheck" / "laws"
    # the facade imports no law's module (the packing loop asks the traits; its spring fast path imports the
    # spring's module itself), only the shared helpers of laws/tangential_laws/common.py
    source = (laws / "tangential_force.py").read_text()
    named = re.findall(r"^from \.tangential_laws\.(\w+) import .*$", source, flags=re.M)
    assert sorted(named) == ["common"], named
    facade = source.split('"""', 2)[2]
    assert "walton" not in facade.lower() and "spring" not in facade.lower()
    text = facade + (laws / "tangential_dispatch.py").read_text()
    assert len(tangential_slot.KERNELS) >= 8  # every seed family registered: the loop below checks each
    for family, k in tangential_slot.KERNELS.items():
        record = tangential_slot.records(family)[0]
        name = k.force.py_func.__name__
        assert name not in text and f"{record.id}_" not in text.replace("tangential_force", "")
        owners = [f for f in (ROOT / "src").rglob("*.py") if f"def {name}(" in f.read_text()]
        assert owners == [Path(k.force.py_func.__code__.co_filename)], (name, owners)
        assert f"family == {family}" in tangential_dispatch.source()
