"""The 3-D two-body contact in continuous time (kernels3d.py's state and kinematics): the right-hand side with the
history's flow on and off the slip surface, the stick/slip and normal events, and the adaptive DP5(4) driver
that locates them (integrator.py's core).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from ..laws.normal_force import (hls_unloading, L_ETA, L_KL, L_LIMIT, loads_and_unloads, viscoelastic_force)
from ..laws.tangential import T_MU_K, T_MU_S, T_NEAR_LIMIT, T_RIDE_BAND, T_UNLOAD_MARGIN
from ..laws.tangential_force import (_cross, _dot, eta_of, F_CONSTRAINT, F_HISTORY, F_NO_FORCE, F_OWN_RATE,
                                     F_REVERSAL, F_RIDES, F_SLIP_KEEPS, F_SLIP_READS_SURFACE, F_SLIP_SNAPS, F_STATES,
                                     F_STICK_KINK, F_VISCOUS_KINK, has, history_rate, limit_margin, _norm,
                                     return_map, slip_surface, tangential_force)
from .integrator import (crossed, ended_with_it, error, grow, H_MIN, H_START, illinois_step, illinois_trial,
                         LOCATE_ITERATIONS, resume, shrink, solution, stage2, stage3, stage4, stage5, stage6,
                         THETA_TOL)
from .kernels import (EV_END, EV_FORCE_END, EV_MAX_OVERLAP, EV_PEAK, EV_REENTER, EV_RELOAD, EV_START, M_FREE, M_LOAD,
                      M_PRE, M_UNLOAD, M_VE, ST_NO_CONTACT, ST_NO_SEPARATION, ST_OK, ST_STEPS, ST_TOLERANCE)
from .kernels3d import (A_DMAX, A_LSTAR, A_NMODE, A_SIZE, A_TMODE, A_TREF, ARM_RADIUS, ARM_SURFACE, C_FN, C_FT,
                        EV_KINK, EV_REVERSAL, EV_SLIP_STICK, EV_STICK_SLIP, G_GX, G_I0, G_I1, G_M0, G_M1, G_TS,
                        G_WALL, kinematics, NCOL, R_SLIP_ARM, R_WALL_SLIP_ARM, record_row, SLIP, STICK)

# ----------------------------------------------------------------------------- the continuous system


@njit(cache=KERNEL_CACHE)
def _normal_mode_force(nl, nmode, delta, rate, dmax):
    if nmode == M_VE:
        return viscoelastic_force(nl, delta, rate)
    if nmode == M_LOAD:
        return nl[L_KL] * delta
    if nmode == M_UNLOAD:
        ku, d0 = hls_unloading(nl, dmax)
        return ku * (delta - d0)
    return 0.0


@njit(cache=KERNEL_CACHE)
def _contact_force(nl, nmode, delta, rate, dmax):
    """The normal force the contact applies: the mode's law, held at 0 where limit_force forbids attraction."""
    fn = _normal_mode_force(nl, nmode, delta, rate, dmax)
    if nl[L_LIMIT] != 0.0 and nmode == M_VE and fn < 0.0:
        return 0.0
    return fn


@njit(cache=KERNEL_CACHE)
def _accelerations(y, geo, fvec0, tau0, tau1, dy):
    g = geo[G_GX:G_GX + 3]
    dy[0:3] = y[3:6]
    dy[3:6] = fvec0 / geo[G_M0] + g
    dy[6:9] = tau0 / geo[G_I0]
    if geo[G_WALL] == 0.0:
        dy[9:12] = y[12:15]
        dy[12:15] = -fvec0 / geo[G_M1] + g
        dy[15:18] = tau1 / geo[G_I1]
    else:
        dy[9:18] = 0.0


@njit(cache=KERNEL_CACHE, inline="always")
def _tangent_history(y, n):
    """The history in the current tangent plane: exact in continuous time, and immune to numerical drift."""
    xi = y[18:21]
    return xi - _dot(xi, n) * n


@njit(cache=KERNEL_CACHE)
def _psi_at(y, aux, nl, tl, geo, rules, mu, fsign):
    """ψ at a nearby state, with |Fn| taken on the branch of the base point (fsign·Fn), so that a one-sided
    difference does not straddle the kink of |Fn| where a viscous normal force changes sign."""
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    fn = _contact_force(nl, aux[A_NMODE], delta, rate, aux[A_DMAX])
    psi, w, d = slip_surface(tl, nl, _tangent_history(y, n), vt, fsign * fn, delta, mu)
    return psi


@njit(cache=KERNEL_CACHE)
def _mapped_at(y, aux, nl, tl, geo, rules, mu, fsign):
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    fn = _contact_force(nl, aux[A_NMODE], delta, rate, aux[A_DMAX])
    return return_map(tl, nl, _tangent_history(y, n), vt, fsign * fn, delta, mu)


@njit(cache=KERNEL_CACHE)
def _fn_at(y, aux, nl, geo, rules):
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    return _normal_mode_force(nl, aux[A_NMODE], delta, rate, aux[A_DMAX])


@njit(cache=KERNEL_CACHE)
def _slip_drift(y, geo, rules, delta, rate, n, ndot, a0s, a1s):
    """Tangential part of dv_t/dt with no tangential force (the normal force and gravity act along n for a
    pair; a wall sees gravity's tangential part): b in v̇_t = A F_t + b."""
    vr_n = rate
    arm = rules[R_WALL_SLIP_ARM] if geo[G_WALL] != 0.0 else rules[R_SLIP_ARM]
    adot0 = 0.0 if arm == ARM_RADIUS else (-rate if arm == ARM_SURFACE else -0.5 * rate)
    acc = _cross(y[6:9], adot0 * n + a0s * ndot)
    if geo[G_WALL] != 0.0:
        acc = acc + geo[G_GX:G_GX + 3]
    else:
        acc = acc + _cross(y[15:18], adot0 * n + a1s * ndot)
    b = acc - _dot(acc, n) * n - vr_n * ndot
    return b


@njit(cache=KERNEL_CACHE)
def rhs(y, aux, nl, tl, geo, rules, dy):
    """dy ← f(y). Returns (λ, Fn, |F_req| − μs|Fn| for SLIDING in stick, the tangential force (3))."""
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    nmode = aux[A_NMODE]
    contact = nmode != M_PRE
    fn = _contact_force(nl, nmode, delta, rate, aux[A_DMAX]) if contact else 0.0
    fabs = abs(fn)
    slipping = aux[A_TMODE] == SLIP
    xi = _tangent_history(y, n)
    ft = np.zeros(3)
    req_margin = -1.0
    lam = 0.0
    ts = geo[G_TS]
    if contact and not has(tl, F_NO_FORCE):
        if has(tl, F_CONSTRAINT) and not slipping:
            # constraint force keeping v_t = 0: v̇_t = A F + b
            amob = 1.0 / geo[G_M0] + a0t * a0s / geo[G_I0]
            if geo[G_WALL] == 0.0:
                amob += 1.0 / geo[G_M1] + a1t * a1s / geo[G_I1]
            b = _slip_drift(y, geo, rules, delta, rate, n, ndot, a0s, a1s)
            ft = -b / amob
            req_margin = _norm(ft) - tl[T_MU_S] * fabs
        elif slipping and has(tl, F_SLIP_READS_SURFACE):
            # a slipping history lies on its surface |ξ| = ξm by definition: the force reads it there, not the
            # integrated value, which is not error-controlled while slipping (below) and would drift off it —
            # a drift the viscous term's (1 − |ξ|/ξm)^{1/4} magnifies a thousandfold
            ft = tangential_force(tl, nl, return_map(tl, nl, xi, vt, fabs, delta, tl[T_MU_K]), vt, fabs, delta,
                                  slipping, aux[A_TREF:A_TREF + 3])
        else:
            ft = tangential_force(tl, nl, xi, vt, fabs, delta, slipping, aux[A_TREF:A_TREF + 3])
    fvec0 = -fn * n + ft
    tau0 = _cross(a0t * n, ft)
    tau1 = _cross(a1t * n, ft)
    _accelerations(y, geo, fvec0, tau0, tau1, dy)
    dy[18:21] = 0.0
    if contact and has(tl, F_HISTORY):
        rot = _dot(xi, ndot) * n
        if has(tl, F_OWN_RATE):
            dh = history_rate(tl, nl, xi, vt, fabs, delta, aux[A_LSTAR:A_LSTAR + 3]) - rot
        else:
            dh = vt - rot
        if has(tl, F_RIDES):
            hn = _norm(xi)
            cap = tl[T_MU_K] * fabs
            if hn > 0.0 and cap > 0.0 and hn >= (1.0 - tl[T_NEAR_LIMIT]) * cap:
                # at the Coulomb limit the load rides it, |L|/μ|Fn| held — within T_NEAR_LIMIT of a falling
                # limit, which carries the load down with it (the verlet method truncates it after each
                # increment, slip_surface; a load above the limit is put back on it after each step,
                # _ride_truncate), and within T_RIDE_BAND of a rising one: there Walton's Kt ∝ x^{1/3} makes the
                # approach infinitely stiff, while farther below the lag x of the load behind a rising limit
                # is physics (the verlet plateau test) and is integrated as it is. The limit's rate by a
                # one-sided difference along the flow, on the branch of |Fn| of the base point
                capdot = _limit_rate(y, aux, nl, tl, geo, rules, fn, dy)
                if capdot < 0.0 or hn >= (1.0 - tl[T_RIDE_BAND]) * cap:
                    most = (hn / cap) * capdot
                    u = xi / hn
                    radial = _dot(u, dh)
                    if radial > most:
                        dh = dh - (radial - most) * u
        dy[18:21] = dh
        if slipping and not has(tl, F_SLIP_KEEPS):
            mu = tl[T_MU_K]
            psi, w, dpsi = slip_surface(tl, nl, xi, vt, fabs, delta, mu)
            # one-sided (forward, second order) along the flow: |ξ| has a kink at ξ = 0, where every slip
            # begins at contact start, and a central difference would straddle it
            s = 1e-7 * ts
            fsign = 1.0 if fn >= 0.0 else -1.0
            psid = (-3.0 * psi + 4.0 * _psi_at(y + s * dy, aux, nl, tl, geo, rules, mu, fsign)
                    - _psi_at(y + 2.0 * s * dy, aux, nl, tl, geo, rules, mu, fsign)) / (2.0 * s)
            # λ = ψ̇/D: the rate at which sticking would push past the surface; its sign decides stick or
            # slip. While slipping the history follows its return-mapped value along the flow (the
            # continuous limit of the engines' "increment, then truncate"), differentiated one-sidedly;
            # unlike ξ̇ = v_t − λw this does not divide by Kt, which vanishes with δ for DDt and TTIt.
            lam = psid / dpsi if dpsi > 0.0 else psid
            h0 = _mapped_at(y, aux, nl, tl, geo, rules, mu, fsign)
            ha = _mapped_at(y + s * dy, aux, nl, tl, geo, rules, mu, fsign)
            hb = _mapped_at(y + 2.0 * s * dy, aux, nl, tl, geo, rules, mu, fsign)
            dy[18:21] = (-3.0 * h0 + 4.0 * ha - hb) / (2.0 * s)
    return lam, fn, req_margin, ft


@njit(cache=KERNEL_CACHE)
def _dp5_from(y, k1, aux, nl, tl, geo, rules, h, k7):
    """One Dormand–Prince 5(4) step of the state (integrator.py's stages) from y, whose f(y) is ``k1``; ``k7`` ←
    f(yn). Returns the 5th-order state, the error estimate and f(yn)'s (λ, Fn, margin, Ft) (rhs)."""
    n = y.shape[0]
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    k5 = np.empty(n)
    k6 = np.empty(n)
    rhs(stage2(y, h, k1), aux, nl, tl, geo, rules, k2)
    rhs(stage3(y, h, k1, k2), aux, nl, tl, geo, rules, k3)
    rhs(stage4(y, h, k1, k2, k3), aux, nl, tl, geo, rules, k4)
    rhs(stage5(y, h, k1, k2, k3, k4), aux, nl, tl, geo, rules, k5)
    rhs(stage6(y, h, k1, k2, k3, k4, k5), aux, nl, tl, geo, rules, k6)
    yn = solution(y, h, k1, k3, k4, k5, k6)
    out = rhs(yn, aux, nl, tl, geo, rules, k7)
    return yn, error(h, k1, k3, k4, k5, k6, k7), out


@njit(cache=KERNEL_CACHE)
def _dp5_3(y, k1, aux, nl, tl, geo, rules, h):
    """One Dormand–Prince 5(4) step of the state from y, whose f(y) is ``k1``; returns the 5th-order state and the
    error estimate."""
    k7 = np.empty(y.shape[0])
    yn, err, _ = _dp5_from(y, k1, aux, nl, tl, geo, rules, h, k7)
    return yn, err


@njit(cache=KERNEL_CACHE, inline="always")
def _same(a, b):
    """Whether two states are equal in every component (f of one is then f of the other: rhs is pure)."""
    for i in range(a.shape[0]):
        if a[i] != b[i]:
            return False
    return True


N_EVENTS = 8
MAX_EVENTS = 250  # events located in one run (its event arrays hold 256)
# of a step: two events located this close are taken as simultaneous (LSDn with a spring law at 5°: the slip
# ended where the force did, located 1e-16 of a step before it, and the force's end went unrecorded)
SIMULTANEOUS_THETA = 1e-9
# of the time scale: a stick→slip graze retaken within this of the last one is at the same instant (LTH at the
# end of an LSDn contact, Chung & Ooi Test 4 at 30°: a graze retaken every 6.5e-20 s ran out of output points).
# So is one retaken every 5e-11 t_c (the suite's LTH on a wall at 57.4–58.5°, at δ ≈ 7.6e-13 m, 1e-6 of the
# largest overlap: the stick each graze predicts re-crosses its surface within a few steps, 250 events ran out
# and the run stopped with too-many-steps). A stick that short moves no metric by more than its 1e-9 of t_c;
# the contact lies on its slip surface, where stick and slip give LTH and ZZY the same force.
GRAZE_SAME_INSTANT = 1e-9
# A law whose stick force reaches μ|Fn| through a term of unbounded slope (LTH and ZZY: laws/tangential_laws/lth.py,
# UNLOAD_MARGIN) declares an unloading margin: its slip ends only when sticking would unload the history by more
# than that fraction of |v_t|; below it the contact stays on the surface instead of chattering.


@njit(cache=KERNEL_CACHE, inline="always")
def _margin(tl, vt):
    margin = tl[T_UNLOAD_MARGIN]
    return margin * _norm(vt) if margin != 0.0 else 0.0


@njit(cache=KERNEL_CACHE, inline="always")
def _unloads(tl, lam, vt):
    """Whether a slip whose stick flow has multiplier λ sticks again (λ < 0, past the margin above)."""
    return lam < -_margin(tl, vt)


@njit(cache=KERNEL_CACHE)
def _limit_rate(y, aux, nl, tl, geo, rules, fn, dy):
    """d(μk|Fn|)/dt by a one-sided (forward, second-order) difference along the flow ``dy``, on the branch of
    |Fn| of the base point."""
    s = 1e-7 * geo[G_TS]
    fsign = 1.0 if fn >= 0.0 else -1.0
    fa = fsign * _fn_at(y + s * dy, aux, nl, geo, rules)
    fb = fsign * _fn_at(y + 2.0 * s * dy, aux, nl, geo, rules)
    return tl[T_MU_K] * (-3.0 * fsign * fn + 4.0 * fa - fb) / (2.0 * s)


# _ride_truncate, _onto_surface and _settle are inlined into adaptive_3d (one or two call sites each): a function
# numba compiles on its own is a library that links, and optimises once more, the whole right-hand side it calls;
# inlined, the 3-D solver compiles in ~3/4 of the time (docs/performance.md, "Cold start")
@njit(cache=KERNEL_CACHE, inline="always")
def _ride_truncate(y, aux, nl, tl, geo, rules, fy, known):
    """A riding law's stored load (F_RIDES: Walton's) back onto the Coulomb limit where it lies above it (the
    verlet method's truncation), and onto it where it rides within T_NEAR_LIMIT below a falling limit (rhs): a
    load that close to a
    falling limit meets it at once, and snapping it there keeps the answer from depending on where a step
    happened to enter the band. ``fy`` is f(y) where ``known`` (the step's last stage, at this very state)."""
    if aux[A_NMODE] == M_PRE:
        return
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    xi = _tangent_history(y, n)
    hn = _norm(xi)
    fn = _contact_force(nl, aux[A_NMODE], delta, rate, aux[A_DMAX])
    cap = tl[T_MU_K] * abs(fn)
    if hn > cap:
        y[18:21] = xi * (cap / hn)
    elif hn > 0.0 and hn >= (1.0 - tl[T_NEAR_LIMIT]) * cap:
        if known:
            dy = fy
        else:
            dy = np.empty(y.shape[0])
            rhs(y, aux, nl, tl, geo, rules, dy)
        if _limit_rate(y, aux, nl, tl, geo, rules, fn, dy) < 0.0:
            y[18:21] = xi * (cap / hn)


@njit(cache=KERNEL_CACHE, inline="always")
def _onto_surface(y, aux, nl, tl, geo, rules, dy):
    """A slipping spring's history back onto its slip surface after each step. While slipping it follows the
    return map's rate (rhs) and is not error-controlled (the map is unbounded where Kt ∝ √δ → 0 under a
    finite cap: TTIt's ξ ∝ −δ^{-1/4} at onset); left to drift, the slip→stick multiplier λ is read off a history
    beside the surface — TTIt at 85° on alumina stayed on the slip surface's non-dissipative root (force along
    the slip) until δ = 7.9e-8 m where λ < 0 from 1e-8 m on it, as the engines' step finds (docs/benchmarks.md)."""
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    fn = _contact_force(nl, aux[A_NMODE], delta, rate, aux[A_DMAX])
    y[18:21] = return_map(tl, nl, _tangent_history(y, n), vt, abs(fn), delta, tl[T_MU_K])
    # a slip whose stick flow unloads the history (λ < 0) sticks — also where λ has been negative since the slip
    # began, so that no crossing of it can be seen: TTIt's slip at contact onset, dissipative there, whose stick
    # swings the trial force round to push along the slip, as the engines' step does (Thornton e 0.25 at 45°: a
    # 6 % error in e_t while it went on slipping). Returns whether it stuck, and f at the state on the surface
    # (dy ← f, with its λ, Fn, margin, Ft) as it was before a switch to stick.
    lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
    if _unloads(tl, lam, vt) and fn != 0.0:
        aux[A_TMODE] = STICK
        return True, lam, fn, req, ft
    return False, lam, fn, req, ft


@njit(cache=KERNEL_CACHE, inline="always")
def _settle(y, aux, nl, tl, geo, rules):
    """After an event: a sticking contact whose force exceeds the static limit slips, and a slipping history
    is put back on its slip surface (the cap collapses where Fn passes through 0, and two switches can
    fall inside one step there)."""
    if aux[A_NMODE] == M_PRE:
        return
    if has(tl, F_RIDES):  # no slip state: its load rides the limit (rhs), and is truncated to it
        _ride_truncate(y, aux, nl, tl, geo, rules, np.empty(0), False)
        return
    constraint = has(tl, F_CONSTRAINT)
    if not (has(tl, F_STATES) or constraint):
        return
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    dy = np.empty(y.shape[0])
    lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
    if aux[A_TMODE] == SLIP:
        if not constraint and not has(tl, F_SLIP_KEEPS):
            # back onto the slip surface (the multiplier is least accurate at |Fn|'s kink); a slip that
            # would unload the history (λ < 0) sticks from there
            y[18:21] = return_map(tl, nl, _tangent_history(y, n), vt, abs(fn), delta, tl[T_MU_K])
            lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
            if _unloads(tl, lam, vt) and fn != 0.0:
                aux[A_TMODE] = STICK
        return
    if constraint:
        if req > 0.0:
            aux[A_TMODE] = SLIP
            fnorm = _norm(ft)
            if fnorm > 0.0:
                aux[A_TREF:A_TREF + 3] = -ft / fnorm
        return
    psi = slip_surface(tl, nl, _tangent_history(y, n), vt, abs(fn), delta, tl[T_MU_S])[0]
    if psi > 1e-12 * max(tl[T_MU_S] * abs(fn), 1e-300):
        aux[A_TMODE] = SLIP
        y[18:21] = return_map(tl, nl, _tangent_history(y, n), vt, abs(fn), delta, tl[T_MU_K])
        if not has(tl, F_SLIP_KEEPS):
            # as at a stick→slip event: from the surface, a slip that would unload the history sticks
            lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
            if _unloads(tl, lam, vt) and fn != 0.0:
                aux[A_TMODE] = STICK


@njit(cache=KERNEL_CACHE)
def _event_direction(nl, tl, aux, event):
    nmode = aux[A_NMODE]
    slipping = aux[A_TMODE] == SLIP
    in_contact = nmode != M_PRE
    if event == 0:
        return 1 if nmode == M_PRE else -1
    if not in_contact:
        return 0
    if event == 1:
        if nmode == M_VE or nmode == M_UNLOAD:
            return -1
        if nmode == M_FREE:
            return 1
        return 0
    if event == 2:
        return -1 if (nmode == M_VE or nmode == M_LOAD) else 0
    if event == 3:
        return -1 if (nmode == M_VE and nl[L_ETA] != 0.0) else 0
    if event == 4:
        return 1 if nmode == M_UNLOAD else 0
    states = has(tl, F_STATES) or has(tl, F_CONSTRAINT)
    if event == 5:
        return 1 if (states and not slipping) else 0
    if event == 6:
        return -1 if (states and slipping) else 0
    if event == 7:
        return 2 if (has(tl, F_REVERSAL) or has(tl, F_VISCOUS_KINK)) else 0
    return 0


@njit(cache=KERNEL_CACHE)
def _event_value(y, aux, nl, tl, geo, rules, event):
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    dy = np.empty(y.shape[0])
    if event >= 3 and event != 4:
        lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
    else:
        lam, fn, req = 0.0, 0.0, 0.0
    return _event_of(y, aux, nl, tl, geo, rules, event, delta, rate, n, vt, dy, lam, fn, req)


@njit(cache=KERNEL_CACHE)
def _event_value_with(y, aux, nl, tl, geo, rules, event, dy, lam, fn, req):
    """_event_value(y, …, event) given y's rhs (dy = f(y), λ, Fn, margin), as _event_values is."""
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    return _event_of(y, aux, nl, tl, geo, rules, event, delta, rate, n, vt, dy, lam, fn, req)


@njit(cache=KERNEL_CACHE)
def _event_values(y, aux, nl, tl, geo, rules, dirs, out, dy, lam, fn, req):
    """out[e] ← _event_value(y, …, e) for every event whose direction is not 0, given y's rhs: ``dy`` = f(y) and
    its (λ, Fn, margin) — the step's stage at that very state (its first or its last: rhs is pure, so they are the
    values an rhs here would give, bit for bit)."""
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    for event in range(N_EVENTS):
        if dirs[event] != 0:
            out[event] = _event_of(y, aux, nl, tl, geo, rules, np.int64(event), delta, rate, n, vt, dy, lam, fn,
                                   req)


@njit(cache=KERNEL_CACHE, inline="always")
def _event_of(y, aux, nl, tl, geo, rules, event, delta, rate, n, vt, dy, lam, fn, req):
    """An event function at y, given its kinematics and (for events 3, 5, 6, 7) its rhs (dy, λ, Fn, margin)."""
    nmode = aux[A_NMODE]
    if event == 0:
        return delta
    if event == 1:
        if nmode == M_FREE:
            if delta <= 0.0:  # re-entry needs overlap: beyond δ = 0 the contact has ended instead
                return -1.0
            if loads_and_unloads(nl):
                # (a float: aux holds the modes as floats, and the other call site passes one)
                return _normal_mode_force(nl, np.float64(M_UNLOAD), delta, rate, aux[A_DMAX])
            return viscoelastic_force(nl, delta, rate)
        return _normal_mode_force(nl, nmode, delta, rate, aux[A_DMAX])
    if event == 2:
        return rate
    if event == 4:
        return delta - aux[A_DMAX]
    if event == 3:
        s = 1e-7 * geo[G_TS]
        return (_fn_at(y + s * dy, aux, nl, geo, rules) - _fn_at(y - s * dy, aux, nl, geo, rules)) / (2 * s)
    if event == 5:
        if has(tl, F_CONSTRAINT):
            return req
        psi, w, d = slip_surface(tl, nl, _tangent_history(y, n), vt, abs(fn), delta, tl[T_MU_S])
        return psi
    if event == 6:
        if has(tl, F_CONSTRAINT):
            return _dot(vt, aux[A_TREF:A_TREF + 3])
        if has(tl, F_SLIP_KEEPS):  # a plain cap sticks when the trial force drops below it
            return slip_surface(tl, nl, _tangent_history(y, n), vt, abs(fn), delta, tl[T_MU_K])[0]
        if fn == 0.0:  # a zero cap (limit_force, force ended) admits only the slip state's zero force
            return 1.0
        return lam + _margin(tl, vt)  # falls through 0 where the slip ends (_unloads)
    if event == 7:
        if has(tl, F_REVERSAL):  # a reversal of the slip (tangential_laws.common.reverses)
            return _dot(vt, aux[A_TREF:A_TREF + 3])
        return eta_of(tl, nl, delta) * _norm(vt) - tl[T_MU_K] * abs(fn)
    return 1.0


@njit(cache=KERNEL_CACHE)
def _locate(y, k1, aux, nl, tl, geo, rules, h, event, direction, g0, g1):
    """The crossing of ``event`` in the step h from y (whose f(y) is ``k1``: every trial step starts from y), by
    trial steps; the event function at a trial's end reads the trial's last stage, f there."""
    lo, hi, glo, ghi = 0.0, 1.0, g0, g1
    side = 0
    k7 = np.empty(y.shape[0])
    for _ in range(LOCATE_ITERATIONS):
        if hi - lo <= THETA_TOL:
            break
        theta = illinois_trial(lo, hi, glo, ghi)
        yt, _, f7 = _dp5_from(y, k1, aux, nl, tl, geo, rules, theta * h, k7)
        g = _event_value_with(yt, aux, nl, tl, geo, rules, event, k7, f7[0], f7[1], f7[2])
        lo, hi, glo, ghi, side = illinois_step(lo, hi, glo, ghi, side, theta, g, direction)
    return hi


@njit(cache=KERNEL_CACHE)
def _record(rec, i, t, y, aux, nl, tl, geo, rules, dy):
    """A record row of y; dy ← f(y), whose (λ, Fn, margin, Ft) it returns (the next step's first stage)."""
    out = rhs(y, aux, nl, tl, geo, rules, dy)
    _record_with(rec, i, t, y, aux, geo, rules, out[1], out[3])
    return out


@njit(cache=KERNEL_CACHE)
def _record_with(rec, i, t, y, aux, geo, rules, fn, ft):
    """A record row of y, whose rhs gave the normal force fn and tangential force ft."""
    delta, rate, n, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
    record_row(rec, i, t, y, geo, delta, rate, fn, ft, vt, n, aux[A_TMODE])


@njit(cache=KERNEL_CACHE, nogil=True)  # the suite runs cases in threads
def adaptive_3d(y0, nl, tl, geo, rules, rtol, scales, t_max, capacity):
    """Integrate to relative tolerance ``rtol`` with event location (contact start/end, force end, maximum
    overlap, peak force, loading/unloading, stick→slip, slip→stick, slip reversal). ``scales`` (21) are the
    absolute scales of the state components. Returns (status, n, rec, ne, ev_t, ev_code)."""
    rec = np.empty((capacity, NCOL))
    ev_t = np.empty(256)
    ev_c = np.empty(256, dtype=np.int64)
    aux = np.zeros(A_SIZE)
    y = y0.copy()
    delta0 = kinematics(y, geo, rules)[0]
    aux[A_NMODE] = M_PRE if delta0 <= 0.0 else (M_LOAD if loads_and_unloads(nl) else M_VE)
    t = 0.0
    # What the last step computed and the next may reuse, each valid for the state (y, aux) it is kept with — rhs
    # and the event functions are pure, so a reuse changes no bit: f(y) for the step's first stage (kept across
    # rejected steps; the event functions at y read it), f(yn) (the next step's first stage, the record of yn, the
    # event functions at yn and a riding load's truncation there), the event functions at yn (the next step's g0).
    # Where a fix moves the state off yn (a truncation, a snap onto the slip surface, an event), f at the state it
    # moves to — evaluated by the snap or by the record of that state — is kept as the next step's first stage.
    k1, k7 = np.empty(21), np.empty(21)
    y_k1, aux_k1, y_k7, aux_k7 = np.full(21, np.nan), np.zeros(A_SIZE), np.full(21, np.nan), np.zeros(A_SIZE)
    # (np.int64, np.bool_: a literal argument would make numba compile a specialisation of the callee for it,
    # and so would a counter's first, literal, value while the loop's types are being inferred)
    f1 = _record(rec, np.int64(0), t, y, aux, nl, tl, geo, rules, k1)  # f(y)'s (λ, Fn, margin, Ft), with k1
    y_k1[:] = y
    aux_k1[:] = aux
    n, ne = np.int64(1), np.int64(0)
    ts = geo[G_TS]
    hstep = H_START * ts
    status = ST_NO_SEPARATION
    force_ended = False
    graze_t = -1.0  # the time of the last stick→slip graze
    f7 = (0.0, 0.0, 0.0, np.zeros(3))
    dirs = np.zeros(N_EVENTS, dtype=np.int64)
    g0s, g1s = np.zeros(N_EVENTS), np.zeros(N_EVENTS)
    y_g, aux_g = np.full(21, np.nan), np.zeros(A_SIZE)
    for _ in range(10_000_000):
        if t >= t_max:
            break
        if n >= capacity - 2 or ne >= MAX_EVENTS:
            status = ST_STEPS
            break
        hstep = min(hstep, t_max - t)
        if not (_same(y, y_k1) and _same(aux, aux_k1)):
            if _same(y, y_k7) and _same(aux, aux_k7):
                k1[:] = k7
                f1 = f7
            else:
                f1 = rhs(y, aux, nl, tl, geo, rules, k1)
            y_k1[:] = y
            aux_k1[:] = aux
        yn, err, f7 = _dp5_from(y, k1, aux, nl, tl, geo, rules, hstep, k7)
        y_k7[:] = yn
        aux_k7[:] = aux
        emax = 0.0
        # absolute, physical scales (positions are ~10³ times the overlap). While slipping the history is
        # slaved to the return map (it diverges where Kt ∝ √δ → 0 under a finite cap, the force does not),
        # so only the bodies' state is error-controlled then.
        n_ctrl = 18 if aux[A_TMODE] == SLIP else 21
        if has(tl, F_RIDES) and aux[A_NMODE] != M_PRE:
            # within T_NEAR_LIMIT (1e-6) of the Coulomb limit Walton's Kt ∝ x^{1/3} is non-Lipschitz (infinitely
            # stiff as x → 0 with a rising |Fn|): the load is then slaved to the limit to within 1e-6 μ|Fn| whatever its
            # integration error, and is left out of the error control (else the steps shrink without end)
            kin = kinematics(y, geo, rules)
            fnow = abs(_contact_force(nl, aux[A_NMODE], kin[0], kin[1], aux[A_DMAX]))
            if limit_margin(tl, nl, _tangent_history(y, kin[2]), kin[4], fnow, kin[0], aux[A_LSTAR:A_LSTAR + 3]) \
                    < tl[T_NEAR_LIMIT]:
                n_ctrl = 18
        for i in range(n_ctrl):
            sc = scales[i] * rtol
            if sc > 0.0:
                emax = max(emax, abs(err[i]) / sc)
        if not (emax <= 1.0):
            hstep *= shrink(emax)
            if hstep < H_MIN * ts:
                status = ST_TOLERANCE
                break
            continue
        best_theta, best_event, best_dir = 2.0, -1, 0
        for event in range(N_EVENTS):
            dirs[event] = _event_direction(nl, tl, aux, event)
        # the event functions at the step's ends read its stages there: k1 = f(y) (y, aux are still the state it
        # was computed at: the step left both as they were) and k7 = f(yn), computed at yn with this aux
        if _same(y, y_g) and _same(aux, aux_g):
            g0s[:] = g1s
        else:
            _event_values(y, aux, nl, tl, geo, rules, dirs, g0s, k1, f1[0], f1[1], f1[2])
        _event_values(yn, aux, nl, tl, geo, rules, dirs, g1s, k7, f7[0], f7[1], f7[2])
        y_g[:] = yn
        aux_g[:] = aux
        for event in range(N_EVENTS):
            direction = dirs[event]
            if direction == 0:
                continue
            g0, g1 = g0s[event], g1s[event]
            if crossed(g0, g1, direction):
                theta = _locate(y, k1, aux, nl, tl, geo, rules, hstep, event, direction, g0, g1)
                # events within SIMULTANEOUS_THETA of each other are one instant: the first in index order
                # is taken (the force's end before a slip→stick its collapsing cap brings about)
                if theta < best_theta - SIMULTANEOUS_THETA:
                    best_theta, best_event, best_dir = theta, event, direction
        if best_event < 0 and aux[A_NMODE] == M_PRE:
            # a graze: the gap may close and open again inside one free-flight step (δ < 0 at both ends,
            # its maximum inside, where the approach δ̇ turns into recession)
            r0 = _event_value(y, aux, nl, tl, geo, rules, np.int64(2))
            r1 = _event_value(yn, aux, nl, tl, geo, rules, np.int64(2))
            if r0 > 0.0 and r1 <= 0.0:
                tm = _locate(y, k1, aux, nl, tl, geo, rules, hstep, np.int64(2), np.int64(-1), r0, r1)
                ym, _ = _dp5_3(y, k1, aux, nl, tl, geo, rules, tm * hstep)
                dm = kinematics(ym, geo, rules)[0]
                if dm > 0.0:
                    d0 = kinematics(y, geo, rules)[0]
                    best_theta = tm * _locate(y, k1, aux, nl, tl, geo, rules, tm * hstep, np.int64(0), np.int64(1),
                                              d0, dm)
                    best_event, best_dir = 0, 1
        if best_event < 0 and has(tl, F_STICK_KINK) and aux[A_TMODE] == STICK and aux[A_NMODE] != M_PRE \
                and _event_value_with(yn, aux, nl, tl, geo, rules, np.int64(5), k7, f7[0], f7[1], f7[2]) > 0.0:
            # a spring's stick that ends past the slip surface with no crossing seen: it began on the surface
            # (a slip→stick switch puts it there), dipped inside and came back out within the step — the trial
            # force reversing through 0, a kink of |F| that the state's error control does not see (TTIt at
            # 85°: |F_t| reached 124 μ|Fn| in stick). Halve the step until its end lies inside; at H_MIN the
            # contact slips from here (_settle)
            if hstep > H_MIN * ts:
                hstep *= 0.5
                continue
            t += hstep
            y = yn
            _settle(y, aux, nl, tl, geo, rules)
            f1 = _record(rec, n, t, y, aux, nl, tl, geo, rules, k1)
            y_k1[:] = y
            aux_k1[:] = aux
            n += 1
            continue
        if best_event < 0:
            t += hstep
            y = yn
            if aux[A_NMODE] == M_LOAD:
                aux[A_DMAX] = max(aux[A_DMAX], kinematics(y, geo, rules)[0])
            if has(tl, F_RIDES):
                _ride_truncate(y, aux, nl, tl, geo, rules, k7, _same(y, y_k7) and _same(aux, aux_k7))
            elif has(tl, F_SLIP_SNAPS) and aux[A_TMODE] == SLIP:
                # k1 ← f at the state on the surface (the step is taken: f at its start is done with)
                stuck, lam1, fn1, req1, ft1 = _onto_surface(y, aux, nl, tl, geo, rules, k1)
                if stuck:  # f of the slipping state serves no state now
                    y_k1[:] = np.nan
                    ev_t[ne], ev_c[ne] = t, EV_SLIP_STICK
                    ne += 1
                else:
                    f1 = (lam1, fn1, req1, ft1)
                    y_k1[:] = y
                    aux_k1[:] = aux
            if (has(tl, F_CONSTRAINT) and aux[A_TMODE] == SLIP) or has(tl, F_REVERSAL):
                # the slip direction: a constraint law's force direction, the reference for a reversal
                vt = kinematics(y, geo, rules)[4]
                vn = _norm(vt)
                if vn > 0.0:
                    aux[A_TREF:A_TREF + 3] = vt / vn
            if _same(y, y_k7) and _same(aux, aux_k7):
                _record_with(rec, n, t, y, aux, geo, rules, f7[1], f7[3])
            elif _same(y, y_k1) and _same(aux, aux_k1):
                _record_with(rec, n, t, y, aux, geo, rules, f1[1], f1[3])
            else:
                f1 = _record(rec, n, t, y, aux, nl, tl, geo, rules, k1)
                y_k1[:] = y
                aux_k1[:] = aux
            n += 1
            hstep *= grow(emax)
            continue
        he = best_theta * hstep
        y, _ = _dp5_3(y, k1, aux, nl, tl, geo, rules, he)
        t += he
        delta, rate, nvec, ndot, vt, a0s, a1s, a0t, a1t = kinematics(y, geo, rules)
        code = 0
        terminal = False
        constraint = has(tl, F_CONSTRAINT)
        if best_event == 0 and best_dir > 0:
            code = EV_START
            aux[A_NMODE] = M_LOAD if loads_and_unloads(nl) else M_VE
            aux[A_DMAX] = 0.0
            y[18:21] = 0.0
            aux[A_LSTAR:A_LSTAR + 3] = 0.0
            aux[A_TMODE] = STICK
            vn = _norm(vt)
            aux[A_TREF:A_TREF + 3] = 0.0
            if (constraint or has(tl, F_REVERSAL)) and vn > 0.0:
                aux[A_TREF:A_TREF + 3] = vt / vn
            if constraint and vn > 0.0:
                aux[A_TMODE] = SLIP
        elif best_event == 0:
            code = EV_END
            terminal = True
        elif best_event == 1 and best_dir < 0:
            code = EV_FORCE_END if not force_ended else -EV_FORCE_END
            force_ended = True
            if loads_and_unloads(nl) or nl[L_LIMIT] != 0.0:
                aux[A_NMODE] = M_FREE
        elif best_event == 1:
            code = EV_REENTER
            aux[A_NMODE] = M_UNLOAD if loads_and_unloads(nl) else M_VE
        elif best_event == 2:
            code = EV_MAX_OVERLAP
            if aux[A_NMODE] == M_LOAD:
                aux[A_DMAX] = delta
                aux[A_NMODE] = M_UNLOAD
        elif best_event == 3:
            code = EV_PEAK
        elif best_event == 4:
            code = EV_RELOAD
            aux[A_NMODE] = M_LOAD
            aux[A_DMAX] = delta
        elif best_event == 5:
            code = EV_STICK_SLIP
            dy = np.empty(21)
            lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
            aux[A_TMODE] = SLIP
            if constraint:
                fnorm = _norm(ft)
                if fnorm > 0.0:
                    aux[A_TREF:A_TREF + 3] = -ft / fnorm
            else:
                y[18:21] = return_map(tl, nl, _tangent_history(y, nvec), vt, abs(fn), delta, tl[T_MU_K])
                if not has(tl, F_SLIP_KEEPS):
                    # slip only where sticking would push past the surface (λ > 0); else it is a graze —
                    # unless a graze was taken at this very instant already (within GRAZE_SAME_INSTANT: each
                    # retaken graze advances t by an ulp or so): then the first-order test
                    # contradicts the step it predicts (near contact end |Fn| ∝ δ^{1/4} has an unbounded
                    # rate), sticking would re-cross at θ = 0 for ever, and the contact slips
                    lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
                    if _unloads(tl, lam, vt) and t - graze_t > GRAZE_SAME_INSTANT * ts:
                        aux[A_TMODE] = STICK
                        graze_t = t
        elif best_event == 6:
            code = EV_SLIP_STICK
            if not constraint:  # stick from exactly on the surface
                dy = np.empty(21)
                lam, fn, req, ft = rhs(y, aux, nl, tl, geo, rules, dy)
                y[18:21] = return_map(tl, nl, _tangent_history(y, nvec), vt, abs(fn), delta, tl[T_MU_K])
            aux[A_TMODE] = STICK
        elif best_event == 7:
            if has(tl, F_REVERSAL):
                code = EV_REVERSAL
                aux[A_LSTAR:A_LSTAR + 3] = _tangent_history(y, nvec)
                aux[A_TREF:A_TREF + 3] = -aux[A_TREF:A_TREF + 3]  # the slip now runs the other way
            else:
                code = EV_KINK
        if not terminal and code != EV_STICK_SLIP and code != EV_SLIP_STICK:
            _settle(y, aux, nl, tl, geo, rules)
        f1 = _record(rec, n, t, y, aux, nl, tl, geo, rules, k1)
        y_k1[:] = y
        aux_k1[:] = aux
        if code == EV_END:
            rec[n, C_FN] = 0.0
            rec[n, C_FT:C_FT + 3] = 0.0
        n += 1
        ev_t[ne], ev_c[ne] = t, code
        ne += 1
        if ended_with_it(terminal, code == EV_START, aux[A_NMODE] != M_PRE, delta, rate):
            ev_t[ne], ev_c[ne] = t, EV_END
            ne += 1
            terminal = True
        if terminal:
            status = ST_OK
            break
        hstep = resume(hstep, best_theta, ts)
    if status == ST_NO_SEPARATION and aux[A_NMODE] == M_PRE:
        status = ST_NO_CONTACT
    return status, n, rec[:n].copy(), ne, ev_t[:ne].copy(), ev_c[:ne].copy()
