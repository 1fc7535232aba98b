"""LIGGGHTS-PUBLIC 3.8.0's vocabulary: a seed model → ``pair_style gran`` settings with their fidelity
(:func:`map_model`), and settings → the reference laws that compute exactly what LIGGGHTS computes
(:func:`twin`)."""

from __future__ import annotations

import math

from ...reference import twins
from ...laws.model import ResolvedModel
from ...laws.damping import ConstantDamping, NoDamping, QuarterDamping, SqrtDamping
from ...laws.normal import HertzNormal, HookeNormal, HysteresisNormal, NormalLaw
from ...laws.tangential import (TRUNC_CAP, TRUNC_MAW, TRUNC_SPRING, LthTangential, NoTangential, SlidingTangential,
                                SpringTangential, SqrtSpringTangential, TangentialLaw, ViscousSlidingTangential,
                                ViscousTangential, WaltonTangential, ZzyTangential)
from ..damping import damping
from ..base import APPROXIMATE, EXACT, Mapping, Native, refused, worst
from ..mapping import HUGE_MU, SLIDING_XT, mu_of


def map_model(model: ResolvedModel, cp: dict) -> Mapping:
    """The contact's slot records, by class (named here by their ids): normal hooke | hertz | hls, damping none |
    constant | sqrt | quarter, tangential none | sliding | viscous | viscous_sliding | spring | sqrt_spring."""
    contact = model.contact
    nat = Native("liggghts", normal="", limit=model.limit_force)
    comments: list[str] = []
    if type(contact.normal) is HysteresisNormal:
        return _hysteretic(model, nat, comments)
    refusal = _map_normal(model, contact, nat, comments)
    if refusal is not None:
        return refusal
    if model.limit_force:
        comments.append("limitForce on: total normal force ≥ 0")
    return _map_tangential(model, contact, nat, comments)


def _hysteretic(model: ResolvedModel, nat: Native, comments: list[str]) -> Mapping:
    normal, tl = model.contact.normal, model.contact.tangential
    if normal.ku == 0.0:
        return _luding(model, nat)
    # edinburgh, linear (overlapExponent 1), no adhesion, e = 1: loading K_L = 2E*R̄, unloading r·K_L
    nat.normal = "edinburgh"
    nat.props.update(kl=normal.kl, unloading=normal.ku / normal.kl, adhesion=0.0, pulloff=0.0,
                     surface_energy=0.0, restitution=1.0)
    comments.append(f"edinburgh (fixKc on, overlapExponent 1, no adhesion, coefficientRestitution 1): "
                    f"K_L = 2E*R̄ = {normal.kl:.10g} N/m through the types' Young's moduli, UnloadingStiffness = "
                    f"K_U/K_L = {normal.ku / normal.kl:.17g}")
    if type(tl) is not NoTangential:
        return refused("liggghts", "edinburgh's tangential stiffness is 2E*√(R̄δ) with E* set for K_L; "
                                    "no seed tangential law shares it")
    nat.tangential = "off"
    nat.comments = comments
    return Mapping("liggghts", EXACT, [], nat)


def _map_normal(model: ResolvedModel, contact, nat: Native, comments: list[str]) -> Mapping | None:
    """The normal and damping slots into ``nat`` (None), or the refusal."""
    normal, damp, pair, p = contact.normal, contact.damping, model.pair, nat.props
    m, r = pair.m_eff, pair.r_eff
    eta = getattr(damp, "eta", 0.0)
    if type(normal) not in (HookeNormal, HertzNormal):
        return refused("liggghts", f"no LIGGGHTS normal model for the normal record '{normal.id}'")
    if type(normal) is HookeNormal and (eta == 0.0 or type(damp) in (NoDamping, ConstantDamping)):
        nat.normal = "hooke/stiffness"
        p.update(kn=normal.k, gamman=eta / m, kt=0.0, gammat=0.0)
        comments.append(f"hooke/stiffness kn = {normal.k:.10g} N/m, gamman = ηn/m̄ = {eta / m:.10g} 1/s (per pair, "
                        f"m̄ = {m:.10g} kg)")
    elif type(normal) is HertzNormal and (eta == 0.0 or type(damp) in (NoDamping, SqrtDamping)):
        nat.normal = "hertz/stiffness"
        gamman = eta / (m * math.sqrt(r))
        p.update(kn=normal.k / math.sqrt(r), gamman=gamman, kt=0.0, gammat=0.0)
        comments.append(f"hertz/stiffness kn = (4/3)Ē = {normal.k / math.sqrt(r):.10g} Pa, gamman = ηn/(m̄√R̄) = "
                        f"{gamman:.10g} (per pair, m̄ = {m:.10g} kg, R̄ = {r:.10g} m)")
    elif type(normal) is HertzNormal and type(damp) is QuarterDamping:
        nat.normal = "hertz"
        e_prime = twins.restitution_for_eta(eta / math.sqrt(m * normal.k), math.sqrt(5.0))
        if not (0.05 < e_prime <= 1.0):
            return refused("liggghts", f"TTIn's ηn = {eta:g} needs coefficientRestitution e′ = "
                                        f"{e_prime:.4g}, outside LIGGGHTS's 0.05 < e ≤ 1")
        # E*, G* as LIGGGHTS mixes the types' moduli (a rigid wall is a type of modulus 1e30 Pa: the same
        # to round-off)
        p.update(restitution=e_prime, youngs_eff=pair.e_eff, shear_eff=pair.g_eff)
        comments.append(f"hertz coefficientRestitution e′ = {e_prime:.17g}: TTIn's ηn = {eta:.10g} through "
                        "√5 β(e′)√(m̄K_HZ) (docs/models.md, Engine twins)")
    else:
        return refused("liggghts", f"no LIGGGHTS model for normal '{model.normal.id}'")
    return None


def _map_tangential(model: ResolvedModel, contact, nat: Native, comments: list[str]) -> Mapping:
    """The tangential slot into ``nat``."""
    tl, damp, pair, p = contact.tangential, contact.damping, model.pair, nat.props
    m = pair.m_eff
    eta = getattr(damp, "eta", 0.0)
    reasons: list[str] = []
    keywords: dict[str, str] = {}  # an approximate reason → the pair_style gran keyword it is about
    fid = EXACT
    nid, tid = model.normal.id, model.tangential.id
    stiff = nat.normal == "hooke/stiffness"
    if type(tl) is NoTangential:
        nat.tangential = "off"
    elif type(tl) in (LthTangential, ZzyTangential, WaltonTangential):
        return refused("liggghts", f"LIGGGHTS 3.8.0 has no {model.tangential.seed_name} law")
    else:
        mu, f_mu = mu_of(model, reasons)
        if f_mu == APPROXIMATE:
            keywords[reasons[-1]] = "coefficientFriction"
        fid = worst(fid, f_mu)
        p["friction"] = mu
        if type(tl) in (SlidingTangential, ViscousTangential, ViscousSlidingTangential):
            if not stiff:
                return refused("liggghts", f"no_history's dashpot follows the model's δ-law; a constant ηt "
                                            f"needs hooke/stiffness, i.e. normal 'lsd' (not '{nid}')")
            nat.tangential = "no_history"
            if type(tl) is SlidingTangential:
                p["gammat"] = SLIDING_XT * max(eta, 1.0) / m
                fid = worst(fid, APPROXIMATE)
                reasons.append(f"simple sliding friction as no_history with gammat = {p['gammat']:.4g} 1/s: a "
                               "regularised slider near v_t = 0")
                keywords[reasons[-1]] = "tangential no_history"
            else:
                p["gammat"] = tl.eta / m
                if type(tl) is ViscousTangential:
                    p["friction"] = HUGE_MU
                    if model.limit_force:
                        fid = worst(fid, APPROXIMATE)
                        reasons.append("with limitForce the Coulomb cap μ|Fn| is 0 wherever the normal force is "
                                       "held at 0, so the viscous force vanishes there too")
                        keywords[reasons[-1]] = "limitForce on"
                comments.append(f"no_history gammat = ηt/m̄ = {p['gammat']:.10g} 1/s"
                                + (f", coefficientFriction = {HUGE_MU:g} (no Coulomb limit)" if type(tl) is ViscousTangential
                                   else ""))
        elif type(tl) in (SpringTangential, SqrtSpringTangential):
            spring = _map_spring(model, contact, nat, comments, reasons, keywords)
            if isinstance(spring, Mapping):
                return spring
            fid = worst(fid, spring)
        else:
            return refused("liggghts", f"no LIGGGHTS equivalent of tangential '{tid}'")
    nat.comments = comments
    return Mapping("liggghts", fid, reasons, nat, keywords)


def _map_spring(model: ResolvedModel, contact, nat: Native, comments: list[str], reasons: list[str],
                keywords: dict[str, str]):
    """A spring tangential record as LIGGGHTS ``tangential history``: its fidelity, or the refusal."""
    tl, damp, pair, p = contact.tangential, contact.damping, model.pair, nat.props
    m, nid = pair.m_eff, model.normal.id
    eta = getattr(damp, "eta", 0.0)
    stiff = nat.normal == "hooke/stiffness"
    fid = EXACT
    nat.tangential = "history"
    if tl.eta_normal and eta > 0.0:  # TTIt on the hertz model: same Kt, γt = γn √(4G*/E*), dashpot
        # outside the cap (undamped, ηt = ηn = 0, it is DDt's case below on hertz/stiffness)
        if not (type(contact.normal) is HertzNormal and type(damp) is QuarterDamping):
            return refused("liggghts", "TTIt's ηt = ηn needs TTIn's normal damping")
        fid = APPROXIMATE
        ratio = math.sqrt(4.0 * pair.g_eff / pair.e_eff)
        reasons.append(f"hertz + history: Kt = 8G*√(R̄δ) as TTIt, but ηt = {ratio:.4f} ηn (√(4G*/E*)) and "
                       "the dashpot lies outside the Coulomb cap (spring-only truncation)")
        keywords[reasons[-1]] = "model hertz tangential history"
    elif type(tl) is SqrtSpringTangential:  # DDt on hertz/stiffness
        if nat.normal != "hertz/stiffness":
            return refused("liggghts", "Kt ∝ √δ (DDt) needs hertz/stiffness, whose normal law is "
                                        f"Hertz-type; normal '{nid}' is not")
        if tl.eta > 0.0 and not tl.eta_normal:
            return refused("liggghts", "DDt's constant ηt: hertz/stiffness damps with √(R̄δ)")
        p["kt"] = tl.kt
        nat.tangential_damping = False
        if tl.truncation == TRUNC_CAP:
            fid = APPROXIMATE
            reasons.append("LIGGGHTS truncates the spring at μ|Fn|; the case's truncation = force is the "
                           "seed's min() cap, which keeps the spring's extension (they part after a slip "
                           "that reverses)")
            keywords[reasons[-1]] = "tangential history"
        comments.append(f"hertz/stiffness kt = {tl.kt:.10g} Pa (Kt = kt √(R̄δ)), tangential_damping off")
    else:
        if not stiff:
            return refused("liggghts", "a constant Kt needs hooke/stiffness, i.e. normal 'lsd' "
                                        f"(not '{nid}')")
        p["kt"] = tl.kt
        p["gammat"] = tl.eta / m
        nat.tangential_damping = tl.eta > 0.0
        comments.append(f"hooke/stiffness kt = {tl.kt:.10g} N/m, gammat = ηt/m̄ = {p['gammat']:.10g} 1/s")
        if tl.truncation != TRUNC_SPRING and tl.eta > 0.0:
            fid = APPROXIMATE
            name = {TRUNC_CAP: "force", TRUNC_MAW: "overlap"}[tl.truncation]
            reasons.append("LIGGGHTS caps the spring only (truncation = spring: the dashpot is added "
                           f"uncapped while sticking and dropped while slipping); the case asks for "
                           f"truncation = {name}")
            keywords[reasons[-1]] = "tangential history"
    return fid


def luding_limit(props: dict, r: float) -> float:
    """luding's δ_lim = r/(r − 1) · phiF · 2R̄ (r = UnloadingStiffness, phiF = coefficientPlasticityDepth), as
    normal_model_luding.h computes it (R̄: the particle's radius on a wall)."""
    ratio = props["unloading"]
    return ratio / (ratio - 1.0) * props["plasticity_depth"] * 2.0 * r


def _luding(model: ResolvedModel, nat: Native) -> Mapping:
    """HLS with variable unloading as LIGGGHTS ``luding`` (no adhesion, no pull-off, e = 1: no dashpot).

    luding loads along k1 δ (k1 = LoadingStiffness) and, while δ_max < δ_lim, unloads along
    k2 (δ − δ_max) + k1 δ_max ≥ 0 with k2 = k1 + (r − 1) k1 δ_max/δ_lim: HLS's K_U = K_L + S·K_L·δ_max
    exactly when (r − 1)/δ_lim = S. r is free: δ_lim is chosen above the largest overlap the impact can reach
    (and r ≥ 2, so that k2Max − k1 = (r − 1)k1 loses no digits), and phiF follows."""
    normal, tl, pair = model.contact.normal, model.contact.tangential, model.pair
    if type(tl) is not NoTangential:
        return refused("liggghts", "luding's tangential stiffness is its loading stiffness (kt = kn); no seed "
                                    "tangential law shares it")
    kl, s, r_eff, m = normal.kl, normal.s, pair.r_eff, pair.m_eff
    v = pair.impact_speed
    if not math.isfinite(v):
        v = model.params.get("reference_velocity", math.nan)
    # the largest overlap of the loading line K_L δ at impact speed v, with the weight pressing along
    # (an upper bound for a pair, where gravity moves both bodies alike): ½K_L δ² − m̄|g|δ = ½m̄v²
    w = m * math.sqrt(sum(g * g for g in model.gravity))
    bound = (w + math.sqrt(w * w + kl * m * v * v)) / kl if math.isfinite(v) else math.nan
    d_lim = max(1.0 / s, 2.0 * bound) if math.isfinite(bound) else max(1.0 / s, r_eff)
    ratio = 1.0 + s * d_lim
    p = nat.props
    p.update(loading=kl, unloading=ratio, plasticity_depth=d_lim * (ratio - 1.0) / (2.0 * r_eff * ratio),
             adhesion=0.0, pulloff=0.0, restitution=1.0)
    d_lim = luding_limit(p, r_eff)  # as LIGGGHTS will compute it from the written numbers
    if math.isfinite(bound) and not bound < d_lim:
        return refused("liggghts", f"luding: δ_lim = {d_lim:.4g} m does not lie above the largest overlap "
                                    f"{bound:.4g} m; beyond δ_lim it loads along r·K_L, not K_L")
    nat.normal = "luding"
    nat.tangential = "off"
    reach = (f"above the impact's largest overlap {bound:.6g} m (K_L δ² = m̄v² with the weight)"
             if math.isfinite(bound) else "no impact speed: δ_lim at max(1/S, R̄)")
    nat.comments = [f"luding (coefficientAdhesionStiffness 0, pullOffForce 0, coefficientRestitution 1): "
                    f"LoadingStiffness = K_L = {kl:.10g} N/m, UnloadingStiffness r = {ratio:.17g}, "
                    f"coefficientPlasticityDepth phiF = {p['plasticity_depth']:.17g}",
                    f"δ_lim = r/(r−1)·phiF·2R̄ = {d_lim:.6g} m = (r − 1)/S, {reach}: "
                    f"K_U = K_L + (r − 1)K_L δ_max/δ_lim = K_L + S·F_max (S = {s:.10g} 1/m)"]
    return Mapping("liggghts", EXACT, [], nat)


def twin(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    p = nat.props
    if nat.normal == "luding":  # δ_max < δ_lim: K_U = k1 + (r − 1)k1 δ_max/δ_lim, i.e. S = (r − 1)/δ_lim
        s = (p["unloading"] - 1.0) / luding_limit(p, r)
        return (NormalLaw.from_slots(HysteresisNormal(kl=p["loading"], ku=0.0, s=s), NoDamping(), nat.limit),
                twins.no_friction())
    if nat.normal == "hooke/stiffness":
        spring = HookeNormal(k=p["kn"])
        dashpot = damping("stiffness_hooke", p["gamman"], spring, m, r)
        kt, sqrt_law, eta_t = p["kt"], False, m * p["gammat"]
    elif nat.normal == "hertz/stiffness":
        spring = HertzNormal(k=p["kn"] * math.sqrt(r))
        dashpot = damping("stiffness_hertz", p["gamman"], spring, m, r)
        kt, sqrt_law, eta_t = p["kt"], True, None  # γt = gammat m̄ √(R̄δ): the normal law's δ^½
    elif nat.normal == "hooke":  # characteristic velocity v_c: Kn from Hertz's energy at v_c; Kt = Kn, γt = γn
        y_eff, vc = p["youngs_eff"], p["characteristic_velocity"]
        spring = HookeNormal(k=16.0 / 15.0 * math.sqrt(r) * y_eff * (15.0 * m * vc * vc / (16.0 * math.sqrt(r) * y_eff))
                             ** 0.2)
        dashpot = damping("restitution_hooke", p["restitution"], spring, m, r)
        kt, sqrt_law, eta_t = spring.k, False, dashpot.eta
    elif nat.normal == "edinburgh":
        kl = p["kl"]
        return (NormalLaw.from_slots(HysteresisNormal(kl=kl, ku=kl * p["unloading"]), NoDamping(), nat.limit),
                twins.no_friction())
    elif nat.normal == "hertz":
        y_eff, g_eff = p["youngs_eff"], p["shear_eff"]
        spring = HertzNormal(k=4.0 / 3.0 * y_eff * math.sqrt(r))
        dashpot = damping("restitution_hertz", p["restitution"], spring, m, r)
        kt, sqrt_law, eta_t = 8.0 * g_eff, True, None
    else:
        raise ValueError(f"no twin for LIGGGHTS model {nat.normal!r}")
    nl = NormalLaw.from_slots(spring, dashpot, nat.limit)
    mu = p.get("friction", 0.0)
    if nat.tangential == "off" or mu == 0.0 and nat.tangential == "no_history":
        return nl, twins.no_friction()
    # the tangential dashpot: constant (hooke/stiffness), or a factor of the normal η(δ)
    if not nat.tangential_damping:
        factor, const = 0.0, 0.0
    elif nat.normal in ("hooke/stiffness", "hooke"):
        factor, const = None, eta_t
    elif nat.normal == "hertz/stiffness":
        # (an undamped normal law — TTIn at e = 1 — maps here with gamman = gammat = 0: no dashpot at all)
        factor = p["gammat"] / p["gamman"] if p["gamman"] > 0 else (0.0 if p["gammat"] == 0.0 else math.nan)
        const = None
    else:  # hertz: γt = γn √(4G*/E*)
        factor, const = math.sqrt(4.0 * p["shear_eff"] / p["youngs_eff"]), None
    if factor is not None and math.isnan(factor):
        raise ValueError("hertz/stiffness with gammat > 0 and gamman = 0 has no twin")

    def law(record, **kw):
        if factor is None:
            return TangentialLaw.from_slot(record(eta=const, eta_normal=False, mu_s=mu, mu_k=mu, r_eff=r, m_eff=m,
                                                  **kw))
        return TangentialLaw.from_slot(record(eta=factor, eta_normal=True, mu_s=mu, mu_k=mu, r_eff=r, m_eff=m, **kw))

    if nat.tangential == "no_history":
        return nl, law(ViscousSlidingTangential)
    return nl, law(SqrtSpringTangential if sqrt_law else SpringTangential, kt=kt, truncation=TRUNC_SPRING)


