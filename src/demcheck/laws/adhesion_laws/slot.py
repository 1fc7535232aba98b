"""The adhesion slot's interface: the record every adhesion law is (:class:`AdhesionSubModel`, with the traits
the scenario solvers ask instead of a law's id) and the registry of the laws' compiled force functions
(:data:`KERNELS`).

Sign: F > 0 repels. ``touching`` (0 or 1) is the contact state kept between steps (JKR's hysteresis). A law's
compiled force function is ``<id>_adhesion_force(c, delta, touching) → (F, touching after)``: the whole elastic
normal force for a law that replaces the normal law (``replaces_normal``), the cohesive force to add to the
normal law's for one that does not."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..registry import BeyondSubModel, Kernels

KERNELS = Kernels("adhesion")


@dataclass(frozen=True)
class AdhesionSubModel(BeyondSubModel):
    """An adhesion law's record. Its traits:

    * ``replaces_normal``: it is the whole elastic normal law (JKR, DMT); without it, a cohesion added to an
      elastic normal law while the bodies overlap (sjkr);
    * ``necks``: the contact holds past δ = 0 (a neck) and breaks at a negative overlap, with hysteresis (JKR);
    * :meth:`pull_off_force` (the largest tension under imposed load or displacement),
      :meth:`separation_at_pull_off` (the overlap where it breaks) and :meth:`limit_force` (the force the rolling
      and twisting limits scale with in the engines' scheme)."""

    slot: ClassVar[str] = "adhesion"
    replaces_normal: ClassVar[bool] = False
    necks: ClassVar[bool] = False

    def pull_off_force(self, control: str = "load") -> float:
        return 0.0

    def separation_at_pull_off(self, control: str | None = None) -> float:
        return 0.0

    def limit_force(self, fn: float) -> float:
        """|Fn|: the force the contact's rolling and twisting limits scale with at normal force Fn."""
        return abs(fn)
