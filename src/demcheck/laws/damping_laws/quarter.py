"""The dashpot η δ^{1/4} δ̇ on Hertz (TTIn; the engines' restitution dashpot on Hertz)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import Damping, compiled, power_dashpot_force, power_dashpot_rate

QUARTER = 3  # its family id (L_DAMPING)
EXPONENT = 0.25


@dataclass(frozen=True)
class QuarterDamping(Damping):
    id: ClassVar[str] = "quarter"
    title: ClassVar[str] = "η δ^{1/4} δ̇ (TTIn; the engines' restitution dashpot on Hertz)"
    exponent: ClassVar[float] = EXPONENT
    family: ClassVar[int] = QUARTER
    eta: float = 0.0  # N·s/m^1.25


@njit(cache=KERNEL_CACHE)
def quarter_damping_force(law, delta, rate):
    return power_dashpot_force(law, delta, rate, EXPONENT)


@njit(cache=KERNEL_CACHE)
def quarter_damping_rate(law, delta, rate, acc):
    return power_dashpot_rate(law, delta, rate, acc)


compiled(QuarterDamping, force=quarter_damping_force, rate=quarter_damping_rate)
