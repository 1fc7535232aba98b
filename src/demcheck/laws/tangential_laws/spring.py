"""The linear spring (and dashpot) on the history ξ, Coulomb-limited by a truncation rule: trial
F = −Kt ξ − ηt v_t, Kt constant (``spring``) or kt √(R̄δn) (``sqrt_spring``: DDt, TTIt; LAMMPS mindlin); the
truncations ``force`` (cap |F|, leave ξ alone), ``overlap`` (Maw: ξ such that |Kt ξ + ηt v_t| = μ|Fn|) and
``spring`` (cap the spring only, drop the dashpot while slipping)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import math

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
    states: ClassVar[bool] = True
    stick_kink: ClassVar[bool] = True  # the trial force −Kt ξ − ηt v_t can reverse through 0 within a step
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
    def slip_keeps_history(self) -> bool:
        """The force cap slips with the history left alone."""
        return self.truncation == TRUNC_CAP

    @property
    def slip_snaps(self) -> bool:
        """Maw's and the spring-only truncation keep a slipping history on the slip surface."""
        return self.truncation != TRUNC_CAP

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


@njit(cache=KERNEL_CACHE, inline="always")
def spring_slip(xi0, xi1, xi2, vt, kt, eta, trunc, mu_test, mu_k, fabs):
    """The spring family's slip test and Coulomb truncation after the increment, as the engines do it: the
    trial force −Kt ξ − η v_t; it slips when the trial force (or, for the spring-only truncation, the spring
    force) exceeds ``mu_test`` |Fn|, and is then cut to ``mu_k`` |Fn|: along the trial force with the history
    kept (force cap), along it with the history put back on the limit (Maw: spring + dashpot = μ|Fn|), or the
    spring shortened to the limit and the dashpot dropped. Returns (xi0, xi1, xi2, f0, f1, f2, sliding). The one
    rule of the two-body verlet kernel and the packing loop."""
    s0, s1, s2 = -kt * xi0 - eta * vt[0], -kt * xi1 - eta * vt[1], -kt * xi2 - eta * vt[2]
    sn = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    hm = math.sqrt(xi0 * xi0 + xi1 * xi1 + xi2 * xi2)
    cap_test = mu_test * fabs
    psi = kt * hm - cap_test if trunc == TRUNC_SPRING else sn - cap_test
    if psi <= 0.0:
        return xi0, xi1, xi2, s0, s1, s2, False
    cap = mu_k * fabs
    if kt <= 0.0:  # no spring, no history
        xi0 = xi1 = xi2 = 0.0
        hm = 0.0
    if trunc == TRUNC_SPRING:
        if hm > 0.0:
            r = cap / (kt * hm)
            xi0, xi1, xi2 = xi0 * r, xi1 * r, xi2 * r
            return xi0, xi1, xi2, -kt * xi0, -kt * xi1, -kt * xi2, True
        return xi0, xi1, xi2, 0.0, 0.0, 0.0, True
    r = cap / sn if sn > 0.0 else 0.0
    f0, f1, f2 = s0 * r, s1 * r, s2 * r
    if trunc == TRUNC_MAW and kt > 0.0:
        xi0, xi1, xi2 = -(f0 + eta * vt[0]) / kt, -(f1 + eta * vt[1]) / kt, -(f2 + eta * vt[2]) / kt
    return xi0, xi1, xi2, f0, f1, f2, True


@njit(cache=KERNEL_CACHE)
def spring_discrete_slip(tl, nl, xi, vt, fn_abs, delta, mu):
    """The engines' step of the spring (spring_slip): (history, force, sliding) after the increment."""
    x0, x1, x2, f0, f1, f2, sliding = spring_slip(xi[0], xi[1], xi[2], vt, kt_of(tl, delta), eta_of(tl, nl, delta),
                                                  tl[T_TRUNC], mu, tl[T_MU_K], fn_abs)
    return np.array([x0, x1, x2]), np.array([f0, f1, f2]), sliding


for _record in (SpringTangential, SqrtSpringTangential):
    compiled(_record, force=spring_tangential_force, slip_surface=spring_slip_surface, return_map=spring_return_map,
             discrete_slip=spring_discrete_slip)
