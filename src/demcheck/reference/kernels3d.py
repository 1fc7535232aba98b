"""The compiled 3-D two-body contact's state, layouts and kinematics (seed 000 §2), shared by its two methods:
the adaptive solver (adaptive3d.py) and the engines' discrete scheme (verlet3d.py). The tangential laws they
call are laws/tangential_force.py, the normal law laws/normal_force.py.

State y (21): x0 v0 ω0 x1 v1 ω1 ξ, with ξ the tangential history (a displacement; for Walton the load L).
In the code ``xi`` is a history, ``h`` a time step.
Body 1 is a particle, or a fixed plane wall (its state is then unused). n points from body 0 into body 1
(into the wall); δ > 0 in contact; the relative velocity at the contact point is v_r = v_c0 − v_c1, its
normal part δ̇ = v_r·n (> 0 approaching) and its tangential part v_t (the slip velocity). The force on body 0
is −Fn n + Ft; body 1 takes the opposite force. Torques: τ0 = (a0 n) × Ft, τ1 = (a1 n) × Ft with the torque
arms a = R − δ/2 (or R, by rule).

Continuous-time history (adaptive method): ξ̇ = v_t − (ξ·ṅ) n keeps ξ in the tangent plane as the normal
turns (projection and rotation coincide in continuous time). While slipping, ξ̇ = ξ̇_stick − λ w, where λ
keeps the state on the slip surface ψ = 0; λ < 0 means the contact sticks again. The engines' discrete
rules (verlet method) are chosen by ``rules``: rotation (none, project, project + rescale), lever arms.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..laws.tangential_force import _cross, _dot, _norm

EV_STICK_SLIP, EV_SLIP_STICK, EV_REVERSAL, EV_KINK = 8, 9, 10, 11
EVENT_NAMES_3D = {EV_STICK_SLIP: "slip_start", EV_SLIP_STICK: "stick_start", EV_REVERSAL: "slip_reversal",
                  EV_KINK: "viscous_sliding_switch"}

# geometry array
G_WALL, G_R0, G_R1, G_M0, G_M1, G_I0, G_I1, G_PX, G_NX, G_GX, G_TS = 0, 1, 2, 3, 4, 5, 6, 7, 10, 13, 16
G_SIZE = 17
# rules array
R_SLIP_ARM, R_TORQUE_ARM, R_WALL_TORQUE_ARM, R_ROTATION, R_WALL_SLIP_ARM = 0, 1, 2, 3, 4
ARM_CONTACT, ARM_RADIUS, ARM_SURFACE = 0, 1, 2  # R − δ/2, R, R − δ (the last for walls: Yade's contact point)
# a pair's slip velocity as Yade's ScGeom with avoidGranularRatcheting (Ig2_Sphere_Sphere_ScGeom's default):
# α(v0 − v1) + ω0 × R0 n + ω1 × R1 n with α = (R0 + R1)/(R0 + R1 − δ) (slip arm rule only)
ARM_RATCHET = 3


@njit(cache=KERNEL_CACHE, inline="always")
def wall_arm(code, r, delta):
    """A sphere's lever arm to its contact with a wall, by rule code."""
    if code == ARM_RADIUS:
        return r
    if code == ARM_SURFACE:
        return r - delta
    return r - 0.5 * delta
ROT_NONE, ROT_PROJECT, ROT_RESCALE, ROT_RESCALE_SIGNIFICANT = 0, 1, 2, 3
# Yade's ScGeom::rotate before the increment: h −= h × (n_old × n), then h −= h × (½dt n_old·(ω0 + ω1)) n_old
ROT_SCGEOM = 4
# aux array: dmax, L*(3), t_ref(3), normal mode, tangential mode (0 stick, 1 slip)
A_DMAX, A_LSTAR, A_TREF, A_NMODE, A_TMODE = 0, 1, 4, 7, 8
A_SIZE = 9
STICK, SLIP = 0.0, 1.0
# record columns
NCOL = 33
C_T, C_X0, C_V0, C_W0, C_X1, C_V1, C_W1, C_D, C_R, C_FN, C_FT, C_VT, C_N, C_E, C_SLIP = (
    0, 1, 4, 7, 10, 13, 16, 19, 20, 21, 22, 25, 28, 31, 32)


@njit(cache=KERNEL_CACHE)
def kinematics(y, geo, rules):
    """(δ, δ̇, n, ṅ, v_t, slip arms a0s a1s, torque arms a0t a1t)."""
    r0 = geo[G_R0]
    x0, v0, w0 = y[0:3], y[3:6], y[6:9]
    if geo[G_WALL] != 0.0:
        nw = geo[G_NX:G_NX + 3]
        n = -nw
        delta = r0 - _dot(x0 - geo[G_PX:G_PX + 3], nw)
        ndot = np.zeros(3)
        a0s = wall_arm(rules[R_WALL_SLIP_ARM], r0, delta)
        a0t = wall_arm(rules[R_WALL_TORQUE_ARM], r0, delta)
        vr = v0 + _cross(w0, a0s * n)
        a1s, a1t = 0.0, 0.0
        if rules[R_WALL_SLIP_ARM] == ARM_RATCHET:  # a Wall carries the sphere's radius in Yade's ScGeom
            vs = (2.0 * r0 / (2.0 * r0 - delta)) * v0 + _cross(w0, r0 * n)
            return delta, _dot(vr, n), n, ndot, vs - _dot(vs, n) * n, a0s, a1s, a0t, a1t
    else:
        r1 = geo[G_R1]
        x1, v1, w1 = y[9:12], y[12:15], y[15:18]
        d = x1 - x0
        dist = _norm(d)
        n = d / dist
        delta = r0 + r1 - dist
        dd = v1 - v0
        ndot = (dd - _dot(dd, n) * n) / dist
        if rules[R_SLIP_ARM] == ARM_RADIUS:
            a0s, a1s = r0, r1
        else:  # (ARM_RATCHET: the contact point's arms for δ̇)
            a0s, a1s = r0 - 0.5 * delta, r1 - 0.5 * delta
        if rules[R_TORQUE_ARM] == ARM_RADIUS:
            a0t, a1t = r0, r1
        else:
            a0t, a1t = r0 - 0.5 * delta, r1 - 0.5 * delta
        vr = (v0 + _cross(w0, a0s * n)) - (v1 + _cross(w1, -a1s * n))
        if rules[R_SLIP_ARM] == ARM_RATCHET:  # the slip only: δ̇ stays the contact point's
            alpha = (r0 + r1) / (r0 + r1 - delta)
            vs = alpha * (v0 - v1) + _cross(w0, r0 * n) + _cross(w1, r1 * n)
            return delta, _dot(vr, n), n, ndot, vs - _dot(vs, n) * n, a0s, a1s, a0t, a1t
    rate = _dot(vr, n)
    vt = vr - rate * n
    return delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t


@njit(cache=KERNEL_CACHE, inline="always")
def record_row(rec, i, t, y, geo, delta, rate, fn, ft, vt, n, slip):
    """Row i of a record (the C_* columns): the time, the state, the overlap, its rate, the forces, the slip
    velocity, the normal, the energy and the slip mode — one layout for every 3-D kernel."""
    rec[i, C_T] = t
    rec[i, C_X0:C_X0 + 18] = y[0:18]
    rec[i, C_D] = delta
    rec[i, C_R] = rate
    rec[i, C_FN] = fn
    rec[i, C_FT:C_FT + 3] = ft
    rec[i, C_VT:C_VT + 3] = vt
    rec[i, C_N:C_N + 3] = n
    rec[i, C_E] = energy(y, geo)
    rec[i, C_SLIP] = slip


@njit(cache=KERNEL_CACHE)
def energy(y, geo):
    """Kinetic (translation + rotation) plus gravitational potential energy of the bodies."""
    g = geo[G_GX:G_GX + 3]
    e = 0.5 * geo[G_M0] * _dot(y[3:6], y[3:6]) + 0.5 * geo[G_I0] * _dot(y[6:9], y[6:9]) - geo[G_M0] * _dot(g, y[0:3])
    if geo[G_WALL] == 0.0:
        e += 0.5 * geo[G_M1] * _dot(y[12:15], y[12:15]) + 0.5 * geo[G_I1] * _dot(y[15:18], y[15:18]) \
            - geo[G_M1] * _dot(g, y[9:12])
    return e
