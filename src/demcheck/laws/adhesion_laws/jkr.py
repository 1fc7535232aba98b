"""Johnson, Kendall & Roberts (Proc. R. Soc. A 324 (1971) 301-313): with the contact radius a,
δ = a²/R̄ − √(2πwa/E*) and F = 4E*a³/(3R̄) − √(8πwE*a³) (w the work of adhesion, w = 2γ for two like surfaces of
surface energy γ). It replaces the elastic normal law. Hysteresis: the contact forms at δ = 0 (jumping to
F = −(8/9)·(3/2)πwR̄) and breaks at δ_f = −3a_f²/R̄ with a_f³ = πwR̄²/(8E*), where F = −(5/6)πwR̄ (pull-off under
imposed displacement; ``break_at`` = load moves the break to δ_c, as LAMMPS does); under imposed load it breaks at
F = −(3/2)πwR̄, δ_c = −a_c²/(3R̄), a_c³ = 9πwR̄²/(8E*)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import Key, positive
from .slot import KERNELS, AdhesionSubModel

BREAK_DISPLACEMENT, BREAK_LOAD = 0, 1


@dataclass(frozen=True)
class JkrAdhesion(AdhesionSubModel):
    id: ClassVar[str] = "jkr"
    history_size: ClassVar[int] = 1  # the touching flag
    title: ClassVar[str] = "Johnson-Kendall-Roberts adhesive elastic contact"
    scenarios: ClassVar[tuple] = ("pull_off", "adhesive_impact")
    replaces_normal: ClassVar[bool] = True
    necks: ClassVar[bool] = True
    keys: ClassVar[tuple] = (
        Key("w", "work of adhesion (J/m²; 2γ for like surfaces)", "must be > 0 (J/m²)", positive),
        Key("break_at", "where the contact breaks: δ_f (imposed displacement) or δ_c (imposed load, LAMMPS)",
            default="displacement", choices={"displacement": BREAK_DISPLACEMENT, "load": BREAK_LOAD}))
    formula: ClassVar[str] = "δ = a²/R̄ − √(2πwa/E*), F = 4E*a³/(3R̄) − √(8πwE*a³); breaks at δ_f (or δ_c)"
    source: ClassVar[str] = "Johnson, Kendall & Roberts, Proc. R. Soc. A 324 (1971) 301"
    example: ClassVar[dict] = {"w": 0.1}
    r_eff: float = 0.0  # R̄
    e_eff: float = 0.0  # E*
    w: float = 0.0  # work of adhesion (J/m²)
    break_at: int = BREAK_DISPLACEMENT  # the contact breaks at δ_f (imposed displacement) or δ_c (imposed load)

    @property
    def control(self) -> str:
        """Where the record breaks the contact: "load" (δ_c) or "displacement" (δ_f)."""
        return "load" if self.break_at == BREAK_LOAD else "displacement"

    def pull_off_force(self, control: str = "load") -> float:
        return (1.5 if control == "load" else 5.0 / 6.0) * math.pi * self.w * self.r_eff

    def separation_at_pull_off(self, control: str | None = None) -> float:
        """The overlap δ at which the contact breaks (negative: a neck); by default under the record's rule."""
        control = control or self.control
        return jkr_break(self.r_eff, self.e_eff, self.w, BREAK_LOAD if control == "load" else BREAK_DISPLACEMENT)

    def limit_force(self, fn: float) -> float:
        """|Fn + 2·(3/2)πwR̄|: LAMMPS's critical force of a JKR contact."""
        return abs(fn + 2.0 * self.pull_off_force("load"))


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


KERNELS.register(JkrAdhesion, jkr_adhesion_force)
