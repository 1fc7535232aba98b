"""Derjaguin, Muller & Toporov (J. Colloid Interface Sci. 53 (1975) 314-326): F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄ while
δ ≥ 0; pull-off 2πwR̄ at δ = 0, no hysteresis. It replaces the elastic normal law."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, AdhesionSubModel


@dataclass(frozen=True)
class DmtAdhesion(AdhesionSubModel):
    id: ClassVar[str] = "dmt"
    title: ClassVar[str] = "Derjaguin-Muller-Toporov adhesive elastic contact"
    scenarios: ClassVar[tuple] = ("pull_off",)
    replaces_normal: ClassVar[bool] = True
    keys: ClassVar[tuple] = (Key("w", "work of adhesion (J/m²)", "must be > 0 (J/m²)", positive),)
    formula: ClassVar[str] = "F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄ (δ ≥ 0)"
    source: ClassVar[str] = "Derjaguin, Muller & Toporov, J. Colloid Interface Sci. 53 (1975) 314"
    example: ClassVar[dict] = {"w": 0.1}
    r_eff: float = 0.0
    e_eff: float = 0.0
    w: float = 0.0

    def pull_off_force(self, control: str = "load") -> float:
        return 2.0 * math.pi * self.w * self.r_eff


@njit(cache=KERNEL_CACHE)
def dmt_adhesion_force(c, delta, touching):
    if delta < 0.0:
        return 0.0, 0.0
    r, e, w = c[0], c[1], c[2]
    return 4.0 / 3.0 * e * math.sqrt(r) * delta ** 1.5 - 2.0 * math.pi * w * r, 1.0


KERNELS.register(DmtAdhesion, dmt_adhesion_force)
