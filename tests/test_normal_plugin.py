"""Adding a normal law touches that law's module only (issue 29 item 1): a new module in laws/normal_laws/ — its
record, family id and compiled spring force and rate — and nothing else, in a copy of demcheck's source: a law
that is not a power law (Hertz's spring stiffened by a cubic term, k δ^{3/2} + k3 δ³) then collides in the 1-D
and 3-D solvers as its closed form says (undamped: the largest overlap and the contact time by quadrature, and
no energy lost), every engine refusing it with its name; and a copy of the hertz spring under another family id
gives the built-in's bits in every solver that calls the normal force (1-D and 3-D, adaptive and verlet, the
packing loop). And the solvers' switch names no normal law."""

import math
import sys
from pathlib import Path

import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from .helpers import code_names, with_law_modules

ROOT = Path(__file__).resolve().parents[1]

CUBIC = '''
"""A toy normal law: Hertz's spring stiffened by a cubic term, F = k delta^1.5 + k3 delta^3 (not a power law)."""
import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import L_K, L_KL, NormalSubModel, compiled


@dataclass(frozen=True)
class HertzCubicNormal(NormalSubModel):
    id: ClassVar[str] = "hertz_cubic"
    title: ClassVar[str] = "Hertz spring with a cubic stiffening"
    exponent: ClassVar[float] = 1.5  # its leading power (the solvers' time scale)
    family: ClassVar[int] = 40
    columns: ClassVar[dict] = {"k3": "kl"}  # k3 in the array's kl column
    k: float = 0.0  # N/m^1.5
    k3: float = 0.0  # N/m^3


@njit(cache=KERNEL_CACHE)
def hertz_cubic_normal_force(law, delta):
    a = abs(delta)
    f = law[L_K] * a * math.sqrt(a) + law[L_KL] * a * a * a
    return f if delta >= 0.0 else -f


@njit(cache=KERNEL_CACHE)
def hertz_cubic_normal_rate(law, delta, rate):
    a = abs(delta)
    return (1.5 * law[L_K] * math.sqrt(a) + 3.0 * law[L_KL] * a * a) * rate


compiled(HertzCubicNormal, force=hertz_cubic_normal_force, rate=hertz_cubic_normal_rate)
'''

COPY = '''
"""The hertz spring under another family id: its record and its compiled functions, one module."""
from dataclasses import dataclass
from typing import ClassVar

from .common import compiled
from .hertz import HertzNormal, hertz_normal_force, hertz_normal_rate


@dataclass(frozen=True)
class CopyHertzNormal(HertzNormal):
    id: ClassVar[str] = "copy_hertz"
    family: ClassVar[int] = 41


compiled(CopyHertzNormal, force=hertz_normal_force, rate=hertz_normal_rate)
'''

RUN = r'''
import dataclasses, hashlib, json, math
import numpy as np
from demcheck.engines import mapping, registry
from demcheck.laws import damping
from demcheck.laws.base import sub_model
from demcheck.laws.model import characteristic_time, resolve
from demcheck.laws.normal import NormalLaw
from demcheck.laws.normal_force import L_FAMILY
from demcheck.reference import collision3d, kernels
from demcheck.reference import packing as P
from demcheck.reference.collision import Geometry1D, auto_dt
from tests.helpers import glass_case

cubic, copy_hertz = sub_model("normal", "hertz_cubic"), sub_model("normal", "copy_hertz")
out = {}
# the cubic law, undamped, a sphere on a wall: k3 such that the cubic term equals Hertz's at Hertz's largest overlap
case = glass_case("hertz", {}, wall=True)
model = resolve(case)
m, k, v = model.pair.m_eff, model.normal_law.k, model.pair.impact_speed
d_hertz = (1.25 * m * v * v / k) ** 0.4
k3 = k / d_hertz ** 1.5
law = NormalLaw.from_slots(cubic(k=k, k3=k3), damping.NoDamping(), False)
model = dataclasses.replace(model, normal_law=law)
geo, tc = Geometry1D(case), characteristic_time(model)
row = {"m": m, "k": k, "k3": k3, "v": v, "family": float(law.array()[L_FAMILY]), "slots": [r.id for r in law.slots()],
       "record": law.slots()[0].describe()}


def events(got):
    status, n, T, D, R, F, ne, ET, EC, ED, ER, EF = got
    ev = {int(c): (float(t), float(d), float(r)) for t, c, d, r in zip(ET[:ne], EC[:ne], ED[:ne], ER[:ne])}
    start, end = ev[kernels.EV_START], ev[kernels.EV_END]
    return {"contact_time": end[0] - start[0], "max_overlap": ev[kernels.EV_MAX_OVERLAP][1],
            "restitution": -end[2] / v, "status": int(status)}


row["1d-adaptive"] = events(kernels.adaptive_normal(law.array(), m, geo.an, geo.delta0, geo.rate0, 1e-11, tc,
                                                    v * tc, v, 1e3 * tc, 100000))
dt = tc / 4000.0
status, n, T, D, R, F = kernels.verlet_normal(law.array(), m, geo.an, geo.delta0, geo.rate0, dt, 1e3 * tc, 1000000)
inside = np.flatnonzero(D > 0.0)
first, last = inside[0], inside[-1]  # the crossings of δ = 0, linear between the steps around them
t0 = T[first - 1] + (T[first] - T[first - 1]) * D[first - 1] / (D[first - 1] - D[first])
t1 = T[last] + (T[last + 1] - T[last]) * D[last] / (D[last] - D[last + 1])
row["1d-verlet"] = {"restitution": -float(R[-1]) / v, "max_overlap": float(D.max()), "status": int(status),
                    "contact_time": float(t1 - t0), "dt": dt}
for method in ("adaptive", "verlet"):
    res = collision3d.collide(case, model, method, dt=None if method == "adaptive" else dt)
    mt = res.metrics()
    row[f"3d-{method}"] = {"contact_time": float(mt["contact_time"]), "max_overlap": float(mt["max_overlap"]),
                           "restitution": float(mt["restitution"]), "status": res.status}
out["cubic"] = row
out["engines"] = {}
for name in registry.names():
    mp = mapping.map_model(model, name, dict(case.contact.params))
    out["engines"][name] = [mp.fidelity, mp.reasons]

# the copy of the hertz spring: the bits of the built-in in every solver
def digest(*arrays):
    return hashlib.sha256(b"".join(np.asarray(x, float).tobytes() for x in arrays)).hexdigest()

case = glass_case("kk", {"eta_n": 20.0}, wall=True)
model = resolve(case)
normal, dashpot = model.normal_law.slots()
copy = dataclasses.replace(model, normal_law=NormalLaw.from_slots(copy_hertz(k=normal.k), dashpot, False))
geo, tc, m, v = Geometry1D(case), characteristic_time(model), model.pair.m_eff, model.pair.impact_speed
for name, mo in (("builtin", model), ("copy", copy)):
    law = mo.normal_law.array()
    row = {"family": float(law[L_FAMILY]), "slots": [r.id for r in mo.normal_law.slots()]}
    got = kernels.adaptive_normal(law, m, geo.an, geo.delta0, geo.rate0, 1e-10, tc, v * tc, v, 1e3 * tc, 100000)
    row["1d-adaptive"] = digest(*(x[:got[1]] for x in got[2:6]))
    row["1d-verlet"] = digest(*kernels.verlet_normal(law, m, geo.an, geo.delta0, geo.rate0, auto_dt(case), 1e3 * tc,
                                                     100000)[2:])
    for method in ("adaptive", "verlet"):
        res = collision3d.collide(case, mo, method, dt=None if method == "adaptive" else auto_dt(case))
        row[f"3d-{method}"] = digest(*[res.contact[c] for c in res.contact.columns if c != "t"])
    out[name] = row
pack = __import__("demcheck.case", fromlist=["load"]).load("src/demcheck/cases/packing/layer-kk.toml")
laws = P.resolve_laws(pack)
for name, family in (("builtin", None), ("copy", 41.0)):
    use = tuple(x.copy() for x in laws)
    if family is not None:
        use[1][..., L_FAMILY] = family
        use[3][..., L_FAMILY] = family
    st = P.PackState(pack)
    P.advance(pack, st, P.packing_dt(pack), 3000, laws=use)
    out[name]["packing"] = digest(st.x, st.v, st.w)
    out[name]["packing-family"] = sorted(set(use[3][..., L_FAMILY].ravel().tolist()) | set(use[1][..., L_FAMILY].ravel().tolist()))
print(json.dumps(out))
'''


def cubic_closed_form(m, k, k3, v) -> dict:
    """The undamped collision of m δ̈ = −k δ^{3/2} − k3 δ³ from δ = 0 at δ̇ = v: the largest overlap δm (the
    potential U = (2/5) k δ^{5/2} + (1/4) k3 δ⁴ equal to ½ m v²) and the contact time 2 ∫₀^δm dδ / √(v² − 2U/m),
    by quadrature with δ = δm (1 − w²) (no singularity at δm; U(δm) − U(δ) written without cancellation)."""
    dm = brentq(lambda d: 0.4 * k * d**2.5 + 0.25 * k3 * d**4 - 0.5 * m * v * v, 0.0, (1.25 * m * v * v / k) ** 0.4,
                xtol=1e-300, rtol=1e-15)

    def integrand(w):
        y, diff = dm * (1.0 - w * w), dm * w * w  # δ, δm − δ
        sx, sy = math.sqrt(dm), math.sqrt(y)
        five_halves = diff / (sx + sy) * (dm * dm + dm * sx * sy + dm * y + sx * sy * y + y * y)  # δm^{5/2} − δ^{5/2}
        du = 0.4 * k * five_halves + 0.25 * k3 * diff * (dm + y) * (dm * dm + y * y)
        return 2.0 * dm * w / math.sqrt(2.0 * du / m)

    t, err = quad(integrand, 0.0, 1.0, epsabs=0.0, epsrel=1e-13, limit=200)
    assert err < 1e-12 * t
    return {"max_overlap": dm, "contact_time": 2.0 * t, "restitution": 1.0}


def test_a_normal_law_in_one_module_runs_in_every_solver(tmp_path):
    out = with_law_modules(tmp_path, "normal_laws", {"hertz_cubic": CUBIC, "copy_hertz": COPY}, RUN)

    c = out["cubic"]
    assert c["family"] == 40.0 and c["slots"] == ["hertz_cubic", "none"]
    assert c["record"] == {"slot": "normal", "id": "hertz_cubic", "k": c["k"], "k3": c["k3"]}
    exact = cubic_closed_form(c["m"], c["k"], c["k3"], c["v"])
    # the cubic term matters: the largest overlap is well below Hertz's alone (0.85 of it here)
    assert exact["max_overlap"] < 0.9 * (1.25 * c["m"] * c["v"] ** 2 / c["k"]) ** 0.4
    # the adaptive solvers against the closed form at their tolerance (measured: 2e-10 and 5e-13); verlet at its
    # O(dt²), 4000 steps per t_c: (1/4000)² = 6e-8 (measured 6e-8 on the contact time)
    for key, rtol in (("1d-adaptive", 1e-9), ("3d-adaptive", 1e-9), ("1d-verlet", 1e-6), ("3d-verlet", 1e-6)):
        assert c[key]["status"] in (0, "ok"), (key, c[key])
        for metric in ("max_overlap", "contact_time", "restitution"):
            assert c[key][metric] == pytest.approx(exact[metric], rel=rtol), (key, metric, c[key][metric], exact)
    # no engine expresses the toy law: each refuses it, naming it
    for name, (fidelity, reasons) in out["engines"].items():
        assert fidelity == "none" and any("hertz_cubic" in r for r in reasons), (name, fidelity, reasons)

    builtin, copy = out["builtin"], out["copy"]
    assert builtin["family"] == 2.0 and copy["family"] == 41.0 and copy["packing-family"] == [41.0]
    assert builtin["slots"] == ["hertz", "sqrt"] and copy["slots"] == ["copy_hertz", "sqrt"]
    for key in ("1d-adaptive", "1d-verlet", "3d-adaptive", "3d-verlet", "packing"):
        assert copy[key] == builtin[key], key


def test_the_solvers_switch_names_no_normal_law():
    """The switch on the normal family id is assembled from the laws' modules: the facade and the generator name
    none of them (no module, no function, no family constant), no solver does, and each built-in law's compiled
    functions live in its own module only."""
    from demcheck.laws import normal_force  # noqa: F401  (assembles the switch)
    from demcheck.laws.normal_laws import common, dispatch

    laws = ROOT / "src" / "demcheck" / "laws"
    assert {r.id for r in common.RECORDS.values()} >= {"hooke", "hertz", "hls"}  # the loop below checks each
    texts = {p: p.read_text() for p in [laws / "normal_force.py", laws / "normal_laws" / "dispatch.py",
                                         *(ROOT / "src" / "demcheck" / "reference").glob("*.py")]}
    for family, k in common.KERNELS.items():
        record = common.RECORDS[family]
        module = sys.modules[record.__module__]
        constants = {n for n, v in vars(module).items() if n.isupper() and v == family and type(v) is int
                     and n not in vars(common)}  # (not the array's L_* columns it imports)
        assert constants, record  # the law's family constant, e.g. HERTZ
        for fn in (k.force, k.rate, k.unloading):
            if fn is None:
                continue
            name = fn.py_func.__name__
            assert name.startswith(f"{record.id}_normal_"), name
            owners = [f for f in (ROOT / "src").rglob("*.py") if f"def {name}(" in f.read_text()]
            assert owners == [Path(fn.py_func.__code__.co_filename)], (name, owners)
            for path, text in texts.items():
                assert name not in text, (path.name, name)
        for path, text in texts.items():
            assert f"normal_laws.{module.__name__.rsplit('.', 1)[1]}" not in text, (path.name, record.id)
            assert not (code_names(text) & constants), (path.name, constants)
        assert f"family == {family}" in dispatch.source()


def test_hooke_and_hertz_are_a_module_each_and_two_spellings_of_a_law_stay_equal():
    """hooke and hertz have a family id each; a law built from the records (the engines' twins) equals the one
    built from the seed's numbers, and the array's family is the record's."""
    from demcheck.laws.damping import ConstantDamping, NoDamping, QuarterDamping, SqrtDamping
    from demcheck.laws.normal import VISCOELASTIC, HertzNormal, HookeNormal, HysteresisNormal, NormalLaw
    from demcheck.laws.normal_force import L_FAMILY

    assert len({HookeNormal.family, HertzNormal.family, HysteresisNormal.family}) == 3
    assert HookeNormal.__module__ != HertzNormal.__module__
    for spring, record in ((HookeNormal(k=2.0), ConstantDamping(eta=3.0)), (HertzNormal(k=2.0), SqrtDamping(eta=3.0)),
                           (HertzNormal(k=2.0), QuarterDamping(eta=3.0)), (HertzNormal(k=2.0), NoDamping())):
        law = NormalLaw.from_slots(spring, record, False)
        assert law == NormalLaw(VISCOELASTIC, k=2.0, a=spring.exponent, eta=getattr(record, "eta", 0.0),
                                b=record.exponent)
        assert law.array()[L_FAMILY] == type(spring).family and NormalLaw.from_array(law.array()) == law
        assert law.slots() == (spring, record)
    with pytest.raises(ValueError, match="δ\\^2 spring"):
        NormalLaw(VISCOELASTIC, k=1.0, a=2.0).array()
