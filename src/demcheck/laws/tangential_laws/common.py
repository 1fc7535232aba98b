"""What the tangential laws' compiled functions share: 3-vector helpers, the stiffness Kt(δ) and dashpot ηt(δ)
of a spring-like law (read from the composed law array's columns), and the defaults of a law without a slip
surface of its own."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..normal_force import L_B, L_ETA, loads_and_unloads, spow
from ..tangential_slot import T_ETA, T_ETA_NORMAL, T_KT, T_KT_SQRT, T_R


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
def reverses(vt, previous):
    """Whether the slip reverses its direction: v_t turns against the last nonzero slip velocity (a law with
    F_REVERSAL stores its history there)."""
    return vt[0] * previous[0] + vt[1] * previous[1] + vt[2] * previous[2] < 0.0


@njit(cache=KERNEL_CACHE, inline="always")
def kt_of(tl, delta):
    if tl[T_KT_SQRT] != 0.0:
        return tl[T_KT] * math.sqrt(tl[T_R] * max(delta, 0.0))
    return tl[T_KT]


@njit(cache=KERNEL_CACHE, inline="always")
def eta_of(tl, nl, delta):
    if tl[T_ETA_NORMAL] != 0.0:
        if loads_and_unloads(nl):
            return 0.0
        return tl[T_ETA] * nl[L_ETA] * spow(max(delta, 0.0), nl[L_B])
    return tl[T_ETA]


@njit(cache=KERNEL_CACHE)
def no_slip_surface(tl, nl, xi, vt, fn_abs, delta, mu):
    """A law without a slip surface: ψ = −1 (it never slips by its history), w the history's direction."""
    hn = _norm(xi)
    w = xi / hn if hn > 0.0 else np.zeros(3)
    return -1.0, w, 1.0


@njit(cache=KERNEL_CACHE)
def radial_return_map(tl, nl, xi, vt, fn_abs, delta, mu):
    """The history scaled onto |ξ| = μ|Fn| (Walton's load; the default of a law with no return map)."""
    hn = _norm(xi)
    cap = mu * fn_abs
    if hn == 0.0:
        return xi
    return xi * (cap / hn)
