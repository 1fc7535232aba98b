"""The linear spring F = k δ: the normal slot's record ``hooke`` (LSDn's spring; the engines' hooke). Its dashpot is
the damping slot's (laws/damping_laws/), added with ``limit_force``'s clip by laws/normal_force.py. Its traits: no
history, one branch (the solvers' M_VE mode)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import L_K, NormalSubModel, compiled, spow

HOOKE = 0  # its family id (L_FAMILY)
EXPONENT = 1.0


@dataclass(frozen=True)
class HookeNormal(NormalSubModel):
    """F = k δ (a linear spring)."""

    id: ClassVar[str] = "hooke"
    title: ClassVar[str] = "linear spring k δ"
    exponent: ClassVar[float] = EXPONENT
    family: ClassVar[int] = HOOKE
    k: float = 0.0  # N/m


@njit(cache=KERNEL_CACHE)
def hooke_normal_force(law, delta):
    """k δ (spow: the sign kept, +0 at δ = −0, as the power law's formula gave)."""
    return law[L_K] * spow(delta, EXPONENT)


@njit(cache=KERNEL_CACHE)
def hooke_normal_rate(law, delta, rate):
    """d/dt (k δ) = k δ̇."""
    return law[L_K] * rate


compiled(HookeNormal, force=hooke_normal_force, rate=hooke_normal_rate)
