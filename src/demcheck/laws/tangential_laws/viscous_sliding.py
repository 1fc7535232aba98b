"""Viscous damping with sliding friction: F = −min(ηt|v_t|, μk|Fn|) t̂."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import T_MU_K, TangentialSubModel, compiled
from .common import _norm, eta_of

VISCOUS_SLIDING = 3


@dataclass(frozen=True)
class ViscousSlidingTangential(TangentialSubModel):
    """F = −min(ηt|v_t|, μk|Fn|) t̂."""

    id: ClassVar[str] = "viscous_sliding"
    family: ClassVar[int] = VISCOUS_SLIDING
    caps: ClassVar[bool] = True
    viscous_kink: ClassVar[bool] = True
    title: ClassVar[str] = "viscous damping with sliding friction"
    eta: float = 0.0
    eta_normal: bool = False
    mu_s: float = 0.0
    mu_k: float = 0.0
    r_eff: float = 0.0
    m_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def viscous_sliding_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    vn = _norm(vt)
    if vn == 0.0:
        return np.zeros(3)
    return -(min(eta_of(tl, nl, delta) * vn, tl[T_MU_K] * fn_abs) / vn) * vt


compiled(ViscousSlidingTangential, force=viscous_sliding_tangential_force)
