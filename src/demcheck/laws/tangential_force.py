"""The tangential slot's compiled force: the law array ``TangentialLaw.array()`` (the T_* columns of
laws/tangential.py) and the pure functions of it every solver calls — the stiffness and dashpot of a history
law, its slip surface and return map (Coulomb truncation), the force in the stick or slip state, and Walton's
reversal rule and stiffness. Vectors are 3-arrays; the normal law's array (laws/normal_force.py) gives the
dashpot prefactor η(δ) the TTIt and engine-twin dashpots reuse.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from .normal_force import L_B, L_ETA, L_FAMILY, spow
from .tangential import (LTH, NONE, SLIDING, SPRING, T_ETA, T_ETA1, T_ETA_NORMAL, T_FAMILY, T_G, T_K0, T_KT,
                         T_KT_SQRT, T_M, T_MU_K, T_MU_S, T_R, T_TRUNC, T_XI, TRUNC_CAP, TRUNC_MAW, TRUNC_SPRING,
                         VISCOUS, VISCOUS_SLIDING, WALTON, ZZY)


@njit(cache=KERNEL_CACHE, inline="always")
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=KERNEL_CACHE, inline="always")
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit(cache=KERNEL_CACHE, inline="always")
def _norm(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])



@njit(cache=KERNEL_CACHE, inline="always")
def kt_of(tl, delta):
    if tl[T_KT_SQRT] != 0.0:
        return tl[T_KT] * math.sqrt(tl[T_R] * max(delta, 0.0))
    return tl[T_KT]


@njit(cache=KERNEL_CACHE, inline="always")
def eta_of(tl, nl, delta):
    if tl[T_ETA_NORMAL] != 0.0:
        if nl[L_FAMILY] == 1.0:
            return 0.0
        return tl[T_ETA] * nl[L_ETA] * spow(max(delta, 0.0), nl[L_B])
    return tl[T_ETA]


@njit(cache=KERNEL_CACHE)
def _lth_zzy_force(tl, family, xi, vt, fn_abs, delta, mu):
    xm = tl[T_XI] * max(delta, 0.0)
    hn = _norm(xi)
    f = np.zeros(3)
    if xm <= 0.0 or mu * fn_abs <= 0.0:
        return f
    u = min(hn, xm) / xm
    root = math.sqrt(max(1.0 - u, 0.0))
    if hn > 0.0:
        f = -(mu * fn_abs * (1.0 - (1.0 - u) ** 1.5) / hn) * xi
    if family == LTH:
        f = f - tl[T_ETA] * math.sqrt(6.0 * tl[T_M] * mu * fn_abs * root / xm) * vt
    else:
        c = tl[T_ETA1] / (2.0 * tl[T_G] * xm)
        f = f - c * (1.0 - 0.4 * c * _norm(vt)) * (1.5 * mu * fn_abs * root) * vt
    fm = _norm(f)
    cap = mu * fn_abs
    if fm > cap:
        f = f * (cap / fm)
    return f


@njit(cache=KERNEL_CACHE)
def slip_surface(tl, nl, xi, vt, fn_abs, delta, mu):
    """(ψ, w, D): the slip function of the history laws (ψ ≤ 0 sticks), the direction w in history space
    along which a slip reduces ψ, and D = ∇_hψ·w."""
    family = tl[T_FAMILY]
    hn = _norm(xi)
    w = xi / hn if hn > 0.0 else np.zeros(3)
    cap = mu * fn_abs
    if family == SPRING:
        kt = kt_of(tl, delta)
        eta = eta_of(tl, nl, delta)
        if tl[T_TRUNC] == TRUNC_SPRING:
            return kt * hn - cap, w, kt
        s = kt * xi + eta * vt
        sn = _norm(s)
        return sn - cap, (s / sn if sn > 0.0 else w), kt
    if family == LTH or family == ZZY:
        return hn - tl[T_XI] * max(delta, 0.0), w, 1.0
    if family == WALTON:
        # the load saturates by itself on a rising limit (Kt → 0 at μ|Fn|); a falling limit μk|Fn| below |L|
        # carries the stored load down with it (seed 000 §4.8: the force is the state and obeys Coulomb's law)
        return hn - tl[T_MU_K] * fn_abs, w, 1.0
    return -1.0, w, 1.0


@njit(cache=KERNEL_CACHE)
def return_map(tl, nl, xi, vt, fn_abs, delta, mu):
    """The history on the slip surface of friction coefficient mu (Coulomb truncation)."""
    family = tl[T_FAMILY]
    hn = _norm(xi)
    cap = mu * fn_abs
    if family == SPRING:
        kt = kt_of(tl, delta)
        if kt <= 0.0:
            return np.zeros(3)
        eta = eta_of(tl, nl, delta)
        trunc = tl[T_TRUNC]
        if trunc == TRUNC_CAP:  # the force is capped, the spring keeps its extension
            return xi
        if trunc == TRUNC_MAW:  # spring + dashpot = μ|Fn| along the trial force
            s = -kt * xi - eta * vt
            sn = _norm(s)
            f = s * (cap / sn) if sn > 0.0 else np.zeros(3)
            return -(f + eta * vt) / kt
        return xi * (cap / (kt * hn)) if hn > 0.0 else xi
    if hn == 0.0:
        return xi
    if family == LTH or family == ZZY:
        return xi * (tl[T_XI] * max(delta, 0.0) / hn)
    return xi * (cap / hn)  # WALTON


@njit(cache=KERNEL_CACHE)
def tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    """Force on body 0 of the tangential law, in its stick or slip state (SLIDING's stick force is the
    constraint force, computed by the caller)."""
    family = tl[T_FAMILY]
    if family == NONE:
        return np.zeros(3)
    mu = tl[T_MU_K] if slipping else tl[T_MU_S]
    vn = _norm(vt)
    if family == VISCOUS:
        return -eta_of(tl, nl, delta) * vt
    if family == VISCOUS_SLIDING:
        if vn == 0.0:
            return np.zeros(3)
        return -(min(eta_of(tl, nl, delta) * vn, tl[T_MU_K] * fn_abs) / vn) * vt
    if family == SLIDING:
        if vn > 0.0:
            return -(tl[T_MU_K] * fn_abs / vn) * vt
        return -(tl[T_MU_K] * fn_abs) * tref
    if family == WALTON:  # −L, limited to μ|Fn| when a falling normal force drops the limit below |L|
        hn = _norm(xi)
        cap = tl[T_MU_K] * fn_abs
        return -(cap / hn) * xi if hn > cap else -xi
    if family == LTH or family == ZZY:
        return _lth_zzy_force(tl, family, xi, vt, fn_abs, delta, tl[T_MU_K])
    # SPRING
    kt = kt_of(tl, delta)
    eta = eta_of(tl, nl, delta)
    trial = -kt * xi - eta * vt
    if not slipping:
        return trial
    trunc = tl[T_TRUNC]
    cap = mu * fn_abs
    if trunc != TRUNC_SPRING:
        tn = _norm(trial)
        return trial * (cap / tn) if tn > 0.0 else trial
    hn = _norm(xi)
    return -(cap / hn) * xi if hn > 0.0 else np.zeros(3)


@njit(cache=KERNEL_CACHE)
def walton_margin(tl, xi, vt, fn_abs, lstar):
    """x = 1 − (T − T*)/(μ|Fn| − T*): the fraction of the way left to the Coulomb limit (≤ 0: at it)."""
    vn = _norm(vt)
    if vn == 0.0:
        return 1.0
    t = vt / vn
    tt, ts = _dot(xi, t), _dot(lstar, t)
    den = tl[T_MU_K] * fn_abs - ts
    if den <= 0.0:
        return 0.0
    return 1.0 - (tt - ts) / den


WALTON_NEAR_LIMIT = 1e-6
WALTON_RIDE = 1e-9  # below a rising limit, the band in which the load rides it (rhs)


@njit(cache=KERNEL_CACHE, inline="always")
def walton_reverses(vt, previous):
    """Whether the slip reverses its direction (seed 000 §4.8, Walton & Braun 1986): v_t turns against the last
    nonzero slip velocity. Only then is the load at the reversal stored (L* := L); the load passing through
    zero while the slip keeps its direction is no reversal. The verlet method and the packing loop test this
    each step; the adaptive method locates the zero of v_t·t̂ (t̂ the slip direction before it) as an event."""
    return vt[0] * previous[0] + vt[1] * previous[1] + vt[2] * previous[2] < 0.0


@njit(cache=KERNEL_CACHE)
def walton_stiffness(tl, xi, vt, fn_abs, lstar):
    """Kt = K0 (1 − (T − T*)/(μ|Fn| − T*))^{1/3} with T, T* the load and the load at the last reversal,
    both measured along the current slip direction (docs/models.md: the 3-D definition); 0 without slip
    or at the limit."""
    if _norm(vt) == 0.0:
        return 0.0
    x = walton_margin(tl, xi, vt, fn_abs, lstar)
    if x <= 0.0:
        return 0.0
    return tl[T_K0] * x ** (1.0 / 3.0)
