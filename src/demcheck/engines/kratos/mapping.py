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
* Four more 3-D laws are twinned for a native configuration and the audit (:func:`law_numbers`, measured against
  runs: docs/kratos.md): ``DEM_D_Linear_HighStiffness``, ``DEM_D_Hertz_viscous_Coulomb_Nestle``,
  ``DEM_D_Linear_Simple_Coulomb``, ``DEM_D_Linear_Custom_Constants``; the seed models map onto the two above only.

γ (DAMPING_GAMMA) is what Kratos derives from COEFFICIENT_OF_RESTITUTION (a bisection to 1e-4 for Linear
laws, Thornton's fit for Hertz laws); demcheck's runner sets the γ of the seed's η directly on the contact's
properties after Kratos has initialised them, so the run carries the seed's damping to round-off.
"""

from __future__ import annotations

import math

from ...reference import twins
from ...laws.model import ResolvedModel
from ...laws.damping import ConstantDamping, NoDamping, QuarterDamping
from ...laws.normal import HertzNormal, HookeNormal, HysteresisNormal, NormalLaw
from ...laws.tangential import (TRUNC_SPRING, NoTangential, SpringTangential, SqrtSpringTangential,
                               TangentialLaw)
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused
from ..mapping import mu_of

HERTZ = "DEM_D_Hertz_viscous_Coulomb"
LINEAR = "DEM_D_Linear_viscous_Coulomb"
HIGH = "DEM_D_Linear_HighStiffness"
NESTLE = "DEM_D_Hertz_viscous_Coulomb_Nestle"
SIMPLE = "DEM_D_Linear_Simple_Coulomb"
CUSTOM = "DEM_D_Linear_Custom_Constants"
LAWS = (HERTZ, LINEAR, HIGH, NESTLE, SIMPLE, CUSTOM)  # twinned (the three last: a native configuration's, not mapped)
# how each twinned law differs from its parent, as measured against Kratos 10.4.4 runs (docs/kratos.md):
# Linear_HighStiffness: Kn five times Linear_viscous_Coulomb's, Kt (and its dashpot) that of the unaugmented Kn;
# Hertz_viscous_Coulomb_Nestle: Hertz_viscous_Coulomb's forces exactly (the source's tangential dashpot
# 2γ√(m̄Kn)/0.55 does not act in the installed build); Linear_Simple_Coulomb: Kn = E₁·2R₁R₂/(R₁ + R₂) (E₁·R on a
# wall), Kt = ν₁Kn, no dashpot, no √(δ/δ_prev), the cap tan(STATIC_FRICTION)·Fn
# the laws `demcheck audit` probes in a user's project: E* and γ are all it needs of them (Simple_Coulomb needs the
# first material's E and ν, Custom_Constants the relation's K_NORMAL and K_TANGENTIAL: not read yet)
AUDITED = (HERTZ, LINEAR, HIGH, NESTLE)
PARENT = {HERTZ: HERTZ, LINEAR: LINEAR, HIGH: LINEAR, NESTLE: HERTZ, SIMPLE: SIMPLE, CUSTOM: LINEAR}
KN_FACTOR = {HIGH: 5.0}
FRICTION = "spring-dashpot-coulomb"  # a Native's tangential: the law's own incremental spring, dashpot and cap
LINEAR_BETA = 1.432  # the particle–particle factor of DEM_D_Linear_viscous_Coulomb's Kn (absent for walls)
LINEAR_RADIUS = 0.31225  # its modified radius factor √(α(2 − α)), α = 0.05


def linear_kn(young_eff: float, r_eff: float, wall: bool, factor: float = 1.0) -> float:
    """DEM_D_Linear_viscous_Coulomb's Kn, in Kratos' order of operations (``factor``: Linear_HighStiffness' 5)."""
    beta = factor if wall else factor * LINEAR_BETA
    return beta * young_eff * math.pi * (r_eff * LINEAR_RADIUS)


def particle_young(e_star: float, nus: list, wall: bool) -> float:
    """The YOUNG_MODULUS the deck gives the particles for a contact's E* (a wall's face is rigid)."""
    if wall:
        return e_star * (1.0 - nus[0] ** 2)
    return e_star * ((1.0 - nus[0] ** 2) + (1.0 - nus[1] ** 2))


def map_model(model: ResolvedModel, cp: dict) -> Mapping:
    """The contact's slot records, by class (named here by their ids): normal hertz with damping none | quarter, or
    hooke with none | constant; tangential none."""
    contact, pair = model.contact, model.pair
    normal, damp = contact.normal, contact.damping
    eta = getattr(damp, "eta", 0.0)
    m, r = pair.m_eff, pair.r_eff
    nid = model.normal.id
    reasons: list[str] = []
    fid = EXACT
    if type(normal) is HysteresisNormal:
        return refused("kratos", "Kratos DEM 10.4.4 has no linear hysteretic (HLS) discontinuum law")
    if type(normal) not in (HookeNormal, HertzNormal):
        return refused("kratos", f"no Kratos DEM discontinuum law for the normal record '{normal.id}'")
    tl = contact.tangential
    if type(tl) is not NoTangential:
        why = _no_friction_law(normal, tl)
        if why:
            return refused("kratos", why)
    if type(normal) is HertzNormal and (eta == 0.0 or type(damp) in (NoDamping, QuarterDamping)):
        law = HERTZ
        young_eff = normal.k / (4.0 / 3.0 * math.sqrt(r))  # F = (4/3)E*√R̄ δ^3/2
        gamma = eta / (2.0 * math.sqrt(2.0 * m * young_eff * math.sqrt(r))) if eta > 0 else 0.0
        kn_note = f"E* = {young_eff:.10g} Pa (Kn = 2E*√(R̄δ), F = ⅔Knδ)"
    elif type(normal) is HookeNormal and type(damp) in (NoDamping, ConstantDamping):
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
                           "properties after Kratos' own e → γ"])
    if type(tl) is NoTangential:
        nat.comments.append("STATIC_FRICTION = DYNAMIC_FRICTION = 0, no rolling friction, no global damping")
        return Mapping("kratos", fid, reasons, nat, keywords)
    n_reasons = len(reasons)
    mu, _ = mu_of(model, reasons)
    for reason in reasons[n_reasons:]:  # one friction coefficient for the seed's two: the deck's setting
        keywords[reason] = "STATIC_FRICTION = DYNAMIC_FRICTION"
    rho = tl.kt / normal.k if law == LINEAR else 2.0 / 3.0 * tl.kt * math.sqrt(r) / normal.k
    if not 2.0 / 3.0 < rho < 4.0 / 3.0:
        return refused("kratos", f"Kratos' tangential stiffness is Kt = 4G*/E*·Kn = 2(1 − ν)/(2 − ν)·Kn, in (2/3, 4/3)"
                                  f"·Kn for ν in (−1, 0.5); the case's Kt = {rho:.4g}·Kn")
    nu = (2.0 - 2.0 * rho) / (2.0 - rho)
    nat.tangential = FRICTION
    nat.props.update(mu_s=mu, mu_d=mu, decay=0.0, poisson=nu)
    nat.comments.append(f"Kt/Kn = 4G*/E* = 2(1 − ν)/(2 − ν) = {rho:.10g}: POISSON_RATIO ν = {nu:.17g} (E set for "
                        f"E*); STATIC_FRICTION = DYNAMIC_FRICTION = {mu:.10g}, FRICTION_DECAY = 0, no rolling "
                        "friction, no global damping")
    reasons.append(FRICTION_REASON[type(tl) is SqrtSpringTangential].format(
        ratio=math.sqrt(rho), measured=MEASURED.get((model.tangential.id, tl.truncation), "not measured for this law")))
    keywords[reasons[-1]] = law
    return Mapping("kratos", APPROXIMATE, reasons, nat, keywords)


# the seed's tangential laws Kratos' own law stands for, and why not exactly
FRICTION_REASON = {
    False: ("Kratos' tangential force is its own law: an incremental spring on the elastic force (turned with the "
            "normal, its increment from the contact point's displacement with the arm R − δ on a wall), a dashpot "
            "2γ√(m̄Kt) = {ratio:.4g}·ηn tied to the normal one, and the cap μ|Fn| split between spring and dashpot "
            "in its own way, not the seed's; measured against the seed law: {measured}"),
    True: ("Kratos' tangential force is its own law: an incremental spring on the elastic force (turned with the "
           "normal, shrunk by √(δ/δ_prev) on unloading, its increment from the contact point's displacement with the "
           "arm R − δ on a wall), a dashpot 2γ√(m̄Kt) = {ratio:.4g}·ηn, and the cap μ|Fn| split between spring and "
           "dashpot in its own way, not the seed's; measured against the seed law: {measured}"),
}
# measured (docs/kratos.md): the seed law by the adaptive solver against Kratos' twin at the suite's dt, on the
# suite's 45° impacts on a wall (the normal clamp of Kratos included; the seed's glass, ν = 0.22), by (law,
# truncation): the tangential restitution and the rebound spin apart
MEASURED = {
    ("spring_sliding", 1): "7.3e-2 in tangential restitution, 1.3e-1 in rebound spin (oblique-spring-sliding)",
    ("lsd_sliding", 0): "1.4e-2 in tangential restitution, 2.9e-2 in rebound spin (oblique-lsd-sliding-force)",
    ("lsd_sliding", 1): "3.3e-2 in tangential restitution, 7.6e-2 in rebound spin (oblique-lsd-sliding-overlap)",
    ("lsd_sliding", 2): "6.4e-2 in tangential restitution, 1.7e-1 in rebound spin (oblique-lsd-sliding-spring)",
    ("tti", 0): "3.3e-2 in tangential restitution, 7.4e-2 in rebound spin (oblique-tti)",
    ("tti", 1): "6.3e-2 in tangential restitution, 1.3e-1 in rebound spin (oblique-tti-overlap)",
}


def _no_friction_law(normal, tl) -> str:
    """Why Kratos' own tangential law cannot stand for the seed's ('' where it can): a spring Kt = ρKn beside
    its normal law (constant with Linear_viscous_Coulomb, √δ with Hertz_viscous_Coulomb), ρ = 4G*/E* =
    2(1 − ν)/(2 − ν) in (2/3, 4/3) for ν in (−1, 0.5), its dashpot √ρ times the normal one."""
    family = {HookeNormal: SpringTangential, HertzNormal: SqrtSpringTangential}[type(normal)]
    if type(tl) is not family:
        return (f"Kratos' tangential force is part of its normal law (an incremental spring Kt = 4G*Kn/E*, "
                f"{'constant' if type(normal) is HookeNormal else '∝ √δ'} with this normal law, a dashpot 2γ√(m̄Kt), μ "
                f"decaying with the slip speed); the seed's tangential record '{tl.id}' is not a spring of that form")
    return ""



def law_numbers(nat: Native, m: float, r: float) -> dict:
    """What a twinned law computes on a pair (m̄, R̄): its normal records ``spring`` (hooke or hertz, k_el δ^a) and
    ``damping`` (the dashpot c δ^b; k_el, a, c, b: their numbers), Kn's coefficient (× √δ for Hertz) and the
    tangential kernel's options."""
    law, e_star, gamma, wall = nat.normal, nat.normal_args[0], nat.damping_coeff, bool(nat.props.get("wall"))
    parent = PARENT.get(law)
    if parent is None:
        raise ValueError(f"no twin for Kratos law {law!r}")
    out = {"hertz": parent == HERTZ, "rho": None, "gamma": gamma, "minor": None}
    if parent == HERTZ:
        out.update(kn=2.0 * e_star * math.sqrt(r), spring=HertzNormal(k=4.0 / 3.0 * e_star * math.sqrt(r)),
                   damping=QuarterDamping(eta=2.0 * gamma * math.sqrt(2.0 * m * e_star * math.sqrt(r))))
    elif parent == LINEAR:
        k = nat.props["k_normal"] if law == CUSTOM else linear_kn(e_star, r, wall, KN_FACTOR.get(law, 1.0))
        out.update(kn=k, spring=HookeNormal(k=k), damping=ConstantDamping(eta=2.0 * gamma * math.sqrt(m * k)))
        if law in KN_FACTOR and nat.tangential == FRICTION:
            out["rho"] = tangential_ratio(nat) / KN_FACTOR[law]
        elif law == CUSTOM:
            out["rho"] = nat.props["k_tangential"] / k
    else:  # Simple_Coulomb: element 1's E and ν, no dashpot, the cap tan(STATIC_FRICTION)·Fn
        nu = nat.props.get("poisson")
        if nu is None:
            raise ValueError(f"{law}'s twin needs the deck's POISSON_RATIO (its Kt = ν·Kn)")
        k = particle_young(e_star, [nu, nu], wall) * (r if wall else 2.0 * r)
        out.update(kn=k, spring=HookeNormal(k=k), damping=NoDamping(), rho=nu, gamma=0.0, minor=False)
    # the records' numbers, for the wall and settling scenarios' force closures (kratos/scenario.py)
    spring, dashpot = out["spring"], out["damping"]
    out.update(k_el=spring.k, a=spring.exponent, c=getattr(dashpot, "eta", 0.0), b=dashpot.exponent)
    return out


def twin(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    ln = law_numbers(nat, m, r)
    nl = NormalLaw.from_slots(ln["spring"], ln["damping"], True)
    if nat.tangential == FRICTION:
        # the nearest seed record, for the model's description only: the twin's steps are twins_kratos'
        # (Engine.twin_collide), whose history, rotation, cap and arms are Kratos' own
        kt = (ln["rho"] or tangential_ratio(nat)) * ln["kn"]
        record = SqrtSpringTangential if ln["hertz"] else SpringTangential
        mu_s, mu_d = friction_of(nat)
        return nl, TangentialLaw.from_slot(record(kt=kt / math.sqrt(r) if ln["hertz"] else kt,
                                                  eta=0.0, mu_s=mu_s, mu_k=mu_d,
                                                  truncation=TRUNC_SPRING, r_eff=r, m_eff=m, force_history=True))
    if nat.tangential != "none":
        raise ValueError(f"no twin for Kratos tangential {nat.tangential!r}")
    return nl, twins.no_friction()


def friction_of(nat: Native) -> tuple[float, float]:
    """(μs, μd) of the cap: Simple_Coulomb's is tan(STATIC_FRICTION) (an angle), the others' the two numbers."""
    if nat.normal == SIMPLE:
        mu = math.tan(nat.props["mu_s"])
        return mu, mu
    return nat.props["mu_s"], nat.props["mu_d"]


def tangential_ratio(nat: Native) -> float:
    """Kt/Kn = 4G*/E* of the materials the deck writes: 2(1 − ν)/(2 − ν) for two equal particles or a particle
    on a rigid face (Kratos' equiv_shear and equiv_young)."""
    nu = nat.props["poisson"]
    return 2.0 * (1.0 - nu) / (2.0 - nu)


def twin_law_array(nat: Native, m: float, r: float):
    """The numbers of twins_kratos' kernel for a frictional Kratos native on a pair (m̄, R̄)."""
    from ...reference import twins_kratos

    ln = law_numbers(nat, m, r)
    mu_s, mu_d = friction_of(nat)
    decay = 0.0 if nat.normal == SIMPLE else nat.props.get("decay", 0.0)
    return twins_kratos.law_array(ln["hertz"], ln["kn"], ln["rho"] or tangential_ratio(nat), ln["gamma"], m, mu_s,
                                  mu_d, decay, ln["minor"])
