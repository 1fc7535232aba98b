"""Every mapping claim, backed by a computation (no engine needed).

``exact``: the twin (what the engine configuration computes) and the seed model give the same collision
under the engine's own kinematic rules, to the adaptive solver's accuracy. ``approximate``: they differ,
measurably. ``none``: no configuration and a reason. The engines' agreement with the twins is
tests/test_engines.py's business.
"""

import math

import pytest

from demcheck.engines import mapping, registry
from demcheck.reference import collision3d
from demcheck.reference.model import resolve

from .helpers import glass_case, oblique_case

METRICS = ("restitution", "contact_time", "peak_force", "max_overlap")
OBLIQUE = METRICS + ("tangential_restitution", "rebound_angular_velocity")

# (normal, normal params, tangential, tangential params) — normal-only rows at head-on impacts, tangential
# rows at a 30° impact with spin (it sticks, slips and sticks again, where truncations differ), every truncation, particle–particle and particle–wall
NORMAL_ROWS = [("lsd", {"stiffness_method": "energy"}), ("lsd", {"kn": 3e6, "eta_n": 0.5}), ("hertz", {}),
               ("bshp", {"dissipative_constant": 1e-7}), ("kk", {"eta_n": 20.0}), ("tti", {}),
               ("hls", {"stiffness_method": "overlap"}), ("hls", {"kl": 3e6, "unloading": "variable", "S": 1e4})]
TANGENTIAL_ROWS = [
    ("lsd", None, "spring_sliding", None),
    ("lsd", None, "lsd_sliding", {"truncation": "overlap", "tangential_restitution": 0.5}),
    ("lsd", None, "lsd_sliding", {"truncation": "spring", "tangential_restitution": 0.5}),
    ("lsd", None, "lsd_sliding", {"truncation": "force", "tangential_restitution": 0.5}),
    ("lsd", None, "viscous", {"eta_t": 2.0}),
    ("lsd", {"stiffness_method": "energy", "limit_force": True}, "viscous", {"eta_t": 2.0}),
    ("lsd", None, "viscous_sliding", {"eta_t": 2.0}),
    ("lsd", None, "sliding", {}),
    ("hertz", {}, "ddt", {}),
    ("kk", {"eta_n": 20.0}, "ddt", {}),
    ("tti", {}, "tti", {"truncation": "overlap"}),
    ("tti", {}, "tti", {}),
    ("lsd", None, "lth", None), ("lsd", None, "zzy", None), ("lsd", None, "walton", None),
]


def _compare(case, engine, keys):
    mp = mapping.contact_mapping(case, engine)
    if mp.native is None:
        return mp, None
    seed = resolve(case)
    twin = mapping.twin_model(seed, mp.native)
    rules = registry.get(engine).rules
    a = collision3d.collide(case, seed, "adaptive", rules=rules).metrics()
    b = collision3d.collide(case, twin, "adaptive", rules=rules).metrics()
    return mp, max(abs(a[k] - b[k]) / max(abs(a[k]), 1e-300) for k in keys)


def _check(mp, diff):
    if mp.fidelity == mapping.EXACT:
        assert diff < 1e-9, diff
        assert not mp.reasons
    elif mp.fidelity == mapping.APPROXIMATE:
        # the difference the reason names is real: ten times the solver's accuracy at least
        assert mp.reasons and diff > 1e-8, (diff, mp.reasons)
    else:
        assert mp.native is None and mp.reasons


@pytest.mark.parametrize("engine", registry.names())
@pytest.mark.parametrize("wall", [False, True], ids=["pair", "wall"])
@pytest.mark.parametrize("normal,params", NORMAL_ROWS, ids=[f"{n}-{i}" for i, (n, _) in enumerate(NORMAL_ROWS)])
def test_normal_mapping_claims(normal, params, wall, engine):
    case = glass_case(normal, params, wall=wall, restitution=0.8)
    mp, diff = _compare(case, engine, METRICS)
    _check(mp, diff)


@pytest.mark.parametrize("engine", registry.names())
@pytest.mark.parametrize("normal,nparams,tangential,tparams", TANGENTIAL_ROWS,
                         ids=[f"{t}-{i}" for i, (_, _, t, _) in enumerate(TANGENTIAL_ROWS)])
def test_tangential_mapping_claims(normal, nparams, tangential, tparams, engine):
    """An approximate mapping may coincide in one geometry (the regularised slider on a wall with LAMMPS's
    radius arms rolls exactly as the ideal one): it must differ in at least one of pair and wall."""
    diffs = []
    for wall in (False, True):
        case = oblique_case(tangential, tparams, normal=normal, normal_params=nparams, wall=wall, angle=30.0,
                            spin=500.0)
        mp, diff = _compare(case, engine, OBLIQUE)
        diffs.append(diff)
        if mp.fidelity != mapping.APPROXIMATE:
            _check(mp, diff)
    if mp.fidelity == mapping.APPROXIMATE:
        _check(mp, max(diffs))


def test_every_registered_model_has_a_mapping_row():
    from demcheck.reference import normal, tangential

    rows = mapping.by_model()
    assert {("normal", m) for m in normal.REGISTRY} | {("tangential", m) for m in tangential.REGISTRY} == set(rows)
    for row in rows.values():
        for engine in registry.names():
            assert row[engine]["fidelity"] in (mapping.EXACT, mapping.APPROXIMATE, mapping.NONE_)
            assert row[engine]["fidelity"] == mapping.EXACT or row[engine]["reason"]


def test_static_and_kinetic_friction_is_approximate_in_both_engines():
    case = oblique_case("spring_sliding", None, overrides=["contact.friction_kinetic=0.2"])
    for engine in registry.names():
        mp = mapping.contact_mapping(case, engine)
        assert mp.fidelity == mapping.APPROXIMATE and any("μk" in r for r in mp.reasons)


def test_tti_transform_carries_ttin_damping_exactly():
    """ENGINES.md §3: coeff_restitution with e′ = exp(−cπ/√(1−c²)), c = α_TTI/√5, carries TTIn's ηn."""
    from demcheck.reference import twins

    for e in (0.1, 0.5, 0.9):
        case = glass_case("tti", {}, restitution=e)
        model = resolve(case)
        mp = mapping.map_model(model, "lammps")
        nl, _ = registry.get(mp.native.engine).twin(mp.native, model.pair.m_eff, model.pair.r_eff)
        assert nl.eta == pytest.approx(model.normal_law.eta, rel=1e-13)
        assert nl.b == 0.25
    # the transform's fixed points from ENGINES.md: ε = 0.1 → 0.0983, 0.5 → 0.4997, 0.9 → 0.9000
    for eps, e_prime in ((0.1, 0.0983), (0.5, 0.4997), (0.9, 0.9000)):
        model = resolve(glass_case("tti", {}, restitution=eps))
        c = model.normal_law.eta / math.sqrt(model.pair.m_eff * model.normal_law.k)
        assert twins.restitution_for_eta(c, math.sqrt(5.0)) == pytest.approx(e_prime, abs=1e-4)
