"""Kratos DEM 10.4.4's other 3-D discontinuum laws that are variants of the twinned two, run for real through
demcheck's deck (the law as the relation's DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME) against the twin
(reference/twins_kratos.py with the law's numbers: engines/kratos/mapping.law_numbers), oblique, pair and wall."""

from __future__ import annotations

import pytest

from demcheck import case as C
from demcheck.engines import collide as CO
from .test_kratos_tangential import ALL_METRICS, CASES, TWIN_TOL, _native

HIGH, NESTLE, SIMPLE, CUSTOM = ("DEM_D_Linear_HighStiffness", "DEM_D_Hertz_viscous_Coulomb_Nestle",
                                "DEM_D_Linear_Simple_Coulomb", "DEM_D_Linear_Custom_Constants")
# (law, case file, overrides, friction and the native's other numbers): each law on a wall and on a pair,
# sticking then sliding or spinning; Custom_Constants' Kn, Kt given (the relation's K_NORMAL, K_TANGENTIAL)
LAW_CASES = [
    (CUSTOM, "oblique-lsd-wall.toml", ["impact.angle=30", "contact.tangential=none"],
     {"k_normal": 4e6, "k_tangential": 2.8e6}),
    (CUSTOM, "glass-pair.toml", ["impact.angle=30", "contact.normal=lsd", "contact.stiffness_method=energy"],
     {"k_normal": 3e6, "k_tangential": 3.3e6, "mu_s": 0.5, "decay": 1.0}),
    (HIGH, "oblique-lsd-wall.toml", ["impact.angle=30", "contact.tangential=none"], {}),
    (HIGH, "glass-pair.toml", ["impact.angle=30", "contact.normal=lsd", "contact.stiffness_method=energy"],
     {"mu_s": 0.5, "decay": 1.0}),
    (NESTLE, "oblique-lsd-wall.toml", ["impact.angle=30", "contact.tangential=none"], {}),
    (NESTLE, "glass-pair.toml", ["impact.angle=30", "contact.normal=tti", "contact.limit_force=true"], {}),
    (SIMPLE, "hertz-wall.toml", ["impact.angle=30", "impact.spin=-2000"], {}),
    (SIMPLE, "glass-pair.toml", ["impact.angle=20", "impact.spin=-3000"], {}),
]


@pytest.mark.engine("kratos")
@pytest.mark.parametrize("law,path,overrides,friction", LAW_CASES)
def test_kratos_variant_laws_run_as_their_twin(law, path, overrides, friction):
    """Measured ≤ 3.8e-12 every metric (Custom_Constants between spheres, the energy dissipated; 1.2e-10 in rebound
    spin with an exact rotation of the arms, not Kratos' low-angle quaternion). Each law's
    difference from its parent, dropped in the twin alone, misses Kratos (docs/kratos.md): HighStiffness with
    Kt = ρ·(5Kn) as its source reads by 0.18 in tangential restitution (wall), Nestle with the source's tangential
    dashpot 2γ√(m̄Kn)/0.55 by 1.7e-2. (Before: the deck refused these laws and there was no twin.)"""
    case = C.load(CASES / path, overrides)
    nat = _native(case, **{k: v for k, v in friction.items() if not k.startswith("k_")})
    nat.normal = law
    nat.props.update({k: v for k, v in friction.items() if k.startswith("k_")})
    run = CO.collide(case, "kratos", native=nat)
    assert run.ok, run.message
    twin = CO.twin_states(case, "kratos", run.dt, native=nat)
    a, b = run.metrics(), twin.metrics()
    assert a["tangential_restitution"] < 0.99 or abs(a["rebound_angular_velocity"]) > 0.0  # friction acted
    diffs = {k: abs(a[k] - b[k]) / abs(b[k]) for k in ALL_METRICS if k in a and b[k] != 0.0}
    assert max(diffs.values()) <= TWIN_TOL, diffs


def test_simple_coulomb_numbers():
    """Linear_Simple_Coulomb: Kn = E₁·2R₁R₂/(R₁ + R₂) (E₁R on a wall), Kt = ν₁Kn, no dashpot, the cap
    tan(STATIC_FRICTION)·Fn; HighStiffness: 5× Linear_viscous_Coulomb's Kn, Kt of the unaugmented one."""
    import math

    from demcheck.engines.base import Native
    from demcheck.engines.kratos.mapping import FRICTION, linear_kn, twin_law_array
    from demcheck.reference.twins_kratos import K_GAMMA, K_KN, K_MINOR, K_MU_D, K_MU_S, K_RHO

    props = {"wall": True, "poisson": 0.25, "mu_s": 0.3, "mu_d": 0.1, "decay": 2.0}
    nat = Native("kratos", normal=SIMPLE, normal_args=(1e9,), damping="gamma", damping_coeff=0.2,
                 tangential=FRICTION, limit=True, props=dict(props))
    kp = twin_law_array(nat, 1e-5, 1e-3)
    assert kp[K_KN] == pytest.approx(1e9 * (1 - 0.25 ** 2) * 1e-3, rel=1e-15)
    assert kp[K_RHO] == 0.25 and kp[K_GAMMA] == 0.0 and kp[K_MINOR] == 0.0
    assert kp[K_MU_S] == kp[K_MU_D] == math.tan(0.3)
    nat.props["wall"] = False
    assert twin_law_array(nat, 1e-5, 0.5e-3)[K_KN] == pytest.approx(1e9 * 2 * (1 - 0.25 ** 2) * 1e-3, rel=1e-15)
    nat.normal = HIGH
    kp = twin_law_array(nat, 1e-5, 1e-3)
    assert kp[K_KN] == pytest.approx(5 * linear_kn(1e9, 1e-3, False), rel=1e-15)
    assert kp[K_RHO] == pytest.approx(2 * 0.75 / 1.75 / 5, rel=1e-15) and kp[K_GAMMA] == 0.2


@pytest.mark.engine("kratos")  # Kratos' own γ is read from Kratos, the probes run Kratos
def test_the_audit_probes_a_project_with_the_variant_laws(tmp_path):
    """A user's project with Linear_HighStiffness between the spheres and Hertz_viscous_Coulomb_Nestle on the
    wall: both relations are probed with real Kratos runs from demcheck's deck, the engine equal to its twin
    (Nestle's γ by Thornton's fit, as Kratos derives it for a 'Hertz' law). Simple_Coulomb and Custom_Constants
    are listed, not probed (their stiffness is not read). (Before: each was 'no twin', not probed.)"""
    from demcheck.comparisons import audit as A

    from .test_audit_kratos import _project

    r = A.audit(_project(tmp_path, dt=5e-9, law_pair=HIGH, law_wall=NESTLE), speed=1.0)
    assert r["coverage"]["pairs"]["probed"] == 1 and r["coverage"]["walls"]["probed"] == 1
    for p in r["pairs"]:
        q = p["probes"][0]
        assert q["engine"]["status"] == "ok" and q["engine_vs_twin"] <= 1e-9, q
    assert any("Thornton's fit" in n for n in next(p for p in r["pairs"] if p["wall"])["notes"])
    setup = A.read(_project(tmp_path, law_pair=SIMPLE, law_wall=CUSTOM))
    for ps in setup.pairs:
        assert not ps.probe and any("twinned but its stiffness is not read" in n for n in ps.notes)
