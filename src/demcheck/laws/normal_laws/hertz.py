"""Hertz's spring F = k δ^{3/2} (k = (4/3) Ē √R̄ for the seed's Hertz law): the normal slot's record ``hertz``
(Hertz, BSHPn, KKn, TTIn; the engines' hertz). Its dashpot is the damping slot's (laws/damping_laws/), added with
``limit_force``'s clip by laws/normal_force.py. Its traits: no history, one branch (the solvers' M_VE mode)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import L_A, L_K, NormalSubModel, compiled, spow

HERTZ = 2  # its family id (L_FAMILY)
EXPONENT = 1.5


@dataclass(frozen=True)
class HertzNormal(NormalSubModel):
    """F = k δ^{3/2}, k = (4/3) Ē √R̄ for the seed's Hertz law."""

    id: ClassVar[str] = "hertz"
    title: ClassVar[str] = "Hertz spring k δ^{3/2}"
    exponent: ClassVar[float] = EXPONENT
    family: ClassVar[int] = HERTZ
    k: float = 0.0  # N/m^1.5


@njit(cache=KERNEL_CACHE)
def hertz_normal_force(law, delta):
    """k δ^{3/2} (sign-preserving; spow's δ·√δ for the constant exponent)."""
    return law[L_K] * spow(delta, EXPONENT)


@njit(cache=KERNEL_CACHE)
def hertz_normal_rate(law, delta, rate):
    """d/dt (k δ^{3/2}) = k (3/2) |δ|^{1/2} δ̇ — with the array's exponent (L_A, 3/2 for this record): a pow of
    a constant ½ may compile to a square root, whose last bit can differ from the pow's."""
    a = law[L_A]
    return law[L_K] * (a * abs(delta) ** (a - 1.0) * rate)


compiled(HertzNormal, force=hertz_normal_force, rate=hertz_normal_rate)
