"""Simple viscous damping: F = −ηt v_t."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import TangentialSubModel, compiled
from .common import eta_of

VISCOUS = 2


@dataclass(frozen=True)
class ViscousTangential(TangentialSubModel):
    """F = −ηt v_t (ηt constant, or ``eta`` times the normal dashpot's η(δ) with ``eta_normal``); the friction
    coefficients are carried (an engine twin's) but not read."""

    id: ClassVar[str] = "viscous"
    family: ClassVar[int] = VISCOUS
    title: ClassVar[str] = "viscous damping"
    eta: float = 0.0
    eta_normal: bool = False
    mu_s: float = 0.0
    mu_k: float = 0.0
    r_eff: float = 0.0
    m_eff: float = 0.0


@njit(cache=KERNEL_CACHE)
def viscous_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    return -eta_of(tl, nl, delta) * vt


compiled(ViscousTangential, force=viscous_tangential_force)
