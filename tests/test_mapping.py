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
from demcheck.laws.model import resolve

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
    eng = registry.get(engine)
    rules = eng.twin_rules(mp.native)
    if eng.own_twin(mp.native):  # a kernel of the engine's own (Kratos' friction, Yade's Luding): verlet only
        from demcheck.engines.collide import twin_states

        a = collision3d.collide(case, seed, "verlet", rules=rules)
        b = twin_states(case, engine, a.dt, native=mp.native).metrics()
        a = a.metrics()
        return mp, max(abs(a[k] - b[k]) / max(abs(a[k]), 1e-300) for k in keys)
    if twin.tangential_law.force_history:  # no adaptive solve: both by the engines' scheme at the case's dt
        a = collision3d.collide(case, seed, "verlet", rules=rules).metrics()
        b = collision3d.collide(case, twin, "verlet", rules=rules).metrics()
        return mp, max(abs(a[k] - b[k]) / max(abs(a[k]), 1e-300) for k in keys)
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
    from demcheck.laws import normal, tangential

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
        if mp.fidelity == mapping.NONE_ and mp.reasons:  # an engine without this law at all
            continue
        assert mp.fidelity == mapping.APPROXIMATE and any("μk" in r for r in mp.reasons)


def test_tti_transform_carries_ttin_damping_exactly():
    """docs/models.md, Engine twins: coeff_restitution with e′ = exp(−cπ/√(1−c²)), c = α_TTI/√5, carries TTIn's ηn."""
    from demcheck.reference import twins

    for e in (0.1, 0.5, 0.9):
        case = glass_case("tti", {}, restitution=e)
        model = resolve(case)
        mp = mapping.map_model(model, "lammps")
        nl, _ = registry.get(mp.native.engine).twin(mp.native, model.pair.m_eff, model.pair.r_eff)
        assert nl.eta == pytest.approx(model.normal_law.eta, rel=1e-13)
        assert nl.b == 0.25
    # the transform's fixed points (docs/models.md): ε = 0.1 → 0.0983, 0.5 → 0.4997, 0.9 → 0.9000
    for eps, e_prime in ((0.1, 0.0983), (0.5, 0.4997), (0.9, 0.9000)):
        model = resolve(glass_case("tti", {}, restitution=eps))
        c = model.normal_law.eta / math.sqrt(model.pair.m_eff * model.normal_law.k)
        assert twins.restitution_for_eta(c, math.sqrt(5.0)) == pytest.approx(e_prime, abs=1e-4)


# ----------------------------------------------------------------------------- luding: HLS with variable unloading


@pytest.mark.parametrize("wall", [False, True], ids=["pair", "wall"])
@pytest.mark.parametrize("speed,s,gravity", [(1.0, 1e4, 0.0), (1.0, 1e6, 0.0), (20.0, 1e6, 0.0), (0.05, 1e6, 9.81)])
def test_luding_limit_lies_above_the_impacts_overlap(speed, s, gravity, wall):
    """luding unloads as HLS (K_U = K_L + S·F_max) only while δ_max < δ_lim = (r − 1)/S: the mapping picks r so
    that δ_lim lies above the overlap the impact reaches — the reference's adaptive δ_max (an independent path)
    — with gravity pressing along, and keeps r ≥ 2 (δ_lim ≥ 1/S) so that (r − 1)k1 loses no digits."""
    from demcheck.engines.liggghts.mapping import luding_limit

    case = glass_case("hls", {"stiffness_method": "overlap", "unloading": "variable", "S": s}, wall=wall,
                      speed=speed, overrides=[f"run.gravity=[0.0, 0.0, {-gravity}]"])
    model = resolve(case)
    mp = mapping.map_model(model, "liggghts")
    assert mp.fidelity == mapping.EXACT and mp.native.normal == "luding"
    p, r_eff = mp.native.props, model.pair.r_eff
    d_lim = luding_limit(p, r_eff)
    assert (p["unloading"] - 1.0) / d_lim == pytest.approx(s, rel=1e-14)
    assert p["unloading"] >= 2.0 and p["loading"] == model.normal_law.kl
    assert p["adhesion"] == p["pulloff"] == 0.0 and p["restitution"] == 1.0  # no cohesion, no dashpot
    d_max = collision3d.collide(case, model, "adaptive").metrics()["max_overlap"]
    assert d_max < d_lim
    # the twin is the seed law: the same loading stiffness and S, read back from LIGGGHTS's numbers
    nl, _ = registry.get("liggghts").twin(mp.native, model.pair.m_eff, r_eff)
    assert nl.kl == model.normal_law.kl and nl.ku == 0.0 and nl.s == pytest.approx(s, rel=1e-14)


def test_luding_carries_no_tangential_law():
    case = oblique_case("spring_sliding", None, normal="hls",
                        normal_params={"stiffness_method": "overlap", "unloading": "variable", "S": 1e4})
    mp = mapping.contact_mapping(case, "liggghts")
    assert mp.native is None and "luding" in mp.reasons[0]
