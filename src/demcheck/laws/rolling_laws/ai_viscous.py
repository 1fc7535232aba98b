"""Ai, Chen, Rotter & Ooi (2011)'s model B, the viscous rolling resistance, as the codes that implement the paper
write it (Lethe's ``viscous_rolling_resistance_torque``, Kratos's ``DEMRollingFrictionModelViscousTorque``,
DEMLab's ``RollResist_Viscous``; the paper's own pages past the first are not reachable here):
M = −μr Rr |Fn| |Vω| ŵ, with Vω the relative velocity of the contact point caused by the rotations. μr is then in
s/m (a torque per unit normal force, radius and speed). It is not demcheck's ``viscous`` (M = −Cr w, a fixed
Cr): here the coefficient follows the normal force and the contact speed, Cr = μr Rr R |Fn| on a wall.

Vω on a wall is R ω × n, |Vω| = R |w_t| (every reading above agrees). Between two spheres the readings differ and
neither is a function of the relative spin w = ω0 − ω1 alone: Lethe takes Vω = (R0ω0 + R1ω1) × n (zero when
equal spheres roll on each other, ω0 = −ω1), Kratos R0'ω0 − R1'ω1 (R' = R minus a share of the overlap, no cross
product). The compiled force of the slot (``ai_viscous_rolling_force(c, w, …)``: w only) is the wall's form
|Vω| = R0 |w_t|, and between two spheres |Vω| = ½(R0 + R1) |w_t| (symmetric in the pair, Kratos's reading for
equal spheres; the packing loop's pairs take it); :func:`ai_viscous_pair_torque` is Lethe's reading for a pair, for
a solver that has both spins.
The direction ŵ is that of the rolling part w_t (Lethe and Kratos use all of ω0 − ω1: the same without twist).

A sphere rolling without slip on a level plane under it (|Fn| = m g, Rr = R): (m + I/R²) v̇ = −μr R² m g v/R², so
v = v0 e^{−t/T}, T = 1.4 R²/(μr Rr R0 g) = 1.4/(μr g) — whatever the mass and, for Rr = R0 = R, the radius."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, R_ROLL, RollingSubModel, _rolling_part


@dataclass(frozen=True)
class AiViscousRolling(RollingSubModel):
    id: ClassVar[str] = "ai_viscous"
    title: ClassVar[str] = "viscous rolling resistance as Ai et al. 2011 model B (Lethe, Kratos)"
    decays: ClassVar[bool] = True
    keys: ClassVar[tuple] = (
        Key("mu_r", "coefficient of viscous rolling resistance μr (s/m): M = −μr Rr |Fn| |Vω| ŵ", "must be > 0",
            positive),
        R_ROLL)
    formula: ClassVar[str] = "M = −μr Rr |Fn| |Vω| ŵt, |Vω| = R0 |wt| on a wall, ½(R0 + R1) |wt| between two spheres"
    source: ClassVar[str] = ("Ai, Chen, Rotter & Ooi, Powder Technol. 206 (2011) 269, model B, as Lethe and Kratos "
                             "implement it")
    example: ClassVar[dict] = {"mu_r": 0.3}
    mu_r: float = 0.0  # s/m
    r_roll: float = 0.0  # Rr
    r0: float = 0.0  # body 0's radius: the arm of Vω on a wall (filled from the contact's geometry)
    r1: float = 0.0  # body 1's radius, 0 on a wall: between two spheres the arm is ½(r0 + r1), symmetric in the pair

    def time_constant(self, gravity: float) -> float:
        """T of a sphere of radius r0 rolling without slip on a level plane (|Fn| = m g): 1.4 r0²/(μr Rr r0 g)."""
        return 1.4 * self.r0 / (self.mu_r * self.r_roll * gravity)


@njit(cache=KERNEL_CACHE)
def ai_viscous_rolling_force(c, w, n, fn_abs, dt, history):
    wt = _rolling_part(w, n)  # |Vω| = arm |wt| and ŵt = wt/|wt|: the torque is linear in wt
    arm = c[2] if c[3] == 0.0 else 0.5 * (c[2] + c[3])  # R0 on a wall; ½(R0 + R1) between two spheres
    return (-c[0] * c[1] * arm * fn_abs) * wt, history


@njit(cache=KERNEL_CACHE)
def ai_viscous_pair_torque(c, w0, w1, r0, r1, n, fn_abs):
    """Lethe's reading between two spheres: M = −μr Rr |Fn| |(R0ω0 + R1ω1) × n| ŵ, ŵ along the rolling part of
    ω0 − ω1 (zero without one); the torque on body 0 (body 1 takes the opposite)."""
    wt = _rolling_part(w0 - w1, n)
    wm = math.sqrt(wt[0] * wt[0] + wt[1] * wt[1] + wt[2] * wt[2])
    if wm == 0.0:
        return np.zeros(3)
    s = r0 * w0 + r1 * w1
    v = np.array([s[1] * n[2] - s[2] * n[1], s[2] * n[0] - s[0] * n[2], s[0] * n[1] - s[1] * n[0]])
    vm = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (-c[0] * c[1] * fn_abs * vm / wm) * wt


KERNELS.register(AiViscousRolling, ai_viscous_rolling_force)
