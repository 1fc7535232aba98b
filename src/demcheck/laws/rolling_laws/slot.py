"""The rolling slot's interface: the record every rolling law is (:class:`RollingSubModel`, with the traits the
scenario solvers ask instead of a law's id), the registry of the laws' compiled force functions
(:data:`KERNELS`) and what the laws share (their case keys μr, Rr, Cr; the rolling part of a spin).

A law's compiled force function is ``<id>_rolling_force(c, w, n, fn_abs, dt, history) → (torque on body 0, new
history)`` (c the record's ``array()``, w = ω0 − ω1, n the unit normal; body 1 takes the opposite torque)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import BeyondSubModel, Kernels, Key, positive

KERNELS = Kernels("rolling")

MU_R = Key("mu_r", "coefficient of rolling resistance (limit torque μr Rr |Fn|)")
R_ROLL = Key("r_roll", "rolling radius Rr (m; default R̄, the sphere's radius on a wall)", "must be > 0 (m)", positive,
             from_pair=True)
C_R = Key("c_r", "rolling damping coefficient Cr (N·m·s/rad)", default=0.0)


@dataclass(frozen=True)
class RollingSubModel(BeyondSubModel):
    """A rolling law's record. Its traits (what the scenario solvers and the engines' layouts ask):

    * ``stops``: a sphere rolling on a level plane under it stops in finite time (type A: the stop event);
    * ``decays``: it never stops, its speed decays as e^{−t/T} (type B: the scenario measures T);
    * ``spring``: it keeps a spring torque Mk (its history), integrated and held at its limit (type C);
    * ``kn_column``: the place in its ``array()`` of the contact's normal stiffness kn, which a solver that has it
      per contact and step writes there before calling the force (the packing loop: the normal spring's secant
      stiffness F_spring/δ); -1: the law reads no kn;
    * ``ir_column``: the place of Ai's equivalent inertia Ir (1/Ir = 1/(I0 + m0R0²) + 1/(I1 + m1R1²), a sphere's
      I + mR² = 1.4 m R², on a wall 1.4 m R²), which a solver that knows the bodies' masses writes there per pair
      (the packing loop's table); -1: none.

    A solver that supplies ``kn_column``'s or ``ir_column``'s number supplies it for every contact: a case running
    there may not set it (the packing loop refuses it, packing_rolling.rolling_laws); elsewhere it is the law's
    case key as any other."""

    slot: ClassVar[str] = "rolling"
    stops: ClassVar[bool] = False
    decays: ClassVar[bool] = False
    spring: ClassVar[bool] = False
    kn_column: ClassVar[int] = -1
    ir_column: ClassVar[int] = -1


@njit(cache=KERNEL_CACHE, inline="always")
def _rolling_part(w, n):
    wn = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    return w - wn * n
