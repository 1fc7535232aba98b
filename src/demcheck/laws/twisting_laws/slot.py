"""The twisting slot's interface: the record every twisting law is (:class:`TwistingSubModel`, with the traits
the scenario solvers ask instead of a law's id), the registry of the laws' compiled force functions
(:data:`KERNELS`) and the Coulomb-limited spring–dashpot the laws share (:func:`_sds`).

A law's compiled force function is ``<id>_twisting_force(c, w, n, fn_abs, a, dt, phi) → (Mt n on body 0, new φ)``;
body 1 takes the opposite; a is the contact radius. μtw carries a length: μtw |Fn| is a torque."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..registry import BeyondSubModel, Kernels

KERNELS = Kernels("twisting")


@dataclass(frozen=True)
class TwistingSubModel(BeyondSubModel):
    """A twisting law's record. Its trait ``from_contact_radius``: its coefficients follow the contact radius a
    (:meth:`at` gives the law it is at a given a; a law without the trait is itself at every a)."""

    slot: ClassVar[str] = "twisting"
    history_size: ClassVar[int] = 1  # the twist angle φ
    from_contact_radius: ClassVar[bool] = False

    def at(self, a: float):
        """The law at contact radius a."""
        return self


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
