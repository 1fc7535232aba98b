"""Rolling resistance: the slot ``rolling`` (a torque that opposes the relative rolling of two bodies).

Types after Ai, Chen, Rotter & Ooi, "Assessment of rolling resistance models in discrete element simulations",
Powder Technology 206 (2011) 269-282:

* ``constant_torque`` (type A, "constant directional torque"): M = −μr Rr |Fn| ŵ, with w the rolling part of the
  relative angular velocity (ω0 − ω1 minus its component along the normal n). Zero when w = 0. With
  ``full_direction`` the direction is taken from all of ω0 − ω1 and its normal part removed afterwards (what
  LIGGGHTS's ``cdt`` does: a twisting spin then lowers the torque).
* ``viscous`` (type B): M = −Cr w, a torque proportional to the relative rolling velocity (Cr in N·m·s).
* ``epsd`` (type C, elastic–plastic spring–dashpot, Iwashita & Oda 1998 as written by Ai et al.): a spring torque
  Mk updated incrementally, Mk ← Mk − kr w dt, limited to the full-mobilisation torque Mm = μr Rr |Fn|; a dashpot
  Md = −f Cr w with Cr = ηr·2√(Ir kr). Ai et al. take f = 0 once the spring is fully mobilised (``cap`` = 0,
  spring), LAMMPS's ``rolling sds`` caps the sum of spring and dashpot (``cap`` = 1, total: Mk is reset so that
  |Mk − Cr w| = Mm, the Maw rule of its tangential model; with ``slack_zero`` the torque is zero when the sum is
  over the limit while the spring is unstretched, as LAMMPS does at its set-up step). ηr = 0 is the type C model
  without its viscous part.

Rr is the rolling radius (R̄ = R0R1/(R0+R1) for a pair, R for a sphere on a wall); Ir the equivalent moment of
inertia of Ai et al., 1/Ir = 1/(I0 + m0R0²) + 1/(I1 + m1R1²) (= 1.4 m R² for a solid sphere on a wall).

Compiled force functions ``<id>_rolling_force(c, w, n, fn_abs, dt, history) → (torque on body 0, new history)``
(c the record's ``array()``, w = ω0 − ω1, n the unit normal; body 1 takes the opposite torque). They take n
and dt beside laws/base.py's ``(c, fn_abs, r_eff, rate, history)``: the rolling part of w needs n, the spring
needs dt, and the record holds its own rolling radius. :func:`rolling_torque` calls the one of a record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from .base import SubModel

CAP_SPRING, CAP_TOTAL = 0, 1


@dataclass(frozen=True)
class ConstantTorqueRolling(SubModel):
    slot: ClassVar[str] = "rolling"
    id: ClassVar[str] = "constant_torque"
    title: ClassVar[str] = "constant directional torque (Ai et al. 2011 type A)"
    mu_r: float = 0.0  # coefficient of rolling resistance (Mm = μr Rr |Fn|)
    r_roll: float = 0.0  # rolling radius Rr
    full_direction: bool = False


@dataclass(frozen=True)
class ViscousRolling(SubModel):
    slot: ClassVar[str] = "rolling"
    id: ClassVar[str] = "viscous"
    title: ClassVar[str] = "viscous rolling resistance (Ai et al. 2011 type B)"
    c_r: float = 0.0  # N·m·s/rad


@dataclass(frozen=True)
class EpsdRolling(SubModel):
    slot: ClassVar[str] = "rolling"
    id: ClassVar[str] = "epsd"
    history_size: ClassVar[int] = 3  # the spring torque Mk
    title: ClassVar[str] = "elastic-plastic spring-dashpot rolling resistance (Ai et al. 2011 type C)"
    mu_r: float = 0.0
    r_roll: float = 0.0
    k_r: float = 0.0  # N·m/rad
    c_r: float = 0.0  # N·m·s/rad
    cap: int = CAP_SPRING
    slack_zero: bool = False


def equivalent_inertia(m0: float, r0: float, m1: float = math.inf, r1: float = 1.0) -> float:
    """Ai et al.'s Ir for two solid spheres (1/Ir = 1/(1.4 m0 R0²) + 1/(1.4 m1 R1²)); a wall has m1 = ∞."""
    j0 = 1.4 * m0 * r0 * r0
    j1 = 1.4 * m1 * r1 * r1
    return j0 if math.isinf(j1) else j0 * j1 / (j0 + j1)


def epsd_damping(eta_r: float, i_r: float, k_r: float) -> float:
    """Cr = ηr · 2√(Ir kr) (Ai et al. 2011: ηr is the ratio to the critical damping)."""
    return eta_r * 2.0 * math.sqrt(i_r * k_r)


@njit(cache=KERNEL_CACHE, inline="always")
def _rolling_part(w, n):
    wn = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    return w - wn * n


@njit(cache=KERNEL_CACHE)
def constant_torque_rolling_force(c, w, n, fn_abs, dt, history):
    wt = _rolling_part(w, n)
    d = w if c[2] != 0.0 else wt  # full_direction
    dm = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    if dm == 0.0:
        return np.zeros(3), history
    return (-c[0] * c[1] * fn_abs / dm) * wt, history


@njit(cache=KERNEL_CACHE)
def viscous_rolling_force(c, w, n, fn_abs, dt, history):
    return -c[0] * _rolling_part(w, n), history


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


FORCES = {"constant_torque": constant_torque_rolling_force, "viscous": viscous_rolling_force,
          "epsd": epsd_rolling_force}


def rolling_torque(law, w, n, fn_abs: float, dt: float, history=None):
    """(torque on body 0, new history) of a rolling record (any, or None: no torque)."""
    history = np.zeros(3) if history is None else np.asarray(history, dtype=np.float64)
    if law is None or law.id not in FORCES:
        return np.zeros(3), history
    return FORCES[law.id](law.array(), np.asarray(w, dtype=np.float64), np.asarray(n, dtype=np.float64),
                          float(fn_abs), float(dt), history)
