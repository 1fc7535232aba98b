"""The damping slot: the normal dashpot η δ^b δ̇ of a viscoelastic contact. Each law is one module of
laws/damping_laws/ (its record, family id and compiled force); this module gathers the built-in records and
names a dashpot by its exponent where the seed's laws give one.

The seed's damped normal models are pairs of an elastic law and one of these (LSDn: hooke + constant; BSHPn and
KKn: hertz + sqrt; TTIn: hertz + quarter); the engines' tangential dashpots reuse the prefactor η(δ) = η δ^b.
"""

from __future__ import annotations

from . import damping_laws  # noqa: F401  (every damping law registered)
from .damping_laws.common import RECORDS, Damping  # noqa: F401
from .damping_laws.constant import ConstantDamping
from .damping_laws.none import NoDamping
from .damping_laws.quarter import QuarterDamping
from .damping_laws.sqrt import SqrtDamping

# the seed's damped records by their exponent (the one place an exponent names a record: NormalLaw.slots)
BY_EXPONENT = {cls.exponent: cls for cls in (ConstantDamping, SqrtDamping, QuarterDamping)}
SEED_FAMILIES = frozenset(cls.family for cls in (NoDamping, *BY_EXPONENT.values()))


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
