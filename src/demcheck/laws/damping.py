"""The damping slot: the normal dashpot η δ^b δ̇ of a viscoelastic contact, one record per exponent family.

The seed's damped normal models are pairs of an elastic law and one of these (LSDn: hooke + constant; BSHPn and
KKn: hertz + sqrt; TTIn: hertz + quarter); the engines' tangential dashpots reuse the prefactor η(δ) = η δ^b.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .base import SubModel


@dataclass(frozen=True)
class Damping(SubModel):
    """η(δ) = eta · δ^exponent, the prefactor of the approach rate δ̇ in the normal force."""

    slot: ClassVar[str] = "damping"
    exponent: ClassVar[float] = 0.0


@dataclass(frozen=True)
class NoDamping(Damping):
    id: ClassVar[str] = "none"
    title: ClassVar[str] = "no normal dashpot (elastic)"


@dataclass(frozen=True)
class ConstantDamping(Damping):
    id: ClassVar[str] = "constant"
    title: ClassVar[str] = "η δ̇ (linear dashpot: LSDn)"
    exponent: ClassVar[float] = 0.0
    eta: float = 0.0  # N·s/m


@dataclass(frozen=True)
class SqrtDamping(Damping):
    id: ClassVar[str] = "sqrt"
    title: ClassVar[str] = "η δ^{1/2} δ̇ (BSHPn, KKn; LAMMPS viscoelastic)"
    exponent: ClassVar[float] = 0.5
    eta: float = 0.0  # N·s/m^1.5


@dataclass(frozen=True)
class QuarterDamping(Damping):
    id: ClassVar[str] = "quarter"
    title: ClassVar[str] = "η δ^{1/4} δ̇ (TTIn; the engines' restitution dashpot on Hertz)"
    exponent: ClassVar[float] = 0.25
    eta: float = 0.0  # N·s/m^1.25


# the damped records by their exponent (the one place an exponent names a record: NormalLaw.slots)
BY_EXPONENT = {cls.exponent: cls for cls in (ConstantDamping, SqrtDamping, QuarterDamping)}


def damping_of(eta: float, b: float) -> Damping:
    """The record of the dashpot η δ^b δ̇ (``none`` for η = 0 with b = 0; a law's undamped dashpot of another
    family keeps its family, η = 0: TTIn with ηn = 0 is still TTIn's dashpot); ValueError for an exponent no
    record has."""
    if eta == 0.0 and b == 0.0:
        return NoDamping()
    if b not in BY_EXPONENT:
        raise ValueError(f"no damping record has the δ^{b:g} dashpot (known: "
                         f"{', '.join(f'{c.id} δ^{e:g}' for e, c in BY_EXPONENT.items())})")
    return BY_EXPONENT[b](eta=eta)
