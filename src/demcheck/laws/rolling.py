"""Rolling resistance: the slot ``rolling`` (a torque that opposes the relative rolling of two bodies).

Types after Ai, Chen, Rotter & Ooi, "Assessment of rolling resistance models in discrete element simulations",
Powder Technology 206 (2011) 269-282:

* ``constant_torque`` (type A, "constant directional torque"): M = −μr Rr |Fn| ŵ, with w the rolling part of the
  relative angular velocity (ω0 − ω1 minus its component along the normal n). Zero when w = 0. With
  ``full_direction`` the direction is taken from all of ω0 − ω1 and its normal part removed afterwards (what
  LIGGGHTS's ``cdt`` does: a twisting spin then lowers the torque).
* ``viscous`` (type B): M = −Cr w, a torque proportional to the relative rolling velocity (Cr in N·m·s).
* ``epsd`` (type C, elastic–plastic spring–dashpot, Iwashita & Oda 1998 as written by Ai et al.): a spring torque
  Mk updated incrementally, Mk ← Mk − kr w dt, limited to the full-mobilisation torque Mm = μr Rr |Fn|; a dashpot
  Md = −f Cr w with Cr = ηr·2√(Ir kr). Ai et al. take f = 0 once the spring is fully mobilised (``cap`` = 0,
  spring), LAMMPS's ``rolling sds`` caps the sum of spring and dashpot (``cap`` = 1, total: Mk is reset so that
  |Mk − Cr w| = Mm, the Maw rule of its tangential model; with ``slack_zero`` the torque is zero when the sum is
  over the limit while the spring is unstretched, as LAMMPS does at its set-up step). ηr = 0 is the type C model
  without its viscous part.
* ``ai_viscous`` (Ai's model B as Lethe and Kratos write it): M = −μr Rr |Fn| |Vω| ŵ, Vω the contact point's
  relative velocity from the rotations (μr in s/m; on a wall |Vω| = R |w_t|, a Cr = μr Rr R |Fn| that follows the
  load); ``ai_epsd`` (Ai's model C as LIGGGHTS epsd and Lethe write it): ``epsd`` with kr = ε kn μr² Rr²,
  Cr = ηr·2√(Ir kr) and the dashpot scaled by f at full mobilisation.

Rr is the rolling radius (R̄ = R0R1/(R0+R1) for a pair, R for a sphere on a wall); Ir the equivalent moment of
inertia of Ai et al., 1/Ir = 1/(I0 + m0R0²) + 1/(I1 + m1R1²) (= 1.4 m R² for a solid sphere on a wall).

Each law is one module of ``laws/rolling_laws/`` (its record with its traits, case keys and docs row, its compiled
force function ``<id>_rolling_force(c, w, n, fn_abs, dt, history) → (torque on body 0, new history)`` and its
registration; rolling_laws/slot.py the interface). The functions take n and dt beside laws/base.py's
``(c, fn_abs, r_eff, rate, history)``: the rolling part of w needs n, the spring needs dt, and the record holds its
own rolling radius. This module is the slot's face: the records and :func:`rolling_torque`, which calls the one
of a record.
"""

from __future__ import annotations

import math

import numpy as np

from .rolling_laws.ai_epsd import AiEpsdRolling
from .rolling_laws.ai_viscous import AiViscousRolling, ai_viscous_pair_torque
from .rolling_laws.constant_torque import ConstantTorqueRolling
from .rolling_laws.epsd import CAP_SPRING, CAP_TOTAL, EpsdRolling
from .rolling_laws.slot import KERNELS, RollingSubModel
from .rolling_laws.viscous import ViscousRolling

__all__ = ["AiEpsdRolling", "AiViscousRolling", "CAP_SPRING", "CAP_TOTAL", "ConstantTorqueRolling", "EpsdRolling",
           "KERNELS", "RollingSubModel", "ViscousRolling", "ai_rolling_stiffness", "ai_viscous_pair_torque",
           "epsd_damping", "equivalent_inertia", "rolling_torque"]


def equivalent_inertia(m0: float, r0: float, m1: float = math.inf, r1: float = 1.0) -> float:
    """Ai et al.'s Ir for two solid spheres (1/Ir = 1/(1.4 m0 R0²) + 1/(1.4 m1 R1²)); a wall has m1 = ∞."""
    j0 = 1.4 * m0 * r0 * r0
    j1 = 1.4 * m1 * r1 * r1
    return j0 if math.isinf(j1) else j0 * j1 / (j0 + j1)


def ai_rolling_stiffness(k_n: float, mu_r: float, r_roll: float, ratio: float = 2.25) -> float:
    """Ai et al.'s rolling stiffness kr = ε kn μr² Rr² (ε = 2.25 in 3D; Lethe's 2D runs take 3)."""
    return ratio * k_n * (mu_r * r_roll) ** 2


def epsd_damping(eta_r: float, i_r: float, k_r: float) -> float:
    """Cr = ηr · 2√(Ir kr) (Ai et al. 2011: ηr is the ratio to the critical damping)."""
    return eta_r * 2.0 * math.sqrt(i_r * k_r)


def rolling_torque(law, w, n, fn_abs: float, dt: float, history=None):
    """(torque on body 0, new history) of a rolling record (any, or None: no torque)."""
    history = np.zeros(3) if history is None else np.asarray(history, dtype=np.float64)
    force = KERNELS.of(law)
    if force is None:
        return np.zeros(3), history
    return force(law.array(), np.asarray(w, dtype=np.float64), np.asarray(n, dtype=np.float64),
                 float(fn_abs), float(dt), history)
