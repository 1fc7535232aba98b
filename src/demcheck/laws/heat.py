"""Heat conduction between bodies in contact: the slot ``heat`` (a conductance H; the heat flow into body 0 is
Q = H (T1 − T0)).

* ``radius`` (Batchelor & O'Brien, Proc. R. Soc. A 355 (1977) 313-333, for a contact much more conductive than
  the gap): H = 2 ks a with a the contact radius, ks = 2k0k1/(k0+k1) for two materials (LAMMPS ``heat radius ks``).
* ``area``: H = hs·A with A = πa² the contact area and hs a contact conductance per area (LAMMPS ``heat area hs``).
* ``lens``: H = 4·k0k1/(k0+k1)·√A with A the circle where the undeformed spheres intersect (LIGGGHTS
  ``fix heat/gran/conduction`` with its default ``contact_area overlap``). For like spheres and small δ this is
  √(2π) ≈ 2.51 times Batchelor & O'Brien's 2ka at the Hertz radius.

a is the Hertz contact radius √(R̄δ) unless stated. Two bodies at fixed contact relax as
T1 − T0 ∝ exp(−t/τ), τ = 1/(H (1/C0 + 1/C1)), C = m c_p (reference/beyond.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import KERNEL_CACHE

NONE, RADIUS, AREA, LENS = 0, 1, 2, 3
FAMILIES = {"none": NONE, "radius": RADIUS, "area": AREA, "lens": LENS}
HT_FAMILY, HT_K, HT_R, HT_R0, HT_R1, HT_WALL = range(6)
HT_SIZE = 6


@dataclass(frozen=True)
class HeatLaw:
    id: str = "none"
    k: float = 0.0  # ks (W/(m·K)) for radius, hs (W/(m²·K)) for area, 2k0k1/(k0+k1) for lens
    r_eff: float = 0.0
    r0: float = 0.0
    r1: float = 0.0
    wall: bool = False

    slot = "heat"
    params = ("k", "r_eff", "r0", "r1", "wall")
    history_size = 0

    def array(self) -> np.ndarray:
        return np.array([FAMILIES[self.id], self.k, self.r_eff, self.r0, self.r1, float(self.wall)])

    @classmethod
    def from_array(cls, a) -> "HeatLaw":
        ids = {v: k for k, v in FAMILIES.items()}
        return cls(ids[int(a[HT_FAMILY])], float(a[HT_K]), float(a[HT_R]), float(a[HT_R0]), float(a[HT_R1]),
                   bool(a[HT_WALL]))


def series_conductivity(k0: float, k1: float) -> float:
    """2k0k1/(k0+k1): the conductivity of two half-spaces in series (k for like materials)."""
    return 2.0 * k0 * k1 / (k0 + k1)


@njit(cache=KERNEL_CACHE)
def conductance(p, delta):
    """H at overlap δ (0 out of contact)."""
    if delta <= 0.0:
        return 0.0
    family = p[HT_FAMILY]
    if family == RADIUS:
        return 2.0 * p[HT_K] * math.sqrt(p[HT_R] * delta)
    if family == AREA:
        return p[HT_K] * math.pi * p[HT_R] * delta
    if family == LENS:
        r0 = p[HT_R0]
        if p[HT_WALL] != 0.0:
            area = math.pi * (2.0 * r0 * delta - delta * delta)
        else:
            r1 = p[HT_R1]
            d = r0 + r1 - delta
            area = -0.25 * math.pi * (d - r0 - r1) * (d + r0 - r1) * (d - r0 + r1) * (d + r0 + r1) / (d * d)
        return 2.0 * p[HT_K] * math.sqrt(area)
    return 0.0


@njit(cache=KERNEL_CACHE)
def heat_flow(p, delta, t0, t1):
    """Q into body 0 (W)."""
    return conductance(p, delta) * (t1 - t0)
