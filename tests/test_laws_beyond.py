"""Beyond sliding: each scenario solver (solve_ivp at rtol 1e-11 over the laws' compiled force functions) against
its closed form, and each closed form against an independent path (another integration, a quadrature, a matrix
exponential, or the published numbers). Tolerances: 1e-9 relative for a solver at rtol 1e-11 (the events and
the accumulated error of DOP853 stay two decades inside it); 1e-12 for two exact routes that differ only by
round-off."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq

from demcheck.laws.adhesion import DmtAdhesion, JkrAdhesion, SjkrAdhesion, adhesive_force, jkr_radius
from demcheck.laws.base import SUBMODELS
from demcheck.laws.heat import AreaHeat, LensHeat, RadiusHeat, conductance, series_conductivity
from demcheck.laws.rolling import (CAP_SPRING, CAP_TOTAL, ConstantTorqueRolling, EpsdRolling, ViscousRolling,
                                   equivalent_inertia, rolling_torque)
from demcheck.laws.twisting import MarshallTwisting, SdsTwisting, twisting_torque
from demcheck.reference import beyond as b

R = 1e-3
M = 2500.0 * 4.0 / 3.0 * math.pi * R ** 3
G = 9.81
SOLVER = 1e-9


def rel(a, b_):
    return abs(a - b_) / abs(b_)


# ----------------------------------------------------------------------------- rolling


def test_type_a_stop_time_and_distance_solver_against_closed_form():
    law = ConstantTorqueRolling(0.05, R)
    out = b.rolling_on_plane(law, M, R, 0.2, G)
    t, s = b.rolling_stop_closed(0.05, R, R, 0.2, G)
    assert rel(out["rolling_stop_time"], t) < SOLVER and rel(out["rolling_distance"], s) < SOLVER


def test_type_a_closed_form_against_newton_euler_with_the_friction_as_unknown():
    """Independent path: x and ω integrated separately (rtol 1e-12), the friction force solved from the no-slip
    condition at each instant — no m + I/R² in sight."""
    mu_r, v0 = 0.05, 0.2
    inertia = 0.4 * M * R * R
    torque = mu_r * R * M * G

    def rhs(t, y):  # v' = −Ft/m, ω' = (Ft R − torque)/I, with v' = R ω' (no slip) → Ft
        ft = torque / R / (1.0 + inertia / (M * R * R))
        return [-ft / M, (ft * R - torque) / inertia, y[0]]

    ev = lambda t, y: y[0]  # noqa: E731
    ev.terminal = True
    sol = solve_ivp(rhs, (0, 10), [v0, v0 / R, 0.0], rtol=1e-12, atol=1e-15, events=ev, method="DOP853")
    t, s = b.rolling_stop_closed(mu_r, R, R, v0, G)
    assert rel(sol.t_events[0][0], t) < 1e-10 and rel(sol.y_events[0][0][2], s) < 1e-10
    assert abs(sol.y_events[0][0][1]) < 1e-9 * v0 / R  # it rolls to rest: ω = 0 when v = 0


def test_type_b_decay_solver_against_closed_form():
    law = ViscousRolling(1e-9)
    tau, s = b.rolling_viscous_closed(1e-9, M, R, 0.2)
    out = b.rolling_on_plane(law, M, R, 0.2, G, t_end=60 * tau)
    assert rel(out["x"][-1], s) < SOLVER
    k = np.searchsorted(out["t"], tau)
    assert rel(out["v"][k], 0.2 * math.exp(-out["t"][k] / tau)) < SOLVER


@pytest.mark.parametrize("law", [ConstantTorqueRolling(0.05, R), EpsdRolling(0.05, R, 1e-4, 2e-9),
                                 EpsdRolling(0.05, R, 1e-4, 0.0)])
def test_incline_rolls_above_the_critical_angle_with_the_closed_acceleration(law):
    crit, _ = b.incline_closed(0.05, R, R, 0.0, G)
    theta = crit * 1.5
    out = b.rolling_on_plane(law, M, R, 0.0, G, theta=theta, t_end=0.5)
    assert rel(out["acceleration"], b.incline_closed(0.05, R, R, theta, G)[1]) < SOLVER


def test_incline_type_c_stays_below_the_critical_angle():
    crit = math.atan(0.05)
    law = EpsdRolling(0.05, R, 1e-4, epsd_c(1e-4, 0.3))
    out = b.rolling_on_plane(law, M, R, 0.0, G, theta=crit * (1 - 1e-3), t_end=0.5)
    # it rocks (its spring overshoots the limit, so it also rolls a little while fully mobilised), then rests
    late = out["t"] > 0.25
    assert np.abs(out["v"][late]).max() < 1e-12 and np.ptp(out["x"][late]) < 1e-12 * R
    assert rel(b.incline_critical_angle(law, M, R, G), math.atan(0.05)) < 1e-13


def epsd_c(k_r, eta):
    from demcheck.laws.rolling import epsd_damping
    return epsd_damping(eta, equivalent_inertia(M, R), k_r)


def test_rolling_torques_never_exceed_their_limit_and_never_drive():
    rng = np.random.default_rng(1)
    fn, dt = 0.7, 1e-5
    for law in (ConstantTorqueRolling(0.1, R), EpsdRolling(0.1, R, 50.0, 0.0, CAP_SPRING),
                EpsdRolling(0.1, R, 50.0, 1e-3, CAP_TOTAL)):
        hist = np.zeros(3)
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)  # one normal per run: the spring torque is not rotated with a turning normal
        for _ in range(300):
            w = rng.normal(size=3) * 10
            m, hist = rolling_torque(law, w, n, fn, dt, hist)
            assert np.linalg.norm(m) <= 0.1 * R * fn * (1 + 1e-12)
            assert abs(m @ n) < 1e-12 * max(np.linalg.norm(m), 1e-300)  # no twisting part
            if law.id == "constant_torque":
                assert m @ w <= 0.0


def test_type_c_without_cap_is_a_linear_spring_dashpot():
    law = EpsdRolling(1e9, R, 3.0, 0.5)
    n, w = np.array([0.0, 0.0, 1.0]), np.array([0.2, -0.1, 7.0])
    m, hist = rolling_torque(law, w, n, 1.0, 0.01, np.array([0.01, 0.02, 0.0]))
    wt = np.array([0.2, -0.1, 0.0])
    np.testing.assert_allclose(hist, [0.01, 0.02, 0] - 3.0 * 0.01 * wt, rtol=0, atol=1e-15)
    np.testing.assert_allclose(m, hist - 0.5 * wt, rtol=0, atol=1e-15)


def test_records_round_trip_through_their_arrays():
    for law in (ConstantTorqueRolling(0.1, R, True), ViscousRolling(2.0),
                EpsdRolling(0.1, R, 2.0, 3.0, CAP_TOTAL, True),
                SdsTwisting(1.0, 2.0, 3.0), MarshallTwisting(1.0, 2.0, 3.0), JkrAdhesion(1.0, 2.0, 3.0, 1),
                DmtAdhesion(1.0, 2.0, 3.0), SjkrAdhesion(1.0, 1, True, 5.0, 6.0), RadiusHeat(1.0, 2.0),
                AreaHeat(1.0, 2.0), LensHeat(1.0, 2.0, 3.0, True)):
        assert type(law).from_array(law.array()) == law
        assert SUBMODELS[(law.slot, law.id)] is type(law)  # registered in its slot by its id


# ----------------------------------------------------------------------------- twisting


def test_twist_stop_time_solver_against_closed_form():
    law = SdsTwisting(1e-3, 0.0, 1e-4)
    out = b.twist_decay(law, M, R, 10.0, M * G, 10.0)
    assert rel(out["twist_stop_time"], b.twist_stop_closed(M, R, 10.0, 1e-4, M * G)) < SOLVER


def test_twist_closed_form_against_the_discrete_law_at_small_steps():
    """Independent path: the law's own step function, explicit in time, converging at first order to t_stop."""
    law = SdsTwisting(1e-3, 0.0, 1e-4)
    inertia = 0.4 * M * R * R
    closed = b.twist_stop_closed(M, R, 10.0, 1e-4, M * G)
    errs = []
    for steps in (1999.3, 3999.7):
        dt, w, phi, t = closed / steps, 10.0, (1e-4 * M * G) / 1e-3, 0.0
        n = np.array([0.0, 0.0, -1.0])
        while w > 0 and t < 2 * closed:
            m, phi = twisting_torque(law, np.array([0, 0, -w]), n, M * G, 0.0, dt, phi)
            w -= dt * m[2] / inertia  # ω_z = −w, and ω_z grows by dt·M_z/I
            t += dt
        errs.append(abs(t - closed) / closed)
    assert errs[0] < 1 / 1999.3 and errs[1] < 1 / 3999.7  # the constant torque stops it within one step


def test_marshall_coefficients():
    law = MarshallTwisting(kt=200.0, gamma_t=0.3, mu_t=0.5).at(1e-4)
    assert rel(law.k_tw, 0.5 * 200.0 * 1e-8) < 1e-15 and rel(law.gamma_tw, 0.5 * 0.3 * 1e-8) < 1e-15
    assert rel(law.mu_tw, 2.0 / 3.0 * 1e-4 * 0.5) < 1e-15


# ----------------------------------------------------------------------------- adhesion

JKR = JkrAdhesion(r_eff=5e-4, e_eff=5e7, w=0.1)


def test_jkr_radius_solves_the_jkr_overlap_relation():
    for d in (-1e-7, 0.0, 1e-8, 1e-6, 1e-4):
        a = jkr_radius(d, 5e-4, 5e7, 0.1)
        resid = a * a / 5e-4 - math.sqrt(2 * math.pi * 0.1 * a / 5e7) - d
        assert abs(resid) < 1e-13 * max(abs(d), a * a / 5e-4)


def test_jkr_published_points():
    """JKR 1971 and Johnson (Contact Mechanics, 1985, §5.5): the force at zero overlap is −(8/9) of the
    load-controlled pull-off (3/2)πwR̄; under imposed displacement the contact breaks at F = −(5/6)πwR̄."""
    fc = 1.5 * math.pi * 0.1 * 5e-4
    assert rel(adhesive_force(JKR, 0.0, 0.0)[0], -8.0 / 9.0 * fc) < 1e-12
    d_f = JKR.separation_at_pull_off("displacement")
    f, touching = adhesive_force(JKR, d_f * (1 - 1e-14), 1.0)
    # a(δ) has a square-root singularity at the break: 1e-14 in δ is ~1e-7 in a and F
    assert touching == 1.0 and rel(f, -5.0 / 6.0 * math.pi * 0.1 * 5e-4) < 1e-6
    assert adhesive_force(JKR, d_f * (1 + 1e-9), 1.0)[1] == 0.0  # beyond δ_f: broken
    assert adhesive_force(JKR, -1e-12, 0.0) == (0.0, 0.0)  # approaching: no force before δ = 0


def test_pull_off_solver_against_closed_forms():
    out = b.pull_off(JKR)
    assert rel(out["pull_off_force"], JKR.pull_off_force("load")) < SOLVER
    assert rel(out["separation_at_pull_off"], JKR.separation_at_pull_off("displacement")) < SOLVER
    dmt = DmtAdhesion(5e-4, 5e7, 0.1)
    assert rel(b.pull_off(dmt)["pull_off_force"], 2 * math.pi * 0.1 * 5e-4) < 1e-14


def test_jkr_break_against_the_turning_point_of_the_overlap():
    """Independent path: δ_f is where δ(a) turns (dδ/da = 0), found by brentq on the derivative."""
    r, e, w = 5e-4, 5e7, 0.1
    c = math.sqrt(2 * math.pi * w / e)
    af = brentq(lambda a: 2 * a / r - 0.5 * c / math.sqrt(a), 1e-12, 1e-3, xtol=1e-30, rtol=1e-15)
    assert rel(af * af / r - c * math.sqrt(af), JKR.separation_at_pull_off("displacement")) < 1e-12


def test_jkr_loop_energy_against_quadrature():
    r, e, w = 5e-4, 5e7, 0.1
    d_f = JKR.separation_at_pull_off("displacement")
    q = quad(lambda d: -adhesive_force(JKR, d, 1.0)[0], d_f, 0.0, epsabs=0, epsrel=1e-13, limit=200)[0]
    assert rel(b.jkr_loop_energy(r, e, w), q) < 1e-10


def test_capture_velocity_matches_thornton_ning_up_to_their_convention():
    """Thornton & Ning (1998) print v_s = 1.84 (F_c⁵/(E*² R̄ m̄³))^{1/6}. The loop energy gives 1.0348 with the
    same symbols; 1.0348 · 32^{1/6} = 1.844: their coefficient is ours with a factor 2 in F_c (or 4 in E*² with
    2 in m̄ … ): recorded in docs/models.md ("Beyond sliding"), checked here to the 3 digits they print."""
    r, e, w, m = 5e-4, 5e7, 0.1, M / 2
    fc = 1.5 * math.pi * w * r
    coef = b.capture_velocity_closed(r, e, w, m) / (fc ** 5 / (e * e * r * m ** 3)) ** (1 / 6)
    assert abs(coef * 32 ** (1 / 6) - 1.84) < 0.005


@pytest.mark.parametrize("factor", [0.5, 0.99, 1.01, 2.0, 10.0])
def test_adhesive_impact_solver_against_closed_restitution(factor):
    vs = b.capture_velocity_closed(5e-4, 5e7, 0.1, M / 2)
    out = b.adhesive_impact(JKR, M / 2, factor * vs)
    closed = b.adhesive_restitution_closed(factor * vs, vs)
    if factor < 1:
        assert out["captured"] and closed == 0.0
    else:
        assert abs(out["restitution"] - closed) < 1e-8  # e → 0 near v_s: an absolute tolerance


# ----------------------------------------------------------------------------- heat


def test_conduction_solver_against_closed_time_constant():
    law = RadiusHeat(10.0, 5e-4)
    c0, c1 = M * 800.0, 2 * M * 800.0
    out = b.conduction(law, 1e-6, c0, c1, 300.0, 400.0, 100.0)
    assert rel(out["heat_time_constant"], b.heat_time_constant_closed(out["conductance"], c0, c1)) < SOLVER


def test_conduction_closed_form_against_the_matrix_exponential():
    h, c0, c1, t = 4e-4, 0.02, 0.05, 7.0
    a = np.array([[-h / c0, h / c0], [h / c1, -h / c1]])
    y = expm(a * t) @ np.array([300.0, 400.0])
    tau = b.heat_time_constant_closed(h, c0, c1)
    assert rel(y[1] - y[0], 100.0 * math.exp(-t / tau)) < 1e-12
    assert rel(c0 * y[0] + c1 * y[1], c0 * 300 + c1 * 400) < 1e-14


def test_conductances():
    d, r = 1e-6, 5e-4
    assert rel(conductance(RadiusHeat(10.0, r), d), 2 * 10.0 * math.sqrt(r * d)) < 1e-15
    assert rel(conductance(AreaHeat(10.0, r), d), 10.0 * math.pi * r * d) < 1e-15
    lens = conductance(LensHeat(10.0, 1e-3, 1e-3), d)
    assert rel(lens, 2 * 10.0 * math.sqrt(math.pi * (1e-3 * d - d * d / 4))) < 1e-9  # intersection circle
    assert series_conductivity(3.0, 3.0) == 3.0
    assert conductance(RadiusHeat(10.0, r), -1e-9) == 0.0


def test_slack_zero_gives_no_torque_only_while_the_spring_is_unstretched():
    base = dict(mu_r=0.01, r_roll=R, k_r=1.0, c_r=1.0, cap=CAP_TOTAL)
    n, w = np.array([1.0, 0.0, 0.0]), np.array([0.0, 5.0, 0.0])
    plain = rolling_torque(EpsdRolling(**base), w, n, 1.0, 0.0, np.zeros(3))[0]
    zero = rolling_torque(EpsdRolling(slack_zero=True, **base), w, n, 1.0, 0.0, np.zeros(3))[0]
    assert rel(np.linalg.norm(plain), 0.01 * R) < 1e-15 and not zero.any()
    stretched = rolling_torque(EpsdRolling(slack_zero=True, **base), w, n, 1.0, 1e-3, np.zeros(3))[0]
    assert rel(np.linalg.norm(stretched), 0.01 * R) < 1e-15


def test_adhesive_impact_with_the_load_controlled_break():
    law = JkrAdhesion(5e-4, 5e7, 0.1, break_at=1)
    vs = b.capture_velocity_closed(5e-4, 5e7, 0.1, M / 2, "load")
    assert vs < b.capture_velocity_closed(5e-4, 5e7, 0.1, M / 2)  # less of the loop is walked
    for factor in (0.9, 3.0):
        out = b.adhesive_impact(law, M / 2, factor * vs)
        assert abs(out["restitution"] - b.adhesive_restitution_closed(factor * vs, vs)) < 1e-8
    assert b.pull_off(law)["pull_off_force"] > 0  # the largest tension is still (3/2)πwR̄


def test_twist_from_an_unstretched_spring_against_its_closed_form():
    """Wind-up first (an undamped oscillator: φ = (ω0/Ω) sin Ωt, Ω = √(ktw/I)) until ktw φ reaches the limit at t1,
    then a constant torque: t_stop = t1 + I ω0 cos(Ω t1)/limit."""
    law = SdsTwisting(1e-8, 0.0, 1e-6)
    inertia, fn, w0 = 0.4 * M * R * R, M * G, 10.0
    cap = 1e-6 * fn
    omega = math.sqrt(1e-8 / inertia)
    t1 = math.asin(cap * omega / (1e-8 * w0)) / omega
    closed = t1 + inertia * w0 * math.cos(omega * t1) / cap
    out = b.twist_decay(law, M, R, w0, fn, 10 * closed, preloaded=False)
    assert rel(out["twist_stop_time"], closed) < SOLVER
    assert out["twist_stop_time"] > b.twist_decay(law, M, R, w0, fn, 10 * closed)["twist_stop_time"]


def test_the_two_lens_areas_agree():
    from demcheck.laws import adhesion, heat
    for args in ((1e-3, 1e-3, 1e-6, False), (1e-3, 2e-3, 3e-5, False), (1e-3, 0.0, 1e-6, True)):
        assert adhesion.lens_area(*args) == heat.lens_area(*args)


# ----------------------------------------------------------------------------- sjkr and type B in their scenarios


@pytest.mark.parametrize("area", [0, 1])
def test_sjkr_pull_off_closed_form_against_the_tension_found_on_a_fine_grid(area):
    """The closed form's largest tension (reference/beyond.py sjkr_pull_off_closed) against the sum of the Hertz
    force and the compiled sjkr force, minimised on a grid of 2e5 overlaps and refined by brentq on the slope:
    independent of the closed form's algebra."""
    e_eff, radius = 3.13e6, 1e-3
    r_eff = radius / 2
    k_h = 4.0 / 3.0 * e_eff * math.sqrt(r_eff)
    law = SjkrAdhesion(1e5, area, False, radius, radius)

    def f(d):
        return k_h * d ** 1.5 + adhesive_force(law, d, 1.0)[0]

    grid = np.linspace(1e-12, 0.2 * radius, 200001)
    k = int(np.argmin([f(d) for d in grid]))
    h = 1e-9 * radius

    def slope(d):
        return (f(d + h) - f(d - h)) / (2 * h)

    d_star = brentq(slope, grid[k - 1], grid[k + 1], xtol=1e-20)
    closed = b.sjkr_pull_off_closed(k_h, 1e5, area, radius, r_eff)
    assert abs(-f(d_star) / closed - 1) < 1e-9
    assert abs(b.cohesive_pull_off(law, lambda d: k_h * d ** 1.5, 0.5 * radius)["pull_off_force"] / closed - 1) < 1e-9


def test_sjkr_and_viscous_scenarios_solve_against_their_closed_forms():
    """The suite's beyond-pull-off-sjkr (lens and band) and beyond-rolling-viscous: the reference's solve against
    its closed form (measured 1.2e-13 and 0 for the pull, 1.0e-12 and 2e-16 for the roll)."""
    from demcheck.case import load
    from demcheck.reference.scenarios import scenario_metrics
    from demcheck.resources import case_path

    for name, over in (("pull-off-sjkr", []), ("pull-off-sjkr", ["contact.area=band"]), ("rolling-viscous", [])):
        c = load(case_path(f"suite/beyond-{name}.toml"), over)
        got, closed = scenario_metrics(c), scenario_metrics(c, closed=True)
        assert got.keys() == closed.keys()
        for k, v in closed.items():
            assert abs(got[k] - v) <= 1e-9 * abs(v), (name, over, k, got[k], v)
    c = load(case_path("suite/beyond-rolling-viscous.toml"))
    law, m, radius = c.contact.params["c_r"], c.mass(0), c.particles[0].radius
    tau = scenario_metrics(c, closed=True)["rolling_time_constant"]
    assert abs(tau - 1.4 * m * radius ** 2 / law) <= 1e-15 * tau
    assert set(scenario_metrics(c)) == {"rolling_time_constant", "rolling_distance"}


def test_the_stepped_viscous_roll_reads_the_time_constant_and_the_distance_to_rest():
    """stepped_metrics on an exact exponential sampled coarsely: T from the e-fold time (log-linear between samples)
    and the distance to rest from the distance run plus v·T still to go."""
    from demcheck.case import load
    from demcheck.reference.scenarios import stepped_metrics
    from demcheck.resources import case_path

    c = load(case_path("suite/beyond-rolling-viscous.toml"))
    tau, v0 = 0.01, 0.02
    t = np.linspace(0.0, 3 * tau, 37)
    v = v0 * np.exp(-t / tau)
    x = v0 * tau * (1 - np.exp(-t / tau))
    zeros = np.zeros_like(t)
    run = {"t": t, "x": np.column_stack([x, zeros, zeros + 1e-3]), "v": np.column_stack([v, zeros, zeros]),
           "omega": np.column_stack([zeros, v / 1.59e-3, zeros])}
    got = stepped_metrics(c, run)
    assert abs(got["rolling_time_constant"] / tau - 1) < 1e-12
    assert abs(got["rolling_distance"] / (v0 * tau) - 1) < 1e-12


@pytest.mark.parametrize("change, key", [(["particles.1.radius=2e-3", "particles.1.position=[3e-3, 0.0, 0.0]"],
                                          "particles"),
                                         (["contact.normal=lsd", "contact.kn=1e5"], "contact.normal")])
def test_sjkr_pull_off_refuses_what_its_closed_form_does_not_cover(change, key):
    from demcheck.case import load
    from demcheck.errors import ConfigError
    from demcheck.resources import case_path

    with pytest.raises(ConfigError) as exc:
        load(case_path("suite/beyond-pull-off-sjkr.toml"), change)
    assert exc.value.key == key and "sjkr" in exc.value.rule
