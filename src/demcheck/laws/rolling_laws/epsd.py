"""Type C, the elastic–plastic spring–dashpot (Iwashita & Oda 1998 as written by Ai et al. 2011): a spring torque
Mk updated incrementally, Mk ← Mk − kr w dt, limited to the full-mobilisation torque Mm = μr Rr |Fn|; a dashpot
Md = −f Cr w with Cr = ηr·2√(Ir kr). Ai et al. take f = 0 once the spring is fully mobilised (``cap`` = 0,
spring), LAMMPS's ``rolling sds`` caps the sum of spring and dashpot (``cap`` = 1, total: Mk is reset so that
|Mk − Cr w| = Mm, the Maw rule of its tangential model; with ``slack_zero`` the torque is zero when the sum is
over the limit while the spring is unstretched, as LAMMPS does at its set-up step). ηr = 0 is the type C model
without its viscous part."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import C_R, KERNELS, MU_R, R_ROLL, RollingSubModel, _rolling_part

CAP_SPRING, CAP_TOTAL = 0, 1


@dataclass(frozen=True)
class EpsdRolling(RollingSubModel):
    id: ClassVar[str] = "epsd"
    history_size: ClassVar[int] = 3  # the spring torque Mk
    title: ClassVar[str] = "elastic-plastic spring-dashpot rolling resistance (Ai et al. 2011 type C)"
    scenarios: ClassVar[tuple] = ("incline",)
    spring: ClassVar[bool] = True
    keys: ClassVar[tuple] = (
        MU_R, R_ROLL, Key("k_r", "rolling stiffness kr (N·m/rad)", "must be > 0", positive), C_R,
        Key("cap", "what the limit caps: the spring (Ai et al.) or spring + dashpot (LAMMPS sds)", default="spring",
            choices={"spring": CAP_SPRING, "total": CAP_TOTAL}),
        Key("slack_zero", "no torque while the spring is unstretched and the dashpot alone exceeds the limit",
            default=False, flag=True))
    formula: ClassVar[str] = "Mk ← Mk − kr wt dt, |Mk| ≤ μr Rr |Fn|; Md = −Cr wt (off at the limit, or the sum capped)"
    source: ClassVar[str] = "Ai et al. 2011, model C (Iwashita & Oda 1998); LAMMPS rolling sds"
    example: ClassVar[dict] = {"mu_r": 0.1, "k_r": 1e-3}
    mu_r: float = 0.0
    r_roll: float = 0.0
    k_r: float = 0.0  # N·m/rad
    c_r: float = 0.0  # N·m·s/rad
    cap: int = CAP_SPRING
    slack_zero: bool = False


@njit(cache=KERNEL_CACHE)
def epsd_rolling_force(c, w, n, fn_abs, dt, history):
    mu_r, r_roll, k_r, c_r, cap_rule, slack_zero = c[0], c[1], c[2], c[3], c[4], c[5]
    wt = _rolling_part(w, n)
    cap = mu_r * r_roll * fn_abs
    spring = history - (k_r * dt) * wt
    damp = -c_r * wt
    if cap_rule == CAP_TOTAL:
        total = spring + damp
        mag = math.sqrt(total[0] ** 2 + total[1] ** 2 + total[2] ** 2)
        if mag > cap:
            if slack_zero != 0.0 and spring[0] == 0.0 and spring[1] == 0.0 and spring[2] == 0.0:
                return np.zeros(3), spring  # the engine's rule: no stored rolling, no torque
            total = total * (cap / mag)
            spring = total - damp
        return total, spring
    mag = math.sqrt(spring[0] ** 2 + spring[1] ** 2 + spring[2] ** 2)
    if mag > cap:  # full mobilisation: the spring saturates, the dashpot is off (Ai et al.'s f = 0)
        spring = spring * (cap / mag)
        return spring, spring
    return spring + damp, spring


KERNELS.register(EpsdRolling, epsd_rolling_force)
