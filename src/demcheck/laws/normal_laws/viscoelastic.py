"""The viscoelastic power law F = k δ^a + η δ^b δ̇: a spring record of the normal slot (hooke a = 1, hertz
a = 3/2; laws/normal.py) with a damping record's dashpot (none, constant, sqrt, quarter; laws/damping.py).
``limit_force`` clips the total at 0. Its traits: no history, one branch (the solvers' M_VE mode)."""

from __future__ import annotations

from numba import njit

from ... import KERNEL_CACHE
from .common import L_A, L_B, L_ETA, L_K, L_LIMIT, spow

FAMILY = 0  # its id in the law array (L_FAMILY)
RECORDS = ("hooke", "hertz")  # the normal slot's records it computes (with every damping record)
HISTORY_SIZE = 0
LOAD_UNLOAD = False  # loading and unloading branches with the largest overlap as history


@njit(cache=KERNEL_CACHE)
def viscoelastic_force(law, delta, rate):
    return law[L_K] * spow(delta, law[L_A]) + law[L_ETA] * spow(delta, law[L_B]) * rate


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_contact_force(law, delta, rate):
    """The force at overlap δ > 0, held at 0 where limit_force forbids attraction."""
    f = viscoelastic_force(law, delta, rate)
    if law[L_LIMIT] != 0.0 and f < 0.0:
        return 0.0
    return f
