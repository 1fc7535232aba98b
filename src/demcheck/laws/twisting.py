"""Twisting resistance: the slot ``twisting`` (a torque about the normal that opposes relative spin).

* ``sds``: a Coulomb-limited spring–dashpot on the relative twist angle φ (φ̇ = (ω0 − ω1)·n):
  Mt = −ktw φ − γtw φ̇, limited to |Mt| ≤ μtw |Fn|; when the limit is reached the stored angle is reset so that
  spring + dashpot equal the limit (the Maw rule; LAMMPS ``twisting sds``, after Marshall 2009).
* ``marshall``: the same law with its coefficients from the tangential law and the contact radius a
  (Marshall, J. Comput. Phys. 228 (2009) 1541-1561; LAMMPS ``twisting marshall``):
  ktw = ½ kt a², γtw = ½ γt a², μtw = ⅔ a μt.

The torque returned (a vector, Mt n) acts on body 0; body 1 takes its opposite. The history is φ (1 value).
μtw carries a length: Mt is a torque, μtw |Fn| its limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import KERNEL_CACHE

NONE, SDS = 0, 1
FAMILIES = {"none": NONE, "sds": SDS, "marshall": SDS}
TW_FAMILY, TW_K, TW_GAMMA, TW_MU = range(4)
TW_SIZE = 4


@dataclass(frozen=True)
class TwistingLaw:
    id: str = "none"
    k_tw: float = 0.0  # N·m/rad
    gamma_tw: float = 0.0  # N·m·s/rad
    mu_tw: float = 0.0  # m (limit torque per unit normal force)

    slot = "twisting"
    params = ("k_tw", "gamma_tw", "mu_tw")

    @property
    def history_size(self) -> int:
        return 0 if self.id == "none" else 1

    def array(self) -> np.ndarray:
        return np.array([FAMILIES[self.id], self.k_tw, self.gamma_tw, self.mu_tw])

    @classmethod
    def from_array(cls, a) -> "TwistingLaw":
        return cls("sds" if a[TW_FAMILY] == SDS else "none", float(a[TW_K]), float(a[TW_GAMMA]), float(a[TW_MU]))


def marshall(kt: float, gamma_t: float, mu_t: float, a: float) -> TwistingLaw:
    """Marshall's coefficients at contact radius a from the tangential stiffness, damping and friction."""
    return TwistingLaw("marshall", 0.5 * kt * a * a, 0.5 * gamma_t * a * a, 2.0 / 3.0 * a * mu_t)


@njit(cache=KERNEL_CACHE)
def twisting_torque(p, w, n, fn_abs, dt, phi):
    """(Mt n on body 0, new stored twist angle) for w = ω0 − ω1; φ is the stored angle before this step."""
    if p[TW_FAMILY] != SDS:
        return np.zeros(3), phi
    rate = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    phi = phi + rate * dt
    m = -p[TW_K] * phi - p[TW_GAMMA] * rate
    cap = p[TW_MU] * fn_abs
    if abs(m) > cap:
        m = math.copysign(cap, m)
        phi = -(m + p[TW_GAMMA] * rate) / p[TW_K] if p[TW_K] > 0.0 else phi
    return m * n, phi
