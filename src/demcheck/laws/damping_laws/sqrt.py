"""The dashpot η δ^{1/2} δ̇ on Hertz (BSHPn, KKn; LAMMPS's viscoelastic damping)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import Damping, compiled, power_dashpot_force, power_dashpot_rate

SQRT = 2  # its family id (L_DAMPING)
EXPONENT = 0.5


@dataclass(frozen=True)
class SqrtDamping(Damping):
    id: ClassVar[str] = "sqrt"
    title: ClassVar[str] = "η δ^{1/2} δ̇ (BSHPn, KKn; LAMMPS viscoelastic)"
    exponent: ClassVar[float] = EXPONENT
    family: ClassVar[int] = SQRT
    eta: float = 0.0  # N·s/m^1.5


@njit(cache=KERNEL_CACHE)
def sqrt_damping_force(law, delta, rate):
    return power_dashpot_force(law, delta, rate, EXPONENT)


@njit(cache=KERNEL_CACHE)
def sqrt_damping_rate(law, delta, rate, acc):
    return power_dashpot_rate(law, delta, rate, acc)


compiled(SqrtDamping, force=sqrt_damping_force, rate=sqrt_damping_rate)
