"""The simplified JKR cohesion (LIGGGHTS ``cohesion sjkr``/``sjkr2``): an extra force −kc·A on top of the normal
law while the bodies overlap, kc a cohesion energy density (J/m³) and A a contact area: ``lens`` the circle where
the two undeformed spheres intersect (π(2Rδ − δ²) on a wall), ``band`` 2πR_x δ with R_x = 2R̄ for a pair and R on
a wall (what sjkr2 uses)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, AdhesionSubModel

AREA_LENS, AREA_BAND = 0, 1


@dataclass(frozen=True)
class SjkrAdhesion(AdhesionSubModel):
    id: ClassVar[str] = "sjkr"
    title: ClassVar[str] = "simplified JKR cohesion (force = energy density × contact area)"
    scenarios: ClassVar[tuple] = ("pull_off",)
    keys: ClassVar[tuple] = (
        Key("k_c", "cohesion energy density (J/m³)", "must be > 0 (J/m³)", positive),
        Key("area", "contact area: lens (sjkr) or band 2πRxδ (sjkr2)", default="lens",
            choices={"lens": AREA_LENS, "band": AREA_BAND}))
    formula: ClassVar[str] = "F = −kc A added to the normal law (A: the spheres' intersection circle, or 2πRxδ)"
    source: ClassVar[str] = "simplified JKR: LIGGGHTS cohesion sjkr / sjkr2"
    example: ClassVar[dict] = {"k_c": 1e5}
    k_c: float = 0.0  # cohesion energy density (J/m³)
    area: int = AREA_LENS
    wall: bool = False
    r0: float = 0.0
    r1: float = 0.0  # unused on a wall (the case sets it 0)


@njit(cache=KERNEL_CACHE)
def lens_area(r0, r1, delta, wall):
    """The circle where two undeformed spheres (or a sphere and a plane) intersect."""
    if wall:
        return math.pi * (2.0 * r0 * delta - delta * delta)
    d = r0 + r1 - delta
    return -0.25 * math.pi * (d - r0 - r1) * (d + r0 - r1) * (d - r0 + r1) * (d + r0 + r1) / (d * d)


@njit(cache=KERNEL_CACHE)
def sjkr_adhesion_force(c, delta, touching):
    k_c, area, wall, r0, r1 = c[0], c[1], c[2], c[3], c[4]
    if delta <= 0.0:
        return 0.0, 0.0
    if area == AREA_BAND:
        rx = r0 if wall != 0.0 else 2.0 * (r0 * r1 / (r0 + r1))
        return -k_c * 2.0 * math.pi * rx * delta, 1.0
    return -k_c * lens_area(r0, r1, delta, wall != 0.0), 1.0


KERNELS.register(SjkrAdhesion, sjkr_adhesion_force)
