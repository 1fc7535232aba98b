"""The Coulomb-limited twisting spring–dashpot on the relative twist angle φ (φ̇ = (ω0 − ω1)·n):
Mt = −ktw φ − γtw φ̇, |Mt| ≤ μtw |Fn|; at the limit the stored angle is reset so that spring + dashpot equal it
(the Maw rule; LAMMPS ``twisting sds``, after Marshall 2009)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, TwistingSubModel, _sds


@dataclass(frozen=True)
class SdsTwisting(TwistingSubModel):
    id: ClassVar[str] = "sds"
    title: ClassVar[str] = "Coulomb-limited twisting spring-dashpot"
    scenarios: ClassVar[tuple] = ("twist",)
    keys: ClassVar[tuple] = (
        Key("k_tw", "twisting stiffness (N·m/rad)", "must be > 0", positive),
        Key("gamma_tw", "twisting damping (N·m·s/rad)", default=0.0),
        Key("mu_tw", "twisting limit coefficient (m: μtw |Fn| is a torque)"))
    formula: ClassVar[str] = "Mt = −ktw φ − γtw φ̇, |Mt| ≤ μtw |Fn|"
    source: ClassVar[str] = "Marshall, J. Comput. Phys. 228 (2009) 1541; LAMMPS twisting sds"
    example: ClassVar[dict] = {"k_tw": 1e-3, "mu_tw": 1e-4}
    k_tw: float = 0.0  # N·m/rad
    gamma_tw: float = 0.0  # N·m·s/rad
    mu_tw: float = 0.0  # m


@njit(cache=KERNEL_CACHE)
def sds_twisting_force(c, w, n, fn_abs, a, dt, phi):
    return _sds(c[0], c[1], c[2], w, n, fn_abs, dt, phi)


KERNELS.register(SdsTwisting, sds_twisting_force)
