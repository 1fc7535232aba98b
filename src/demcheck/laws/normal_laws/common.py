"""The normal slot's interface: the law array's layout ``NormalLaw.array()`` — [family, k, a, eta, b, kl, ku, s,
damping, limit], the L_* columns (``family``: the normal law's id, ``damping``: the damping law's,
laws/damping_laws/) —, the record every normal law is (:class:`NormalSubModel`), the registry of the laws'
compiled functions (:func:`compiled`) from which ``dispatch`` assembles the kernels' switch on the family id, and
the sign-preserving power the laws (and the tangential dashpots) use.

A normal law is one module of this package (every module in it is imported, in name order): its record, its
family id, its compiled functions and their registration here — docs/architecture.md, "The normal slot, one
module per law". Its signatures, by its trait ``load_unload``:

* one branch (``load_unload = False``: hooke, hertz): ``force(law, δ)`` the spring's force (N, + repulsive; the
  dashpot is the damping slot's, the clip ``limit_force``'s, both added by laws/normal_force.py) and
  ``rate(law, δ, δ̇)`` its time derivative (the 1-D adaptive solver's peak-force event);
* loading and unloading branches with the largest overlap δ_max as history (``load_unload = True``: hls):
  ``force(law, δ, δ_max)`` the contact's force (≥ 0, no dashpot) and ``unloading(law, δ_max)`` → (K_U, δ₀), the
  unloading branch K_U (δ − δ₀); the loading branch is K_L δ (``L_KL``). The solvers' M_LOAD / M_UNLOAD modes
  hold one such law (laws/normal_force.py asserts it).

A record's numbers go to the array's columns of the same name, or to the one its ``columns`` names (``k``, ``kl``,
``ku``, ``s``: four numbers at most); its ``exponent`` (a power-law spring's, if it has one) to ``a``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..base import SubModel

L_FAMILY, L_K, L_A, L_ETA, L_B, L_KL, L_KU, L_S, L_DAMPING, L_LIMIT = range(10)
# (limit stays the last column: the array's length is L_LIMIT + 1 where the packing loop and the warm-up use it)
NUMBER_COLUMNS = ("k", "kl", "ku", "s")  # the columns a record's numbers may fill


@dataclass(frozen=True)
class NormalSubModel(SubModel):
    """A normal law's record. ``family``: its id in the law array's ``L_FAMILY`` column (unique per law module);
    ``exponent``: a power-law spring's exponent (``L_A``; None: the law has none); ``load_unload``: its force has
    loading and unloading branches with the largest overlap as history (``history_size`` 1); ``columns``: field →
    the array column that holds it, where the column's name is not the field's."""

    slot: ClassVar[str] = "normal"
    family: ClassVar[int | None] = None  # None: a record with no compiled law (yet)
    exponent: ClassVar[float | None] = None
    load_unload: ClassVar[bool] = False
    columns: ClassVar[dict[str, str]] = {}

    def law_numbers(self) -> dict[str, float]:
        """The record's numbers by the law array's column names (``NormalLaw``'s fields)."""
        out = {self.columns.get(f, f): getattr(self, f) for f in self.param_names()}
        if self.exponent is not None:
            out["a"] = self.exponent
        return out

    @classmethod
    def from_law(cls, law) -> "NormalSubModel":
        """The record of a ``NormalLaw`` of its family (the inverse of :meth:`law_numbers`)."""
        return cls(**{f: getattr(law, cls.columns.get(f, f)) for f in cls.param_names()})


@dataclass(frozen=True)
class Kernels:
    """One normal law's compiled functions (numba dispatchers; signatures in the module docstring): ``force``,
    and ``rate`` (one branch) or ``unloading`` (loading and unloading branches). ``law``: the normal law array."""

    family: int
    load_unload: bool
    force: object
    rate: object = None
    unloading: object = None


KERNELS: dict[int, Kernels] = {}
RECORDS: dict[int, type] = {}  # family → the record class
_BUILT: list[bool] = []  # set once the switch is assembled: a later law would be missing from it


def compiled(record: type, *, force, rate=None, unloading=None) -> Kernels:
    """Registers the compiled functions of the normal law whose record class is ``record`` under its family."""
    if not (isinstance(record, type) and issubclass(record, NormalSubModel)):
        raise TypeError(f"{record!r} is not a normal record class")
    if not isinstance(record.family, int) or isinstance(record.family, bool) or record.family < 0:
        raise ValueError(f"normal record {record.id!r}: family must be an int >= 0, not {record.family!r}")
    cols = [record.columns.get(f, f) for f in record.param_names()]
    if any(c not in NUMBER_COLUMNS for c in cols) or len(set(cols)) != len(cols):
        raise ValueError(f"normal record {record.id!r}: its numbers {record.param_names()} must go to distinct "
                         f"columns of {', '.join(NUMBER_COLUMNS)} (its ``columns``: {record.columns})")
    ok = (unloading is not None and rate is None) if record.load_unload else (rate is not None and unloading is None)
    if not ok:
        need = "force and unloading" if record.load_unload else "force and rate"
        raise ValueError(f"normal record {record.id!r} (load_unload={record.load_unload}) registers {need}")
    k = Kernels(record.family, record.load_unload, force, rate, unloading)
    if KERNELS.get(k.family, k) != k:
        raise ValueError(f"normal family {k.family} ({record.id!r}) registered twice with other functions")
    if _BUILT and k.family not in KERNELS:
        raise RuntimeError(f"normal law {record.id!r} registered after the kernels' switch was assembled")
    KERNELS[k.family] = k
    RECORDS[k.family] = record
    return k


@njit(cache=KERNEL_CACHE, inline="always")
def spow(x, p):
    """Sign-preserving power; p = 0 gives 1 (so LSD's dashpot stays linear through δ = 0). The exponents the
    laws use (1, 1/2, 3/2, 1/4) without a pow call: the packing solver's inner loop calls this per contact
    (sqrt is correctly rounded, pow to within an ulp: the results agree to that)."""
    if p == 0.0:
        return 1.0
    a = abs(x)
    if p == 1.0:
        y = a
    elif p == 0.5:
        y = math.sqrt(a)
    elif p == 1.5:
        y = a * math.sqrt(a)
    elif p == 0.25:
        y = math.sqrt(math.sqrt(a))
    else:
        y = a**p
    return y if x >= 0.0 else -y
