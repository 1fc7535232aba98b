"""Engine twins: reference laws that compute exactly what an engine configuration computes.

The engines' normal force is F = F_ne(δ) + η(δ) δ̇ with F_ne = k δ^a; their damping styles differ only in
η(δ) = c δ^b, and their tangential dashpots reuse η(δ) times a factor. These helpers turn an engine's
coefficients into records of the contact's slots (laws/base.py) and those into the reference's
:class:`NormalLaw` / :class:`TangentialLaw` numbers, formula by formula as the engines' documentation states
them (and as the engine tests check against the binaries). An engine's twin names its normal law's records itself
(``NormalLaw.from_slots(HertzNormal(k=…), QuarterDamping(eta=…), limit)``), never exponents or family ids. Which
engine keyword maps to which helper is the engine package's business (engines/<name>/mapping.py; the
damping styles in engines/damping.py).
"""

from __future__ import annotations

import math

from ..laws.tangential import (TRUNC_MAW, TRUNC_SPRING, NoTangential, SpringTangential, SqrtSpringTangential,
                               TangentialLaw, ViscousSlidingTangential)


def damping_ratio(e: float) -> float:
    """The damping ratio of a linear spring-dashpot whose restitution is e: −ln e/√(π² + ln² e) (> 0 for
    e < 1; the engines' docs call it β(e) — not Chung & Ooi's tangential restitution β of validate)."""
    le = math.log(e)
    return -le / math.sqrt(math.pi**2 + le * le)


def restitution_for_eta(c_over_root: float, factor: float) -> float:
    """The e whose restitution damping factor·β(e)·√(m̄K) equals a given prefactor c (c_over_root = c/√(m̄K)):
    the input transform that makes LAMMPS coeff_restitution / LIGGGHTS hertz carry TTIn's ηn."""
    x = c_over_root / factor
    if x <= 0.0:
        return 1.0
    if x >= 1.0:
        return math.nan
    return math.exp(-x * math.pi / math.sqrt(1.0 - x * x))


def tangential_viscous_sliding(x_t: float, mu: float, r_eff: float, m_eff: float) -> TangentialLaw:
    """F_t = −min(x_t η(δ)|v_t|, μ|Fn|) v̂_t with the normal law's damping η(δ)."""
    return TangentialLaw.from_slot(ViscousSlidingTangential(eta=x_t, eta_normal=True, mu_s=mu, mu_k=mu, r_eff=r_eff,
                                                            m_eff=m_eff))


def tangential_spring(kt: float, sqrt_law: bool, x_t: float, mu: float, truncation: int, r_eff: float,
                      m_eff: float) -> TangentialLaw:
    """−Kt ξ − x_t η(δ) v_t with Kt = kt (constant) or kt √(R̄δ), Coulomb-limited by ``truncation``."""
    record = SqrtSpringTangential if sqrt_law else SpringTangential
    return TangentialLaw.from_slot(record(kt=kt, eta=x_t, eta_normal=True, mu_s=mu, mu_k=mu, truncation=truncation,
                                          r_eff=r_eff, m_eff=m_eff))


def no_friction() -> TangentialLaw:
    return TangentialLaw.from_slot(NoTangential())


__all__ = ["TRUNC_MAW", "TRUNC_SPRING", "damping_ratio", "no_friction", "restitution_for_eta",
           "tangential_spring", "tangential_viscous_sliding"]
