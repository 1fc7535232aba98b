"""The linear dashpot η δ̇ (LSDn)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import L_ETA, Damping, compiled

CONSTANT = 1  # its family id (L_DAMPING)


@dataclass(frozen=True)
class ConstantDamping(Damping):
    id: ClassVar[str] = "constant"
    title: ClassVar[str] = "η δ̇ (linear dashpot: LSDn)"
    exponent: ClassVar[float] = 0.0
    family: ClassVar[int] = CONSTANT
    eta: float = 0.0  # N·s/m


@njit(cache=KERNEL_CACHE)
def constant_damping_force(law, delta, rate):
    return law[L_ETA] * rate


@njit(cache=KERNEL_CACHE)
def constant_damping_rate(law, delta, rate, acc):
    return law[L_ETA] * acc


compiled(ConstantDamping, force=constant_damping_force, rate=constant_damping_rate)
