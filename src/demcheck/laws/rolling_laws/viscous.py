"""Type B, the viscous rolling torque (Ai et al. 2011): M = −Cr w, proportional to the relative rolling velocity
(Cr in N·m·s). A sphere rolling under it never stops: v = v0 e^{−t/T}, T = (7/5) m R²/Cr."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, RollingSubModel, _rolling_part


@dataclass(frozen=True)
class ViscousRolling(RollingSubModel):
    id: ClassVar[str] = "viscous"
    title: ClassVar[str] = "viscous rolling resistance (Ai et al. 2011 type B)"
    scenarios: ClassVar[tuple] = ("rolling",)
    decays: ClassVar[bool] = True
    keys: ClassVar[tuple] = (Key("c_r", "rolling damping coefficient Cr (N·m·s/rad)", "must be > 0", positive),)
    formula: ClassVar[str] = "M = −Cr wt"
    source: ClassVar[str] = "Ai et al. 2011, model B"
    example: ClassVar[dict] = {"c_r": 1e-8}
    c_r: float = 0.0  # N·m·s/rad


@njit(cache=KERNEL_CACHE)
def viscous_rolling_force(c, w, n, fn_abs, dt, history):
    return -c[0] * _rolling_part(w, n), history


KERNELS.register(ViscousRolling, viscous_rolling_force)
