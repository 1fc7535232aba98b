"""Zheng, Zhu & Yu on the history ξ: LTH's elastic part, slip surface and return map (``lth.py``) with the
viscous part η₁/(2Gᵢξm)(1 − 0.4η₁|v_t|/(2Gᵢξm))(1.5μ|Fn|√(1 − min(|ξ|,ξm)/ξm)) v_t; |Ft| ≤ μ|Fn|."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import T_ETA1, T_G, T_MU_K, T_XI, TangentialSubModel, compiled
from .common import _norm
from .lth import UNLOAD_MARGIN, bounded_return_map, bounded_slip_surface, coulomb_capped, elastic_part

ZZY = 6


@dataclass(frozen=True)
class ZzyTangential(TangentialSubModel):
    """Zheng, Zhu & Yu on the history ξ (viscosity η₁ = eta1, shear modulus G_i = g_i)."""

    id: ClassVar[str] = "zzy"
    family: ClassVar[int] = ZZY
    caps: ClassVar[bool] = True
    states: ClassVar[bool] = True
    slip_reads_surface: ClassVar[bool] = True
    # its stick force reaches μ|Fn| through a viscous term of unbounded slope: a slip ends only where sticking
    # would unload the history by more than this fraction of |v_t| (adaptive3d.py, at UNLOAD_MARGIN's use)
    unload_margin: ClassVar[float] = UNLOAD_MARGIN
    title: ClassVar[str] = "Zheng, Zhu & Yu"
    history_size: ClassVar[int] = 3
    eta1: float = 0.0
    g_i: float = 0.0
    xi_coef: float = 0.0
    mu_s: float = 0.0
    mu_k: float = 0.0
    r_eff: float = 0.0
    m_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def zzy_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    mu = tl[T_MU_K]
    xm = tl[T_XI] * max(delta, 0.0)
    if xm <= 0.0 or mu * fn_abs <= 0.0:
        return np.zeros(3)
    f, root = elastic_part(xi, fn_abs, xm, mu)
    c = tl[T_ETA1] / (2.0 * tl[T_G] * xm)
    f = f - c * (1.0 - 0.4 * c * _norm(vt)) * (1.5 * mu * fn_abs * root) * vt
    return coulomb_capped(f, mu * fn_abs)


compiled(ZzyTangential, force=zzy_tangential_force, slip_surface=bounded_slip_surface,
         return_map=bounded_return_map)
