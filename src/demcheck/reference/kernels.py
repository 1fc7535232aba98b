"""Compiled (numba, cached on disk) 1-D normal-impact integrators, adaptive and verlet, and many collisions at once.

The law array is ``NormalLaw.array()``: [family, k, a, eta, b, kl, ku, s, damping, limit]; its force (the
spring's plus the damping law's, and their rate) is laws/normal_force.py's, and the solver asks its trait
(``loads_and_unloads``: the hysteretic law's loading and unloading modes), never its family id.

State of the 1-D problem: δ (overlap, > 0 in contact) and r = δ̇ (approach rate); m̄ δ̈ = −F + m̄ a_n.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..laws.normal_force import (L_ETA, L_KL, L_LIMIT, hls_unloading, loads_and_unloads, normal_force,
                                 viscoelastic_force, viscoelastic_force_rate)
from ..metrics import stepped
from .health import reading
from .integrator import (H_MIN, H_START, LOCATE_ITERATIONS, THETA_TOL, crossed, ended_with_it, error, grow,
                         illinois_step, illinois_trial, resume, shrink, solution, stage2, stage3, stage4, stage5,
                         stage6)


# modes of the piecewise-smooth normal law (adaptive method)
M_PRE, M_VE, M_LOAD, M_UNLOAD, M_FREE = 0, 1, 2, 3, 4
# event codes
EV_START, EV_END, EV_FORCE_END, EV_MAX_OVERLAP, EV_PEAK, EV_RELOAD, EV_REENTER = 1, 2, 3, 4, 5, 6, 7
EVENT_NAMES = {EV_START: "contact_start", EV_END: "contact_end", EV_FORCE_END: "force_end",
               EV_MAX_OVERLAP: "max_overlap", EV_PEAK: "peak_force", EV_RELOAD: "reload",
               EV_REENTER: "force_restart"}
# status codes
ST_OK, ST_TOLERANCE, ST_STEPS, ST_NO_CONTACT, ST_NO_SEPARATION, ST_UNRESOLVED = 0, 1, 2, 3, 4, 5


# ----------------------------------------------------------------------------- adaptive (DP5(4))


@njit(cache=KERNEL_CACHE, inline="always")
def _mode_force(law, mode, d, r, dmax):
    if mode == M_VE:
        return viscoelastic_force(law, d, r)
    if mode == M_LOAD:
        return law[L_KL] * d
    if mode == M_UNLOAD:
        ku, d0 = hls_unloading(law, dmax)
        return ku * (d - d0)
    return 0.0


@njit(cache=KERNEL_CACHE, inline="always")
def _acc(law, mode, d, r, dmax, m, an):
    return -_mode_force(law, mode, d, r, dmax) / m + an


@njit(cache=KERNEL_CACHE)
def _dp5(law, mode, d, r, h, dmax, m, an):
    """One Dormand–Prince 5(4) step of (δ, δ̇) (integrator.py's stages); returns the 5th-order state and the
    error estimate."""
    k1d, k1r = r, _acc(law, mode, d, r, dmax, m, an)
    d2, r2 = stage2(d, h, k1d), stage2(r, h, k1r)
    k2d, k2r = r2, _acc(law, mode, d2, r2, dmax, m, an)
    d3, r3 = stage3(d, h, k1d, k2d), stage3(r, h, k1r, k2r)
    k3d, k3r = r3, _acc(law, mode, d3, r3, dmax, m, an)
    d4, r4 = stage4(d, h, k1d, k2d, k3d), stage4(r, h, k1r, k2r, k3r)
    k4d, k4r = r4, _acc(law, mode, d4, r4, dmax, m, an)
    d5, r5 = stage5(d, h, k1d, k2d, k3d, k4d), stage5(r, h, k1r, k2r, k3r, k4r)
    k5d, k5r = r5, _acc(law, mode, d5, r5, dmax, m, an)
    d6, r6 = stage6(d, h, k1d, k2d, k3d, k4d, k5d), stage6(r, h, k1r, k2r, k3r, k4r, k5r)
    k6d, k6r = r6, _acc(law, mode, d6, r6, dmax, m, an)
    dn, rn = solution(d, h, k1d, k3d, k4d, k5d, k6d), solution(r, h, k1r, k3r, k4r, k5r, k6r)
    k7d, k7r = rn, _acc(law, mode, dn, rn, dmax, m, an)
    return dn, rn, error(h, k1d, k3d, k4d, k5d, k6d, k7d), error(h, k1r, k3r, k4r, k5r, k6r, k7r)


@njit(cache=KERNEL_CACHE)
def _event_value(law, mode, event, d, r, dmax, m, an):
    """Value of event function ``event`` in ``mode`` (_event_direction tells which are live)."""
    if event == 0:
        return d
    if event == 1:  # the force of the law, unclipped (VE), or of the unloading branch (HLS)
        if mode == M_FREE:
            if d <= 0.0:  # re-entry needs overlap: beyond δ = 0 the contact has ended instead
                return -1.0
            if loads_and_unloads(law):
                return _mode_force(law, M_UNLOAD, d, r, dmax)
            return viscoelastic_force(law, d, r)
        return _mode_force(law, mode, d, r, dmax)
    if event == 2:
        return r
    if event == 3:  # dF/dt of the viscoelastic law
        return viscoelastic_force_rate(law, d, r, _acc(law, mode, d, r, dmax, m, an))
    return d - dmax  # event 4


@njit(cache=KERNEL_CACHE)
def _event_direction(law, mode, event):
    """+1 / −1 for a live event of this mode, 0 for none."""
    if mode == M_PRE:
        return 1 if event == 0 else 0
    if mode == M_VE:
        if event == 0 or event == 1 or event == 2:
            return -1
        if event == 3 and law[L_ETA] != 0.0:
            return -1
        return 0
    if mode == M_LOAD:
        return -1 if (event == 0 or event == 2) else 0
    if mode == M_UNLOAD:
        if event == 0 or event == 1:
            return -1
        return 1 if event == 4 else 0
    if mode == M_FREE:
        if event == 0:
            return -1
        if event == 1:
            return 1
        return 0
    return 0


@njit(cache=KERNEL_CACHE)
def _locate(law, mode, event, direction, d, r, h, dmax, m, an, g0, g1):
    """Root of event function ``event`` within the step [0, h] from (d, r): Illinois regula falsi on θ with a
    bisection fallback, each trial evaluated by a fresh RK step of length θh (5th-order accurate)."""
    lo, hi, glo, ghi = 0.0, 1.0, g0, g1
    side = 0
    for _ in range(LOCATE_ITERATIONS):
        if hi - lo <= THETA_TOL:
            break
        theta = illinois_trial(lo, hi, glo, ghi)
        dt_, rt_, _, _ = _dp5(law, mode, d, r, theta * h, dmax, m, an)
        g = _event_value(law, mode, event, dt_, rt_, dmax, m, an)
        lo, hi, glo, ghi, side = illinois_step(lo, hi, glo, ghi, side, theta, g, direction)
    return hi


@njit(cache=KERNEL_CACHE)
def _touch_inside(law, d, r, h, m, an, rn):
    """A free-flight step [0, h] whose ends both have a gap (δ < 0) but whose approach turned into
    recession (δ̇: + → −) may hold a touch between them (δ has its maximum inside): the step fraction of the
    touch (the root of δ before the maximum), or 2 when the maximum has no overlap."""
    # (np.int64: a literal argument would make numba compile a specialisation of the callee for it)
    pre = np.int64(M_PRE)
    tm = _locate(law, pre, np.int64(2), np.int64(-1), d, r, h, 0.0, m, an, r, rn)
    dm, _, _, _ = _dp5(law, pre, d, r, tm * h, 0.0, m, an)
    if not (dm > 0.0):
        return 2.0
    return tm * _locate(law, pre, np.int64(0), np.int64(1), d, r, tm * h, 0.0, m, an, d, dm)


@njit(cache=KERNEL_CACHE, nogil=True)  # the suite runs cases in threads
def adaptive_normal(law, m, an, d_init, r_init, rtol, t_scale, l_scale, v_scale, t_max, capacity):
    """Integrate the 1-D normal impact to relative tolerance ``rtol``.

    Returns (status, n_points, T, D, R, F, n_events, ET, EC, ED, ER, EF). Points are the accepted steps
    and the events; F is the total normal force (after limit_force) at each point."""
    T = np.empty(capacity)
    D = np.empty(capacity)
    R = np.empty(capacity)
    F = np.empty(capacity)
    ET = np.empty(64)
    EC = np.empty(64, dtype=np.int64)
    ED = np.empty(64)
    ER = np.empty(64)
    EF = np.empty(64)
    atol_d, atol_r = rtol * l_scale, rtol * v_scale
    d, r, t = d_init, r_init, 0.0
    mode = M_PRE if d <= 0.0 else (M_LOAD if loads_and_unloads(law) else M_VE)
    dmax = max(d, 0.0)
    force_ended = False
    n, ne = 0, 0
    T[0], D[0], R[0], F[0] = t, d, r, normal_force(law, d, r, dmax)
    n = 1
    h = H_START * t_scale
    if mode == M_PRE and r > 0.0:
        h = min(h, 0.5 * (-d) / r) if d < 0 else h
        h = max(h, 1e-6 * t_scale)
    h_min = H_MIN * t_scale
    status = ST_NO_SEPARATION
    for _ in range(10_000_000):
        if t >= t_max:
            status = ST_NO_SEPARATION
            break
        if n >= capacity - 2 or ne >= 60:
            status = ST_STEPS
            break
        h = min(h, t_max - t)
        dn, rn, ed, er = _dp5(law, mode, d, r, h, dmax, m, an)
        err = max(abs(ed) / (atol_d + rtol * max(abs(d), abs(dn))),
                  abs(er) / (atol_r + rtol * max(abs(r), abs(rn))))
        if not (err <= 1.0):
            h *= shrink(err)
            if h < h_min:
                status = ST_TOLERANCE
                break
            continue
        # accepted: look for the earliest live event in the step
        best_theta, best_event, best_dir = 2.0, -1, 0
        for event in range(5):
            direction = _event_direction(law, mode, event)
            if direction == 0:
                continue
            g0 = _event_value(law, mode, event, d, r, dmax, m, an)
            g1 = _event_value(law, mode, event, dn, rn, dmax, m, an)
            if crossed(g0, g1, direction):
                theta = _locate(law, mode, event, direction, d, r, h, dmax, m, an, g0, g1)
                if theta < best_theta:
                    best_theta, best_event, best_dir = theta, event, direction
        if best_event < 0 and mode == M_PRE and r > 0.0 and rn <= 0.0:
            best_theta = _touch_inside(law, d, r, h, m, an, rn)
            if best_theta <= 1.0:
                best_event, best_dir = 0, 1
        if best_event < 0:
            t += h
            d, r = dn, rn
            if mode == M_LOAD:
                dmax = max(dmax, d)
            T[n], D[n], R[n] = t, d, r
            F[n] = max(_mode_force(law, mode, d, r, dmax), 0.0) if (law[L_LIMIT] != 0.0 or mode != M_VE) \
                else _mode_force(law, mode, d, r, dmax)
            n += 1
            h *= grow(err)
            continue
        # advance exactly to the event
        he = best_theta * h
        d, r, _, _ = _dp5(law, mode, d, r, he, dmax, m, an)
        t += he
        code = 0
        terminal = False
        if best_event == 0 and best_dir > 0:
            code = EV_START
            d = 0.0
            mode = M_LOAD if loads_and_unloads(law) else M_VE
            dmax = 0.0
        elif best_event == 0:
            code = EV_END
            d = 0.0
            terminal = True
        elif best_event == 1 and best_dir < 0:
            code = EV_FORCE_END
            if not force_ended:
                force_ended = True
            else:
                code = -EV_FORCE_END  # a later force end, kept but not the first
            if loads_and_unloads(law) or law[L_LIMIT] != 0.0:
                mode = M_FREE
        elif best_event == 1:
            code = EV_REENTER
            mode = M_UNLOAD if loads_and_unloads(law) else M_VE
        elif best_event == 2:
            code = EV_MAX_OVERLAP
            if mode == M_LOAD:
                dmax = d
                mode = M_UNLOAD
            r = 0.0
        elif best_event == 3:
            code = EV_PEAK
        elif best_event == 4:
            code = EV_RELOAD
            mode = M_LOAD
            dmax = d
        fv = _mode_force(law, mode, d, r, dmax)
        if mode == M_VE and law[L_LIMIT] != 0.0:
            fv = max(fv, 0.0)
        if code == EV_FORCE_END or code == -EV_FORCE_END:
            fv = 0.0
        if code == EV_END:
            fv = 0.0
        T[n], D[n], R[n], F[n] = t, d, r, fv
        n += 1
        ET[ne], EC[ne], ED[ne], ER[ne], EF[ne] = t, code, d, r, fv
        ne += 1
        if ended_with_it(terminal, code == EV_START, mode != M_PRE, d, r):
            ET[ne], EC[ne], ED[ne], ER[ne], EF[ne] = t, EV_END, d, r, 0.0
            ne += 1
            terminal = True
        if terminal:
            status = ST_OK
            break
        h = resume(h, best_theta, t_scale)
    if status == ST_NO_SEPARATION and mode == M_PRE:
        status = ST_NO_CONTACT
    return status, n, T[:n].copy(), D[:n].copy(), R[:n].copy(), F[:n].copy(), ne, \
        ET[:ne].copy(), EC[:ne].copy(), ED[:ne].copy(), ER[:ne].copy(), EF[:ne].copy()


# ----------------------------------------------------------------------------- velocity Verlet


@njit(cache=KERNEL_CACHE, nogil=True)  # the suite runs cases in threads
def verlet_normal(law, m, an, d_init, r_init, dt, t_max, capacity, stop=True):
    """The engines' scheme (fix nve/sphere) on the 1-D normal problem: v += ½dt a; x += dt v; forces from
    full-step positions and half-step velocities; v += ½dt a. History (δ_max) is updated with each force
    evaluation of a step, not at setup; it is forgotten when the overlap ends. Stops at the first step
    after the contact has ended (``stop=False``: runs to t_max, as an engine deck does — for measuring what
    the early stop saves). Returns (status, n, T, D, R, F); R holds full-step rates."""
    T = np.empty(capacity)
    D = np.empty(capacity)
    R = np.empty(capacity)
    F = np.empty(capacity)
    status, n = _verlet_into(law, m, an, d_init, r_init, dt, t_max, capacity, np.bool_(stop), T, D, R, F)
    return status, n, T[:n].copy(), D[:n].copy(), R[:n].copy(), F[:n].copy()


@njit(cache=KERNEL_CACHE)
def _verlet_into(law, m, an, d_init, r_init, dt, t_max, capacity, stop, T, D, R, F):
    """``verlet_normal``'s run into the given arrays (at least ``capacity`` long): (status, n)."""
    d, r = d_init, r_init
    dmax = 0.0
    f = normal_force(law, d, r, max(d, 0.0))  # setup: no history update
    T[0], D[0], R[0], F[0] = 0.0, d, r, f
    n = 1
    touched = d > 0.0
    status = ST_NO_SEPARATION
    step = 0
    while n < capacity:
        step += 1
        t = step * dt
        if t > t_max:
            status = ST_NO_SEPARATION if touched else ST_NO_CONTACT
            break
        r_half = r + 0.5 * dt * (-f / m + an)
        d = d + dt * r_half
        if d > 0.0:
            if d > dmax:
                dmax = d
            f = normal_force(law, d, r_half, dmax)
        else:
            f = 0.0
            dmax = 0.0
        r = r_half + 0.5 * dt * (-f / m + an)
        if not (math.isfinite(d) and math.isfinite(r)):
            T[n], D[n], R[n], F[n] = t, d, r, f
            n += 1
            status = ST_UNRESOLVED
            break
        T[n], D[n], R[n], F[n] = t, d, r, f
        n += 1
        if d > 0.0:
            touched = True
        elif touched:
            status = ST_OK
            if stop:
                break
    else:
        status = ST_STEPS
    return status, n


# ----------------------------------------------------------------------------- many collisions at once

# a batched point's frame: what turns its 1-D solution into the relative velocity of the centres (reference/batch.py)
FR_WALL, FR_N, FR_A, FR_B, FR_M0, FR_M1, FR_MT, FR_W = 0, 1, 4, 7, 10, 11, 12, 13
FR_SIZE = 16
# a batched point's output row: the run's status and steps, metrics.stepped's reading of its contact,
# health.reading's of its state, and the tangential metrics
(O_STATUS, O_STEPS, O_KS, O_TS, O_VIN, O_KE, O_TE, O_VOUT, O_KF, O_TF, O_DMAX, O_FMAX, O_BAD, O_INSIDE, O_DALL,
 O_DLAST, O_TLAST, O_TBAD, O_TR, O_ANGLE, O_SPIN) = range(21)
O_SIZE = 21


@njit(cache=KERNEL_CACHE, inline="always")
def _relative_velocity(fr, t, r, j):
    """Component j of the relative velocity of the centres (v0 − v1, or v0 at a wall) at time t and approach rate
    r, in collision._particles_1d's arithmetic: a wall's particle keeps its tangential velocity (and gravity's
    tangential part), a pair's centre of mass moves uniformly."""
    nj = fr[FR_N + j]
    if fr[FR_WALL] != 0.0:
        return (fr[FR_A + j] + t * fr[FR_B + j]) + r * nj
    vcom = fr[FR_A + j] + t * fr[FR_B + j]
    return (vcom + r * fr[FR_M1] / fr[FR_MT] * nj) - (vcom - r * fr[FR_M0] / fr[FR_MT] * nj)


@njit(cache=KERNEL_CACHE)
def _tangential_1d(fr, t_in, r_in, t_out, r_out, row):
    """metrics.tangential of a 1-D solve (a fixed normal, no slip columns) into ``row``."""
    n0, n1, n2 = fr[FR_N], fr[FR_N + 1], fr[FR_N + 2]
    a0, a1, a2 = (_relative_velocity(fr, t_in, r_in, 0), _relative_velocity(fr, t_in, r_in, 1),
                  _relative_velocity(fr, t_in, r_in, 2))
    b0, b1, b2 = (_relative_velocity(fr, t_out, r_out, 0), _relative_velocity(fr, t_out, r_out, 1),
                  _relative_velocity(fr, t_out, r_out, 2))
    an_ = a0 * n0 + a1 * n1 + a2 * n2
    bn = b0 * n0 + b1 * n1 + b2 * n2
    ta0, ta1, ta2 = a0 - an_ * n0, a1 - an_ * n1, a2 - an_ * n2
    tb0, tb1, tb2 = b0 - bn * n0, b1 - bn * n1, b2 - bn * n2
    row[O_ANGLE] = math.degrees(math.atan2(math.sqrt(tb0 * tb0 + tb1 * tb1 + tb2 * tb2), -bn))
    speed_t = math.sqrt(ta0 * ta0 + ta1 * ta1 + ta2 * ta2)
    if speed_t > 1e-12 * math.sqrt(a0 * a0 + a1 * a1 + a2 * a2):
        h0, h1, h2 = ta0 / speed_t, ta1 / speed_t, ta2 / speed_t
        row[O_TR] = (tb0 * h0 + tb1 * h1 + tb2 * h2) / speed_t
        # ω0 · (t̂ × n)
        row[O_SPIN] = (fr[FR_W] * (h1 * n2 - h2 * n1) + fr[FR_W + 1] * (h2 * n0 - h0 * n2)
                       + fr[FR_W + 2] * (h0 * n1 - h1 * n0))


@njit(cache=KERNEL_CACHE, nogil=True)
def verlet_normal_many(laws, m, an, d_init, r_init, dt, t_max, capacity, frames):
    """``verlet_normal`` for each row i of the arguments (a law per row of ``laws``; ``frames``: FR_* columns),
    its series read where they are made (metrics.stepped, health.reading, the tangential metrics) and dropped:
    an (N, O_SIZE) array of O_* columns, NaN where a reading has no value."""
    out = np.full((laws.shape[0], O_SIZE), np.nan)
    size = capacity.max() if capacity.shape[0] else 0
    T_, D_, R_, F_ = np.empty(size), np.empty(size), np.empty(size), np.empty(size)  # one record for every point
    for i in range(laws.shape[0]):
        status, n = _verlet_into(laws[i], m[i], an[i], d_init[i], r_init[i], dt[i], t_max[i], capacity[i],
                                 np.bool_(True), T_, D_, R_, F_)
        T, D, R, F = T_[:n], D_[:n], R_[:n], F_[:n]
        row = out[i]
        row[O_STATUS], row[O_STEPS] = status, n
        (k_s, row[O_TS], row[O_VIN], k_e, row[O_TE], row[O_VOUT], k_f, row[O_TF], row[O_DMAX],
         row[O_FMAX]) = stepped(T, D, R, F)
        row[O_KS], row[O_KE], row[O_KF] = k_s, k_e, k_f
        k_bad, inside, row[O_DALL], row[O_DLAST], row[O_TLAST] = reading(T, D, R, F)
        row[O_BAD], row[O_INSIDE] = k_bad, inside
        if k_bad >= 0:
            row[O_TBAD] = T[k_bad]
        if k_s >= 0 and k_e < n:
            k_in = max(k_s - 1, 0)
            _tangential_1d(frames[i], T[k_in], R[k_in], T[k_e], R[k_e], row)
    return out
