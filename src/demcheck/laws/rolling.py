"""Rolling resistance: the slot ``rolling`` (a torque that opposes the relative rolling of two bodies).

Types after Ai, Chen, Rotter & Ooi, "Assessment of rolling resistance models in discrete element simulations",
Powder Technology 206 (2011) 269-282:

* ``constant_torque`` (type A, "constant directional torque"): M = −μr Rr |Fn| ŵ, with w the rolling part of the
  relative angular velocity (ω0 − ω1 minus its component along the normal n). Zero when w = 0.
* ``viscous`` (type B): M = −Cr w, a torque proportional to the relative rolling velocity (Cr in N·m·s).
* ``epsd`` (type C, elastic–plastic spring–dashpot, Iwashita & Oda 1998 as written by Ai et al.): a spring torque
  Mk updated incrementally, Mk ← Mk − kr w dt, limited to the full-mobilisation torque Mm = μr Rr |Fn|; a dashpot
  Md = −f Cr w with Cr = ηr·2√(Ir kr). Ai et al. take f = 0 once the spring is fully mobilised (``cap`` = ``spring``),
  LAMMPS's ``rolling sds`` caps the sum of spring and dashpot (``cap`` = ``total``: Mk is reset so that
  |Mk − Cr w| = Mm, the Maw rule of its tangential model; with ``slack_zero`` the torque is zero when the sum is
  over the limit while the spring is unstretched, as LAMMPS does at its setup step). ηr = 0 is the type C model
  without its viscous part.

Rr is the rolling radius (R̄ = R0R1/(R0+R1) for a pair, R for a sphere on a wall); Ir the equivalent moment of
inertia of Ai et al., 1/Ir = 1/(I0 + m0R0²) + 1/(I1 + m1R1²) (= 1.4 m R² for a solid sphere on a wall).
The torque returned acts on body 0; body 1 takes its opposite. The history is the spring torque Mk (3 values).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import KERNEL_CACHE

NONE, CONSTANT_TORQUE, VISCOUS, EPSD = 0, 1, 2, 3
FAMILIES = {"none": NONE, "constant_torque": CONSTANT_TORQUE, "viscous": VISCOUS, "epsd": EPSD}
CAP_SPRING, CAP_TOTAL = 0, 1
# layout of RollingLaw.array()
RL_FAMILY, RL_MU, RL_R, RL_K, RL_C, RL_CAP, RL_FULL_DIRECTION, RL_SLACK_ZERO = range(8)
RL_SIZE = 8


@dataclass(frozen=True)
class RollingLaw:
    """One rolling-resistance law at one contact (the numbers its force function needs)."""

    id: str = "none"
    mu_r: float = 0.0  # coefficient of rolling resistance (dimensionless: Mm = μr Rr |Fn|)
    r_roll: float = 0.0  # rolling radius Rr
    k_r: float = 0.0  # rolling stiffness (N·m/rad), type C
    c_r: float = 0.0  # rolling viscous coefficient (N·m·s/rad), types B and C
    cap: int = CAP_SPRING  # type C: what the full-mobilisation torque limits (spring only, or spring + dashpot)
    full_direction: bool = False  # type A: direction from all of ω0 − ω1, its normal part removed afterwards
    slack_zero: bool = False  # type C, cap total: over the limit with an unstretched spring (Mk = 0), no torque

    slot = "rolling"
    params = ("mu_r", "r_roll", "k_r", "c_r", "cap", "full_direction", "slack_zero")

    @property
    def history_size(self) -> int:
        return 3 if self.id == "epsd" else 0

    def array(self) -> np.ndarray:
        return np.array([FAMILIES[self.id], self.mu_r, self.r_roll, self.k_r, self.c_r, self.cap,
                         float(self.full_direction), float(self.slack_zero)])

    @classmethod
    def from_array(cls, a) -> "RollingLaw":
        ids = {v: k for k, v in FAMILIES.items()}
        return cls(ids[int(a[RL_FAMILY])], float(a[RL_MU]), float(a[RL_R]), float(a[RL_K]), float(a[RL_C]),
                   int(a[RL_CAP]), bool(a[RL_FULL_DIRECTION]), bool(a[RL_SLACK_ZERO]))


def equivalent_inertia(m0: float, r0: float, m1: float = math.inf, r1: float = 1.0) -> float:
    """Ai et al.'s Ir for two solid spheres (1/Ir = 1/(1.4 m0 R0²) + 1/(1.4 m1 R1²)); a wall has m1 = ∞."""
    j0 = 1.4 * m0 * r0 * r0
    j1 = 1.4 * m1 * r1 * r1
    return j0 if math.isinf(j1) else j0 * j1 / (j0 + j1)


def epsd_damping(eta_r: float, i_r: float, k_r: float) -> float:
    """Cr = ηr · 2√(Ir kr) (Ai et al. 2011: ηr is the ratio to the critical damping)."""
    return eta_r * 2.0 * math.sqrt(i_r * k_r)


@njit(cache=KERNEL_CACHE)
def rolling_torque(p, w, n, fn_abs, dt, hist):
    """(M on body 0, new spring torque) for the relative angular velocity w = ω0 − ω1 and the unit normal n.

    ``hist`` is the spring torque Mk before this step (type C; ignored otherwise); |Fn| sets the limit."""
    family = p[RL_FAMILY]
    wn = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    wt = w - wn * n
    out = np.zeros(3)
    new = hist.copy()
    cap = p[RL_MU] * p[RL_R] * fn_abs
    if family == CONSTANT_TORQUE:
        if p[RL_FULL_DIRECTION] != 0.0:
            wm = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
            return (-cap / wm) * wt if wm > 0.0 else out, new
        wm = math.sqrt(wt[0] * wt[0] + wt[1] * wt[1] + wt[2] * wt[2])
        return (-cap / wm) * wt if wm > 0.0 else out, new
    if family == VISCOUS:
        return -p[RL_C] * wt, new
    if family == EPSD:
        spring = hist - (p[RL_K] * dt) * wt
        damp = -p[RL_C] * wt
        if p[RL_CAP] == CAP_TOTAL:
            total = spring + damp
            mag = math.sqrt(total[0] ** 2 + total[1] ** 2 + total[2] ** 2)
            if mag > cap:
                if p[RL_SLACK_ZERO] != 0.0 and not (spring[0] != 0.0 or spring[1] != 0.0 or spring[2] != 0.0):
                    return out, spring  # the engine's rule: no stored rolling, no torque (seen at its setup step)
                total = total * (cap / mag)
                spring = total - damp
            return total, spring
        mag = math.sqrt(spring[0] ** 2 + spring[1] ** 2 + spring[2] ** 2)
        if mag > cap:  # full mobilisation: the spring saturates, the dashpot is off (Ai et al.'s f = 0)
            spring = spring * (cap / mag)
            return spring, spring
        return spring + damp, spring
    return out, new
