"""Adding a damping law touches that law's module only (issue 29 item 1): a new module in laws/damping_laws/ — its
record, family id and compiled force and rate — and nothing else, in a copy of demcheck's source: a law the
seed's power dashpot η δ^b δ̇ cannot express (a quadratic drag η |δ̇| δ̇) then collides in the 1-D and 3-D
solvers as its closed form says, and a copy of the sqrt dashpot under another family id gives the built-in's bits
in every solver that calls the normal force (1-D and 3-D, adaptive and verlet, the packing loop). And the
solvers' switch names no damping law."""

import math
import sys
from pathlib import Path

import pytest
from scipy.optimize import brentq

from .helpers import code_names, with_law_modules

ROOT = Path(__file__).resolve().parents[1]

QUADRATIC = '''
"""A toy damping law: a quadratic drag F = eta |rate| rate (not of the seed's form eta delta^b rate)."""
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import L_ETA, Damping, compiled


@dataclass(frozen=True)
class QuadraticDamping(Damping):
    id: ClassVar[str] = "quadratic"
    title: ClassVar[str] = "quadratic drag"
    family: ClassVar[int] = 40
    eta: float = 0.0  # N s^2/m^2


@njit(cache=KERNEL_CACHE)
def quadratic_damping_force(law, delta, rate):
    return law[L_ETA] * abs(rate) * rate


@njit(cache=KERNEL_CACHE)
def quadratic_damping_rate(law, delta, rate, acc):
    return 2.0 * law[L_ETA] * abs(rate) * acc


compiled(QuadraticDamping, force=quadratic_damping_force, rate=quadratic_damping_rate)
'''

COPY = '''
"""The sqrt dashpot under another family id: its record and its compiled functions, one module."""
from dataclasses import dataclass
from typing import ClassVar

from .common import compiled
from .sqrt import SqrtDamping, sqrt_damping_force, sqrt_damping_rate


@dataclass(frozen=True)
class CopySqrtDamping(SqrtDamping):
    id: ClassVar[str] = "copy_sqrt"
    family: ClassVar[int] = 41


compiled(CopySqrtDamping, force=sqrt_damping_force, rate=sqrt_damping_rate)
'''

RUN = r'''
import dataclasses, hashlib, json, math
import numpy as np
from demcheck.engines import mapping, registry
from demcheck.laws import damping
from demcheck.laws.model import characteristic_time, resolve
from demcheck.laws.normal import HookeNormal, HertzNormal, NormalLaw
from demcheck.laws.normal_force import L_DAMPING
from demcheck.reference import collision3d, kernels
from demcheck.reference import packing as P
from demcheck.reference.collision import Geometry1D, auto_dt
from tests.helpers import glass_case

rec = {r.id: r for r in damping.RECORDS.values()}
out = {}
# the quadratic drag on a linear spring, a sphere on a wall
case = glass_case("lsd", {"kn": 1e5, "eta_n": 0.0}, wall=True)
model = resolve(case)
m, k, v = model.pair.m_eff, 1e5, model.pair.impact_speed
c = m / (2.0 * v * math.sqrt(m / k))  # λ δ0 = 1 (λ = 2c/m, δ0 the undamped largest overlap)
law = NormalLaw.from_slots(HookeNormal(k=k), rec["quadratic"](eta=c), False)
model = dataclasses.replace(model, normal_law=law)
geo, tc = Geometry1D(case), characteristic_time(model)
a = kernels.adaptive_normal(law.array(), m, geo.an, geo.delta0, geo.rate0, 1e-10, tc, v * tc, v, 1e3 * tc, 100000)
dt = tc / 2000.0  # (the dashpot lags half a step: an O(dt) error)
b = kernels.verlet_normal(law.array(), m, geo.an, geo.delta0, geo.rate0, dt, 1e3 * tc, 1000000)
out["quadratic"] = {"m": m, "k": k, "c": c, "v": v, "family": float(law.array()[L_DAMPING]),
                    "slots": [r.id for r in law.slots()],
                    "1d-adaptive": [-float(a[4][a[1] - 1]) / v, int(a[0])],
                    "1d-verlet": [-float(b[4][b[1] - 1]) / v, int(b[0])]}
for method in ("adaptive", "verlet"):
    res = collision3d.collide(case, model, method, dt=None if method == "adaptive" else dt)
    out["quadratic"][f"3d-{method}"] = [float(res.metrics()["restitution"]), res.status]
out["engines"] = {}
for name in registry.names():
    mp = mapping.map_model(model, name, dict(case.contact.params))
    out["engines"][name] = [mp.fidelity, mp.reasons]

# the copy of the sqrt dashpot: the bits of the built-in in every solver
def digest(*arrays):
    return hashlib.sha256(b"".join(np.asarray(x, float).tobytes() for x in arrays)).hexdigest()

case = glass_case("kk", {"eta_n": 20.0}, wall=True)
model = resolve(case)
copy = dataclasses.replace(model, normal_law=dataclasses.replace(model.normal_law, damping=41))
geo, tc, m, v = Geometry1D(case), characteristic_time(model), model.pair.m_eff, model.pair.impact_speed
for name, mo in (("builtin", model), ("copy", copy)):
    law = mo.normal_law.array()
    row = {"family": float(law[L_DAMPING]), "slots": [r.id for r in mo.normal_law.slots()]}
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
        use[1][..., L_DAMPING] = family
        use[3][..., L_DAMPING] = family
    st = P.PackState(pack)
    P.advance(pack, st, P.packing_dt(pack), 3000, laws=use)
    out[name]["packing"] = digest(st.x, st.v, st.w)
    out[name]["packing-family"] = float(use[3][..., L_DAMPING].max())
print(json.dumps(out))
'''


def quadratic_restitution(m, k, c, v) -> float:
    """The closed form of a linear spring with a quadratic drag, m δ̈ = −kδ − c|δ̇|δ̇, from δ = 0 at δ̇ = v: with
    u = δ̇², λ = 2c/m, κ = 2k/m, u' + λu = −κδ while approaching, u' − λu = −κδ while receding."""
    lam, kap = 2.0 * c / m, 2.0 * k / m
    approach = lambda d: (v * v - kap / lam**2) * math.exp(-lam * d) - kap * d / lam + kap / lam**2  # noqa: E731
    dmax = brentq(approach, 0.0, 2.0 * v * math.sqrt(m / k), xtol=1e-300, rtol=1e-15)
    d = -(kap * dmax / lam + kap / lam**2) * math.exp(-lam * dmax)
    return math.sqrt(d + kap / lam**2) / v


def test_a_damping_law_in_one_module_runs_in_every_solver(tmp_path):
    out = with_law_modules(tmp_path, "damping_laws", {"quadratic": QUADRATIC, "copy_sqrt": COPY}, RUN)

    q = out["quadratic"]
    assert q["family"] == 40.0 and q["slots"] == ["hooke", "quadratic"]
    e = quadratic_restitution(q["m"], q["k"], q["c"], q["v"])
    assert 0.3 < e < 0.9  # the drag takes a good part of the energy: the law is exercised
    for key, rtol in (("1d-adaptive", 1e-8), ("3d-adaptive", 1e-7), ("1d-verlet", 2e-3), ("3d-verlet", 2e-3)):
        got, status = q[key]
        assert status in (0, "ok"), (key, status)
        assert got == pytest.approx(e, rel=rtol), (key, got, e)
    # no engine expresses the toy law: each refuses it with a reason
    for name, (fidelity, reasons) in out["engines"].items():
        assert fidelity == "none" and reasons and all(r.strip() for r in reasons), (name, fidelity, reasons)

    builtin, copy = out["builtin"], out["copy"]
    assert builtin["family"] == 2.0 and copy["family"] == 41.0 and copy["packing-family"] == 41.0
    assert builtin["slots"] == ["hertz", "sqrt"] and copy["slots"] == ["hertz", "copy_sqrt"]
    for key in ("1d-adaptive", "1d-verlet", "3d-adaptive", "3d-verlet", "packing"):
        assert copy[key] == builtin[key], key


def test_the_solvers_switch_names_no_damping_law():
    """The switch on the damping family id is assembled from the laws' modules: the facade and the generator name
    none of them, no solver does, and each built-in law's compiled force lives in its own module only."""
    from demcheck.laws.damping_laws import common, dispatch

    laws = ROOT / "src" / "demcheck" / "laws"
    assert len(common.KERNELS) >= 4  # none, constant, sqrt, quarter: the loop below checks each
    texts = {p: p.read_text() for p in [laws / "normal_force.py", laws / "damping_laws" / "dispatch.py",
                                         *(ROOT / "src" / "demcheck" / "reference").glob("*.py")]}
    for family, k in common.KERNELS.items():
        record = common.RECORDS[family]
        module = sys.modules[record.__module__]
        constants = {n for n, v in vars(module).items() if n.isupper() and v == family and not isinstance(v, bool)}
        assert constants, record  # the law's family constant, e.g. SQRT
        for fn in (k.force, k.rate):
            name = fn.py_func.__name__
            owners = [f for f in (ROOT / "src").rglob("*.py") if f"def {name}(" in f.read_text()]
            assert owners == [Path(fn.py_func.__code__.co_filename)], (name, owners)
            for path, text in texts.items():
                assert name not in text, (path.name, name)
        for path, text in texts.items():
            assert f"damping_laws.{module.__name__.rsplit('.', 1)[1]}" not in text, (path.name, record.id)
            assert not (code_names(text) & constants), (path.name, constants)
        assert f"family == {family}" in dispatch.source()


@pytest.mark.parametrize("eta", [0.0, 3.0])
def test_the_seed_dashpots_keep_the_record_their_exponent_names(eta):
    """A law array's damping family is the one the seed's exponent names, however the law was built: from the
    records (the engines' mappings), or from (η, b) (the seed models) — so two spellings of one law are equal."""
    from demcheck.laws.damping import ConstantDamping, NoDamping, QuarterDamping, SqrtDamping
    from demcheck.laws.normal import VISCOELASTIC, HertzNormal, HookeNormal, NormalLaw
    from demcheck.laws.normal_force import L_DAMPING

    for spring, record in ((HookeNormal(k=2.0), ConstantDamping(eta=eta)), (HertzNormal(k=2.0), SqrtDamping(eta=eta)),
                           (HertzNormal(k=2.0), QuarterDamping(eta=eta)), (HertzNormal(k=2.0), NoDamping())):
        law = NormalLaw.from_slots(spring, record, False)
        assert law == NormalLaw(VISCOELASTIC, k=2.0, a=spring.exponent, eta=getattr(record, "eta", 0.0),
                                b=record.exponent)
        assert NormalLaw.from_array(law.array()) == law
        expected = NoDamping() if (eta == 0.0 and record.exponent == 0.0) else record
        assert law.slots()[1] == expected and law.array()[L_DAMPING] == type(expected).family
