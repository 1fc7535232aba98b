"""The hysteretic linear spring (Walton & Braun): F = min(K_L δ, K_U (δ − δ₀)) ≥ 0, δ₀ = δ_max (1 − K_L/K_U),
K_U given or K_L + S K_L δ_max: the normal slot's record ``hls``; no dashpot. Its traits: the largest overlap δ_max
is its history, and its force has loading and unloading branches (the solvers' M_LOAD / M_UNLOAD modes, switched
at the largest overlap and where a reloading reaches it; its loading branch is K_L δ, the array's ``L_KL``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from .common import L_KL, L_KU, L_S, NormalSubModel, compiled

HYSTERETIC = 1  # its family id (L_FAMILY)


@dataclass(frozen=True)
class HysteresisNormal(NormalSubModel):
    """F = min(K_L δ, K_U (δ − δ₀)) ≥ 0 with K_U = ku (> 0), or K_L + s·F_max (ku = 0); its history is the
    largest overlap δ_max."""

    id: ClassVar[str] = "hls"
    title: ClassVar[str] = "hysteretic linear spring"
    history_size: ClassVar[int] = 1  # δ_max
    family: ClassVar[int] = HYSTERETIC
    load_unload: ClassVar[bool] = True
    kl: float = 0.0  # N/m
    ku: float = 0.0  # N/m; 0: variable unloading
    s: float = 0.0  # 1/m


@njit(cache=KERNEL_CACHE, inline="always")
def hls_normal_unloading(law, dmax):
    """(K_U, δ₀) for the largest overlap reached so far."""
    kl = law[L_KL]
    ku = law[L_KU] if law[L_KU] > 0.0 else kl + law[L_S] * kl * dmax
    return ku, dmax * (1.0 - kl / ku)


@njit(cache=KERNEL_CACHE)
def hls_normal_force(law, delta, dmax):
    """The force at overlap δ > 0 with the largest overlap δ_max so far."""
    ku, d0 = hls_normal_unloading(law, dmax)
    f = min(law[L_KL] * delta, ku * (delta - d0))
    return max(f, 0.0)


compiled(HysteresisNormal, force=hls_normal_force, unloading=hls_normal_unloading)
