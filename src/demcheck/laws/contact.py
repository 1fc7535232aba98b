"""Geometry of a contact and effective properties of a pair (seed 000 §2).

Conventions (docs/models.md):

* R̄ = (1/R₁ + 1/R₂)⁻¹, m̄ = (1/m₁ + 1/m₂)⁻¹,
* Ē = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹,
* Ḡ = [(2−ν₁)/G₁ + (2−ν₂)/G₂]⁻¹ (Mindlin; seed 000 writes 2−ν², a misprint), G = E/(2(1+ν)),
* a rigid wall has infinite R, m, E and G; a wall with a material has infinite R and m only,
* the impact speed is the speed of approach of the contact points along the normal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from typing import TYPE_CHECKING

from ..errors import ConfigError
from .registry import contact_number

if TYPE_CHECKING:  # the case layer sits above the laws: types only
    from ..case import Case, Material


# The rules of a pair's coefficients: one set for a material's values (``materials.NAME.KEY``) and the pair's own
# (``[contact] KEY``, which overrides the materials'): key → (rule, check).
PAIR_RULES = {
    "restitution": ("must be in (0, 1]", lambda v: 0 < v <= 1),
    "friction": ("must be >= 0", lambda v: v >= 0),
    "friction_kinetic": ("must be >= 0", lambda v: v >= 0),
    "tangential_restitution": ("must be in [0, 1]", lambda v: 0 <= v <= 1),
}


def kinetic_rule(friction: float) -> str:
    """The rule of a kinetic friction coefficient against the static one it goes with."""
    return f"must not exceed the static coefficient friction = {friction}"


def pair_params(params: dict) -> dict[str, float]:
    """The pair's own coefficients given in ``[contact]`` ({key: value} of those present), each checked by its
    rule in PAIR_RULES, and friction_kinetic against friction when both are given; a bad one is a ConfigError
    naming ``contact.KEY``, the value and the rule."""
    out = {}
    for key, (rule, check) in PAIR_RULES.items():
        v = contact_number(params, key, rule=rule, check=check)
        if v is not None:
            out[key] = v
    kinetic, static = out.get("friction_kinetic"), out.get("friction")
    if kinetic is not None and static is not None and kinetic > static:
        raise ConfigError("contact.friction_kinetic", params["friction_kinetic"], kinetic_rule(static))
    return out


@dataclass(frozen=True)
class Pair:
    """Effective properties of the two bodies of a collision (or a representative pair of a packing)."""

    r_eff: float
    m_eff: float
    e_eff: float  # Ē
    g_eff: float  # Ḡ
    restitution: float | None
    tangential_restitution: float | None
    friction: float | None
    friction_kinetic: float | None
    dissipative_constant: float | None  # Ā
    poisson_ratio: float  # ν of the pair (mean), for the Kt/Kn ratio and LTH
    youngs_modulus: float  # E of the pair (for TTIt, like spheres)
    impact_speed: float  # normal approach speed at first contact (m/s); nan if they never meet
    wall: bool


def effective_modulus(m1: Material, m2: Material | None) -> float:
    inv = (1 - m1.poisson_ratio**2) / m1.youngs_modulus
    if m2 is not None:
        inv += (1 - m2.poisson_ratio**2) / m2.youngs_modulus
    return 1.0 / inv


def effective_shear_modulus(m1: Material, m2: Material | None) -> float:
    inv = (2 - m1.poisson_ratio) / m1.shear_modulus
    if m2 is not None:
        inv += (2 - m2.poisson_ratio) / m2.shear_modulus
    return 1.0 / inv


def _combine(values, how):
    vals = [v for v in values if v is not None]
    if not vals:
        return None
    if how == "min":
        return min(vals)
    return sum(vals) / len(vals)


def pair_of(case: Case, i: int = 0, j: int | None = 1) -> Pair:
    """Effective pair of particles i and j, or of particle i and wall 0 when j is None / the case has a wall."""
    p1 = case.particles[i]
    mat1 = case.materials[p1.material]
    m1 = case.mass(i)
    wall = j is None or len(case.particles) == 1
    if wall:
        w = case.walls[0]
        mat2 = None if w.rigid else case.materials[w.material]
        r_eff, m_eff = p1.radius, m1
        partner = [mat1] if mat2 is None else [mat1, mat2]
    else:
        p2 = case.particles[j]
        mat2 = case.materials[p2.material]
        m2 = case.mass(j)
        r_eff = p1.radius * p2.radius / (p1.radius + p2.radius)
        m_eff = m1 * m2 / (m1 + m2)
        partner = [mat1, mat2]
    params = pair_params(case.contact.params)
    restitution = params.get("restitution", _combine([m.restitution for m in partner], "mean"))
    friction = params.get("friction", _combine([m.friction for m in partner], "min"))
    friction_kinetic = params.get("friction_kinetic", _combine([m.friction_kinetic for m in partner], "min"))
    return Pair(
        r_eff=r_eff,
        m_eff=m_eff,
        e_eff=effective_modulus(mat1, mat2),
        g_eff=effective_shear_modulus(mat1, mat2),
        restitution=restitution,
        tangential_restitution=params.get(
            "tangential_restitution", _combine([m.tangential_restitution for m in partner], "mean")),
        friction=friction,
        friction_kinetic=friction_kinetic,
        dissipative_constant=_combine([m.dissipative_constant for m in partner], "mean"),
        poisson_ratio=_combine([m.poisson_ratio for m in partner], "mean"),
        youngs_modulus=_combine([m.youngs_modulus for m in partner], "mean"),
        impact_speed=impact_speed(case, i, None if wall else j),
        wall=wall,
    )


def impact_speed(case: Case, i: int = 0, j: int | None = 1) -> float:
    """Normal approach speed of the contact points when the bodies first touch (free flight under gravity
    before contact). nan if they never meet."""
    p1 = case.particles[i]
    x1, v1 = np.asarray(p1.position), np.asarray(p1.velocity)
    g = np.asarray(case.run.gravity)
    if j is None:
        w = case.walls[0]
        n = -np.asarray(w.normal)  # from the particle towards the wall
        gap = float((x1 - np.asarray(w.point)) @ np.asarray(w.normal)) - p1.radius
        vn = float(v1 @ n)
        an = float(g @ n)
    else:
        p2 = case.particles[j]
        d0 = np.asarray(p2.position) - x1
        v_rel = v1 - np.asarray(p2.velocity)  # d(t) = d0 - v_rel t (both bodies fall alike)
        touch = p1.radius + p2.radius
        # |d0 - v_rel t| = touch: a t² - 2 b t + c = 0
        a, b, c = float(v_rel @ v_rel), float(d0 @ v_rel), float(d0 @ d0) - touch**2
        if a == 0.0 or b * b - a * c < 0 or b <= 0:
            return math.nan
        t = (b - math.sqrt(b * b - a * c)) / a
        n = (d0 - v_rel * t) / touch
        return float(v_rel @ n)
    # gap(t) = gap - vn t - an t²/2 reaches 0 with approach speed sqrt(vn² + 2 an gap)
    disc = vn * vn + 2.0 * an * gap
    if disc < 0 or (vn <= 0 and an <= 0 and gap > 0):
        return math.nan
    return math.sqrt(disc)
