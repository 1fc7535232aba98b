"""Kratos DEM's own tangential force (its discontinuum laws' incremental spring, dashpot, slip-speed-dependent
Coulomb cap split in its own way, the history turned and — Hertz — shrunk with the overlap; the contact point's
displacement with finite rotations of the lever arms) against its twin, reference/twins_kratos.py, run for real
at equal dt: oblique and spinning, pair and wall, both laws."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from demcheck import case as C
from demcheck.engines import collide as CO
from demcheck.engines.mapping import contact_mapping

CASES = Path(__file__).resolve().parents[1] / "cases"
# engine − twin, relative, every metric: measured ≤ 7.3e-12 (the energy dissipated, a difference of energies; the
# rebound spin ≤ 5.7e-13) since the twin turns the arms with Kratos' low-angle quaternion (twins_kratos.kratos_rotate);
# with an exact rotation the rebound spin missed by 1.2e-10 and the tangential restitution by 2.9e-10
TWIN_TOL = 5e-11
ALL_METRICS = ("restitution", "contact_time", "max_overlap", "peak_force", "tangential_restitution",
               "rebound_angle", "rebound_angular_velocity", "energy_dissipated")


def _native(case, mu_s=0.3, mu_d=0.3, decay=0.0, nu=0.25):
    from demcheck.engines.kratos.mapping import FRICTION

    nat = copy.deepcopy(contact_mapping(case, "kratos").require())
    nat.tangential = FRICTION
    nat.props.update(mu_s=mu_s, mu_d=mu_d, decay=decay, poisson=nu)
    return nat


# (case file, overrides, friction): Hertz and Linear laws, wall and pair, sticking then sliding (30°, 60°),
# sliding throughout (spinning), damped and undamped, μ decaying with the slip speed
TWIN_CASES = [
    ("hertz-wall.toml", ["impact.angle=30"], {}),
    ("hertz-wall.toml", ["impact.angle=60"], {}),
    ("hertz-wall.toml", ["impact.angle=30", "impact.spin=-2000"], {}),
    ("hertz-wall.toml", ["impact.angle=30", "contact.normal=tti", "contact.limit_force=true"], {}),
    ("glass-pair.toml", ["impact.angle=30", "contact.normal=tti", "contact.limit_force=true"], {}),
    ("glass-pair.toml", ["impact.angle=20", "impact.spin=-3000"], {}),
    ("oblique-lsd-wall.toml", ["impact.angle=30", "contact.tangential=none"], {}),
    ("oblique-lsd-wall.toml", ["impact.angle=30", "impact.spin=-2000", "contact.tangential=none"],
     {"mu_s": 0.5, "decay": 0.5}),
    ("glass-pair.toml", ["impact.angle=30", "contact.normal=lsd", "contact.stiffness_method=energy"],
     {"mu_s": 0.5, "decay": 1.0}),
]


@pytest.mark.engine("kratos")
@pytest.mark.parametrize("path,overrides,friction", TWIN_CASES)
def test_kratos_tangential_force_runs_as_its_twin(path, overrides, friction):
    """Measured ≤ 7.3e-12, every metric (the energy dissipated; ≤ 2.4e-12 in the others). Each rule changed alone
    in the twin misses Kratos (docs/kratos.md): the wall arm R − δ/2 by 2.1e-3 in rebound spin, first-order arm
    turns by 7e-8, an exact rotation of the arms (not Kratos' low-angle quaternion) by 1.2e-10, the cap on the sum
    by 1.6e-2, Hertz without √(δ/δ_prev) by 9.1e-3, Linear with it by 2.4e-3. (Before: Kratos refused friction;
    there was no twin.)"""
    case = C.load(CASES / path, overrides)
    nat = _native(case, **friction)
    run = CO.collide(case, "kratos", native=nat)
    assert run.ok, run.message
    twin = CO.twin_states(case, "kratos", run.dt, native=nat)
    a, b = run.metrics(), twin.metrics()
    assert a["tangential_restitution"] < 0.99 or abs(a["rebound_angular_velocity"]) > 0.0  # friction acted
    diffs = {k: abs(a[k] - b[k]) / abs(b[k]) for k in ALL_METRICS if k in a and b[k] != 0.0}
    assert max(diffs.values()) <= TWIN_TOL, diffs


def test_coulomb_split_is_kratos_four_branches():
    """The cap μ|Fn| split between spring F_e and dashpot F_d when |F_e + F_d| exceeds it."""
    from demcheck.reference.twins_kratos import coulomb_split

    ex = np.array([1.0, 0.0, 0.0])
    fe, fd, s = coulomb_split(0.2 * ex, 0.1 * ex, 1.0)  # under the cap: untouched
    assert not s and fe[0] == 0.2 and fd[0] == 0.1
    fe, fd, s = coulomb_split(2.0 * ex, 0.5 * ex, 1.0)  # same sense, spring over the cap: spring cut, no dashpot
    assert s and fe[0] == 1.0 and fd[0] == 0.0
    fe, fd, s = coulomb_split(0.6 * ex, 0.8 * ex, 1.0)  # same sense, spring under: the dashpot takes the rest
    assert s and fe[0] == 0.6 and fd[0] == pytest.approx(0.4, rel=1e-15)
    fe, fd, s = coulomb_split(0.5 * ex, -2.0 * ex, 1.0)  # opposed, dashpot larger: |F_e + F_d| = cap
    assert s and fe[0] == 0.5 and fd[0] == pytest.approx(-1.5, rel=1e-15)
    fe, fd, s = coulomb_split(3.0 * ex, -1.0 * ex, 1.0)  # opposed, spring larger: spring cut, no dashpot
    assert s and fe[0] == 1.0 and fd[0] == 0.0


def test_finite_rotation_of_the_arms():
    """A pair's arm turns forward, q(Δθ)a − a; a wall's backward, a − q(−Δθ)a: the same first order, opposite
    second-order (normal) parts (0.1 rad: past the low-angle threshold, an exact rotation)."""
    from demcheck.reference.twins_kratos import arm_turn

    a = np.array([0.0, 0.0, 1.0])
    th = np.array([0.1, 0.0, 0.0])
    f, b = arm_turn(a, th, True), arm_turn(a, th, False)
    assert f[1] == pytest.approx(-np.sin(0.1), rel=1e-15) and b[1] == pytest.approx(-np.sin(0.1), rel=1e-15)
    assert f[2] == pytest.approx(np.cos(0.1) - 1.0, rel=1e-12) and b[2] == pytest.approx(1.0 - np.cos(0.1), rel=1e-12)


def test_both_arms_turn_by_kratos_low_angle_quaternion():
    """Kratos' OrientationFromRotationAngle below (θ/2)⁴/24 < ε builds q = (1 + φ²/2, φ̂·φ(1 − φ²/6)), φ = θ/2, and
    normalises it: a rotation by α = 2·atan2(φ(1 − φ²/6), 1 + φ²/2) = θ − θ³/4 + …, not θ. The pair's arms
    (RelativeDisplacementAndVelocityOfContactPointDueToRotationQuaternion: q(Δθ)a − a) and the wall's (a − q(−Δθ)a)
    both turn by α. (Before: the pair's arms turned by θ exactly, 3.6e-9 of the turn apart at θ = 2e-4 — the
    1.2e-10 in rebound spin the collision twins missed Kratos by.)"""
    from demcheck.reference.twins_kratos import arm_turn, rotate

    a = np.array([0.3e-3, -0.2e-3, 1.1e-3])
    for theta in (2e-4, 4e-4):  # both below the threshold θ < 5.4e-4
        axis = np.array([0.6, 0.0, 0.8])
        phi = 0.5 * theta
        alpha = 2.0 * np.arctan2(phi * (1.0 - phi * phi / 6.0), 1.0 + phi * phi / 2.0)
        assert abs(alpha / (theta - theta ** 3 / 4.0) - 1.0) < 1e-12
        want_pair = rotate(a, axis, alpha) - a
        want_wall = a - rotate(a, axis, -alpha)
        scale = np.linalg.norm(a) * theta
        assert np.abs(arm_turn(a, theta * axis, True) - want_pair).max() <= 1e-10 * scale
        assert np.abs(arm_turn(a, theta * axis, False) - want_wall).max() <= 1e-10 * scale
        exact = rotate(a, axis, theta) - a  # what the pair's twin turned by before: θ³/4 of the turn apart
        assert np.abs(exact - want_pair).max() > 10 * 1e-10 * scale


SUITE = CASES / "suite"


@pytest.mark.parametrize("name,law", [("oblique-spring-sliding", "DEM_D_Linear_viscous_Coulomb"),
                                      ("oblique-lsd-sliding-force", "DEM_D_Linear_viscous_Coulomb"),
                                      ("oblique-tti", "DEM_D_Hertz_viscous_Coulomb"),
                                      ("oblique-tti-overlap", "DEM_D_Hertz_viscous_Coulomb")])
def test_seed_tangential_laws_map_to_kratos_own_approximately(name, law):
    """Spring-sliding and LSDt through the Linear law, TTIt through the Hertz law: Kt/Kn = 2(1 − ν)/(2 − ν) sets
    the Poisson's ratio (0.22 here: the seed's Kt is the glass's own), μs = μd = μ, no decay; approximate, the
    measured difference named. (Before: every tangential law was refused.)"""
    from demcheck.engines.kratos.mapping import FRICTION
    from demcheck.laws.model import resolve

    case = C.load(SUITE / f"{name}.toml")
    mp = contact_mapping(case, "kratos")
    assert mp.fidelity == "approximate" and mp.native.normal == law and mp.native.tangential == FRICTION
    assert mp.native.props["poisson"] == pytest.approx(0.22, rel=1e-12)
    assert mp.native.props["mu_s"] == mp.native.props["mu_d"] == resolve(case).contact.tangential.mu_s
    assert any("measured against the seed law" in r and "in rebound spin" in r for r in mp.reasons)


def test_ddt_and_springless_laws_keep_their_reasons():
    ddt = contact_mapping(C.load(SUITE / "oblique-ddt.toml"), "kratos")
    assert ddt.fidelity == "none" and "0.5843·Kn" in ddt.reasons[-1] and "(2/3, 4/3)" in ddt.reasons[-1]
    for name in ("oblique-sliding", "oblique-viscous-sliding", "oblique-viscous"):
        mp = contact_mapping(C.load(SUITE / f"{name}.toml"), "kratos")
        assert mp.fidelity == "none" and "not a spring of that form" in mp.reasons[-1]


@pytest.mark.engine("kratos")
@pytest.mark.parametrize("name,overrides", [("oblique-spring-sliding", []), ("oblique-lsd-sliding-overlap", []),
                                            ("oblique-tti", []), ("oblique-tti", ["impact.spin=1500.0"])])
def test_mapped_suite_cases_run_as_their_twin(name, overrides):
    """The suite's cases through Kratos' own tangential law: the run equals its twin (measured ≤ 5.4e-13; 8.6e-11
    with an exact rotation of the arms)."""
    case = C.load(SUITE / f"{name}.toml", overrides)
    run = CO.collide(case, "kratos")
    assert run.ok, run.message
    twin = CO.twin_states(case, "kratos", run.dt)
    a, b = run.metrics(), twin.metrics()
    diffs = {k: abs(a[k] - b[k]) / abs(b[k]) for k in ALL_METRICS if k in a and b[k] != 0.0}
    assert max(diffs.values()) <= TWIN_TOL, diffs
