"""The linear spring (and dashpot) on the history ξ, Coulomb-limited by a truncation rule: trial
F = −Kt ξ − ηt v_t, Kt constant (``spring``) or kt √(R̄δn) (``sqrt_spring``: DDt, TTIt; LAMMPS mindlin); the
truncations ``force`` (cap |F|, leave ξ alone), ``overlap`` (Maw: ξ such that |Kt ξ + ηt v_t| = μ|Fn|) and
``spring`` (cap the spring only, drop the dashpot while slipping)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numba import njit

from ... import KERNEL_CACHE
from ..tangential_slot import (T_MU_K, T_MU_S, T_TRUNC, TRUNC_CAP, TRUNC_MAW, TRUNC_SPRING, TangentialSubModel,
                               compiled)
from .common import _norm, eta_of, kt_of

SPRING = 4


@dataclass(frozen=True)
class SpringTangential(TangentialSubModel):
    """Trial F = −Kt ξ − ηt v_t on the history ξ, Kt = kt constant, Coulomb-limited by ``truncation``
    (TRUNCATIONS); the engine twins' variants keep the elastic force as the history (``force_history``) or
    rescale it as the contact radius shrinks (``rescale_history``)."""

    id: ClassVar[str] = "spring"
    family: ClassVar[int] = SPRING
    caps: ClassVar[bool] = True
    title: ClassVar[str] = "linear spring (and dashpot) with Coulomb truncation"
    history_size: ClassVar[int] = 3
    kt: float = 0.0
    eta: float = 0.0
    eta_normal: bool = False
    mu_s: float = 0.0
    mu_k: float = 0.0
    truncation: int = TRUNC_MAW
    r_eff: float = 0.0
    m_eff: float = 0.0
    force_history: bool = False
    rescale_history: bool = False

    @property
    def passive(self) -> bool:
        """A spring capped at μ|Fn| with its history left alone (truncation ``force``, the seed's min()) is not:
        after a slip the history is far past the cap, and when the slip reverses the capped force keeps pointing
        the old way — along the new slip — until the history unwinds (Chung & Ooi Test 5 with TTIt: 6 % of the
        impact energy created, in the adaptive and the verlet method alike; docs/models.md)."""
        return self.truncation != TRUNC_CAP


@dataclass(frozen=True)
class SqrtSpringTangential(SpringTangential):
    """As ``spring`` with Kt = kt √(R̄ δn) (Mindlin's no-slip stiffness: DDt, TTIt; LAMMPS mindlin)."""

    id: ClassVar[str] = "sqrt_spring"
    kt_sqrt: ClassVar[bool] = True
    title: ClassVar[str] = "spring Kt = kt √(R̄δ) (and dashpot) with Coulomb truncation"

    @property
    def pushes_at_onset(self) -> bool:
        """Maw's truncation (``overlap``) with a Kt ∝ √δ that vanishes at onset and a dashpot can push along the
        slip there (TTIt, DDt with ηt; docs/models.md finding 9)."""
        return self.eta > 0 and self.truncation == TRUNC_MAW


@njit(cache=KERNEL_CACHE)
def spring_slip_surface(tl, nl, xi, vt, fn_abs, delta, mu):
    hn = _norm(xi)
    w = xi / hn if hn > 0.0 else np.zeros(3)
    cap = mu * fn_abs
    kt = kt_of(tl, delta)
    eta = eta_of(tl, nl, delta)
    if tl[T_TRUNC] == TRUNC_SPRING:
        return kt * hn - cap, w, kt
    s = kt * xi + eta * vt
    sn = _norm(s)
    return sn - cap, (s / sn if sn > 0.0 else w), kt


@njit(cache=KERNEL_CACHE)
def spring_return_map(tl, nl, xi, vt, fn_abs, delta, mu):
    hn = _norm(xi)
    cap = mu * fn_abs
    kt = kt_of(tl, delta)
    if kt <= 0.0:
        return np.zeros(3)
    eta = eta_of(tl, nl, delta)
    trunc = tl[T_TRUNC]
    if trunc == TRUNC_CAP:  # the force is capped, the spring keeps its extension
        return xi
    if trunc == TRUNC_MAW:  # spring + dashpot = μ|Fn| along the trial force
        s = -kt * xi - eta * vt
        sn = _norm(s)
        f = s * (cap / sn) if sn > 0.0 else np.zeros(3)
        return -(f + eta * vt) / kt
    return xi * (cap / (kt * hn)) if hn > 0.0 else xi


@njit(cache=KERNEL_CACHE)
def spring_tangential_force(tl, nl, xi, vt, fn_abs, delta, slipping, tref):
    mu = tl[T_MU_K] if slipping else tl[T_MU_S]
    kt = kt_of(tl, delta)
    eta = eta_of(tl, nl, delta)
    trial = -kt * xi - eta * vt
    if not slipping:
        return trial
    trunc = tl[T_TRUNC]
    cap = mu * fn_abs
    if trunc != TRUNC_SPRING:
        tn = _norm(trial)
        return trial * (cap / tn) if tn > 0.0 else trial
    hn = _norm(xi)
    return -(cap / hn) * xi if hn > 0.0 else np.zeros(3)


compiled(SpringTangential, force=spring_tangential_force, slip_surface=spring_slip_surface,
         return_map=spring_return_map)
compiled(SqrtSpringTangential, force=spring_tangential_force, slip_surface=spring_slip_surface,
         return_map=spring_return_map)
