"""The engines' discrete scheme on the 3-D two-body contact (kernels3d.py's state and kinematics): velocity
Verlet as ``fix nve/sphere``, the history rules of one step (turn, project, the spring family's slip and
truncation) that the packing loop shares, and the two-body verlet kernel.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..laws.normal_force import (normal_force)
from ..laws.tangential import T_FORCE, T_MU_K, T_MU_S, T_R, T_RESCALE, T_TRUNC, TRUNC_SPRING
from ..laws.tangential_force import (_cross, discrete_slip, eta_of, F_DISCRETE_SLIP, F_HISTORY, F_NO_FORCE, F_OWN_RATE,
                                     F_REVERSAL, has, history_rate, kt_of, _norm, return_map, reverses,
                                     slip_surface, tangential_force)
from .kernels import (M_VE, ST_NO_CONTACT, ST_NO_SEPARATION, ST_OK, ST_STEPS, ST_UNRESOLVED)
from .kernels3d import (A_NMODE, A_SIZE, A_TREF, G_GX, G_I0, G_I1, G_M0, G_M1, G_WALL, kinematics, NCOL, R_ROTATION,
                        record_row, ROT_PROJECT, ROT_RESCALE, ROT_RESCALE_SIGNIFICANT, ROT_SCGEOM)

# ----------------------------------------------------------------------------- velocity Verlet (engines)


ROTATION_THRESHOLD = 1e-10  # of μ|Fn|: a history whose normal part is below it is left as it is


@njit(cache=KERNEL_CACHE, inline="always")
def normal_part_matters(normal_part, scale, mu, fabs):
    """The rescale_significant rule (LAMMPS's): a history is turned into the new tangent plane only when its
    normal part matters, |ξ·n| scale > ROTATION_THRESHOLD μ|Fn| (``scale`` turns the history into a force: Kt,
    or 1). The one rule of the two-body verlet kernel and the packing loop; the callers test the mode first, so
    that nothing is computed for the other modes."""
    return abs(normal_part) * scale > ROTATION_THRESHOLD * mu * fabs


@njit(cache=KERNEL_CACHE, inline="always")
def turn_history(xi0, xi1, xi2, n, rot, scale, mu, fabs):
    """The verlet history rule before the increment: LAMMPS turns the history (xi0, xi1, xi2) into the new tangent
    plane and rescales it to its old length — always (ROT_RESCALE) or only where its normal part matters
    (ROT_RESCALE_SIGNIFICANT, ``normal_part_matters`` with ``scale``, ``mu`` and ``fabs``). The one rule of the
    two-body verlet kernel and the packing loop (scalars: it is inlined into the packing's force loop)."""
    if rot == ROT_RESCALE or rot == ROT_RESCALE_SIGNIFICANT:
        hn = xi0 * n[0] + xi1 * n[1] + xi2 * n[2]
        if rot == ROT_RESCALE or normal_part_matters(hn, scale, mu, fabs):
            old = math.sqrt(xi0 * xi0 + xi1 * xi1 + xi2 * xi2)
            xi0, xi1, xi2 = xi0 - hn * n[0], xi1 - hn * n[1], xi2 - hn * n[2]
            new = math.sqrt(xi0 * xi0 + xi1 * xi1 + xi2 * xi2)
            if new > 0.0:
                r = old / new
                xi0, xi1, xi2 = xi0 * r, xi1 * r, xi2 * r
    return xi0, xi1, xi2


@njit(cache=KERNEL_CACHE, inline="always")
def scgeom_rotate(h, n_old, n, spin):
    """Yade's first-order turn of a history (ScGeom::rotate, before the increment): h −= h × (n_old × n), then
    h −= h × (½dt n_old·(ω0 + ω1)) n_old (``spin`` = ½dt (ω0 + ω1)); no projection, no rescale."""
    h = h - _cross(h, _cross(n_old, n))
    return h - _cross(h, (spin[0] * n_old[0] + spin[1] * n_old[1] + spin[2] * n_old[2]) * n_old)


@njit(cache=KERNEL_CACHE, inline="always")
def project_history(xi0, xi1, xi2, n, rot):
    """The verlet history rule after the increment: LIGGGHTS projects the history onto the tangent plane
    (ROT_PROJECT), with no rescale."""
    if rot == ROT_PROJECT:
        hn = xi0 * n[0] + xi1 * n[1] + xi2 * n[2]
        xi0, xi1, xi2 = xi0 - hn * n[0], xi1 - hn * n[1], xi2 - hn * n[2]
    return xi0, xi1, xi2


@njit(cache=KERNEL_CACHE, nogil=True)  # the suite runs cases in threads
def verlet_3d(y0, nl, tl, geo, rules, dt, t_max, capacity):
    """The engines' scheme (fix nve/sphere, I = 0.4 m R²): half kick, drift, forces from full-step positions
    and half-step velocities with the history updated once per step (not at setup), half kick. History
    rules: rotation of ξ into the new tangent plane (none, project after the increment as LIGGGHTS, or
    project and rescale before it as LAMMPS), then ξ += v_t dt, then the law's Coulomb truncation.
    Stops at the first step after the contact has ended."""
    rec = np.empty((capacity, NCOL))
    y = y0.copy()
    aux = np.zeros(A_SIZE)
    aux[A_NMODE] = M_VE
    hist = np.zeros(3)
    n_old = np.zeros(3)  # the normal of the step before (ROT_SCGEOM)
    lstar = np.zeros(3)
    prev_vt = np.zeros(3)
    a_prev = 0.0
    dmax = 0.0
    sliding = np.bool_(False)  # (not a literal: see adaptive_3d)
    history = has(tl, F_HISTORY)
    wall = geo[G_WALL] != 0.0
    touched = False
    touched_now = False  # in contact at the step before (ROT_SCGEOM: a new contact is not turned)
    status = ST_NO_SEPARATION

    fvec0 = np.zeros(3)
    tau0 = np.zeros(3)
    tau1 = np.zeros(3)
    # setup: forces of the initial state, no history update
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    fn = 0.0
    if delta > 0.0:
        fn = normal_force(nl, delta, rate, delta)
        fvec0 = -fn * n
    record_row(rec, 0, 0.0, y, geo, delta, rate, fn, np.zeros(3), vt, n, 0.0)
    g = geo[G_GX:G_GX + 3]
    i = 1
    step = 0
    while i < capacity:
        step += 1
        t = step * dt
        if t > t_max:
            status = ST_NO_SEPARATION if touched else ST_NO_CONTACT
            break
        # initial_integrate
        y[3:6] += 0.5 * dt * (fvec0 / geo[G_M0] + g)
        y[0:3] += dt * y[3:6]
        y[6:9] += 0.5 * dt * tau0 / geo[G_I0]
        if not wall:
            y[12:15] += 0.5 * dt * (-fvec0 / geo[G_M1] + g)
            y[9:12] += dt * y[12:15]
            y[15:18] += 0.5 * dt * tau1 / geo[G_I1]
        # forces
        delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
        ft = np.zeros(3)
        fn = 0.0
        if delta > 0.0:
            if delta > dmax:
                dmax = delta
            fn = normal_force(nl, delta, rate, dmax)
            fabs = abs(fn)
            force_hist = tl[T_FORCE] != 0.0  # (engine twins of the spring: no other law sets it)
            if rules[R_ROTATION] == ROT_SCGEOM:
                if touched_now:
                    spin = 0.5 * dt * (y[6:9] + (0.0 if wall else 1.0) * y[15:18])
                    hist = scgeom_rotate(hist, n_old, n, spin)
                n_old = n.copy()
                touched_now = True
            if tl[T_RESCALE] != 0.0:
                # mindlin_rescale: a shrinking contact radius scales the history by a/a_prev first
                a_now = math.sqrt(tl[T_R] * delta)
                if a_now < a_prev:
                    hist = hist * (a_now / a_prev)
            if history:
                # (a force history's normal part is a force already: its scale is 1)
                hist[0], hist[1], hist[2] = turn_history(hist[0], hist[1], hist[2], n, rules[R_ROTATION],
                                                         1.0 if force_hist else kt_of(tl, delta), tl[T_MU_K], fabs)
            if force_hist:
                # mindlin/force: F_el += −Kt v_t dt; the sum with the dashpot is capped at μ|Fn| and the
                # history keeps the elastic part of the capped force (truncation spring: Yade's rule below)
                eta = eta_of(tl, nl, delta)
                hist = hist - kt_of(tl, delta) * dt * vt
                if tl[T_RESCALE] != 0.0:
                    a_prev = math.sqrt(tl[T_R] * delta)
                cap = tl[T_MU_K] * fabs
                if tl[T_TRUNC] == TRUNC_SPRING:
                    # Yade's MindlinPhys, FrictPhys and ViscElPhys: the elastic force alone capped at μ|Fn| (and
                    # kept there), the dashpot added only while it sticks
                    hm = _norm(hist)
                    sliding = hm > cap
                    if sliding:
                        hist = hist * (cap / hm)
                        ft = hist.copy()
                    else:
                        ft = hist - eta * vt
                else:
                    ft = hist - eta * vt
                    fm = _norm(ft)
                    sliding = fm > cap
                    if sliding:
                        if _norm(hist) != 0.0:
                            ft = ft * (cap / fm)
                            hist = ft + eta * vt
                        else:
                            ft = np.zeros(3)
            elif history:
                if has(tl, F_REVERSAL):
                    if reverses(vt, prev_vt):
                        lstar = hist.copy()
                    if _norm(vt) != 0.0:
                        prev_vt = vt.copy()
                if has(tl, F_OWN_RATE):
                    hist = hist + history_rate(tl, nl, hist, vt, fabs, delta, lstar) * dt
                else:
                    hist = hist + vt * dt
                if tl[T_RESCALE] != 0.0:
                    a_prev = math.sqrt(tl[T_R] * delta)
                hist[0], hist[1], hist[2] = project_history(hist[0], hist[1], hist[2], n, rules[R_ROTATION])
                mu = tl[T_MU_K] if sliding else tl[T_MU_S]  # a slip goes on while the force exceeds μk|Fn|
                if has(tl, F_DISCRETE_SLIP):
                    hist, ft, sliding = discrete_slip(tl, nl, hist, vt, fabs, delta, mu)
                else:
                    psi, w, d = slip_surface(tl, nl, hist, vt, fabs, delta, mu)
                    if psi > 0.0:
                        sliding = True
                        hist = return_map(tl, nl, hist, vt, fabs, delta, tl[T_MU_K])
                    else:
                        sliding = False
                    ft = tangential_force(tl, nl, hist, vt, fabs, delta, sliding, aux[A_TREF:A_TREF + 3])
            elif not has(tl, F_NO_FORCE):
                ft = tangential_force(tl, nl, hist, vt, fabs, delta, np.bool_(False), aux[A_TREF:A_TREF + 3])
        else:
            hist[:] = 0.0
            touched_now = False
            lstar[:] = 0.0
            a_prev = 0.0
            prev_vt = np.zeros(3)
            dmax = 0.0
            sliding = False
        fvec0 = -fn * n + ft
        tau0 = _cross(a0t * n, ft)
        tau1 = _cross(a1t * n, ft)
        # final_integrate
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
        if delta > 0.0:
            touched = True
        elif touched:
            status = ST_OK
            break
    else:
        status = ST_STEPS
    return status, i, rec[:i].copy()
