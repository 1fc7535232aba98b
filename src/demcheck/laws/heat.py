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

Compiled functions ``<id>_heat_force(c, delta, dT) → Q`` (W into body 0, dT = T1 − T0), after laws/base.py's
convention (the record holds its radii); :func:`conductance` gives H of a record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from .. import KERNEL_CACHE
from .base import SubModel


@dataclass(frozen=True)
class RadiusHeat(SubModel):
    slot: ClassVar[str] = "heat"
    id: ClassVar[str] = "radius"
    title: ClassVar[str] = "conductance 2 ks a (Batchelor & O'Brien 1977)"
    k: float = 0.0  # ks (W/(m·K))
    r_eff: float = 0.0


@dataclass(frozen=True)
class AreaHeat(SubModel):
    slot: ClassVar[str] = "heat"
    id: ClassVar[str] = "area"
    title: ClassVar[str] = "conductance hs π a²"
    k: float = 0.0  # hs (W/(m²·K))
    r_eff: float = 0.0


@dataclass(frozen=True)
class LensHeat(SubModel):
    slot: ClassVar[str] = "heat"
    id: ClassVar[str] = "lens"
    title: ClassVar[str] = "conductance 2 ks √A over the spheres' intersection circle"
    k: float = 0.0  # ks = 2k0k1/(k0+k1)
    r0: float = 0.0
    r1: float = 0.0
    wall: bool = False


def series_conductivity(k0: float, k1: float) -> float:
    """2k0k1/(k0+k1): the conductivity of two half-spaces in series (k for like materials)."""
    return 2.0 * k0 * k1 / (k0 + k1)


@njit(cache=KERNEL_CACHE)
def lens_area(r0, r1, delta, wall):
    """The circle where two undeformed spheres (or a sphere and a plane) intersect. (adhesion.py has the same
    function: numba's cache keys a kernel by its own file only, so a kernel here does not call one there.)"""
    if wall:
        return math.pi * (2.0 * r0 * delta - delta * delta)
    d = r0 + r1 - delta
    return -0.25 * math.pi * (d - r0 - r1) * (d + r0 - r1) * (d - r0 + r1) * (d + r0 + r1) / (d * d)


@njit(cache=KERNEL_CACHE)
def radius_heat_force(c, delta, d_temp):
    return 2.0 * c[0] * math.sqrt(c[1] * delta) * d_temp if delta > 0.0 else 0.0


@njit(cache=KERNEL_CACHE)
def area_heat_force(c, delta, d_temp):
    return c[0] * math.pi * c[1] * delta * d_temp if delta > 0.0 else 0.0


@njit(cache=KERNEL_CACHE)
def lens_heat_force(c, delta, d_temp):
    return 2.0 * c[0] * math.sqrt(lens_area(c[1], c[2], delta, c[3] != 0.0)) * d_temp if delta > 0.0 else 0.0


FORCES = {"radius": radius_heat_force, "area": area_heat_force, "lens": lens_heat_force}


def heat_flow(law, delta: float, t0: float, t1: float) -> float:
    """Q into body 0 (W) of a heat record (or None: 0)."""
    if law is None or law.id not in FORCES:
        return 0.0
    return FORCES[law.id](law.array(), float(delta), float(t1 - t0))


def conductance(law, delta: float) -> float:
    """H at overlap δ (0 out of contact)."""
    return heat_flow(law, delta, 0.0, 1.0)
