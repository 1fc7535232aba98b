"""The heat slot's interface: the record every conduction law is (:class:`HeatSubModel`) and the registry of the
laws' compiled functions (:data:`KERNELS`): ``<id>_heat_force(c, delta, dT) → Q`` (W into body 0, dT = T1 − T0;
the record holds its radii)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..registry import BeyondSubModel, Kernels

KERNELS = Kernels("heat")


@dataclass(frozen=True)
class HeatSubModel(BeyondSubModel):
    """A conduction law's record: its conductance H(δ) is the heat flow at dT = 1 K (laws/heat.conductance). Its
    trait ``conductivity``: its coefficient ``k`` is a conductivity ks (W/(m·K)), as an engine that takes a
    material's conductivity needs (without it, e.g. a conductance per contact area)."""

    slot: ClassVar[str] = "heat"
    conductivity: ClassVar[bool] = False
