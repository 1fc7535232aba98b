"""Yade 2023.02a's vocabulary: a seed model → Yade's interaction physics and law with their fidelity
(:func:`map_model`), and those settings → the reference laws that compute what Yade computes (:func:`twin`).

Two of Yade's laws are used, as read in Yade's sources (pkg/dem/ViscoelasticPM.cpp, HertzMindlin.cpp,
ScGeom.cpp, Ig2_Facet_Sphere_ScGeom.cpp, NewtonIntegrator.cpp):

* ``ViscElPhys`` (``Ip2_ViscElMat_ViscElMat_ViscElPhys`` + ``Law2_ScGeom_ViscElPhys_Basic``), given kn, cn,
  ks, cs directly: Fn = kn δ + cn δ̇, **held at ≥ 0** (the law drops any attraction); Ft: an incremental
  elastic force ks·v_t·dt capped at μ|Fn| (the spring only), plus cs·v_t while it sticks. Each material's
  value is combined in series (1/(1/a + 1/b)), so both bodies (and a wall) carry twice the pair's value.
* ``MindlinPhys`` (``Ip2_FrictMat_FrictMat_MindlinPhys`` + ``Law2_ScGeom_MindlinPhys_Mindlin``): Fn =
  kno δ^{3/2} with kno = (4/3)E*√R̄_Y; with betan > 0 a dashpot cn = 2 betan √(m̄ · 3/2 kno δ^½) and the total
  held at ≥ 0; Ft incremental with ks = kso √δ, kso = 2√(4R̄_Y) G/(2 − ν̄) (G, ν̄ the materials' means),
  capped at μ|Fn| (spring only), plus cs v_t while sticking (cs = 2 betas √(m̄ ks)).
  R̄_Y is Yade's radius: R1R2/(R1+R2) for a pair, but **R/2 on a wall** (Ig2_Wall_Sphere_ScGeom gives the
  wall the sphere's radius); the deck sets Young's modulus so that kno is the seed's K_HZ with the true R̄.

Friction: μ = tan(min(φ1, φ2)) with φ in radians (frictionAngle = atan μ is written).
"""

from __future__ import annotations

import math

from ...reference import twins
from ...laws.model import ResolvedModel
from ...laws.damping import ConstantDamping, NoDamping, QuarterDamping
from ...laws.normal import HertzNormal, HookeNormal, HysteresisNormal, NormalLaw
from ...laws.tangential import (TRUNC_SPRING, NoTangential, SpringTangential, SqrtSpringTangential, TangentialLaw,
                                ViscousTangential)
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused, worst
from ..mapping import mu_of

VISCEL = "ViscElPhys"
MINDLIN = "MindlinPhys"
LUDING = "LudingPhys"  # LudingMat + Ip2_LudingMat_LudingMat_LudingPhys + Law2_ScGeom_LudingPhys_Basic (kc = G0 = 0)
# Ip2_FrictMat_FrictMat_FrictPhys + this Law2: a ViscElPhys Native whose props carry law2 = CUNDALL (deck.py)
CUNDALL = "Law2_ScGeom_FrictPhys_CundallStrack"
LAW2 = {VISCEL: "Law2_ScGeom_ViscElPhys_Basic", MINDLIN: "Law2_ScGeom_MindlinPhys_Mindlin",
        LUDING: "Law2_ScGeom_LudingPhys_Basic"}  # each physics' law
CLAMP = ("Yade's {law} holds the total normal force at ≥ 0 (it drops the dashpot's attraction at the end of "
         "the contact); the case has limit_force = false")


def map_model(model: ResolvedModel, cp: dict) -> Mapping:
    """The contact's slot records, by class (named here by their ids): normal hooke | hertz, damping none | constant
    (hooke) or none | quarter (hertz), tangential none | viscous | spring."""
    contact, pair = model.contact, model.pair
    normal, damp, tl = contact.normal, contact.damping, contact.tangential
    m, r = pair.m_eff, pair.r_eff
    eta = getattr(damp, "eta", 0.0)
    reasons: list[str] = []
    keywords: dict[str, str] = {}  # an approximate reason → the Yade class or attribute it is about
    comments: list[str] = []
    fid = EXACT
    if type(normal) is HysteresisNormal:
        return _luding(model)
    if type(normal) not in (HookeNormal, HertzNormal):
        return refused("yade", f"no Yade law for the normal record '{normal.id}'")
    if type(normal) is HookeNormal and (eta == 0.0 or type(damp) in (NoDamping, ConstantDamping)):
        nat = Native("yade", normal=VISCEL, limit=True)
        nat.props.update(kn=normal.k, cn=eta, ks=0.0, cs=0.0, mu=0.0)
        comments.append(f"ViscElMat kn, cn given directly: the pair's kn = {normal.k:.10g} N/m, cn = {eta:.10g} "
                        "kg/s (each material carries twice: Yade combines them in series)")
    elif type(normal) is HertzNormal and (eta == 0.0 or type(damp) in (NoDamping, QuarterDamping)):
        nat = Native("yade", normal=MINDLIN, limit=eta > 0.0 or model.limit_force)
        # cn = 2 betan √(m̄ · 3/2 kno) δ^¼ = η δ^¼
        betan = eta / (2.0 * math.sqrt(1.5 * m * normal.k)) if eta > 0.0 else 0.0
        nat.props.update(kno=normal.k, betan=betan, betas=0.0, kso=0.0, mu=0.0, r_eff=r)
        comments.append(f"MindlinPhys kno = (4/3)E*√R̄ = {normal.k:.10g} N/m^1.5 (Young's modulus set for Yade's "
                        f"R̄_Y), betan = {betan:.17g}")
    elif type(normal) is HertzNormal:
        return refused("yade", f"Yade's Hertz–Mindlin dashpots grow as δ^¼ (alpha from en, or betan); the "
                               f"normal law '{model.normal.id}' damps as δ^{damp.exponent:g}")
    else:
        return refused("yade", f"no Yade law for normal '{model.normal.id}'")
    if nat.limit and eta > 0.0 and not model.limit_force:
        fid = APPROXIMATE
        reasons.append(CLAMP.format(law=nat.normal))
        keywords[reasons[-1]] = LAW2[nat.normal]
    p = nat.props
    if type(tl) is NoTangential:
        nat.tangential = "none"
    else:
        mu, f_mu = mu_of(model, reasons)
        if f_mu == APPROXIMATE:
            keywords[reasons[-1]] = "frictionAngle"
        fid = worst(fid, f_mu)
        p["mu"] = mu
        if nat.normal == VISCEL and type(tl) is ViscousTangential:
            # ks = 0: the elastic part stays 0, never above μ|Fn|, so cs v_t is added uncapped
            nat.tangential = "viscous"
            p["cs"] = tl.eta
            comments.append(f"ViscElMat ks = 0, cs = {tl.eta:.10g} kg/s: Ft = cs v_t, never capped")
        elif nat.normal == VISCEL and type(tl) is SpringTangential and not tl.eta_normal:
            nat.tangential = "spring"
            p["ks"], p["cs"] = tl.kt, tl.eta
            comments.append(f"ViscElMat ks = {tl.kt:.10g} N/m, cs = {tl.eta:.10g} kg/s, frictionAngle = atan μ")
            if tl.eta > 0.0 and tl.truncation != TRUNC_SPRING:
                fid = worst(fid, APPROXIMATE)
                reasons.append("Yade caps the spring only (the dashpot is added uncapped while sticking, dropped "
                               "while slipping); the case asks for another truncation")
                keywords[reasons[-1]] = LAW2[VISCEL]
            fid = worst(fid, APPROXIMATE)
            reasons.append("oblique impacts: on a wall Yade's slip velocity and torque use the arm R − δ (the "
                           "contact point on the wall's plane), and it turns the history with ScGeom's first-order "
                           "rotation")
            keywords[reasons[-1]] = "ScGeom (Ig2_Wall_Sphere_ScGeom, Ig2_Sphere_Sphere_ScGeom)"
        elif nat.normal == MINDLIN and type(tl) is SqrtSpringTangential:
            why = _mindlin_shear(model, tl, nat, eta, comments)
            if why:
                return refused("yade", why)
            fid = worst(fid, APPROXIMATE)
            reasons.append(MINDLIN_SHEAR)
            keywords[reasons[-1]] = LAW2[MINDLIN]
        else:
            return refused("yade", f"no Yade law pairs tangential '{model.tangential.id}' with the normal law "
                                   f"mapped here ({nat.normal})")
    nat.comments = comments
    return Mapping("yade", fid, reasons, nat, keywords)


# measured (docs/yade.md): the seed law by the adaptive solver against Yade's twin at the suite's dt
MINDLIN_SHEAR = ("Yade's Mindlin shear force is incremental (dFt = −kso√δ v_s dt on a force history turned by "
                 "ScGeom::rotate, the spring capped alone at μ|Fn|), not Kt(δ)·ξ, and its slip velocity is ScGeom's "
                 "ratcheting-corrected one; measured against the seed law: {measured}")
MINDLIN_SHEAR = MINDLIN_SHEAR.format(measured="with the normal force held ≥ 0 in both, the tangential restitution "
                                     "9.4e-2 and the rebound spin 1.9e-1 apart on oblique-tti (30° on a wall; "
                                     "1.2e-1 and 2.2e-1 with truncation = overlap)")


def _mindlin_shear(model: ResolvedModel, tl, nat: Native, eta: float, comments: list) -> str:
    """Yade's Mindlin shear for a seed Kt = kt√(R̄δ) (DDt, TTIt) into ``nat``'s props; the reason it cannot be
    ('' where it can): kso = kt√R̄ (Yade's ks = kso√δ) needs kso/kno = 3(1 − ν)/(2 − ν) with ν in (−1, 0.5), and
    its dashpot cs = 2 betas √(m̄ ks) grows as δ^¼, as the normal one: TTIt's ηt = x·ηn is betas, a constant ηt is
    not Yade's."""
    p, m, r = nat.props, model.pair.m_eff, model.pair.r_eff
    kso = tl.kt * math.sqrt(r)
    rho = kso / p["kno"]
    if not 1.0 < rho < 2.0:
        return (f"Yade's Mindlin shear stiffness is kso = {rho:.4g} kno here; its materials give kso/kno = "
                "3(1 − ν)/(2 − ν) in (1, 2) only (ν in (−1, 0.5))")
    betas = 0.0
    if tl.eta > 0.0 and not tl.eta_normal:
        return (f"Yade's Mindlin shear dashpot grows as δ^¼ (cs = 2 betas √(m̄ ks)); the case's ηt = {tl.eta:g} "
                "N·s/m is constant")
    if tl.eta_normal:
        betas = tl.eta * eta / (2.0 * math.sqrt(m * kso))  # cs = x ηn δ^¼ (0 with an undamped normal law)
    nat.tangential = "mindlin"
    p.update(kso=kso, betas=betas)
    comments.append(f"MindlinPhys kso = kt√R̄ = {kso:.10g} (Poisson's ratio set for kso/kno), betas = {betas:.17g}")
    return ""


# measured (docs/yade.md): the seed's HLS by the adaptive solver against Yade's Luding twin at the suite's dt
LUDING_LAG = ("Yade's Luding law computes its unloading stiffness k2 = k1 + (kp − k1) δ_max/δ_Pmax from the largest "
              "overlap of the step before, and δ_0 with that k2, then unloads along min(K_L δ, k2 (δ − δ_0)): a line "
              "through (δ_max, K_L δ_max) only to one step's growth of k2 (measured against the seed's HLS: "
              "{measured})")
LUDING_MEASURED = ("2.3e-5 in restitution, 8.1e-5 in energy dissipated on normal-hls-pair (constant K_U, 0.1 to 10 "
                   "m/s); 7.2e-7 and 6.8e-6 in restitution with variable unloading, S = 2000 and 20000 1/m")
LUDING_CONSTANT = ("HLS's constant K_U = K_L/ε² as Yade's Luding unloading stiffness K_L(1 + S δ_max), which grows "
                   "with the largest overlap: S = {s:.6g} 1/m matches it at the case's impact speed (δ_max = "
                   "v√(m̄/K_L) = {dmax:.6g} m); other speeds, or gravity, differ")
LUDING_WALL = ("Yade's Luding law is elastic against a Wall: its plastic depth φ_F·2a1a2/(a1 + a2) takes the radius "
               "of a body that is not a sphere as 0, so δ_0 = 0 and the contact loads and unloads along kp (measured on "
               "normal-hls-wall at 1 m/s: restitution 1.0005 where HLS gives 0.957, the peak force 12.98 N for "
               "9.18 N); no other Yade law of this build is a linear hysteretic spring "
               "(Law2_ScGeom6D_NormalInelasticityPhys_NormalInelasticity is not in it)")


def _luding(model: ResolvedModel) -> Mapping:
    """HLS between two spheres as Yade's Luding law: k1 = K_L and, with δ_lim above the overlap the collision
    reaches, kp = K_L(1 + S δ_lim) and φ_F = δ_lim (kp − k1)/(2R̄ kp), so that δ_Pmax = δ_lim and the unloading
    stiffness is K_L(1 + S δ_max), HLS's variable K_U (constant K_U: S matched at the impact speed)."""
    contact, pair = model.contact, model.pair
    law = contact.normal
    if pair.wall:
        return refused("yade", LUDING_WALL)
    if type(contact.tangential) is not NoTangential:
        return refused("yade", f"Yade's Luding law is mapped for HLS without friction; the case's tangential law "
                               f"is '{model.tangential.id}'")
    m, r, v = pair.m_eff, pair.r_eff, pair.impact_speed
    dmax = v * math.sqrt(m / law.kl)
    reasons = [LUDING_LAG.format(measured=LUDING_MEASURED)]
    s = law.s
    if law.ku > 0.0:
        s = (law.ku / law.kl - 1.0) / dmax
        reasons.append(LUDING_CONSTANT.format(s=s, dmax=dmax))
    if not (s > 0.0 and math.isfinite(s)):
        return refused("yade", f"Yade's Luding law needs an unloading stiffness above the loading one (S = {s:g})")
    d_lim = max(1.0 / s, 4.0 * dmax)
    kp = law.kl * (1.0 + s * d_lim)
    phi_f = d_lim * (kp - law.kl) / (kp * 2.0 * r)
    nat = Native("yade", normal=LUDING, tangential="none", limit=True,
                 props={"k1": law.kl, "kp": kp, "phi_f": phi_f, "s": s, "kl": law.kl, "r_eff": r},
                 comments=[f"LudingMat k1 = {law.kl:.10g} N/m, kp = {kp:.10g} N/m, PhiF = {phi_f:.10g} (δ_Pmax = "
                           f"{d_lim:.6g} m above the collision's δ_max {dmax:.6g} m: K_U = K_L(1 + S δ_max), "
                           f"S = {s:.10g} 1/m), kc = ks = G0 = 0 (each material carries the pair's value)"])
    return Mapping("yade", APPROXIMATE, reasons, nat, {r_: LAW2[LUDING] for r_ in reasons})


def twin_rules(nat: Native, rules: dict) -> dict:
    """The engine's rules for the twin of ``nat``. CundallStrack and Mindlin keep their shear force as the history,
    turned by ScGeom::rotate before the increment, and take the slip as ScGeom's ratcheting-corrected velocity
    α(v1 − v2) + ω1 × R1 n + ω2 × R2 n, α = (R1 + R2)/(R1 + R2 − δ) (a Wall carries the sphere's radius).
    CundallStrack (sphericalBodies) puts its torque at R − δ/2 on a wall too; Mindlin at the contact point
    (R − δ on a wall). Measured against Yade runs: this combination, and no other of these arms, meets oblique
    and spinning impacts, pair and wall, to ≤ 3e-12 (tests/test_yade.py)."""
    if nat.props.get("law2") == CUNDALL and nat.tangential == "spring":
        return {**rules, "rotation": "scgeom", "slip_arm": "ratchet", "wall_slip_arm": "ratchet",
                "wall_torque_arm": "contact"}
    if nat.normal == MINDLIN and nat.tangential == "mindlin":
        # its own getIncidentVel with the ratcheting correction, pair and wall alike; torques at the contact point
        return {**rules, "rotation": "scgeom", "slip_arm": "ratchet", "wall_slip_arm": "ratchet"}
    return rules


def twin(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    p = nat.props
    mu = p.get("mu", 0.0)
    if nat.normal == VISCEL:
        nl = NormalLaw.from_slots(HookeNormal(k=p["kn"]), ConstantDamping(eta=p["cn"]), True)
        if nat.tangential == "viscous":
            return nl, TangentialLaw.from_slot(ViscousTangential(eta=p["cs"], mu_s=mu, mu_k=mu, r_eff=r, m_eff=m))
        if nat.tangential == "spring":
            # CundallStrack: the force itself is the history (ScGeom::rotate turns it, −ks Δu_s adds to it)
            return nl, TangentialLaw.from_slot(SpringTangential(kt=p["ks"], eta=p["cs"], mu_s=mu, mu_k=mu,
                                                                truncation=TRUNC_SPRING, r_eff=r, m_eff=m,
                                                                force_history=p.get("law2") == CUNDALL))
        return nl, twins.no_friction()
    if nat.normal == MINDLIN:
        c = 2.0 * p["betan"] * math.sqrt(1.5 * m * p["kno"])
        nl = NormalLaw.from_slots(HertzNormal(k=p["kno"]), QuarterDamping(eta=c), nat.limit)
        if nat.tangential == "mindlin":
            factor = (2.0 * p["betas"] * math.sqrt(m * p["kso"]) / c) if c > 0.0 else 0.0
            return nl, TangentialLaw.from_slot(SqrtSpringTangential(
                kt=p["kso"] / math.sqrt(r), eta=factor, eta_normal=True, mu_s=mu, mu_k=mu, truncation=TRUNC_SPRING,
                force_history=True, r_eff=r, m_eff=m))
        return nl, twins.no_friction()
    if nat.normal == LUDING:
        # the nearest seed record, for the model's description: the twin's steps are twins_luding's (twin_collide)
        return (NormalLaw.from_slots(HysteresisNormal(kl=p["kl"], ku=0.0, s=p["s"]), NoDamping(), True),
                twins.no_friction())
    raise ValueError(f"no twin for Yade physics {nat.normal!r}")


def twin_law_array(nat: Native, case):
    """twins_luding's numbers for a Luding native on ``case``'s pair of spheres."""
    from ...reference import twins_luding

    a1, a2 = (q.radius for q in case.particles)
    return twins_luding.law_array(nat.props["k1"], nat.props["kp"], nat.props["phi_f"], 2.0 * a1 * a2 / (a1 + a2))
