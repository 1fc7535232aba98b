"""The damping slot's interface: the record every damping law is (:class:`Damping`), its columns in the normal law
array, the power dashpot the seed's laws share, and the registry of the laws' compiled functions (:func:`compiled`)
from which ``dispatch`` assembles the kernels' switch on the damping family id.

A damping law is one module of this package (every module in it is imported, in name order): its record, its
family id, its compiled functions and their registration here — docs/architecture.md, "The damping slot, one
module per law". Its coefficient is η (the array's ``L_ETA``) and the exponent b of its prefactor η δ^b
(``L_B``: the engines' tangential dashpots reuse η δ^b).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..base import SubModel
from ..normal_laws.common import L_B, L_DAMPING, L_ETA, spow  # noqa: F401  (the columns a law reads)


@dataclass(frozen=True)
class Damping(SubModel):
    """A damping law's record: η(δ) = eta · δ^exponent, the prefactor of the approach rate δ̇ in the normal force.
    ``family``: its id in the normal law array's ``L_DAMPING`` column (unique per law module)."""

    slot: ClassVar[str] = "damping"
    exponent: ClassVar[float] = 0.0
    family: ClassVar[int | None] = None


@dataclass(frozen=True)
class Kernels:
    """One damping law's compiled functions (numba dispatchers): ``force(law, δ, δ̇)`` its contribution to the
    normal force (N, + repulsive), ``rate(law, δ, δ̇, δ̈)`` the time derivative of that contribution (the 1-D
    adaptive solver's peak-force event). ``law``: the normal law array."""

    family: int
    force: object
    rate: object


KERNELS: dict[int, Kernels] = {}
_BUILT: list[bool] = []  # set once the switch is assembled: a later law would be missing from it


def compiled(record: type, *, force, rate) -> Kernels:
    """Registers the compiled functions of the damping law whose record class is ``record`` under its family."""
    if not (isinstance(record, type) and issubclass(record, Damping)):
        raise TypeError(f"{record!r} is not a damping record class")
    if not isinstance(record.family, int) or isinstance(record.family, bool) or record.family < 0:
        raise ValueError(f"damping record {record.id!r}: family must be an int >= 0, not {record.family!r}")
    k = Kernels(record.family, force, rate)
    if KERNELS.get(k.family, k) != k:
        raise ValueError(f"damping family {k.family} ({record.id!r}) registered twice with other functions")
    if _BUILT and k.family not in KERNELS:
        raise RuntimeError(f"damping law {record.id!r} registered after the kernels' switch was assembled")
    KERNELS[k.family] = k
    RECORDS[k.family] = record
    return k


RECORDS: dict[int, type] = {}  # family → the record class


@njit(cache=KERNEL_CACHE, inline="always")
def power_dashpot_force(law, delta, rate, b):
    """η δ^b δ̇ (δ^b sign-preserving; a law passes its own exponent, a constant numba folds into spow's switch —
    faster in the 1-D solver than the array's exponent, docs/performance.md)."""
    return law[L_ETA] * spow(delta, b) * rate


@njit(cache=KERNEL_CACHE, inline="always")
def power_dashpot_rate(law, delta, rate, acc):
    """d/dt (η δ^b δ̇) = η (b |δ|^{b−1} δ̇² + δ^b δ̈), b the array's exponent (b ≠ 0; δ ≠ 0)."""
    b = law[L_B]
    return law[L_ETA] * (b * abs(delta) ** (b - 1.0) * rate * rate + spow(delta, b) * acc)
