"""Ai, Chen, Rotter & Ooi (2011)'s rolling models B and C as the codes that implement the paper write them
(laws/rolling_laws/ai_viscous.py, ai_epsd.py; docs/models.md "Beyond sliding"): their torques against closed forms
written here, the scenario solver (reference/beyond.py ``rolling_on_plane``) against the closed-form decay and
incline at solver tolerance, and every engine's scenario writer refusing them."""

import dataclasses
import math
import tomllib

import numpy as np
import pytest

from demcheck.case import from_dict
from demcheck.engines import registry, scenario
from demcheck.errors import ConfigError
from demcheck.laws import slots
from demcheck.laws.model import resolve
from demcheck.laws.rolling import (AiEpsdRolling, AiViscousRolling, EpsdRolling, ai_rolling_stiffness,
                                   ai_viscous_pair_torque, equivalent_inertia, rolling_torque)
from demcheck.laws.rolling_laws.ai_epsd import I_R, K_N, ai_epsd_rolling_force
from demcheck.reference import beyond
from demcheck.resources import case_path

G = 9.81
DOWN = np.array([0.0, 0.0, -1.0])


def _case(name="suite/beyond-rolling.toml"):
    return from_dict(tomllib.loads(case_path(name).read_text()))


def _record(law_id, params, name="suite/beyond-rolling.toml"):
    case = _case(name)
    p = case.particles[0]
    return slots.record("rolling", law_id, params, resolve(case).pair, (p.radius, 0.0)), case


def test_both_are_rolling_laws_a_case_names_with_their_keys():
    assert {"ai_viscous", "ai_epsd"} <= set(slots.law_ids("rolling"))
    assert [k.name for k in slots.KEYS[("rolling", "ai_viscous")]] == ["mu_r", "r_roll"]
    assert [k.name for k in slots.KEYS[("rolling", "ai_epsd")]] == ["mu_r", "r_roll", "k_n", "k_ratio", "eta_r", "i_r",
                                                                    "f"]
    rec, case = _record("ai_viscous", {"mu_r": 0.3})
    r = case.particles[0].radius
    assert isinstance(rec, AiViscousRolling) and rec.r_roll == r and rec.r0 == r  # on a wall: R̄ = R
    rec, _ = _record("ai_epsd", {"mu_r": 0.1, "k_n": 1e6})
    assert isinstance(rec, AiEpsdRolling) and (rec.k_ratio, rec.eta_r, rec.f) == (2.25, 0.0, 0.0)
    for bad, key in (({"mu_r": 0.1, "k_n": 1e6, "f": 1.5}, "contact.f"), ({"mu_r": 0.1}, "contact.k_n"),
                     ({"mu_r": 0.1, "k_n": 1e6, "k_ratio": 0.0}, "contact.k_ratio"),
                     ({"mu_r": 0.1, "k_n": 1e6, "eta_r": 0.3}, "contact.i_r")):
        with pytest.raises(ConfigError) as exc:
            _record("ai_epsd", bad)
        assert exc.value.key == key
    with pytest.raises(ConfigError) as exc:
        _record("ai_viscous", {"mu_r": 0.0})
    assert exc.value.key == "contact.mu_r"


# ----------------------------------------------------------------------------- model B


def test_model_b_on_a_wall_is_mu_r_rr_r_fn_times_the_rolling_spin():
    """M = −μr Rr |Fn| |Vω| ŵt with Vω = R ω × n: −μr Rr R |Fn| w_t (the twist about n has no Vω, no torque)."""
    rec = AiViscousRolling(mu_r=0.3, r_roll=2e-3, r0=5e-3)
    w = np.array([3.0, -4.0, 7.0])  # rolling part (3, −4, 0), twist 7 about n = −z
    m, h = rolling_torque(rec, w, DOWN, 2.5, 1e-6)
    assert m.tolist() == pytest.approx([-0.3 * 2e-3 * 5e-3 * 2.5 * 3.0, 0.3 * 2e-3 * 5e-3 * 2.5 * 4.0, 0.0],
                                       rel=1e-15, abs=1e-30)
    assert np.all(h == 0.0)
    assert np.all(rolling_torque(rec, [0.0, 0.0, 5.0], DOWN, 2.5, 1e-6)[0] == 0.0)


def test_model_b_between_two_spheres_lethe_s_reading():
    """Lethe's Vω = (R0ω0 + R1ω1) × n: none when equal spheres roll on each other (ω0 = −ω1), 2Rω when they
    turn alike — and the direction from ω0 − ω1, so no torque at all there (ω0 − ω1 = 0)."""
    c = AiViscousRolling(mu_r=0.3, r_roll=1e-3, r0=2e-3).array()
    n = np.array([1.0, 0.0, 0.0])
    w = np.array([0.0, 0.0, 10.0])
    assert np.all(ai_viscous_pair_torque(c, w, -w, 2e-3, 2e-3, n, 4.0) == 0.0)
    assert np.all(ai_viscous_pair_torque(c, w, w, 2e-3, 2e-3, n, 4.0) == 0.0)
    # unequal spins about z: Vω = (R0 ω0 + R1 ω1) ẑ × x̂, |Vω| = |R0 ω0 + R1 ω1|; ŵ = ẑ sign(ω0 − ω1)
    m = ai_viscous_pair_torque(c, np.array([0.0, 0.0, 10.0]), np.array([0.0, 0.0, 2.0]), 2e-3, 3e-3, n, 4.0)
    assert m.tolist() == pytest.approx([0.0, 0.0, -0.3 * 1e-3 * 4.0 * (2e-3 * 10.0 + 3e-3 * 2.0)], rel=1e-14)


@pytest.mark.parametrize("mu_r, r_factor", [(0.3, 1.0), (0.05, 0.5)])
def test_model_b_rolling_decays_as_its_closed_form(mu_r, r_factor):
    """A sphere rolling without slip on a level plane, |Fn| = m g: (m + I/R²) v̇ = −μr Rr R m g v/R², so
    v = v0 e^{−t/T}, T = 1.4 R/(μr Rr g) (= 1.4/(μr g) for Rr = R), whatever the mass. The scenario solver
    (DOP853, rtol 1e-11) against it."""
    mass, radius, v0 = 2.6e-4, 2e-3, 0.02
    rec = AiViscousRolling(mu_r=mu_r, r_roll=r_factor * radius, r0=radius)
    tau = 1.4 * radius / (mu_r * r_factor * radius * G)
    assert rec.time_constant(G) == pytest.approx(tau, rel=1e-15)
    out = beyond.rolling_on_plane(rec, mass, radius, v0, G, t_end=5.0 * tau)
    closed = v0 * np.exp(-out["t"] / tau)
    assert np.max(np.abs(out["v"] / closed - 1.0)) < 1e-9
    assert out["x"][-1] == pytest.approx(v0 * tau * (1.0 - math.exp(-5.0)), rel=1e-9)
    assert beyond.efold_time(out["t"], out["v"]) == pytest.approx(tau, rel=1e-9)


def test_model_b_on_a_wall_is_demcheck_s_type_b_at_the_load_s_cr():
    """On a wall under a steady load, M = −Cr w_t with Cr = μr Rr R |Fn|: the same torque as ``viscous``."""
    from demcheck.laws.rolling import ViscousRolling

    rec = AiViscousRolling(mu_r=0.3, r_roll=2e-3, r0=2e-3)
    fn = 2.6e-4 * G
    rng = np.random.default_rng(30)
    for _ in range(20):
        w = rng.normal(size=3)
        mine = rolling_torque(rec, w, DOWN, fn, 1e-6)[0]
        theirs = rolling_torque(ViscousRolling(c_r=0.3 * 2e-3 * 2e-3 * fn), w, DOWN, fn, 1e-6)[0]
        assert mine == pytest.approx(theirs, rel=1e-14, abs=1e-300)


# ----------------------------------------------------------------------------- model C


def test_model_c_stiffness_and_damping_follow_kn_as_ai_writes():
    rec = AiEpsdRolling(mu_r=0.1, r_roll=2e-3, k_n=1e6, eta_r=0.3, i_r=1.4 * 2.6e-4 * 4e-6)
    assert rec.k_r == pytest.approx(2.25 * 1e6 * (0.1 * 2e-3) ** 2, rel=1e-15)  # 0.09 N·m/rad
    assert ai_rolling_stiffness(1e6, 0.1, 2e-3) == rec.k_r
    assert ai_rolling_stiffness(1e6, 0.1, 2e-3, 3.0) == pytest.approx(3.0 / 2.25 * rec.k_r, rel=1e-15)  # Lethe's 2D
    assert rec.c_r == pytest.approx(0.3 * 2.0 * math.sqrt(rec.i_r * rec.k_r), rel=1e-15)
    assert equivalent_inertia(2.6e-4, 2e-3) == pytest.approx(rec.i_r, rel=1e-15)  # Ai's Ir on a wall: 1.4 m R²


def test_model_c_with_f_0_is_demcheck_s_epsd_at_ai_s_kr_and_cr():
    """Step by step over a random history (loading, the limit, unloading), the torque and the spring equal
    ``epsd`` (cap spring) given kr = 2.25 kn μr² Rr², Cr = ηr·2√(Ir kr)."""
    ai = AiEpsdRolling(mu_r=0.1, r_roll=2e-3, k_n=1e6, eta_r=0.3, i_r=1.4 * 2.6e-4 * 4e-6)
    old = EpsdRolling(mu_r=0.1, r_roll=2e-3, k_r=ai.k_r, c_r=ai.c_r)
    rng = np.random.default_rng(5)
    h_ai = h_old = np.zeros(3)
    limited = 0
    for _ in range(400):
        w, fn = rng.normal(scale=0.1, size=3), abs(rng.normal(scale=0.03))
        m_ai, h_ai = rolling_torque(ai, w, DOWN, fn, 1e-4, h_ai)
        m_old, h_old = rolling_torque(old, w, DOWN, fn, 1e-4, h_old)
        assert m_ai == pytest.approx(m_old, rel=1e-13, abs=1e-18) and h_ai == pytest.approx(h_old, rel=1e-13, abs=1e-18)
        limited += np.linalg.norm(h_ai) >= 0.1 * 2e-3 * fn * (1 - 1e-12)
    assert 50 < limited < 400  # both regimes were visited


def test_model_c_at_full_mobilisation_keeps_f_of_its_dashpot():
    """At the limit: Mk on the limit along the stretched spring, M = Mk − f Cr w_t (Lethe's f_coefficient)."""
    ai = AiEpsdRolling(mu_r=0.1, r_roll=2e-3, k_n=1e6, eta_r=0.5, i_r=1e-9, f=0.25)
    fn, dt = 0.01, 1e-3
    w = np.array([0.0, 50.0, 0.0])
    spring = -ai.k_r * dt * w  # from rest: |Mk| = kr |w| dt = 4.5e-3 > the limit μr Rr |Fn| = 2e-6
    cap = 0.1 * 2e-3 * fn
    m, h = rolling_torque(ai, w, DOWN, fn, dt)
    assert h.tolist() == pytest.approx((cap * spring / np.linalg.norm(spring)).tolist(), rel=1e-15)
    assert m.tolist() == pytest.approx((h - 0.25 * ai.c_r * w).tolist(), rel=1e-15)
    # below the limit the whole dashpot acts
    m, h = rolling_torque(ai, w * 1e-5, DOWN, fn, dt)
    assert m.tolist() == pytest.approx((-ai.k_r * dt * w * 1e-5 - ai.c_r * w * 1e-5).tolist(), rel=1e-14)


def test_model_c_reads_kn_and_ir_from_the_array_a_solver_writes():
    """A Hertz contact's kn changes with its overlap: a solver writes it (and Ir) into the coefficient array."""
    ai = AiEpsdRolling(mu_r=0.1, r_roll=2e-3, k_n=1.0, eta_r=0.2, i_r=1.0)
    c = ai.array()
    c[K_N], c[I_R] = 3e5, 2e-9
    w = np.array([1e-3, 2e-3, 0.0])
    m, _ = ai_epsd_rolling_force(c, w, DOWN, 1.0, 1e-5, np.zeros(3))
    ref = AiEpsdRolling(mu_r=0.1, r_roll=2e-3, k_n=3e5, eta_r=0.2, i_r=2e-9)
    assert m.tolist() == pytest.approx(rolling_torque(ref, w, DOWN, 1.0, 1e-5)[0].tolist(), rel=1e-15)


@pytest.mark.parametrize("eta_r", [0.0, 0.3])
def test_model_c_on_an_incline_rolls_as_the_closed_form_above_its_critical_angle(eta_r):
    """tan θc = μr Rr/R (the static balance, solved by bisection), and above it a = (5/7) g (sin θ − μr (Rr/R)
    cos θ): the scenario solver with the spring integrated as a state, its limit by events (f = 0)."""
    mass, radius = 2.6e-4, 2e-3
    rec = AiEpsdRolling(mu_r=0.1, r_roll=radius, k_n=1e6, eta_r=eta_r, i_r=equivalent_inertia(mass, radius))
    crit = beyond.incline_critical_angle(rec, mass, radius, G)
    assert crit == pytest.approx(math.atan(0.1), rel=1e-12)
    theta = 1.5 * crit
    out = beyond.rolling_on_plane(rec, mass, radius, 0.0, G, theta=theta, t_end=0.05)
    acc = 5.0 / 7.0 * G * (math.sin(theta) - 0.1 * math.cos(theta))
    assert out["acceleration"] == pytest.approx(acc, rel=1e-9)


# ----------------------------------------------------------------------------- the engines


@pytest.mark.parametrize("law_id, params", [("ai_viscous", {"mu_r": 0.3}),
                                            ("ai_epsd", {"mu_r": 0.1, "k_n": 1e6})])
def test_no_scenario_runs_them_and_every_engine_refuses_them(law_id, params):
    """No case scenario names them (the rolling and incline scenarios read a fixed Cr and f = 0: docs/models.md),
    so a case is refused; the engines' scenario mappings say none, with a reason; and an engine's writer handed a
    case with one anyway refuses it by its name."""
    raw = tomllib.loads(case_path("suite/beyond-incline-linear.toml").read_text())
    raw["contact"] = {**{k: v for k, v in raw["contact"].items() if k not in ("mu_r", "k_r")}, "rolling": law_id,
                      **params}
    for s in ("incline", "rolling"):
        raw["run"]["scenario"] = s
        with pytest.raises(ConfigError) as exc:
            from_dict(raw)
        assert exc.value.key == "contact.rolling" or "rolling" in exc.value.rule, (s, exc.value)
    rows = scenario.law_mappings("rolling", law_id)
    assert set(rows) >= {"lammps", "liggghts", "yade", "kratos"}
    for name, row in rows.items():
        assert row["fidelity"] == "none" and row["reason"].strip(), (name, row)
    case = _case("suite/beyond-incline-linear.toml")
    case = dataclasses.replace(case, contact=dataclasses.replace(
        case.contact, rolling=law_id, params={**{k: v for k, v in case.contact.params.items()
                                                 if k not in ("mu_r", "k_r")}, **params}))
    for name in registry.names():
        mp = scenario.mapping(case, name)
        assert mp.fidelity == "none" and any(law_id in r for r in mp.reasons), (name, mp.reasons)


def test_ai_viscous_between_two_spheres_is_symmetric_in_the_pair():
    """The packing loop builds one record per species pair, its radii in the species' order: the pair's torque must
    not depend on that order (review: the arm was body 0's radius, 29 % apart for the sandpile's two sizes); the
    arm is ½(R0 + R1) between two spheres and R0 on a wall."""
    from demcheck.laws.rolling_laws.ai_viscous import AiViscousRolling, ai_viscous_rolling_force

    w, n, fn = np.array([0.0, 0.0, 3.0]), np.array([1.0, 0.0, 0.0]), 0.7
    a = AiViscousRolling(mu_r=0.3, r_roll=2e-3, r0=3.45e-3, r1=4.45e-3).array()
    b = AiViscousRolling(mu_r=0.3, r_roll=2e-3, r0=4.45e-3, r1=3.45e-3).array()
    ta, tb = ai_viscous_rolling_force(a, w, n, fn, 1e-5, np.zeros(3))[0], ai_viscous_rolling_force(b, w, n, fn, 1e-5,
                                                                                                   np.zeros(3))[0]
    assert np.array_equal(ta, tb)
    assert ta[2] == -0.3 * 2e-3 * 0.5 * (3.45e-3 + 4.45e-3) * fn * 3.0
    wall = AiViscousRolling(mu_r=0.3, r_roll=2e-3, r0=3.45e-3).array()
    assert ai_viscous_rolling_force(wall, w, n, fn, 1e-5, np.zeros(3))[0][2] == -0.3 * 2e-3 * 3.45e-3 * fn * 3.0
