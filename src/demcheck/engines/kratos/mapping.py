"""Kratos DEM 10.4.4's vocabulary: a seed model → a DEMApplication discontinuum law with its numbers and
fidelity (:func:`map_model`), and those numbers → the reference laws that compute what Kratos computes
(:func:`twin`).

What the laws compute (read in applications/DEMApplication/custom_constitutive/ and checked against runs):

* ``DEM_D_Hertz_viscous_Coulomb``: Kn = 2E*√(R̄δ), F_e = ⅔ Kn δ = (4/3)E*√R̄ δ^{3/2}, F_d = −2γ√(m̄Kn) δ̇, so
  η(δ) = 2γ√(2m̄E*√R̄) δ^{1/4}; the total normal force is held ≥ 0. A wall is a rigid FEM face with R̄ = R,
  m̄ = m and E* from the face's own E and ν (demcheck gives the face E = 1e30 Pa: E* = E/(1 − ν²)).
* ``DEM_D_Linear_viscous_Coulomb``: Kn = 1.432 π (0.31225 R̄) E* between particles but π (0.31225 R) E* with
  a wall (the wall branch drops the 1.432), F_d = −2γ√(m̄Kn) δ̇, total normal force held ≥ 0.
* Both tangential parts: an incremental spring Kt = 4G*Kn/E* with a dashpot 2γ√(m̄Kt), a Coulomb cap
  μ(v) = μd + (μs − μd) exp(−FRICTION_DECAY |v_t|) split between spring and dashpot in Kratos' own way, and
  (Hertz) the spring force scaled by √(δ/δ_prev) on unloading. No seed tangential law has that form.

γ (DAMPING_GAMMA) is what Kratos derives from COEFFICIENT_OF_RESTITUTION (a bisection to 1e-4 for Linear
laws, Thornton's fit for Hertz laws); demcheck's runner sets the γ of the seed's η directly on the contact's
properties after Kratos has initialised them, so the run carries the seed's damping to round-off.
"""

from __future__ import annotations

import math

from ...reference import twins
from ...laws.model import ResolvedModel
from ...laws.normal import NormalLaw
from ...laws.tangential import TangentialLaw
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused

HERTZ = "DEM_D_Hertz_viscous_Coulomb"
LINEAR = "DEM_D_Linear_viscous_Coulomb"
LAWS = (HERTZ, LINEAR)
LINEAR_BETA = 1.432  # the particle–particle factor of DEM_D_Linear_viscous_Coulomb's Kn (absent for walls)
LINEAR_RADIUS = 0.31225  # its modified radius factor √(α(2 − α)), α = 0.05


def linear_kn(young_eff: float, r_eff: float, wall: bool) -> float:
    """DEM_D_Linear_viscous_Coulomb's Kn, in Kratos' order of operations."""
    beta = 1.0 if wall else LINEAR_BETA
    return beta * young_eff * math.pi * (r_eff * LINEAR_RADIUS)


def map_model(model: ResolvedModel, cp: dict) -> Mapping:
    """The contact's slot records, by id: normal hertz with damping none | quarter, or hooke with none |
    constant; tangential none."""
    contact, pair = model.contact, model.pair
    normal, damp = contact.normal, contact.damping
    eta = getattr(damp, "eta", 0.0)
    m, r = pair.m_eff, pair.r_eff
    nid = model.normal.id
    reasons: list[str] = []
    fid = EXACT
    if normal.id == "hls":
        return refused("kratos", "Kratos DEM 10.4.4 has no linear hysteretic (HLS) discontinuum law")
    if normal.id not in ("hooke", "hertz"):
        return refused("kratos", f"no Kratos DEM discontinuum law for the normal record '{normal.id}'")
    if contact.tangential.id != "none":
        return refused("kratos", f"Kratos' tangential force is part of its normal law (incremental spring Kt = "
                                  f"4G*Kn/E*, dashpot 2γ√(m̄Kt), μ decaying with the slip speed, the Coulomb cap "
                                  f"split between spring and dashpot in its own way); no seed tangential law, "
                                  f"'{model.tangential.id}' included, has that form")
    if normal.id == "hertz" and (eta == 0.0 or damp.id in ("none", "quarter")):
        law = HERTZ
        young_eff = normal.k / (4.0 / 3.0 * math.sqrt(r))  # F = (4/3)E*√R̄ δ^3/2
        gamma = eta / (2.0 * math.sqrt(2.0 * m * young_eff * math.sqrt(r))) if eta > 0 else 0.0
        kn_note = f"E* = {young_eff:.10g} Pa (Kn = 2E*√(R̄δ), F = ⅔Knδ)"
    elif normal.id == "hooke" and damp.id in ("none", "constant"):
        law = LINEAR
        young_eff = normal.k / linear_kn(1.0, r, pair.wall)
        gamma = eta / (2.0 * math.sqrt(m * normal.k)) if eta > 0 else 0.0
        kn_note = (f"E* = {young_eff:.10g} Pa, chosen so that Kratos' Kn = "
                   f"{'' if pair.wall else '1.432·'}π·0.31225·R̄·E* is the seed's k = {normal.k:.10g} N/m")
    else:
        return refused("kratos", f"no Kratos DEM discontinuum law has the δ^{normal.exponent:g} spring with a "
                                  f"δ^{damp.exponent:g} dashpot (Hertz_viscous_Coulomb damps with 2γ√(m̄Kn) ∝ δ^1/4, "
                                  "Linear_viscous_Coulomb with a constant)")
    if eta > 0.0 and not contact.limit_force:
        fid = APPROXIMATE
        reasons.append("Kratos holds the total normal force at ≥ 0 (its dashpot is cut where it would pull); "
                       f"the seed's '{nid}' without limit_force lets it pull at the end of the contact")
    keywords = {r: law for r in reasons}  # the discontinuum law's own clamp
    nat = Native("kratos", normal=law, normal_args=(young_eff,), damping="gamma", damping_coeff=gamma,
                 tangential="none", limit=True,
                 props={"young_eff": young_eff, "gamma": gamma, "wall": pair.wall},
                 comments=[f"{law}: {kn_note}",
                           f"DAMPING_GAMMA γ = {gamma:.17g} (the seed's η = 2γ√(m̄Kn)), set on the contact's "
                           "properties after Kratos' own e → γ",
                           "STATIC_FRICTION = DYNAMIC_FRICTION = 0, no rolling friction, no global damping"])
    return Mapping("kratos", fid, reasons, nat, keywords)


def twin(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    e_star, gamma = nat.normal_args[0], nat.damping_coeff
    if nat.normal == HERTZ:
        k_el, a = 4.0 / 3.0 * e_star * math.sqrt(r), 1.5
        c, b = 2.0 * gamma * math.sqrt(2.0 * m * e_star * math.sqrt(r)), 0.25
    elif nat.normal == LINEAR:
        k_el, a = linear_kn(e_star, r, bool(nat.props.get("wall"))), 1.0
        c, b = 2.0 * gamma * math.sqrt(m * k_el), 0.0
    else:
        raise ValueError(f"no twin for Kratos law {nat.normal!r}")
    if nat.tangential != "none":
        raise ValueError(f"no twin for Kratos tangential {nat.tangential!r}")
    return twins.normal_law(k_el, a, c, b, True), twins.no_friction()
