"""The twin of Yade's Luding law (``LudingMat`` + ``Ip2_LudingMat_LudingMat_LudingPhys`` +
``Law2_ScGeom_LudingPhys_Basic``, Yade 2023.02a) without adhesion (kc = 0), viscosity (G0 = 0) or friction, stepped
as Yade steps a two-body contact (the state, record and Result of collision3d.py).

What Yade computes, in the order it does it (read in pkg/dem/LudingPM.cpp, confirmed by runs): a contact's
physics starts with δ_max = δ_0 = δ_prev = 0; each step, with the overlap δ,

* k2 = k1 + (kp − k1) δ_max/δ_Pmax (kp once δ_max ≥ δ_Pmax), from δ_max **before** this step's overlap;
* if δ > δ_max: δ_max = δ, δ_0 = min((1 − k1/k2) δ_max, δ_P0) — with that k2;
* t = k2 (δ − δ_0); F = k1 δ where t ≥ k1 δ (t past δ_Pmax), t where 0 < t < k1 δ; where t ≤ 0, F = 0 while the
  overlap shrinks (and δ_max = δ k2/(k2 − k1), δ_0 recomputed), t otherwise; δ_prev = δ.

δ_Pmax = kp/(kp − k1) φ_F 2a1a2/(a1 + a2) and δ_P0 = φ_F 2a1a2/(a1 + a2), a the spheres' radii (0 for a body that is
not a sphere). Up to δ_max < δ_Pmax the unloading stiffness is HLS's K_U = K_L + S K_L δ_max with S K_L =
(kp − k1)/δ_Pmax, but k2 lags a step behind δ_max, so that the unloading line misses (δ_max, k1 δ_max) by one step's
growth of k2 — the difference from HLS (docs/yade.md).
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from .kernels import ST_NO_CONTACT, ST_NO_SEPARATION, ST_OK, ST_STEPS, ST_UNRESOLVED
from .kernels3d import (G_GX, G_I0, G_I1, G_M0, G_M1, G_WALL, kinematics, NCOL, record_row)

# the law's numbers: k1, kp, δ_Pmax, δ_P0
L_K1, L_KP, L_DPMAX, L_DP0 = range(4)
L_SIZE = 4
RULES = {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "surface", "rotation": "none"}


@njit(cache=KERNEL_CACHE, inline="always")
def luding_force(law, delta, hist):
    """Yade's hysteretic force of one step; ``hist`` = [δ_max, δ_0, δ_prev, k1] is updated in place."""
    k1, kp, dpmax, dp0 = hist[3], law[L_KP], law[L_DPMAX], law[L_DP0]
    k2 = kp if hist[0] / dpmax >= 1.0 else k1 + (kp - k1) * hist[0] / dpmax
    k2 = min(k2, kp)
    if k1 > k2:
        k1 = k2
        hist[3] = k1
    if delta > hist[0]:
        hist[0] = delta
        hist[1] = min((1.0 - k1 / k2) * hist[0], dp0)
    t = k2 * (delta - hist[1])
    if t >= k1 * delta:
        f = k1 * delta if delta < dpmax else t
    elif t > 0.0:
        f = t
    elif delta - hist[2] < 0.0:
        f = 0.0
        hist[0] = delta * k2 / (k2 - k1)
        hist[1] = min((1.0 - k1 / k2) * hist[0], dp0)
    else:
        f = t
    hist[2] = delta
    return f


@njit(cache=KERNEL_CACHE, nogil=True)
def luding_3d(y0, law, geo, rules, dt, t_max, capacity):
    """Velocity Verlet (Yade's leap-frog gives the same rows) with Yade's Luding normal force and no tangential
    force. The same returns as verlet3d.verlet_3d."""
    rec = np.empty((capacity, NCOL))
    y = y0.copy()
    hist = np.zeros(4)
    wall = geo[G_WALL] != 0.0
    touched = False
    status = ST_NO_SEPARATION
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    fvec0 = np.zeros(3)
    no_force = np.zeros(3)  # Luding's law here has no tangential force
    record_row(rec, 0, 0.0, y, geo, delta, rate, 0.0, no_force, vt, n, 0.0)
    g = geo[G_GX:G_GX + 3]
    i, step = 1, 0
    while i < capacity:
        step += 1
        t = step * dt
        if t > t_max:
            status = ST_NO_SEPARATION if touched else ST_NO_CONTACT
            break
        y[3:6] += 0.5 * dt * (fvec0 / geo[G_M0] + g)
        y[0:3] += dt * y[3:6]
        if not wall:
            y[12:15] += 0.5 * dt * (-fvec0 / geo[G_M1] + g)
            y[9:12] += dt * y[12:15]
        delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
        fn = 0.0
        if delta >= 0.0 and (delta > 0.0 or touched):
            if not touched:
                hist[:] = 0.0
                hist[3] = law[L_K1]
            fn = luding_force(law, delta, hist)
            touched = True
        fvec0 = -fn * n
        y[3:6] += 0.5 * dt * (fvec0 / geo[G_M0] + g)
        if not wall:
            y[12:15] += 0.5 * dt * (-fvec0 / geo[G_M1] + g)
        record_row(rec, i, t, y, geo, delta, rate, fn, no_force, vt, n, 0.0)
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


def law_array(k1: float, kp: float, phi_f: float, two_r: float) -> np.ndarray:
    """The numbers of a contact between spheres with 2a1a2/(a1 + a2) = ``two_r``, as Yade's LudingPhys holds them."""
    law = np.zeros(L_SIZE)
    law[L_K1], law[L_KP] = k1, kp
    law[L_DPMAX] = kp / (kp - k1) * phi_f * two_r
    law[L_DP0] = phi_f * two_r
    return law


def collide(case, model, law: np.ndarray, dt: float):
    """The verlet twin of a Yade Luding contact (``model`` the twin model, for the Result's description and the
    health rules)."""
    from ..errors import ConfigError
    from ..laws.model import characteristic_time
    from ..result import Result
    from . import collision3d
    from .outcome import MESSAGES, ROW_BYTES_3D, STATUS, judge, time_to_contact, verlet_capacity

    if not (dt > 0) or not math.isfinite(dt):
        raise ConfigError("--dt", dt, "must be > 0 (s) and finite")
    t_c = characteristic_time(model)
    geo = collision3d.geometry(case, t_c)
    y0 = collision3d.initial_state(case)
    t_contact = time_to_contact(case)
    t_max = t_contact + 200.0 * t_c
    capacity = verlet_capacity(case, dt, True, t_contact, t_c, t_max, ROW_BYTES_3D)
    started = time.perf_counter()
    status, n, rec = luding_3d(y0, law, geo, collision3d.rules_array(RULES), dt, t_max, capacity)
    contact, particles = collision3d.tables(rec, wall=len(case.particles) == 1)
    name = STATUS[status]
    result = Result(source="reference", method="verlet", case_name=case.name, case_hash=case.hash,
                    model=model.describe(), params=dict(model.params), contact=contact, particles=particles,
                    events=None, dt=dt, rtol=None, wall_time=time.perf_counter() - started, status=name,
                    message=MESSAGES.get(name, ""),
                    meta={"solver": "3d", "steps": int(n), "rules": dict(RULES), "luding": law.tolist(),
                          "radius0": case.particles[0].radius})
    return judge(result, case, model)


__all__ = ["collide", "law_array", "luding_3d", "luding_force"]
