"""The engines' damping styles as the reference's damping records η(δ) = η δ^b (laws/damping.py; shared by the
LAMMPS-family engines' vocabularies: which keyword of which engine takes which style is their package's business)."""

from __future__ import annotations

import math

from ..laws.damping import ConstantDamping, Damping, QuarterDamping, SqrtDamping
from ..laws.normal import HertzNormal, HookeNormal
from ..reference.twins import damping_ratio

# Marshall's polynomial α(e) of Tsuji's damping, as LAMMPS 22Jul2025 evaluates it (no √2 factor)
TSUJI_POLY = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def tsuji_alpha(e: float) -> float:
    return sum(c * e**i for i, c in enumerate(TSUJI_POLY))


# the dashpot of a spring's secant √(m̄ F_ne/δ) = √k δ^{(a−1)/2}: constant for a linear spring, δ^¼ for Hertz
SECANT = {HookeNormal: ConstantDamping, HertzNormal: QuarterDamping}


def damping(style: str, coeff: float, spring, m_eff: float, r_eff: float) -> Damping:
    """The damping record η(δ) of a damping style beside the elastic record ``spring`` (HookeNormal or HertzNormal,
    ``k`` its stiffness; the record, not an exponent, tells a linear spring from Hertz's).

    * ``velocity``: η = η0 (constant)
    * ``mass_velocity``: η = η0 m̄ (constant)
    * ``viscoelastic``: η = η0 m̄ √(R̄δ) (sqrt)
    * ``tsuji``: η = α(e) √(m̄ F_ne/δ) (the spring's secant record: constant for hooke, quarter for hertz)
    * ``coeff_restitution``: √(m̄ F_ne/δ) times 2β(e) for a linear spring, √5 β(e) for Hertz (secant)
    * ``stiffness_hooke``: η = m̄ γ (LIGGGHTS hooke/stiffness γn); ``stiffness_hertz``: η = m̄ γ √(R̄δ)
    * ``restitution_hertz``: √5 β(e) √(m̄ K) δ^¼ (LIGGGHTS hertz, = LAMMPS coeff_restitution)
    * ``restitution_hooke``: 2β(e)√(m̄k) (LIGGGHTS hooke, = LSD)
    """
    if style == "velocity":
        return ConstantDamping(eta=coeff)
    if style in ("mass_velocity", "stiffness_hooke"):
        return ConstantDamping(eta=coeff * m_eff)
    if style in ("viscoelastic", "stiffness_hertz"):
        return SqrtDamping(eta=coeff * m_eff * math.sqrt(r_eff))
    secant = SECANT[type(spring)]
    root = math.sqrt(m_eff * spring.k)
    if style == "tsuji":
        return secant(eta=tsuji_alpha(coeff) * root)
    if style in ("coeff_restitution", "restitution_hertz", "restitution_hooke"):
        if coeff >= 1.0:
            return secant(eta=0.0)
        factor = 2.0 if isinstance(spring, HookeNormal) else math.sqrt(5.0)
        return secant(eta=factor * damping_ratio(coeff) * root)
    raise ValueError(f"unknown damping style {style!r}")
