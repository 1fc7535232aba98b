"""Langston, Tüzün & Heyes on the history ξ: Ft,el = μ|Fn|(1 − (1 − min(|ξ|,ξm)/ξm)^{3/2}) with
ξm = xi_coef · δn, and the dashpot ηt (6 m̄ μ|Fn| √(1 − min(|ξ|,ξm)/ξm)/ξm)^{1/2} v_t; |Ft| ≤ μ|Fn|. Its
elastic part, slip surface |ξ| = ξm and return map are Zheng, Zhu & Yu's too (``zzy.py``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import T_ETA, T_M, T_MU_K, T_XI, TangentialSubModel, compiled
from .common import _norm

LTH = 5
# LTH and ZZY stick with a force that reaches μ|Fn| continuously, through a viscous term ∝ (1 − |ξ|/ξm)^{1/4}
# of unbounded slope: a history that leaves its surface inwards by a hair is pulled back at once, and where
# the stick flow points inwards only weakly the exact solution slides along the surface (a sliding mode
# whose force, μ|Fn|, is the slip state's). A slip of these laws therefore ends only when sticking would
# unload the history by more than this fraction of |v_t| (λ < −UNLOAD_MARGIN |v_t|); below it the contact
# stays on the surface, where stick and slip give the same force, instead of chattering between the two.
UNLOAD_MARGIN = 1e-4


@dataclass(frozen=True)
class LthTangential(TangentialSubModel):
    """Langston, Tüzün & Heyes on the history ξ, δt_max = xi_coef · δn."""

    id: ClassVar[str] = "lth"
    family: ClassVar[int] = LTH
    caps: ClassVar[bool] = True
    states: ClassVar[bool] = True
    slip_reads_surface: ClassVar[bool] = True
    # its stick force reaches μ|Fn| through a viscous term of unbounded slope: a slip ends only where sticking
    # would unload the history by more than this fraction of |v_t| (adaptive3d.py, at UNLOAD_MARGIN's use)
    unload_margin: ClassVar[float] = UNLOAD_MARGIN
    title: ClassVar[str] = "Langston, Tüzün & Heyes"
    history_size: ClassVar[int] = 3
    eta: float = 0.0
    xi_coef: float = 0.0
    mu_s: float = 0.0
    mu_k: float = 0.0
    r_eff: float = 0.0
    m_eff: float = 0.0


@njit(cache=KERNEL_CACHE, inline="always")
def elastic_part(xi, fn_abs, xm, mu):
    """(Ft,el, √(1 − u)) with u = min(|ξ|, ξm)/ξm, for ξm > 0 and μ|Fn| > 0."""
    hn = _norm(xi)
    f = np.zeros(3)
    u = min(hn, xm) / xm
    root = math.sqrt(max(1.0 - u, 0.0))
    if hn > 0.0:
        f = -(mu * fn_abs * (1.0 - (1.0 - u) ** 1.5) / hn) * xi
    return f, root


@njit(cache=KERNEL_CACHE, inline="always")
def coulomb_capped(f, cap):
    fm = _norm(f)
    if fm > cap:
        f = f * (cap / fm)
    return f


@njit(cache=KERNEL_CACHE)
def lth_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    mu = tl[T_MU_K]
    xm = tl[T_XI] * max(delta, 0.0)
    if xm <= 0.0 or mu * fn_abs <= 0.0:
        return np.zeros(3)
    f, root = elastic_part(xi, fn_abs, xm, mu)
    f = f - tl[T_ETA] * math.sqrt(6.0 * tl[T_M] * mu * fn_abs * root / xm) * vt
    return coulomb_capped(f, mu * fn_abs)


@njit(cache=KERNEL_CACHE)
def bounded_slip_surface(tl, nl, xi, vt, fn_abs, delta, mu):
    """ψ = |ξ| − ξm."""
    hn = _norm(xi)
    w = xi / hn if hn > 0.0 else np.zeros(3)
    return hn - tl[T_XI] * max(delta, 0.0), w, 1.0


@njit(cache=KERNEL_CACHE)
def bounded_return_map(tl, nl, xi, vt, fn_abs, delta, mu):
    """ξ scaled onto |ξ| = ξm."""
    hn = _norm(xi)
    if hn == 0.0:
        return xi
    return xi * (tl[T_XI] * max(delta, 0.0) / hn)


compiled(LthTangential, force=lth_tangential_force, slip_surface=bounded_slip_surface,
         return_map=bounded_return_map)
