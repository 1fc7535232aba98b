"""The twin of Kratos DEM's tangential force: its discontinuum laws' incremental spring with its dashpot and its
Coulomb cap, stepped as Kratos steps a two-body contact (the state, record and Result of collision3d.py).

What Kratos 10.4.4 computes (read in applications/DEMApplication: custom_constitutive/DEM_D_Hertz_viscous_Coulomb,
DEM_D_Linear_viscous_Coulomb; custom_elements/spheric_particle.cpp), in the reference's convention (n from body 0
into body 1, v_t the slip velocity, force on body 0 = −Fn n + Ft):

* Kt = ρ Kn with ρ = 4G*/E* from the materials (ρ = 2(1 − ν)/(2 − ν) for equal materials or a rigid face),
  Kn = 2E*√(R̄δ) (Hertz) or constant (Linear); the tangential dashpot c_t = 2γ√(m̄ Kt) (γ the contact's
  DAMPING_GAMMA); the cap μ|Fn|, |Fn| the normal force held ≥ 0, μ = μd + (μs − μd) exp(−d |v_t|).
* The history is the elastic tangential force F_e. Each step it is turned into the new tangent plane
  (a pair: the stored force rotated about n_old × n by asin|n_old × n|; a wall: projected), (Hertz) scaled by
  √(δ/δ_prev) when the overlap shrinks, and incremented by −Kt Δu_t, Δu the contact point's relative
  displacement over the step: the bodies' displacements (x_new − x_old) plus the turn of each lever arm by the
  body's rotation over the step (DELTA_ROTATION = ω dt), by a finite rotation (q(Δθ)a − a for a pair's arms
  a = ±(R − δ/2) n; a − q(−Δθ)a on a wall, a = (R − δ) n) with Kratos' quaternion of the rotation, whose
  low-angle branch turns by θ(1 − θ²/4), not θ (:func:`kratos_rotate`). δ_prev = δ − Δu·n.
* The dashpot −c_t v_t (v_t with the same arms). If |F_e + F_d| > μ|Fn| Kratos splits the cap between spring and
  dashpot: with F_e·F_d ≥ 0, the spring is cut to the cap and the dashpot dropped if |F_e| > cap, else the
  dashpot is cut to cap − |F_e|; with F_e·F_d < 0, the dashpot is cut to (cap + |F_e|)/|F_d| of itself if
  |F_d| ≥ |F_e|, else the spring to the cap and the dashpot dropped.
* Torques at R − δ/2 (pair, equal moduli) and R − δ (wall).

The other twinned laws (engines/kratos/mapping.law_numbers) are these numbers changed: Kn and ρ
(Linear_HighStiffness, Linear_Custom_Constants), or no dashpot, no √(δ/δ_prev) and μ = tan φ
(Linear_Simple_Coulomb).
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..laws.normal_force import normal_force
from ..laws.tangential_force import _cross, _dot, _norm
from .kernels import M_VE, ST_NO_CONTACT, ST_NO_SEPARATION, ST_OK, ST_STEPS, ST_UNRESOLVED
from .kernels3d import (A_NMODE, A_SIZE, G_GX, G_I0, G_I1, G_M0, G_M1, G_R0, G_R1, G_WALL, kinematics, NCOL,
                        record_row)

# the law's numbers (kp array): Kn = KN · δ^½ (Hertz) or KN (Linear); Kt = RHO · Kn; c_t = 2 GAMMA √(M Kt);
# μ = MU_D + (MU_S − MU_D) exp(−DECAY |v_t|); MINOR: the Hertz law's √(δ/δ_prev) on unloading
K_HERTZ, K_KN, K_RHO, K_GAMMA, K_M, K_MU_S, K_MU_D, K_DECAY, K_MINOR = range(9)
K_SIZE = 9
# Kratos' kinematic rules: slip at the contact point (R − δ/2 for a pair, R − δ on a wall), torques likewise
RULES = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "surface", "wall_slip_arm": "surface",
         "rotation": "none"}


@njit(cache=KERNEL_CACHE, inline="always")
def rotate(v, axis, angle):
    """v turned by ``angle`` about the unit ``axis`` (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + _cross(axis, v) * s + axis * (_dot(axis, v) * (1.0 - c))


@njit(cache=KERNEL_CACHE, inline="always")
def kratos_rotate(v, dtheta):
    """``v`` turned by the rotation vector ``dtheta`` as Kratos turns it: Quaternion::RotateVector3 with the
    quaternion of GeometryFunctions::OrientationFromRotationAngle.

    Below (|Δθ|/2)⁴/24 < ε (every DEM step: |Δθ| < 5.4e-4 rad) that function takes its "Taylor: low angle"
    branch, q = (1 + φ²/2, φ̂·φ(1 − φ²/6)) normalised, φ = |Δθ|/2: the scalar part's sign is wrong (cos φ ≈
    1 − φ²/2), and after the normalisation q turns by θ(1 − θ²/4), θ = |Δθ|. A lever arm's tip moves by θ³R/4 less
    than a rotation by θ — on a rolling contact, where the slip increment is the small difference of the
    translation and this turn, that is 1e-5 of the increment (docs/findings.md, "Kratos beyond sliding"); in a
    collision 1e-10 of the rebound spin (docs/kratos.md)."""
    half = 0.5 * dtheta
    phi = math.sqrt(half[0] * half[0] + half[1] * half[1] + half[2] * half[2])
    if phi * phi * phi * phi / 24.0 < 2.220446049250313e-16:
        aux = 1.0 - phi * phi / 6.0
        qw = 1.0 + phi * phi / 2.0
    else:
        aux = math.sin(phi) / phi
        qw = math.cos(phi)
    qx, qy, qz = half[0] * aux, half[1] * aux, half[2] * aux
    norm2 = qx * qx + qy * qy + qz * qz + qw * qw
    if norm2 > 0.0 and norm2 != 1.0:
        norm = math.sqrt(norm2)
        qx, qy, qz, qw = qx / norm, qy / norm, qz / norm, qw / norm
    b0 = 2.0 * (qy * v[2] - qz * v[1])
    b1 = 2.0 * (qz * v[0] - qx * v[2])
    b2 = 2.0 * (qx * v[1] - qy * v[0])
    return np.array([v[0] + b0 * qw + (qy * b2 - qz * b1), v[1] + b1 * qw + (qz * b0 - qx * b2),
                     v[2] + b2 * qw + (qx * b1 - qy * b0)])


@njit(cache=KERNEL_CACHE, inline="always")
def kratos_arm_turn(arm, dtheta):
    """The wall contact point's displacement by the sphere's rotation ``dtheta`` over the step as Kratos computes
    it (SphericParticle::ComputeBallToRigidFaceContactForceAndMoment): a − q(−Δθ) a (:func:`kratos_rotate`)."""
    return arm - kratos_rotate(arm, -dtheta)


@njit(cache=KERNEL_CACHE, inline="always")
def arm_turn(arm, dtheta, forward):
    """The displacement of a lever arm's tip by the body's rotation ``dtheta`` over the step, turned as Kratos
    turns it (:func:`kratos_rotate`): q(Δθ)a − a (``forward``, a pair's arms:
    RelativeDisplacementAndVelocityOfContactPointDueToRotationQuaternion) or a − q(−Δθ)a (a wall's arm)."""
    if forward:
        return kratos_rotate(arm, dtheta) - arm
    return kratos_arm_turn(arm, dtheta)


@njit(cache=KERNEL_CACHE, inline="always")
def turn_pair_history(h, n_old, n):
    """Kratos' RotateOldContactForces then its projection on the new tangent plane."""
    ax = _cross(n_old, n)
    s = _norm(ax)
    if s > 0.0:
        h = rotate(h, ax / s, math.asin(min(s, 1.0)))
    return h - _dot(h, n) * n


@njit(cache=KERNEL_CACHE, inline="always")
def coulomb_split(fe, fd, cap):
    """Kratos' cap of spring + dashpot at ``cap``: (F_e, F_d, sliding)."""
    tot = fe + fd
    if _norm(tot) <= cap:
        return fe, fd, False
    ne, nd = _norm(fe), _norm(fd)
    if _dot(fe, fd) >= 0.0:
        if ne > cap:
            return fe * (cap / ne), np.zeros(3), True
        return fe, fd * ((cap - ne) / nd), True
    if nd >= ne:
        return fe, fd * ((cap + ne) / nd), True
    return fe * (cap / ne), np.zeros(3), True


@njit(cache=KERNEL_CACHE, inline="always")
def tangential(kp, fn, delta, delta_prev, du, vt, hist):
    """(F_t, new history F_e, sliding) of one step: ``hist`` already turned into the new tangent plane, ``du``
    and ``vt`` tangential."""
    kn = kp[K_KN] * (math.sqrt(delta) if kp[K_HERTZ] != 0.0 else 1.0)
    kt = kp[K_RHO] * kn
    if kp[K_MINOR] != 0.0 and delta_prev > delta:
        hist = hist * math.sqrt(delta / delta_prev)
    fe = hist - kt * du
    fd = -2.0 * kp[K_GAMMA] * math.sqrt(kp[K_M] * kt) * vt
    mu = kp[K_MU_D] + (kp[K_MU_S] - kp[K_MU_D]) * math.exp(-kp[K_DECAY] * _norm(vt))
    fe, fd, sliding = coulomb_split(fe, fd, fn * mu)
    return fe + fd, fe, sliding


@njit(cache=KERNEL_CACHE, nogil=True)
def kratos_3d(y0, nl, kp, geo, rules, dt, t_max, capacity):
    """Velocity Verlet as Kratos' Velocity_Verlet with Direct_Integration of the spins (verlet3d's scheme), with
    Kratos' tangential force (the module's doc). The same returns as verlet3d.verlet_3d."""
    rec = np.empty((capacity, NCOL))
    y = y0.copy()
    aux = np.zeros(A_SIZE)
    aux[A_NMODE] = M_VE
    hist = np.zeros(3)
    n_old = np.zeros(3)
    dmax = 0.0
    wall = geo[G_WALL] != 0.0
    touched = False
    status = ST_NO_SEPARATION
    fvec0, tau0, tau1 = np.zeros(3), np.zeros(3), np.zeros(3)
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    fn = normal_force(nl, delta, rate, delta) if delta > 0.0 else 0.0
    fvec0 = -fn * n
    record_row(rec, 0, 0.0, y, geo, delta, rate, fn, np.zeros(3), vt, n, 0.0)
    g = geo[G_GX:G_GX + 3]
    i, step = 1, 0
    while i < capacity:
        step += 1
        t = step * dt
        if t > t_max:
            status = ST_NO_SEPARATION if touched else ST_NO_CONTACT
            break
        y[3:6] += 0.5 * dt * (fvec0 / geo[G_M0] + g)
        dx0 = dt * y[3:6]
        y[0:3] += dx0
        y[6:9] += 0.5 * dt * tau0 / geo[G_I0]
        dth0 = dt * y[6:9]
        dx1, dth1 = np.zeros(3), np.zeros(3)
        if not wall:
            y[12:15] += 0.5 * dt * (-fvec0 / geo[G_M1] + g)
            dx1 = dt * y[12:15]
            y[9:12] += dx1
            y[15:18] += 0.5 * dt * tau1 / geo[G_I1]
            dth1 = dt * y[15:18]
        delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
        ft = np.zeros(3)
        fn = 0.0
        sliding = False
        if delta > 0.0:
            dmax = max(dmax, delta)
            fn = abs(normal_force(nl, delta, rate, dmax))
            if wall:
                du = dx0 + arm_turn((geo[G_R0] - delta) * n, dth0, False)
                hist = hist - _dot(hist, n) * n
            else:
                du = (dx0 - dx1 + arm_turn((geo[G_R0] - 0.5 * delta) * n, dth0, True)
                      - arm_turn(-(geo[G_R1] - 0.5 * delta) * n, dth1, True))
                if touched:
                    hist = turn_pair_history(hist, n_old, n)
            delta_prev = delta - _dot(du, n)
            ft, hist, sliding = tangential(kp, fn, delta, delta_prev, du - _dot(du, n) * n, vt, hist)
            n_old = n.copy()
            touched = True
        else:
            hist[:] = 0.0
            dmax = 0.0
        fvec0 = -fn * n + ft
        tau0 = _cross(a0t * n, ft)
        tau1 = _cross(a1t * n, ft)
        y[3:6] += 0.5 * dt * (fvec0 / geo[G_M0] + g)
        y[6:9] += 0.5 * dt * tau0 / geo[G_I0]
        if not wall:
            y[12:15] += 0.5 * dt * (-fvec0 / geo[G_M1] + g)
            y[15:18] += 0.5 * dt * tau1 / geo[G_I1]
        record_row(rec, i, t, y, geo, delta, rate, fn, ft, vt, n, (1.0 if sliding else 0.0))
        i += 1
        if not np.all(np.isfinite(y[0:18])):
            status = ST_UNRESOLVED
            break
        if delta <= 0.0 and touched:
            status = ST_OK
            break
    else:
        status = ST_STEPS
    return status, i, rec[:i].copy()


def law_array(hertz: bool, kn: float, rho: float, gamma: float, m_eff: float, mu_s: float, mu_d: float,
              decay: float, minor: bool | None = None) -> np.ndarray:
    """The kernel's numbers (``minor``: the √(δ/δ_prev) shrink on unloading, the Hertz law's by default)."""
    kp = np.zeros(K_SIZE)
    kp[K_HERTZ], kp[K_KN], kp[K_RHO], kp[K_GAMMA], kp[K_M] = float(hertz), kn, rho, gamma, m_eff
    kp[K_MU_S], kp[K_MU_D], kp[K_DECAY] = mu_s, mu_d, decay
    kp[K_MINOR] = float(hertz if minor is None else minor)
    return kp


def collide(case, model, kp: np.ndarray, dt: float):
    """The verlet twin of a Kratos contact with friction: collision3d.collide's verlet branch with this module's
    kernel (``model`` the twin model: its normal law is Kratos' normal law)."""
    from ..errors import ConfigError
    from ..laws.model import characteristic_time
    from ..result import Result
    from . import collision3d
    from .outcome import MESSAGES, ROW_BYTES_3D, STATUS, judge, time_to_contact, verlet_capacity

    if not (dt > 0) or not math.isfinite(dt):
        raise ConfigError("--dt", dt, "must be > 0 (s) and finite")
    t_c = characteristic_time(model)
    geo = collision3d.geometry(case, t_c)
    rul = collision3d.rules_array(RULES)
    y0 = collision3d.initial_state(case)
    t_contact = time_to_contact(case)
    t_max = t_contact + 200.0 * t_c
    capacity = verlet_capacity(case, dt, True, t_contact, t_c, t_max, ROW_BYTES_3D)
    started = time.perf_counter()
    status, n, rec = kratos_3d(y0, model.normal_law.array(), kp, geo, rul, dt, t_max, capacity)
    contact, particles = collision3d.tables(rec, wall=len(case.particles) == 1)
    name = STATUS[status]
    result = Result(source="reference", method="verlet", case_name=case.name, case_hash=case.hash,
                    model=model.describe(), params=dict(model.params), contact=contact, particles=particles,
                    events=None, dt=dt, rtol=None, wall_time=time.perf_counter() - started, status=name,
                    message=MESSAGES.get(name, ""),
                    meta={"solver": "3d", "steps": int(n), "rules": dict(RULES), "kratos_tangential": kp.tolist(),
                          "radius0": case.particles[0].radius})
    return judge(result, case, model)
