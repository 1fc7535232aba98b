"""The viscoelastic power law's spring k δ^a: a spring record of the normal slot (hooke a = 1, hertz a = 3/2;
laws/normal.py). Its dashpot is the damping slot's (laws/damping_laws/: none, constant, sqrt, quarter); the
contact's force k δ^a + η δ^b δ̇, and ``limit_force``'s clip at 0, are composed in laws/normal_force.py. Its
traits: no history, one branch (the solvers' M_VE mode)."""

from __future__ import annotations

from numba import njit

from ... import KERNEL_CACHE
from .common import L_A, L_K, spow

FAMILY = 0  # its id in the law array (L_FAMILY)
RECORDS = ("hooke", "hertz")  # the normal slot's records it computes (with every damping record)
HISTORY_SIZE = 0
LOAD_UNLOAD = False  # loading and unloading branches with the largest overlap as history


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_elastic_force(law, delta):
    """The spring's force k δ^a (δ^a sign-preserving)."""
    return law[L_K] * spow(delta, law[L_A])


@njit(cache=KERNEL_CACHE, inline="always")
def viscoelastic_elastic_rate(law, delta, rate):
    """d/dt (k δ^a) = k a |δ|^{a−1} δ̇."""
    a = law[L_A]
    return law[L_K] * (rate if a == 1.0 else a * abs(delta) ** (a - 1.0) * rate)
