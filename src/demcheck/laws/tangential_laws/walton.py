"""Walton & Braun's incrementally slipping friction (seed 000 §4.8) on the tangential load L: ΔL = Kt Δδt with
Kt = K0 (1 − (T − T*)/(μ|Fn| − T*))^{1/3}, T* the load at the last reversal of the slip; its history is L, L*
and the last nonzero slip velocity (3 each). Its slip surface |L| = μk|Fn| carries a falling limit's load down
with it; its return map is the radial one (common.radial_return_map)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import T_K0, T_MU_K, TangentialSubModel, compiled
from .common import _dot, _norm, radial_return_map, reverses

WALTON = 7

WALTON_NEAR_LIMIT = 1e-6
WALTON_RIDE = 1e-9  # below a rising limit, the band in which the load rides it (rhs)


@dataclass(frozen=True)
class WaltonTangential(TangentialSubModel):
    """Walton & Braun's incrementally slipping friction; its history is the load L, the load at the last
    reversal L* and the last nonzero slip velocity (3 each)."""

    id: ClassVar[str] = "walton"
    family: ClassVar[int] = WALTON
    caps: ClassVar[bool] = True
    reversal: ClassVar[bool] = True  # L* := L where the slip reverses
    history_is_load: ClassVar[bool] = True
    near_limit: ClassVar[float] = WALTON_NEAR_LIMIT  # no slip state: the load rides the limit
    ride_band: ClassVar[float] = WALTON_RIDE
    title: ClassVar[str] = "incrementally slipping friction"
    history_size: ClassVar[int] = 9
    k0: float = 0.0
    mu_s: float = 0.0
    mu_k: float = 0.0
    r_eff: float = 0.0
    m_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def walton_slip_surface(tl, nl, xi, vt, fn_abs, delta, mu):
    """The load saturates by itself on a rising limit (Kt → 0 at μ|Fn|); a falling limit μk|Fn| below |L|
    carries the stored load down with it (seed 000 §4.8: the force is the state and obeys Coulomb's law)."""
    hn = _norm(xi)
    w = xi / hn if hn > 0.0 else np.zeros(3)
    return hn - tl[T_MU_K] * fn_abs, w, 1.0


@njit(cache=KERNEL_CACHE)
def walton_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    """−L, limited to μ|Fn| when a falling normal force drops the limit below |L|."""
    hn = _norm(xi)
    cap = tl[T_MU_K] * fn_abs
    return -(cap / hn) * xi if hn > cap else -xi


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


@njit(cache=KERNEL_CACHE, inline="always")
def walton_reverses(vt, previous):
    """Whether the slip reverses its direction (seed 000 §4.8, Walton & Braun 1986): v_t turns against the last
    nonzero slip velocity. Only then is the load at the reversal stored (L* := L); the load passing through
    zero while the slip keeps its direction is no reversal. The verlet method and the packing loop test this
    each step; the adaptive method locates the zero of v_t·t̂ (t̂ the slip direction before it) as an event."""
    return reverses(vt, previous)


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


@njit(cache=KERNEL_CACHE)
def walton_history_rate(tl, nl, xi, vt, fn_abs, delta, lstar):
    """dL/dt = Kt v_t (walton_stiffness)."""
    return walton_stiffness(tl, xi, vt, fn_abs, lstar) * vt


@njit(cache=KERNEL_CACHE)
def walton_limit_margin(tl, nl, xi, vt, fn_abs, delta, lstar):
    """The fraction of the way left to the Coulomb limit (walton_margin)."""
    return walton_margin(tl, xi, vt, fn_abs, lstar)


compiled(WaltonTangential, force=walton_tangential_force, slip_surface=walton_slip_surface,
         return_map=radial_return_map, history_rate=walton_history_rate, limit_margin=walton_limit_margin)
