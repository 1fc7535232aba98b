"""Twisting resistance: the slot ``twisting`` (a torque about the normal that opposes relative spin).

* ``sds``: a Coulomb-limited spring–dashpot on the relative twist angle φ (φ̇ = (ω0 − ω1)·n):
  Mt = −ktw φ − γtw φ̇, limited to |Mt| ≤ μtw |Fn|; when the limit is reached the stored angle is reset so that
  spring + dashpot equal the limit (the Maw rule; LAMMPS ``twisting sds``, after Marshall 2009).
* ``marshall``: the same law with its coefficients from the tangential law and the contact radius a
  (Marshall, J. Comput. Phys. 228 (2009) 1541-1561; LAMMPS ``twisting marshall``):
  ktw = ½ kt a², γtw = ½ γt a², μtw = ⅔ a μt.

Compiled force functions ``<id>_twisting_force(c, w, n, fn_abs, a, dt, phi) → (Mt n on body 0, new φ)``; body 1
takes the opposite; a is the contact radius (used by marshall). μtw carries a length: μtw |Fn| is a torque.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from .. import KERNEL_CACHE
from .base import SubModel


@dataclass(frozen=True)
class SdsTwisting(SubModel):
    slot: ClassVar[str] = "twisting"
    id: ClassVar[str] = "sds"
    history_size: ClassVar[int] = 1
    title: ClassVar[str] = "Coulomb-limited twisting spring-dashpot"
    k_tw: float = 0.0  # N·m/rad
    gamma_tw: float = 0.0  # N·m·s/rad
    mu_tw: float = 0.0  # m


@dataclass(frozen=True)
class MarshallTwisting(SubModel):
    slot: ClassVar[str] = "twisting"
    id: ClassVar[str] = "marshall"
    history_size: ClassVar[int] = 1
    title: ClassVar[str] = "Marshall's twisting (coefficients from the tangential law and the contact radius)"
    kt: float = 0.0  # the tangential law's stiffness (N/m)
    gamma_t: float = 0.0  # its damping (N·s/m)
    mu_t: float = 0.0  # its friction coefficient

    def at(self, a: float) -> SdsTwisting:
        """The sds law it is at contact radius a."""
        return SdsTwisting(0.5 * self.kt * a * a, 0.5 * self.gamma_t * a * a, 2.0 / 3.0 * a * self.mu_t)


@njit(cache=KERNEL_CACHE, inline="always")
def _sds(k, gamma, mu, w, n, fn_abs, dt, phi):
    rate = w[0] * n[0] + w[1] * n[1] + w[2] * n[2]
    phi = phi + rate * dt
    m = -k * phi - gamma * rate
    cap = mu * fn_abs
    if abs(m) > cap:
        m = math.copysign(cap, m)
        phi = -(m + gamma * rate) / k if k > 0.0 else phi
    return m * n, phi


@njit(cache=KERNEL_CACHE)
def sds_twisting_force(c, w, n, fn_abs, a, dt, phi):
    return _sds(c[0], c[1], c[2], w, n, fn_abs, dt, phi)


@njit(cache=KERNEL_CACHE)
def marshall_twisting_force(c, w, n, fn_abs, a, dt, phi):
    return _sds(0.5 * c[0] * a * a, 0.5 * c[1] * a * a, 2.0 / 3.0 * a * c[2], w, n, fn_abs, dt, phi)


FORCES = {"sds": sds_twisting_force, "marshall": marshall_twisting_force}


def twisting_torque(law, w, n, fn_abs: float, a: float, dt: float, phi: float = 0.0):
    """(torque on body 0, new stored angle) of a twisting record (or None: no torque)."""
    if law is None or law.id not in FORCES:
        return np.zeros(3), phi
    return FORCES[law.id](law.array(), np.asarray(w, dtype=np.float64), np.asarray(n, dtype=np.float64),
                          float(fn_abs), float(a), float(dt), float(phi))
