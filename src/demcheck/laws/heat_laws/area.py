"""A contact conductance per area: H = hs·πa², a = √(R̄δ) (LAMMPS ``heat area hs``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, HeatSubModel


@dataclass(frozen=True)
class AreaHeat(HeatSubModel):
    id: ClassVar[str] = "area"
    title: ClassVar[str] = "conductance hs π a²"
    scenarios: ClassVar[tuple] = ("conduction",)
    keys: ClassVar[tuple] = (Key("k", "contact conductance per area hs (W/(m²·K))", "must be > 0", positive),)
    formula: ClassVar[str] = "Q = hs π a² (T1 − T0)"
    source: ClassVar[str] = "LAMMPS pair granular heat area"
    example: ClassVar[dict] = {"k": 1e6}
    k: float = 0.0  # hs (W/(m²·K))
    r_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def area_heat_force(c, delta, d_temp):
    return c[0] * math.pi * c[1] * delta * d_temp if delta > 0.0 else 0.0


KERNELS.register(AreaHeat, area_heat_force)
