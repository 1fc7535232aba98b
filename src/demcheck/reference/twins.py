"""Engine twins: reference laws that compute exactly what an engine configuration computes.

The engines' normal force is F = F_ne(δ) + η(δ) δ̇ with F_ne = k δ^a; their damping styles differ only in
η(δ) = c δ^b, and their tangential dashpots reuse η(δ) times a factor. These helpers turn an engine's
coefficients into the reference's :class:`NormalLaw` / :class:`TangentialLaw` numbers, formula by formula
as the engines' documentation states them (and as the engine tests check against the binaries). Which
engine keyword maps to which helper is the engine package's business (engines/<name>/mapping.py; the
damping styles in engines/damping.py).
"""

from __future__ import annotations

import math

from ..laws.normal import VISCOELASTIC, NormalLaw
from ..laws.tangential import NONE, SPRING, TRUNC_MAW, TRUNC_SPRING, VISCOUS_SLIDING, TangentialLaw


def damping_ratio(e: float) -> float:
    """The damping ratio of a linear spring-dashpot whose restitution is e: −ln e/√(π² + ln² e) (> 0 for
    e < 1; the engines' docs call it β(e) — not Chung & Ooi's tangential restitution β of validate)."""
    le = math.log(e)
    return -le / math.sqrt(math.pi**2 + le * le)


def normal_law(k_el: float, a: float, c: float, b: float, limit: bool) -> NormalLaw:
    return NormalLaw(VISCOELASTIC, k=k_el, a=a, eta=c, b=b, limit=limit)


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
    return TangentialLaw(VISCOUS_SLIDING, eta=x_t, eta_normal=True, mu_s=mu, mu_k=mu, r_eff=r_eff, m_eff=m_eff)


def tangential_spring(kt: float, sqrt_law: bool, x_t: float, mu: float, truncation: int, r_eff: float,
                      m_eff: float) -> TangentialLaw:
    """−Kt ξ − x_t η(δ) v_t with Kt = kt (constant) or kt √(R̄δ), Coulomb-limited by ``truncation``."""
    return TangentialLaw(SPRING, kt=kt, kt_sqrt=sqrt_law, eta=x_t, eta_normal=True, mu_s=mu, mu_k=mu,
                         truncation=truncation, r_eff=r_eff, m_eff=m_eff)


def no_friction() -> TangentialLaw:
    return TangentialLaw(NONE)


__all__ = ["TRUNC_MAW", "TRUNC_SPRING", "damping_ratio", "normal_law", "no_friction", "restitution_for_eta",
           "tangential_spring", "tangential_viscous_sliding"]
