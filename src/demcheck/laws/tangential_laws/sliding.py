"""Simple sliding friction: F = −μk|Fn| t̂ while sliding; the constraint force (≤ μs|Fn|) while stuck (the
solvers compute it; the force here is the one along ``tref`` at zero slip velocity)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import T_MU_K, TangentialSubModel, compiled
from .common import _norm

SLIDING = 1


@dataclass(frozen=True)
class SlidingTangential(TangentialSubModel):
    """F = −μk|Fn| t̂ while sliding; the constraint force (≤ μs|Fn|) while stuck."""

    id: ClassVar[str] = "sliding"
    family: ClassVar[int] = SLIDING
    caps: ClassVar[bool] = True
    constraint: ClassVar[bool] = True
    title: ClassVar[str] = "simple sliding friction"
    mu_s: float = 0.0
    mu_k: float = 0.0
    r_eff: float = 0.0
    m_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def sliding_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    vn = _norm(vt)
    if vn > 0.0:
        return -(tl[T_MU_K] * fn_abs / vn) * vt
    return -(tl[T_MU_K] * fn_abs) * tref


compiled(SlidingTangential, force=sliding_tangential_force)
