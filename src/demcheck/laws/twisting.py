"""Twisting resistance: the slot ``twisting`` (a torque about the normal that opposes relative spin).

* ``sds``: a Coulomb-limited spring–dashpot on the relative twist angle φ (φ̇ = (ω0 − ω1)·n):
  Mt = −ktw φ − γtw φ̇, limited to |Mt| ≤ μtw |Fn|; when the limit is reached the stored angle is reset so that
  spring + dashpot equal the limit (the Maw rule; LAMMPS ``twisting sds``, after Marshall 2009).
* ``marshall``: the same law with its coefficients from the tangential law and the contact radius a
  (Marshall, J. Comput. Phys. 228 (2009) 1541-1561; LAMMPS ``twisting marshall``):
  ktw = ½ kt a², γtw = ½ γt a², μtw = ⅔ a μt.

Each law is one module of ``laws/twisting_laws/`` (its record, case keys, docs row, compiled force function
``<id>_twisting_force(c, w, n, fn_abs, a, dt, phi) → (Mt n on body 0, new φ)`` and its registration;
twisting_laws/slot.py the interface); body 1 takes the opposite; a is the contact radius (used by marshall). μtw
carries a length: μtw |Fn| is a torque. This module is the slot's face: the records and :func:`twisting_torque`.
"""

from __future__ import annotations

import numpy as np

from .twisting_laws.marshall import MarshallTwisting
from .twisting_laws.sds import SdsTwisting
from .twisting_laws.slot import KERNELS, TwistingSubModel

__all__ = ["KERNELS", "MarshallTwisting", "SdsTwisting", "TwistingSubModel", "twisting_torque"]


def twisting_torque(law, w, n, fn_abs: float, a: float, dt: float, phi: float = 0.0):
    """(torque on body 0, new stored angle) of a twisting record (or None: no torque)."""
    force = KERNELS.of(law)
    if force is None:
        return np.zeros(3), phi
    return force(law.array(), np.asarray(w, dtype=np.float64), np.asarray(n, dtype=np.float64),
                 float(fn_abs), float(a), float(dt), float(phi))
