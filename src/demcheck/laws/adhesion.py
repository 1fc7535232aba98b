"""Adhesion: the slot ``adhesion`` (an attractive normal force at a contact).

* ``jkr`` (Johnson, Kendall & Roberts, Proc. R. Soc. A 324 (1971) 301-313): with the contact radius a,
  δ = a²/R̄ − √(2πwa/E*) and F = 4E*a³/(3R̄) − √(8πwE*a³) (w the work of adhesion, w = 2γ for two like surfaces
  of surface energy γ). It replaces the elastic normal law. Hysteresis: the contact forms at δ = 0 (jumping to
  F = −(8/9)·(3/2)πwR̄) and breaks at δ_f = −3a_f²/R̄ with a_f³ = πwR̄²/(8E*), where F = −(5/6)πwR̄ (pull-off under
  imposed displacement; ``break_at`` = load moves the break to δ_c, as LAMMPS does); under imposed load it
  breaks at F = −(3/2)πwR̄, δ_c = −a_c²/(3R̄), a_c³ = 9πwR̄²/(8E*).
* ``dmt`` (Derjaguin, Muller & Toporov, J. Colloid Interface Sci. 53 (1975) 314-326): F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄
  while δ ≥ 0; pull-off 2πwR̄ at δ = 0, no hysteresis. It replaces the elastic normal law.
* ``sjkr`` (simplified JKR cohesion, LIGGGHTS ``cohesion sjkr``/``sjkr2``): an extra force −kc·A on top of the
  normal law while the bodies overlap, kc a cohesion energy density (J/m³) and A a contact area: ``lens`` the
  circle where the two undeformed spheres intersect (π(2Rδ − δ²) on a wall), ``band`` 2πR_x δ with R_x = 2R̄ for a
  pair and R on a wall (what sjkr2 uses).
Thornton & Ning (Powder Technol. 99 (1998) 154-162) give the adhesive impact of elastic JKR spheres: capture below
v_s (the energy of the hysteresis loop) and e = √(1 − (v_s/v)²) above (reference/beyond.py).

Sign: F > 0 repels. ``touching`` (0 or 1) is the contact state kept between steps (JKR's hysteresis).
Compiled force functions ``<id>_adhesion_force(c, delta, touching) → (F, touching after)``: for jkr and dmt the
whole elastic normal force (they replace the normal law: ``replaces_normal``), for sjkr the cohesive force to add
to the normal law's. :func:`adhesive_force` calls the one of a record.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from .. import KERNEL_CACHE
from .base import SubModel

AREA_LENS, AREA_BAND = 0, 1
BREAK_DISPLACEMENT, BREAK_LOAD = 0, 1


@dataclass(frozen=True)
class JkrAdhesion(SubModel):
    slot: ClassVar[str] = "adhesion"
    id: ClassVar[str] = "jkr"
    history_size: ClassVar[int] = 1  # the touching flag
    title: ClassVar[str] = "Johnson-Kendall-Roberts adhesive elastic contact"
    replaces_normal: ClassVar[bool] = True
    r_eff: float = 0.0  # R̄
    e_eff: float = 0.0  # E*
    w: float = 0.0  # work of adhesion (J/m²)
    break_at: int = BREAK_DISPLACEMENT  # the contact breaks at δ_f (imposed displacement) or δ_c (imposed load)

    def pull_off_force(self, control: str = "load") -> float:
        return (1.5 if control == "load" else 5.0 / 6.0) * math.pi * self.w * self.r_eff

    def separation_at_pull_off(self, control: str | None = None) -> float:
        """The overlap δ at which the contact breaks (negative: a neck); by default under the record's rule."""
        control = control or ("load" if self.break_at == BREAK_LOAD else "displacement")
        return jkr_break(self.r_eff, self.e_eff, self.w, BREAK_LOAD if control == "load" else BREAK_DISPLACEMENT)


@dataclass(frozen=True)
class DmtAdhesion(SubModel):
    slot: ClassVar[str] = "adhesion"
    id: ClassVar[str] = "dmt"
    title: ClassVar[str] = "Derjaguin-Muller-Toporov adhesive elastic contact"
    replaces_normal: ClassVar[bool] = True
    r_eff: float = 0.0
    e_eff: float = 0.0
    w: float = 0.0

    def pull_off_force(self, control: str = "load") -> float:
        return 2.0 * math.pi * self.w * self.r_eff

    def separation_at_pull_off(self, control: str | None = None) -> float:
        return 0.0


@dataclass(frozen=True)
class SjkrAdhesion(SubModel):
    slot: ClassVar[str] = "adhesion"
    id: ClassVar[str] = "sjkr"
    title: ClassVar[str] = "simplified JKR cohesion (force = energy density × contact area)"
    replaces_normal: ClassVar[bool] = False
    k_c: float = 0.0  # cohesion energy density (J/m³)
    area: int = AREA_LENS
    wall: bool = False
    r0: float = 0.0
    r1: float = 0.0  # unused on a wall

    def pull_off_force(self, control: str = "load") -> float:
        return 0.0

    def separation_at_pull_off(self, control: str | None = None) -> float:
        return 0.0


@njit(cache=KERNEL_CACHE)
def jkr_radius(delta, r, e, w):
    """The contact radius a on JKR's stable branch at overlap δ (the largest root of a²/R − √(2πwa/E*) = δ)."""
    c = math.sqrt(2.0 * math.pi * w / e)
    s = (2.0 * c * r) ** (1.0 / 3.0) + (2.0 * r * abs(delta)) ** 0.25  # s = √a, right of the largest root
    for _ in range(200):
        f = s ** 4 / r - c * s - delta
        step = f / (4.0 * s ** 3 / r - c)
        s -= step
        if abs(step) <= 1e-16 * s:
            break
    return s * s


@njit(cache=KERNEL_CACHE)
def jkr_break(r, e, w, rule):
    """The overlap below which a JKR contact breaks: δ_f = −3a_f²/R̄ (imposed displacement, a_f³ = πwR̄²/(8E*)),
    or δ_c = −a_c²/(3R̄) (imposed load, a_c³ = 9πwR̄²/(8E*); LAMMPS's pull-off distance)."""
    if rule == BREAK_LOAD:
        ac = (9.0 * math.pi * w * r * r / (8.0 * e)) ** (1.0 / 3.0)
        return -ac * ac / (3.0 * r)
    af = (math.pi * w * r * r / (8.0 * e)) ** (1.0 / 3.0)
    return -3.0 * af * af / r


@njit(cache=KERNEL_CACHE)
def jkr_adhesion_force(c, delta, touching):
    r, e, w = c[0], c[1], c[2]
    if not (delta >= 0.0 or (touching != 0.0 and delta >= jkr_break(r, e, w, c[3]))):
        return 0.0, 0.0
    a = jkr_radius(delta, r, e, w)
    return 4.0 * e * a ** 3 / (3.0 * r) - math.sqrt(8.0 * math.pi * w * e * a ** 3), 1.0


@njit(cache=KERNEL_CACHE)
def dmt_adhesion_force(c, delta, touching):
    if delta < 0.0:
        return 0.0, 0.0
    r, e, w = c[0], c[1], c[2]
    return 4.0 / 3.0 * e * math.sqrt(r) * delta ** 1.5 - 2.0 * math.pi * w * r, 1.0


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


FORCES = {"jkr": jkr_adhesion_force, "dmt": dmt_adhesion_force, "sjkr": sjkr_adhesion_force}


def adhesive_force(law, delta: float, touching: float = 0.0) -> tuple[float, float]:
    """(F, touching after) of an adhesion record (or None: no force)."""
    if law is None or law.id not in FORCES:
        return 0.0, 0.0
    return FORCES[law.id](law.array(), float(delta), float(touching))
