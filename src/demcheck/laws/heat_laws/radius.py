"""Batchelor & O'Brien (Proc. R. Soc. A 355 (1977) 313-333), for a contact much more conductive than the gap:
H = 2 ks a with a = √(R̄δ) the Hertz contact radius, ks = 2k0k1/(k0+k1) for two materials (LAMMPS ``heat radius``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, HeatSubModel


@dataclass(frozen=True)
class RadiusHeat(HeatSubModel):
    id: ClassVar[str] = "radius"
    title: ClassVar[str] = "conductance 2 ks a (Batchelor & O'Brien 1977)"
    scenarios: ClassVar[tuple] = ("conduction",)
    conductivity: ClassVar[bool] = True
    keys: ClassVar[tuple] = (Key("k", "conductivity ks (W/(m·K))", "must be > 0", positive),)
    formula: ClassVar[str] = "Q = 2 ks a (T1 − T0), a = √(R̄δ)"
    source: ClassVar[str] = "Batchelor & O'Brien, Proc. R. Soc. A 355 (1977) 313"
    example: ClassVar[dict] = {"k": 45.0}
    k: float = 0.0  # ks (W/(m·K))
    r_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def radius_heat_force(c, delta, d_temp):
    return 2.0 * c[0] * math.sqrt(c[1] * delta) * d_temp if delta > 0.0 else 0.0


KERNELS.register(RadiusHeat, radius_heat_force)
