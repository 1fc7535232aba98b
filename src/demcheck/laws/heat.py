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

Each law is one module of ``laws/heat_laws/`` (its record, case keys, docs row, compiled function
``<id>_heat_force(c, delta, dT) → Q`` (W into body 0, dT = T1 − T0; the record holds its radii) and its
registration; heat_laws/slot.py the interface). This module is the slot's face: the records, :func:`heat_flow`
and :func:`conductance` (H of a record).
"""

from __future__ import annotations

from .heat_laws.area import AreaHeat
from .heat_laws.lens import LensHeat, lens_area
from .heat_laws.radius import RadiusHeat
from .heat_laws.slot import KERNELS, HeatSubModel

__all__ = ["AreaHeat", "HeatSubModel", "KERNELS", "LensHeat", "RadiusHeat", "conductance", "heat_flow", "lens_area",
           "series_conductivity"]


def series_conductivity(k0: float, k1: float) -> float:
    """2k0k1/(k0+k1): the conductivity of two half-spaces in series (k for like materials)."""
    return 2.0 * k0 * k1 / (k0 + k1)


def heat_flow(law, delta: float, t0: float, t1: float) -> float:
    """Q into body 0 (W) of a heat record (or None: 0)."""
    force = KERNELS.of(law)
    if force is None:
        return 0.0
    return force(law.array(), float(delta), float(t1 - t0))


def conductance(law, delta: float) -> float:
    """H at overlap δ (0 out of contact)."""
    return heat_flow(law, delta, 0.0, 1.0)
