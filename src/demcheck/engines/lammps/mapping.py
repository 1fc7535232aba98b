"""LAMMPS 22Jul2025's vocabulary: a seed model → ``pair_style granular`` settings with their fidelity
(:func:`map_model`), and settings → the reference laws that compute exactly what LAMMPS computes
(:func:`twin`)."""

from __future__ import annotations

import math
from dataclasses import replace

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
    """The contact's slot records, by class (named here by their ids): normal hooke | hertz, damping none | constant |
    sqrt | quarter, tangential none | sliding | viscous | viscous_sliding | spring | sqrt_spring."""
    contact = model.contact
    nat = Native("lammps", normal="", limit=model.limit_force)
    comments: list[str] = []
    refusal = _map_normal(model, contact, cp, nat, comments)
    if refusal is not None:
        return refusal
    if model.limit_force:
        comments.append("limit_damping: total normal force ≥ 0 (the collision-time reduction)")
    return _map_tangential(model, contact, nat, comments)


def _map_normal(model: ResolvedModel, contact, cp: dict, nat: Native, comments: list[str]) -> Mapping | None:
    """The normal and damping slots into ``nat`` (None), or the refusal."""
    normal, damp, pair = contact.normal, contact.damping, model.pair
    m, r = pair.m_eff, pair.r_eff
    eta = getattr(damp, "eta", 0.0)
    if type(normal) is HysteresisNormal:
        return refused("lammps", "LAMMPS 22Jul2025 has no linear hysteretic normal model (HLS)")
    if type(normal) not in (HookeNormal, HertzNormal):
        return refused("lammps", f"no LAMMPS normal model for the normal record '{normal.id}'")
    if type(normal) is HookeNormal and eta > 0.0 and type(damp) not in (NoDamping, ConstantDamping):
        return refused("lammps", f"no LAMMPS normal model has the δ^{normal.exponent:g} spring with a "
                                  f"δ^{damp.exponent:g} dashpot")
    if type(normal) is HookeNormal:
        nat.normal, nat.normal_args = "hooke", (normal.k,)
        # the user's preset (not a slot record): LSD calibrated by restitution is LAMMPS's own coeff_restitution
        if model.normal.id == "lsd" and "eta_n" not in cp and pair.restitution is not None and eta > 0:
            nat.damping, nat.damping_coeff = "coeff_restitution", pair.restitution
            comments.append(f"hooke Kn = {normal.k:.10g} N/m; damping coeff_restitution e = {pair.restitution:g} "
                            "gives ηn = 2β(e)√(m̄Kn), LSD's own")
        else:
            nat.damping, nat.damping_coeff = "velocity", eta
            comments.append(f"hooke Kn = {normal.k:.10g} N/m; damping velocity η0 = ηn = {eta:.10g} N·s/m")
        return None
    k_hz_coef = normal.k / math.sqrt(r)  # (4/3)Ē
    nat.normal, nat.normal_args = "hertz", (k_hz_coef,)
    comments.append(f"hertz k = (4/3)Ē = {k_hz_coef:.10g} Pa, so that F = k√R̄ δ^3/2")
    if eta == 0.0:
        nat.damping, nat.damping_coeff = "velocity", 0.0
    elif type(damp) is SqrtDamping:
        eta0 = eta / (m * math.sqrt(r))
        nat.damping, nat.damping_coeff = "viscoelastic", eta0
        comments.append(f"damping viscoelastic η0 = ηn/(m̄√R̄) = {eta0:.10g} 1/(s·m), per pair "
                        f"(m̄ = {m:.10g} kg, R̄ = {r:.10g} m)")
    elif type(damp) is QuarterDamping:
        e_prime = twins.restitution_for_eta(eta / math.sqrt(m * normal.k), math.sqrt(5.0))
        if not (0.0 < e_prime < 1.0):
            return refused("lammps", f"TTIn's ηn = {eta:g} is at or above what coeff_restitution "
                                      "can express (e′ would be ≤ 0)")
        nat.damping, nat.damping_coeff = "coeff_restitution", e_prime
        comments.append(f"damping coeff_restitution e′ = {e_prime:.17g}: TTIn's ηn = {eta:.10g} "
                        "N·s/m^5/4 through √5 β(e′)√(m̄K_HZ) (the input transform of docs/models.md, Engine twins)")
    else:
        return refused("lammps", f"no LAMMPS damping style has the δ^{damp.exponent:g} law")
    return None


def _map_tangential(model: ResolvedModel, contact, nat: Native, comments: list[str]) -> Mapping:
    """The tangential slot into ``nat``: LAMMPS's dashpot is x_t times the normal damping prefactor η(δ)."""
    tl, damp = contact.tangential, contact.damping
    eta = getattr(damp, "eta", 0.0)
    reasons: list[str] = []
    keywords: dict[str, str] = {}  # an approximate reason → the pair_coeff keyword it is about
    fid = EXACT
    nid, tid = model.normal.id, model.tangential.id
    eta_n_const = type(damp) is ConstantDamping and eta > 0.0
    if type(tl) is NoTangential:
        nat.tangential, nat.tangential_args = "linear_nohistory", (0.0, 0.0)
    elif type(tl) in (LthTangential, ZzyTangential, WaltonTangential):
        return refused("lammps", f"LAMMPS 22Jul2025 has no {model.tangential.seed_name} law "
                                  "(nearest: mindlin_rescale/force, a different law)")
    else:
        mu, f_mu = mu_of(model, reasons)
        mu_reason = reasons[-1] if f_mu == APPROXIMATE else None
        fid = worst(fid, f_mu)
        if type(tl) is SlidingTangential:
            if eta == 0.0:
                return refused("lammps", "simple sliding friction needs linear_nohistory's dashpot, which "
                                          "is x_t × the normal damping, and this normal law has none")
            nat.tangential, nat.tangential_args = "linear_nohistory", (SLIDING_XT, mu)
            fid = worst(fid, APPROXIMATE)
            reasons.append(f"simple sliding friction as linear_nohistory with x_t = {SLIDING_XT:g}: "
                           "min(x_t η(δ)|v_t|, μ|Fn|) is a regularised slider near v_t = 0")
            keywords[reasons[-1]] = "tangential linear_nohistory"
        elif type(tl) in (ViscousTangential, ViscousSlidingTangential):
            if tl.eta_normal or not eta_n_const:
                return refused("lammps", f"a constant ηt needs a constant normal damping (LAMMPS's ηt = "
                                          f"x_t η(δ)); normal '{nid}' damps with δ^{damp.exponent:g}"
                                          + (" and has no damping" if eta == 0 else ""))
            x_t = tl.eta / eta
            if type(tl) is ViscousTangential and model.limit_force:
                fid = worst(fid, APPROXIMATE)
                reasons.append("with limit_damping the Coulomb cap μ|Fn| is 0 wherever the normal force is held "
                               "at 0, so the viscous force vanishes there too")
                keywords[reasons[-1]] = "limit_damping"
            nat.tangential = "linear_nohistory"
            nat.tangential_args = (x_t, HUGE_MU if type(tl) is ViscousTangential else mu)
            comments.append(f"linear_nohistory x_t = ηt/ηn = {x_t:.10g}"
                            + (f", μ = {HUGE_MU:g} (no Coulomb limit)" if type(tl) is ViscousTangential else ""))
        elif type(tl) in (SpringTangential, SqrtSpringTangential):
            if tl.eta_normal:  # TTIt: ηt = ηn
                if not (type(contact.normal) is HertzNormal and type(damp) is QuarterDamping):
                    return refused("lammps", "TTIt's ηt = ηn needs TTIn's normal damping")
                x_t = tl.eta
            elif tl.eta == 0.0:
                x_t = 0.0
            elif eta_n_const:
                x_t = tl.eta / eta
            else:
                return refused("lammps", f"a constant ηt needs a constant normal damping (LAMMPS's ηt = "
                                          f"x_t η(δ)); normal '{nid}' damps with δ^{damp.exponent:g}")
            if type(tl) is SqrtSpringTangential:
                nat.tangential, nat.tangential_args = "mindlin", (tl.kt, x_t, mu)
                comments.append(f"mindlin k_t = {tl.kt:.10g} Pa (Kt = k_t √(R̄δ)), x_t = {x_t:.10g}")
            else:
                nat.tangential, nat.tangential_args = "linear_history", (tl.kt, x_t, mu)
                comments.append(f"linear_history Kt = {tl.kt:.10g} N/m, x_t = {x_t:.10g}")
            if tl.truncation != TRUNC_MAW and x_t > 0.0:
                fid = worst(fid, APPROXIMATE)
                name = {TRUNC_CAP: "force", TRUNC_SPRING: "spring"}[tl.truncation]
                reasons.append(f"LAMMPS limits the history after Maw (truncation = overlap: ξ such that |Kt ξ + "
                               f"ηt v_t| = μ|Fn|); the case asks for truncation = {name}")
                keywords[reasons[-1]] = f"tangential {nat.tangential}"
        else:
            return refused("lammps", f"no LAMMPS equivalent of tangential '{tid}'")
        if mu_reason is not None:
            keywords[mu_reason] = f"tangential {nat.tangential} mu"
    nat.comments = comments
    return Mapping("lammps", fid, reasons, nat, keywords)


def twin(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    if nat.normal == "hooke":
        spring = HookeNormal(k=nat.normal_args[0])
    elif nat.normal == "hertz":
        spring = HertzNormal(k=nat.normal_args[0] * math.sqrt(r))
    else:  # hertz/material E ν: E* = E/(2(1−ν²)) for the pair's own coefficients (and for walls)
        e_mod, nu = nat.normal_args
        spring = HertzNormal(k=4.0 / 3.0 * e_mod / (2.0 * (1.0 - nu * nu)) * math.sqrt(r))
    nl = NormalLaw.from_slots(spring, damping(nat.damping, nat.damping_coeff, spring, m, r), nat.limit)
    args = nat.tangential_args
    if nat.tangential == "linear_nohistory":
        x_t, mu = args
        tl = twins.no_friction() if mu == 0.0 else twins.tangential_viscous_sliding(x_t, mu, r, m)
    elif nat.tangential == "linear_history":
        kt, x_t, mu = args
        tl = twins.tangential_spring(kt, False, x_t, mu, TRUNC_MAW, r, m)
    elif nat.tangential in ("mindlin", "mindlin/force", "mindlin_rescale", "mindlin_rescale/force"):
        kt, x_t, mu = args
        if kt is None:  # NULL: k_t = 8G* from hertz/material's E and ν, G* = E/(4(2−ν)(1+ν)) (pair and wall)
            if nat.normal != "hertz/material":
                raise ValueError("mindlin NULL needs a hertz/material normal model")
            e_mod, nu = nat.normal_args
            kt = 8.0 * e_mod / (4.0 * (2.0 - nu) * (1.0 + nu))
        tl = twins.tangential_spring(kt, True, x_t, mu, TRUNC_MAW, r, m)
        tl = replace(tl, force_history=nat.tangential.endswith("/force"),
                     rescale_history=nat.tangential.startswith("mindlin_rescale"))
    else:
        raise ValueError(f"no twin for LAMMPS tangential {nat.tangential!r}")
    return nl, tl


