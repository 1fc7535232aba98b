"""The hysteretic linear spring (Walton & Braun): F = min(K_L δ, K_U (δ − δ₀)) ≥ 0, δ₀ = δ_max (1 − K_L/K_U),
K_U given or K_L + S K_L δ_max. The normal slot's record ``hls`` (laws/normal.py); no dashpot. Its traits: the
largest overlap δ_max is its history, and its force has loading and unloading branches (the solvers' M_LOAD /
M_UNLOAD modes, switched at the largest overlap and where a reloading reaches it)."""

from __future__ import annotations

from numba import njit

from ... import KERNEL_CACHE
from .common import L_KL, L_KU, L_S

FAMILY = 1  # its id in the law array (L_FAMILY)
RECORDS = ("hls",)
HISTORY_SIZE = 1  # δ_max
LOAD_UNLOAD = True


@njit(cache=KERNEL_CACHE, inline="always")
def hls_unloading(law, dmax):
    """(K_U, δ₀) for the largest overlap reached so far."""
    kl = law[L_KL]
    ku = law[L_KU] if law[L_KU] > 0.0 else kl + law[L_S] * kl * dmax
    return ku, dmax * (1.0 - kl / ku)


@njit(cache=KERNEL_CACHE, inline="always")
def hls_contact_force(law, delta, dmax):
    """The force at overlap δ > 0 with the largest overlap δ_max so far."""
    ku, d0 = hls_unloading(law, dmax)
    f = min(law[L_KL] * delta, ku * (delta - d0))
    return max(f, 0.0)
