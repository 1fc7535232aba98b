"""The engines' damping styles as the reference's η(δ) = c δ^b (shared by the LAMMPS-family engines'
vocabularies: which keyword of which engine takes which style is their package's business)."""

from __future__ import annotations

import math

from ..laws.normal import HookeNormal
from ..reference.twins import damping_ratio

# Marshall's polynomial α(e) of Tsuji's damping, as LAMMPS 22Jul2025 evaluates it (no √2 factor)
TSUJI_POLY = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def tsuji_alpha(e: float) -> float:
    return sum(c * e**i for i, c in enumerate(TSUJI_POLY))


def damping(style: str, coeff: float, spring, m_eff: float, r_eff: float) -> tuple[float, float]:
    """(c, b) of η(δ) = c δ^b for a damping style, with F_ne = k_el δ^a the elastic record ``spring`` (HookeNormal or
    HertzNormal: ``k`` = k_el, its ``exponent`` a; the record, not the exponent, tells a linear spring).

    * ``velocity``: η = η0
    * ``mass_velocity``: η = η0 m̄
    * ``viscoelastic``: η = η0 m̄ √(R̄δ)
    * ``tsuji``: η = α(e) √(m̄ F_ne/δ)
    * ``coeff_restitution``: √(m̄ F_ne/δ) times 2β(e) for a linear spring, √5 β(e) for any other
    * ``stiffness_hooke``: η = m̄ γ (LIGGGHTS hooke/stiffness γn); ``stiffness_hertz``: η = m̄ γ √(R̄δ)
    * ``restitution_hertz``: √5 β(e) √(m̄ K) δ^¼ (LIGGGHTS hertz, = LAMMPS coeff_restitution)
    * ``restitution_hooke``: 2β(e)√(m̄k) (LIGGGHTS hooke, = LSD)
    """
    root = math.sqrt(m_eff * spring.k)
    b_secant = 0.5 * (spring.exponent - 1.0)  # √(F_ne/δ) = √k δ^{(a−1)/2}
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
        factor = 2.0 if isinstance(spring, HookeNormal) else math.sqrt(5.0)
        return factor * damping_ratio(coeff) * root, b_secant
    raise ValueError(f"unknown damping style {style!r}")


