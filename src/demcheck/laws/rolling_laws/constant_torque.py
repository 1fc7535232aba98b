"""Type A, the constant directional torque (Ai, Chen, Rotter & Ooi, Powder Technol. 206 (2011) 269):
M = −μr Rr |Fn| ŵ, w the rolling part of ω0 − ω1; zero when w = 0. With ``full_direction`` the direction is taken
from all of ω0 − ω1 and its normal part removed afterwards (LIGGGHTS's ``cdt``: a twisting spin then lowers the
torque)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key
from .slot import KERNELS, MU_R, R_ROLL, RollingSubModel, _rolling_part


@dataclass(frozen=True)
class ConstantTorqueRolling(RollingSubModel):
    id: ClassVar[str] = "constant_torque"
    title: ClassVar[str] = "constant directional torque (Ai et al. 2011 type A)"
    scenarios: ClassVar[tuple] = ("rolling", "incline")
    stops: ClassVar[bool] = True
    keys: ClassVar[tuple] = (
        MU_R, R_ROLL,
        Key("full_direction", "direction from all of ω0 − ω1 (LIGGGHTS cdt), not its rolling part", default=False,
            flag=True))
    formula: ClassVar[str] = "M = −μr Rr |Fn| ŵt (wt the rolling part of ω0 − ω1)"
    source: ClassVar[str] = "Ai, Chen, Rotter & Ooi, Powder Technol. 206 (2011) 269, model A"
    example: ClassVar[dict] = {"mu_r": 0.1}
    mu_r: float = 0.0  # coefficient of rolling resistance (Mm = μr Rr |Fn|)
    r_roll: float = 0.0  # rolling radius Rr
    full_direction: bool = False


@njit(cache=KERNEL_CACHE)
def constant_torque_rolling_force(c, w, n, fn_abs, dt, history):
    wt = _rolling_part(w, n)
    d = w if c[2] != 0.0 else wt  # full_direction
    dm = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    if dm == 0.0:
        return np.zeros(3), history
    return (-c[0] * c[1] * fn_abs / dm) * wt, history


KERNELS.register(ConstantTorqueRolling, constant_torque_rolling_force)
