"""Walton & Braun's friction in 3-D (seed 000 §4.8): the load at the last reversal F* is stored only where the slip
reverses its direction — not where the load passes through zero while the slip keeps its direction (the rule
demcheck had, which jumped Kt from ≈ 0.79 K0 to K0 there) — and the stored load obeys Coulomb's law, so a falling
limit carries it down. The golden value comes from an independent path: a planar sphere-on-wall integrator written
here from the seed's formulas (scalar state, its own time stepping), extrapolated to dt → 0."""

import math

import numpy as np
import pytest

from demcheck.case import load
from demcheck.reference.collision import collide
from demcheck.laws.model import characteristic_time, resolve

CASE = "cases/suite/oblique-walton.toml"


def planar_walton(case, steps_per_tc: int) -> float:
    """Tangential restitution of a sphere hitting a wall (LSD normal law, Walton's friction), semi-implicit Euler.
    x along the wall, z its normal; the contact point sits a = R − δ/2 below the centre (the seed's arm)."""
    model = resolve(case)
    p = model.params
    kn, eta, k0, mu = p["kn"], p["eta_n"], p["k0"], p["friction"]
    r = case.particles[0].radius
    m = case.mass(0)
    inertia = 0.4 * m * r * r
    v = case.particles[0].velocity
    vx, vz, wy = v[0], v[2], 0.0
    dt = characteristic_time(model) / steps_per_tc
    delta, load, lstar, prev, started = 0.0, 0.0, 0.0, 0.0, False
    vx_in = vx
    for _ in range(100 * steps_per_tc):
        a = r - 0.5 * delta
        vs = vx - a * wy  # slip velocity of the contact point
        fn = kn * delta - eta * vz  # repulsive > 0 (vz < 0 approaching)
        cap = mu * abs(fn)
        if vs * prev < 0.0:  # the slip reverses: F* is the load there
            lstar = load
        if vs != 0.0:
            prev = vs
        s = math.copysign(1.0, vs) if vs != 0.0 else 0.0
        t_now, t_star = load * s, lstar * s  # loads along the current slip direction
        x = 1.0 - (t_now - t_star) / (cap - t_star) if cap - t_star > 0.0 else 0.0
        kt = k0 * x ** (1.0 / 3.0) if x > 0.0 else 0.0
        load += kt * vs * dt
        if abs(load) > cap:  # Coulomb's law on the stored load
            load = math.copysign(cap, load)
        ft = -load
        vz += fn / m * dt
        vx += ft / m * dt
        wy += -a * ft / inertia * dt
        delta -= vz * dt
        started = started or delta > 0.0
        if started and delta <= 0.0:
            return vx / vx_in
    raise AssertionError("no separation")


def test_walton_matches_an_independent_planar_solver_at_30_degrees():
    case = load(CASE, ["impact.angle=30", "impact.spin=0"])
    coarse, fine = planar_walton(case, 20000), planar_walton(case, 40000)
    extrapolated = 2.0 * fine - coarse  # first order: the error halves with the step
    adaptive = collide(case, "adaptive").metrics()["tangential_restitution"]
    # the old rule (F* reset where the load passed through zero) gave 0.601216 here. The extrapolation's own
    # uncertainty: the 20k/40k and 40k/80k extrapolations differ by 1.3e-6 (measured), and the adaptive answer lies
    # 4.7e-7 from this one; 5e-6 holds that with room, 3000 times tighter than the old rule's miss
    assert adaptive == pytest.approx(extrapolated, abs=5e-6)
    assert abs(adaptive - 0.601216) > 1e-2


def test_a_reversal_is_a_reversal_of_the_slip_not_a_zero_of_the_load():
    case = load(CASE, ["impact.angle=30", "impact.spin=0"])
    r = collide(case, "adaptive")
    c = r.contact[(r.contact["t"] >= r.events["t"].iloc[0]) & (r.contact["delta"] > 0.0)]
    c = c[np.abs(c["vtx"]) > 1e-9 * np.abs(c["vtx"]).max()]  # the event rows themselves sit at v_t ≈ 0
    vt, ft, t = c["vtx"].to_numpy(), c["ftx"].to_numpy(), c["t"].to_numpy()
    same_slip = np.sign(vt[1:]) == np.sign(vt[:-1])
    slip_flips = t[1:][~same_slip]
    load_zeros = t[1:][(np.sign(ft[1:]) != np.sign(ft[:-1])) & same_slip]
    reversals = r.events.loc[r.events["event"] == "slip_reversal", "t"].to_numpy()
    assert len(load_zeros) >= 1  # the load does pass through zero under a steady slip here
    assert len(reversals) == len(slip_flips) >= 1
    for tr, flip in zip(reversals, slip_flips):  # each reversal sits between the two rows of its slip flip
        before = t[t < flip].max()
        assert before <= tr <= flip
