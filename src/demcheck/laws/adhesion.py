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

Sign: F > 0 repels. ``touching`` is the contact state kept between steps (JKR's hysteresis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import KERNEL_CACHE

NONE, JKR, DMT, SJKR = 0, 1, 2, 3
FAMILIES = {"none": NONE, "jkr": JKR, "dmt": DMT, "sjkr": SJKR}
AREA_LENS, AREA_BAND = 0, 1
BREAK_DISPLACEMENT, BREAK_LOAD = 0, 1
AD_FAMILY, AD_R, AD_E, AD_W, AD_KC, AD_AREA, AD_WALL, AD_R0, AD_R1, AD_BREAK = range(10)
AD_SIZE = 10


@dataclass(frozen=True)
class AdhesionLaw:
    id: str = "none"
    r_eff: float = 0.0  # R̄
    e_eff: float = 0.0  # E*
    w: float = 0.0  # work of adhesion (J/m²), jkr and dmt
    k_c: float = 0.0  # cohesion energy density (J/m³), sjkr
    area: int = AREA_LENS  # sjkr's contact area rule
    wall: bool = False
    r0: float = 0.0
    r1: float = 0.0
    break_at: int = BREAK_DISPLACEMENT  # jkr: the contact breaks at δ_f (imposed displacement) or δ_c (imposed load)

    slot = "adhesion"
    params = ("r_eff", "e_eff", "w", "k_c", "area", "wall", "r0", "r1", "break_at")

    @property
    def history_size(self) -> int:
        return 1 if self.id == "jkr" else 0  # the touching flag

    @property
    def replaces_normal(self) -> bool:
        return self.id in ("jkr", "dmt")

    def array(self) -> np.ndarray:
        return np.array([FAMILIES[self.id], self.r_eff, self.e_eff, self.w, self.k_c, self.area,
                         float(self.wall), self.r0, self.r1, self.break_at])

    @classmethod
    def from_array(cls, a) -> "AdhesionLaw":
        ids = {v: k for k, v in FAMILIES.items()}
        return cls(ids[int(a[AD_FAMILY])], *(float(x) for x in a[AD_R:AD_AREA]), int(a[AD_AREA]), bool(a[AD_WALL]),
                   float(a[AD_R0]), float(a[AD_R1]), int(a[AD_BREAK]))

    # closed forms of the law (pull-off)
    def pull_off_force(self, control: str = "load") -> float:
        if self.id == "jkr":
            return (1.5 if control == "load" else 5.0 / 6.0) * math.pi * self.w * self.r_eff
        if self.id == "dmt":
            return 2.0 * math.pi * self.w * self.r_eff
        return 0.0

    def separation_at_pull_off(self, control: str = "load") -> float:
        """The overlap δ at which the contact breaks (negative: a neck)."""
        if self.id != "jkr":
            return 0.0
        if control == "load":
            ac = (9.0 * math.pi * self.w * self.r_eff ** 2 / (8.0 * self.e_eff)) ** (1.0 / 3.0)
            return -ac * ac / (3.0 * self.r_eff)
        af = (math.pi * self.w * self.r_eff ** 2 / (8.0 * self.e_eff)) ** (1.0 / 3.0)
        return -3.0 * af * af / self.r_eff


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
def contact_area(p, delta):
    if p[AD_AREA] == AREA_BAND:
        rx = p[AD_R0] if p[AD_WALL] != 0.0 else 2.0 * p[AD_R]
        return 2.0 * math.pi * rx * delta
    r0 = p[AD_R0]
    if p[AD_WALL] != 0.0:
        return math.pi * (2.0 * r0 * delta - delta * delta)
    r1 = p[AD_R1]
    d = r0 + r1 - delta
    return -0.25 * math.pi * (d - r0 - r1) * (d + r0 - r1) * (d - r0 + r1) * (d + r0 + r1) / (d * d)


@njit(cache=KERNEL_CACHE)
def adhesive_force(p, delta, touching):
    """(F, touching after this evaluation): for jkr and dmt the whole elastic normal force, for sjkr the cohesive
    force to add to the normal law's. ``touching`` (0 or 1) is the state before; JKR keeps a contact to δ_f."""
    family = p[AD_FAMILY]
    r, e, w = p[AD_R], p[AD_E], p[AD_W]
    if family == JKR:
        now = delta >= 0.0 or (touching != 0.0 and delta >= jkr_break(r, e, w, p[AD_BREAK]))
        if not now:
            return 0.0, 0.0
        a = jkr_radius(delta, r, e, w)
        return 4.0 * e * a ** 3 / (3.0 * r) - math.sqrt(8.0 * math.pi * w * e * a ** 3), 1.0
    if family == DMT:
        if delta < 0.0:
            return 0.0, 0.0
        return 4.0 / 3.0 * e * math.sqrt(r) * delta ** 1.5 - 2.0 * math.pi * w * r, 1.0
    if family == SJKR:
        if delta <= 0.0:
            return 0.0, 0.0
        return -p[AD_KC] * contact_area(p, delta), 1.0
    return 0.0, 0.0
