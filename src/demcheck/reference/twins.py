"""Engine twins: reference laws that compute exactly what an engine configuration computes.

The engines' normal force is F = F_ne(δ) + η(δ) δ̇ with F_ne = k δ^a; their damping styles differ only in
η(δ) = c δ^b, and their tangential dashpots reuse η(δ) times a factor. These helpers turn an engine's
coefficients into the reference's :class:`NormalLaw` / :class:`TangentialLaw` numbers, formula by formula
as ../shared/ENGINES.md states them (and as the engine tests check against the binaries). Which engine
keyword maps to which helper is ``inputs/``'s business.
"""

from __future__ import annotations

import math

from .normal import VISCOELASTIC, NormalLaw
from .tangential import NONE, SPRING, TRUNC_MAW, TRUNC_SPRING, VISCOUS_SLIDING, TangentialLaw

# Marshall's polynomial α(e) of Tsuji's damping, as LAMMPS 22Jul2025 evaluates it (no √2 factor)
TSUJI_POLY = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def tsuji_alpha(e: float) -> float:
    return sum(c * e**i for i, c in enumerate(TSUJI_POLY))


def beta(e: float) -> float:
    """−ln e/√(π² + ln² e) (> 0 for e < 1)."""
    le = math.log(e)
    return -le / math.sqrt(math.pi**2 + le * le)


def elastic(k: float, a: float) -> tuple[float, float]:
    return k, a


def damping(style: str, coeff: float, k_el: float, a: float, m_eff: float, r_eff: float) -> tuple[float, float]:
    """(c, b) of η(δ) = c δ^b for a damping style, with F_ne = k_el δ^a.

    * ``velocity``: η = η0
    * ``mass_velocity``: η = η0 m̄
    * ``viscoelastic``: η = η0 m̄ √(R̄δ)
    * ``tsuji``: η = α(e) √(m̄ F_ne/δ)
    * ``coeff_restitution``: √(m̄ F_ne/δ) times 2β(e) for a linear spring, √5 β(e) for any other
    * ``stiffness_hooke``: η = m̄ γ (LIGGGHTS hooke/stiffness γn); ``stiffness_hertz``: η = m̄ γ √(R̄δ)
    * ``restitution_hertz``: √5 β(e) √(m̄ K) δ^¼ (LIGGGHTS hertz, = LAMMPS coeff_restitution)
    * ``restitution_hooke``: 2β(e)√(m̄k) (LIGGGHTS hooke, = LSD)
    """
    root = math.sqrt(m_eff * k_el)
    b_secant = 0.5 * (a - 1.0)  # √(F_ne/δ) = √k δ^{(a−1)/2}
    if style == "velocity":
        return coeff, 0.0
    if style in ("mass_velocity", "stiffness_hooke"):
        return coeff * m_eff, 0.0
    if style in ("viscoelastic", "stiffness_hertz"):
        return coeff * m_eff * math.sqrt(r_eff), 0.5
    if style == "tsuji":
        return tsuji_alpha(coeff) * root, b_secant
    if style in ("coeff_restitution", "restitution_hertz", "restitution_hooke"):
        if coeff >= 1.0:
            return 0.0, b_secant
        factor = 2.0 if a == 1.0 else math.sqrt(5.0)
        return factor * beta(coeff) * root, b_secant
    raise ValueError(f"unknown damping style {style!r}")


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


__all__ = ["TRUNC_MAW", "TRUNC_SPRING", "beta", "damping", "normal_law", "no_friction", "restitution_for_eta",
           "tangential_spring", "tangential_viscous_sliding", "tsuji_alpha"]
