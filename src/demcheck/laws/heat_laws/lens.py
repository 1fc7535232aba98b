"""H = 4·k0k1/(k0+k1)·√A = 2ks√A with A the circle where the undeformed spheres intersect (LIGGGHTS
``fix heat/gran/conduction`` with its default ``contact_area overlap``). For like spheres and small δ this is
√(2π) ≈ 2.51 times Batchelor & O'Brien's 2ka at the Hertz radius."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..adhesion_laws.sjkr import lens_area  # the circle sjkr's lens area is: one function for both laws
from ..registry import Key, positive
from .slot import KERNELS, HeatSubModel


@dataclass(frozen=True)
class LensHeat(HeatSubModel):
    id: ClassVar[str] = "lens"
    title: ClassVar[str] = "conductance 2 ks √A over the spheres' intersection circle"
    scenarios: ClassVar[tuple] = ("conduction",)
    conductivity: ClassVar[bool] = True
    keys: ClassVar[tuple] = (Key("k", "conductivity ks = 2k0k1/(k0+k1) (W/(m·K))", "must be > 0", positive),)
    formula: ClassVar[str] = "Q = 2 ks √A (T1 − T0), A the spheres' intersection circle"
    source: ClassVar[str] = "LIGGGHTS fix heat/gran/conduction"
    example: ClassVar[dict] = {"k": 45.0}
    k: float = 0.0  # ks = 2k0k1/(k0+k1)
    r0: float = 0.0
    r1: float = 0.0
    wall: bool = False


@njit(cache=KERNEL_CACHE)
def lens_heat_force(c, delta, d_temp):
    return 2.0 * c[0] * math.sqrt(lens_area(c[1], c[2], delta, c[3] != 0.0)) * d_temp if delta > 0.0 else 0.0


KERNELS.register(LensHeat, lens_heat_force)
