"""Kratos DEM 10.4.4's adhesive laws and its rolling friction on a wall in the scenarios beyond sliding, stepped as
Kratos steps them (the twin of engines/kratos/scenario.py). The rolling sphere: :func:`wall_roll` (its doc).

What Kratos computes (read in applications/DEMApplication/custom_constitutive/DEM_D_JKR_cohesive_law.cpp,
DEM_D_DMT_cohesive_law.cpp, DEM_compound_constitutive_law.h, DEM_D_Hertz_viscous_Coulomb_CL.cpp, and checked
against runs: tests/test_scenarios_kratos.py): ``DEM_D_Hertz_viscous_Coulomb_JKR`` and ``…_DMT`` are the Hertz law
(F_e = (4/3)E*√R̄ δ^{3/2}, its dashpot, the sum held ≥ 0) with a cohesive force subtracted, both only while the
overlap δ is positive (the contact exists for δ > 0 only: no neck, no hysteresis):

* JKR: F_c = √(8π w E* a³) with the Hertz contact radius a = √(R̄δ) (not JKR's own a, which solves
  a²/R̄ − √(2πwa/E*) = δ); w = the relation's PARTICLE_COHESION;
* DMT: F_c = 2π w R̄, constant while δ > 0 — the seed's DMT law itself.

The scheme is the deck's Velocity_Verlet (x += v dt + ½a dt², v += ½a dt; forces; v += ½a dt), as
engines/kratos/deck.py writes it; a pull is Kratos with both bodies' velocities fixed (body 0 at rest, body 1 at
the pull speed): x advances by v·dt each step, and the force is the law's at each step's overlap.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..laws.normal_force import normal_force
from ..laws.tangential_force import _cross, _dot
from .twins_kratos import kratos_arm_turn, tangential

def kratos_jkr_force(r_eff: float, e_eff: float, w: float, delta: float) -> float:
    """The normal force (> 0 repulsive) of Kratos' Hertz_viscous_Coulomb_JKR without damping at overlap δ: the
    Hertz force less √(8πwE*a³) at the Hertz radius a = √(R̄δ); 0 unless δ > 0."""
    if not delta > 0.0:
        return 0.0
    a = math.sqrt(r_eff * delta)
    return _hertz(r_eff, e_eff, delta) - math.sqrt(8.0 * w * math.pi * a * a * a * e_eff)


def kratos_dmt_force(r_eff: float, e_eff: float, w: float, delta: float) -> float:
    """The normal force (> 0 repulsive) of Kratos' Hertz_viscous_Coulomb_DMT without damping at overlap δ: the
    Hertz force less 2πwR̄; 0 unless δ > 0."""
    if not delta > 0.0:
        return 0.0
    return _hertz(r_eff, e_eff, delta) - 2.0 * math.pi * w * r_eff


def _hertz(r_eff: float, e_eff: float, delta: float) -> float:
    return 4.0 / 3.0 * e_eff * math.sqrt(r_eff) * delta ** 1.5


def pair_impact(force, radius: float, mass: float, x1: float, v1: float, dt: float, steps: int) -> dict:
    """Body 0 at rest at the origin, body 1 (like it) at x1 moving at v1 along x, ``force(δ)`` between them,
    stepped by velocity Verlet (Kratos' Velocity_Verlet): the separation speed v1 − v0 and whether the
    contact is closed at the end (adhesive_impact's ``v_rel`` and ``touching``)."""
    x = np.array([0.0, float(x1)])
    v = np.array([0.0, float(v1)])

    def f_on_1():
        return force(2.0 * radius - (x[1] - x[0]))

    f = f_on_1()
    for _ in range(steps):
        a = np.array([-f, f]) / mass
        x += v * dt + 0.5 * a * dt * dt
        v += 0.5 * a * dt
        f = f_on_1()
        v += 0.5 * np.array([-f, f]) / mass * dt
    return {"v_rel": float(v[1] - v[0]), "touching": bool(f != 0.0)}


def pull(force, r_sum: float, x1: float, speed: float, dt: float, steps: int) -> dict:
    """Body 1 moved from x1 at ``speed`` (its displacement += v·dt each step, x = x1 + displacement), body 0 held at the origin: the overlap and the
    force at each step (pull_off's ``delta`` and ``fn``)."""
    disp, deltas, forces = 0.0, [], []
    for k in range(steps + 1):
        if k:
            disp += speed * dt  # Kratos: DISPLACEMENT += v·dt, x = X0 + DISPLACEMENT
        d = r_sum - (float(x1) + disp)
        deltas.append(d)
        forces.append(force(d))
    return {"delta": np.array(deltas), "fn": np.array(forces)}


def jkr_hertz_radius_pull_off(r_eff: float, e_eff: float, w: float) -> tuple[float, float]:
    """(largest tension, overlap where it acts) of the JKR law with the Hertz radius, by dF/dδ = 0:
    2E*√R̄ δ^{1/2} = (3/4)√(8πwE*) R̄^{3/4} δ^{−1/4} ⇒ δ* = ((3/8)√(8πw/E*) R̄^{1/4})^{4/3}."""
    d = (0.375 * math.sqrt(8.0 * math.pi * w / e_eff) * r_eff ** 0.25) ** (4.0 / 3.0)
    return -kratos_jkr_force(r_eff, e_eff, w, d), d


# ----------------------------------------------------------------------------- a sphere rolling on a wall

CONSTANT_TORQUE, VISCOUS_TORQUE = 0, 1  # DEMRollingFrictionModelConstantTorque, …ViscousTorque


def wall_roll(nl, kp, model: int, mu_roll: float, radius: float, mass: float, x0, v0, omega0, gravity,
              wall_point, wall_normal, dt: float, steps: int, every: int) -> dict:
    """One sphere on a rigid face under gravity, stepped as reference/twins_kratos.kratos_3d steps Kratos' wall
    contact (Velocity_Verlet with Direct_Integration of the spin; the tangential law's incremental spring, dashpot
    and cap with the arm R − δ; the normal force ``nl`` held ≥ 0) plus the rolling friction model of the
    relation (``model``; ``mu_roll`` its ROLLING_FRICTION), added to the contact's moment from the spin ω the
    node holds when the forces are computed (the half step's, after the predictor):

    * ConstantTorque: M = −μ |Fn| (R − δ) ω/|ω| (none while ω = 0);
    * ViscousTorque: M = −μ |Fn| (R − δ) · (R − δ) ω.

    Returns, at steps 0, every, 2·every, …: t, x, v, ω, and the total force (the weight included, as Kratos'
    TOTAL_FORCES) ``f`` and moment ``torque`` (rows × 3)."""
    rows = _wall_roll(np.asarray(nl, dtype=float), np.asarray(kp, dtype=float), int(model), float(mu_roll),
                      float(radius), float(mass), *(np.array(a, dtype=float) for a in (x0, v0, omega0, gravity,
                                                                                         wall_point, wall_normal)),
                      float(dt), int(steps), int(every))
    return {"t": np.arange(len(rows)) * every * dt, "x": rows[:, 0:3], "v": rows[:, 3:6], "omega": rows[:, 6:9],
            "f": rows[:, 9:12], "torque": rows[:, 12:15]}


@njit(cache=KERNEL_CACHE)
def _wall_roll(nl, kp, model, mu_roll, radius, mass, x, v, w, g, p, nw, dt, steps, every):
    n = -nw
    inertia = 0.4 * mass * radius * radius
    out = np.empty((steps // every + 1, 15))
    hist = np.zeros(3)
    dmax = 0.0
    f, tq = np.zeros(3), np.zeros(3)
    delta = radius - _dot(x - p, nw)
    if delta > 0.0:  # Kratos' forces before the first step: the bodies still at rest (the runner sets v, ω after)
        f = -abs(normal_force(nl, delta, 0.0, delta)) * n
    _row(out, 0, x, v, w, f + mass * g, tq)
    for k in range(1, steps + 1):
        v += 0.5 * dt * (f / mass + g)
        dx = dt * v
        x += dx
        w += 0.5 * dt * tq / inertia
        dth = dt * w
        delta = radius - _dot(x - p, nw)
        f, tq = np.zeros(3), np.zeros(3)
        if delta > 0.0:
            arm = radius - delta
            vr = v + _cross(w, arm * n)
            rate = _dot(vr, n)
            vt = vr - rate * n
            dmax = max(dmax, delta)
            fn = abs(normal_force(nl, delta, rate, dmax))
            du = dx + kratos_arm_turn(arm * n, dth)
            hist = hist - _dot(hist, n) * n
            ft, hist, _ = tangential(kp, fn, delta, delta - _dot(du, n), du - _dot(du, n) * n, vt, hist)
            f = -fn * n + ft
            tq = _cross(arm * n, ft) + _rolling_moment(model, mu_roll, fn, arm, w)
        else:
            hist = np.zeros(3)
            dmax = 0.0
        v += 0.5 * dt * (f / mass + g)
        w += 0.5 * dt * tq / inertia
        if k % every == 0:
            _row(out, k // every, x, v, w, f + mass * g, tq)
    return out


@njit(cache=KERNEL_CACHE, inline="always")
def _row(out, i, x, v, w, f, tq):
    out[i, 0:3], out[i, 3:6], out[i, 6:9], out[i, 9:12], out[i, 12:15] = x, v, w, f, tq


@njit(cache=KERNEL_CACHE, inline="always")
def _rolling_moment(model, mu, fn, arm, w):
    """The rolling friction model's moment on the sphere (Kratos' order of the products)."""
    if model == VISCOUS_TORQUE:
        return -mu * fn * arm * (arm * w)
    size = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if size == 0.0:
        return np.zeros(3)
    return -(w / size) * mu * fn * arm
