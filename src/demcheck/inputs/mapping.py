"""Which engine configuration computes which seed model, and how faithfully (../shared/ENGINES.md §3).

For one type pair (two particles, or a particle and a wall) :func:`map_model` turns a resolved seed model
into an engine's own terms — a :class:`Native` configuration with every coefficient computed — and says
how faithful it is:

* ``exact``: the engine computes the seed model's force law; its twin is the seed law itself (with the
  engine's kinematic rules: lever arms and history rotation, which differ at O(δ/R) only in oblique
  impacts);
* ``approximate``: the engine computes a named variant (the twin), and the reason says how it differs;
* ``none``: the engine cannot express the model, and the reason says why. No deck is written then.

Every Native has a twin (:meth:`Native.twin`): the reference laws that compute exactly what the engine
computes, run with the engine's scheme (verlet) and rules (:data:`RULES`). The engine tests hold each
engine to its twin at 1e-9, and each ``exact`` claim is tested by comparing the twin's laws with the seed
model's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ..errors import UnsupportedByEngine
from ..reference import twins
from ..reference.model import ResolvedModel
from ..reference.normal import HYSTERETIC, NormalLaw
from ..reference.tangential import (LTH, NONE, SLIDING, SPRING, TRUNC_CAP, TRUNC_MAW, TRUNC_SPRING, VISCOUS,
                                    VISCOUS_SLIDING, WALTON, ZZY, TangentialLaw)

ENGINES = ("lammps", "liggghts")
EXACT, APPROXIMATE, NONE_ = "exact", "approximate", "none"
NATIVE = "native"  # a configuration given in the engine's own terms, not mapped from a seed model

# kinematic rules of each engine's verlet scheme (reference/collision3d.py; ENGINES.md §1.3, §2.2, pitfall 13)
RULES = {
    "lammps": {"slip_arm": "radius", "torque_arm": "contact", "wall_torque_arm": "radius", "rotation": "lammps"},
    "liggghts": {"slip_arm": "contact", "torque_arm": "contact", "wall_torque_arm": "contact",
                 "rotation": "project"},
}
HUGE_MU = 1e100  # "no Coulomb limit" for a viscous law expressed through a capped one (the cap μ|Fn| then
# bites only where Fn is exactly 0; a finite 1e6 changed the tangential restitution by 2e-5 near Fn's sign change)
SLIDING_XT = 1e4  # a dashpot far above the cap: the regularised slider


@dataclass
class Native:
    """One type pair's contact in an engine's own terms.

    LAMMPS: ``normal`` ∈ hooke | hertz | hertz/material with ``normal_args``; ``damping`` style and its
    coefficient; ``tangential`` ∈ linear_nohistory | linear_history | mindlin with ``tangential_args``;
    ``limit`` = limit_damping.
    LIGGGHTS: ``normal`` = the gran model (hooke/stiffness | hertz/stiffness | hertz), its per-pair
    properties in ``props``; ``tangential`` ∈ off | no_history | history; ``tangential_damping``;
    ``limit`` = limitForce.
    """

    engine: str
    normal: str
    normal_args: tuple = ()
    damping: str = ""
    damping_coeff: float = 0.0
    tangential: str = "linear_nohistory"
    tangential_args: tuple = ()
    limit: bool = False
    props: dict = field(default_factory=dict)
    tangential_damping: bool = True
    comments: list[str] = field(default_factory=list)

    # ------------------------------------------------------------------ the twin

    def twin(self, m_eff: float, r_eff: float) -> tuple[NormalLaw, TangentialLaw]:
        """Reference laws computing exactly what this configuration computes for a pair of effective mass
        m̄ and radius R̄ (a wall: the particle's)."""
        return _twin_lammps(self, m_eff, r_eff) if self.engine == "lammps" else _twin_liggghts(self, m_eff, r_eff)


@dataclass
class Mapping:
    engine: str
    fidelity: str
    reasons: list[str]
    native: Native | None

    def require(self) -> Native:
        if self.native is None:
            raise UnsupportedByEngine(f"{self.engine} cannot express this model: {'; '.join(self.reasons)}")
        return self.native


def refused(engine: str, reason: str) -> Mapping:
    """The mapping of a model (or a scene) the engine cannot express, with the one reason why."""
    return Mapping(engine, NONE_, [reason], None)


# ----------------------------------------------------------------------------- twins


def _twin_lammps(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    if nat.normal == "hooke":
        k_el, a = nat.normal_args[0], 1.0
    elif nat.normal == "hertz":
        k_el, a = nat.normal_args[0] * math.sqrt(r), 1.5
    else:  # hertz/material E ν: E* = E/(2(1−ν²)) for the pair's own coefficients (and for walls)
        e_mod, nu = nat.normal_args
        k_el, a = 4.0 / 3.0 * e_mod / (2.0 * (1.0 - nu * nu)) * math.sqrt(r), 1.5
    c, b = twins.damping(nat.damping, nat.damping_coeff, k_el, a, m, r)
    nl = twins.normal_law(k_el, a, c, b, nat.limit)
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


def _twin_liggghts(nat: Native, m: float, r: float) -> tuple[NormalLaw, TangentialLaw]:
    p = nat.props
    if nat.normal == "hooke/stiffness":
        k_el, a = p["kn"], 1.0
        c, b = twins.damping("stiffness_hooke", p["gamman"], k_el, a, m, r)
        kt, sqrt_law, eta_t = p["kt"], False, m * p["gammat"]
    elif nat.normal == "hertz/stiffness":
        k_el, a = p["kn"] * math.sqrt(r), 1.5
        c, b = twins.damping("stiffness_hertz", p["gamman"], k_el, a, m, r)
        kt, sqrt_law, eta_t = p["kt"], True, None  # γt = gammat m̄ √(R̄δ): the normal law's δ^½
    elif nat.normal == "hooke":  # characteristic velocity v_c: Kn from Hertz's energy at v_c; Kt = Kn, γt = γn
        y_eff, vc = p["youngs_eff"], p["characteristic_velocity"]
        k_el, a = 16.0 / 15.0 * math.sqrt(r) * y_eff * (15.0 * m * vc * vc / (16.0 * math.sqrt(r) * y_eff)) ** 0.2, 1.0
        c, b = twins.damping("restitution_hooke", p["restitution"], k_el, a, m, r)
        kt, sqrt_law, eta_t = k_el, False, c
    elif nat.normal == "edinburgh":
        kl = p["kl"]
        return (NormalLaw(HYSTERETIC, kl=kl, ku=kl * p["unloading"], limit=nat.limit), twins.no_friction())
    elif nat.normal == "hertz":
        y_eff, g_eff = p["youngs_eff"], p["shear_eff"]
        k_el, a = 4.0 / 3.0 * y_eff * math.sqrt(r), 1.5
        c, b = twins.damping("restitution_hertz", p["restitution"], k_el, a, m, r)
        kt, sqrt_law, eta_t = 8.0 * g_eff, True, None
    else:
        raise ValueError(f"no twin for LIGGGHTS model {nat.normal!r}")
    nl = twins.normal_law(k_el, a, c, b, nat.limit)
    mu = p.get("friction", 0.0)
    if nat.tangential == "off" or mu == 0.0 and nat.tangential == "no_history":
        return nl, twins.no_friction()
    # the tangential dashpot: constant (hooke/stiffness), or a factor of the normal η(δ)
    if not nat.tangential_damping:
        factor, const = 0.0, 0.0
    elif nat.normal in ("hooke/stiffness", "hooke"):
        factor, const = None, eta_t
    elif nat.normal == "hertz/stiffness":
        factor = p["gammat"] / p["gamman"] if p["gamman"] > 0 else math.nan
        const = None
    else:  # hertz: γt = γn √(4G*/E*)
        factor, const = math.sqrt(4.0 * p["shear_eff"] / p["youngs_eff"]), None
    if factor is not None and math.isnan(factor):
        raise ValueError("hertz/stiffness with gammat > 0 and gamman = 0 has no twin")

    def law(kind, **kw):
        if factor is None:
            return TangentialLaw(kind, eta=const, eta_normal=False, mu_s=mu, mu_k=mu, r_eff=r, m_eff=m, **kw)
        return TangentialLaw(kind, eta=factor, eta_normal=True, mu_s=mu, mu_k=mu, r_eff=r, m_eff=m, **kw)

    if nat.tangential == "no_history":
        return nl, law(VISCOUS_SLIDING)
    return nl, law(SPRING, kt=kt, kt_sqrt=sqrt_law, truncation=TRUNC_SPRING)


# ----------------------------------------------------------------------------- seed model → engine


def _fmt(x: float) -> str:
    return f"{x:.17g}"


def map_model(model: ResolvedModel, engine: str, contact_params: dict | None = None) -> Mapping:
    """The engine configuration for one type pair of a resolved seed model, with its fidelity."""
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}")
    contact_params = contact_params or {}
    return _map_lammps(model, contact_params) if engine == "lammps" else _map_liggghts(model, contact_params)


def _worst(*fidelities: str) -> str:
    order = {EXACT: 0, APPROXIMATE: 1, NONE_: 2}
    return max(fidelities, key=order.__getitem__)


def _mu(model: ResolvedModel, reasons: list[str]) -> tuple[float, str]:
    tl = model.tangential_law
    if tl.mu_s != tl.mu_k:
        reasons.append(f"one friction coefficient only: μ = μs = {tl.mu_s:g} (the case's μk = {tl.mu_k:g} "
                       "is not expressible)")
        return tl.mu_s, APPROXIMATE
    return tl.mu_k, EXACT


def _map_lammps(model: ResolvedModel, cp: dict) -> Mapping:
    nl, tl, pair = model.normal_law, model.tangential_law, model.pair
    m, r = pair.m_eff, pair.r_eff
    reasons: list[str] = []
    comments: list[str] = []
    nid = model.normal.id
    if nl.kind == HYSTERETIC:
        return refused("lammps", "LAMMPS 22Jul2025 has no linear hysteretic normal model (HLS)")
    nat = Native("lammps", normal="", limit=model.limit_force)
    fid = EXACT
    if nid == "lsd":
        nat.normal, nat.normal_args = "hooke", (nl.k,)
        if "eta_n" not in cp and pair.restitution is not None and nl.eta > 0:
            nat.damping, nat.damping_coeff = "coeff_restitution", pair.restitution
            comments.append(f"hooke Kn = {nl.k:.10g} N/m; damping coeff_restitution e = {pair.restitution:g} "
                            "gives ηn = 2β(e)√(m̄Kn), LSD's own")
        else:
            nat.damping, nat.damping_coeff = "velocity", nl.eta
            comments.append(f"hooke Kn = {nl.k:.10g} N/m; damping velocity η0 = ηn = {nl.eta:.10g} N·s/m")
    else:
        k_hz_coef = nl.k / math.sqrt(r)  # (4/3)Ē
        nat.normal, nat.normal_args = "hertz", (k_hz_coef,)
        comments.append(f"hertz k = (4/3)Ē = {k_hz_coef:.10g} Pa, so that F = k√R̄ δ^3/2")
        if nl.eta == 0.0:
            nat.damping, nat.damping_coeff = "velocity", 0.0
        elif nl.b == 0.5:
            eta0 = nl.eta / (m * math.sqrt(r))
            nat.damping, nat.damping_coeff = "viscoelastic", eta0
            comments.append(f"damping viscoelastic η0 = ηn/(m̄√R̄) = {eta0:.10g} 1/(s·m), per pair "
                            f"(m̄ = {m:.10g} kg, R̄ = {r:.10g} m)")
        elif nl.b == 0.25:
            e_prime = twins.restitution_for_eta(nl.eta / math.sqrt(m * nl.k), math.sqrt(5.0))
            if not (0.0 < e_prime < 1.0):
                return refused("lammps", f"TTIn's ηn = {nl.eta:g} is at or above what coeff_restitution "
                                          "can express (e′ would be ≤ 0)")
            nat.damping, nat.damping_coeff = "coeff_restitution", e_prime
            comments.append(f"damping coeff_restitution e′ = {e_prime:.17g}: TTIn's ηn = {nl.eta:.10g} "
                            "N·s/m^5/4 through √5 β(e′)√(m̄K_HZ) (the input transform of ENGINES.md §3)")
        else:
            return refused("lammps", f"no LAMMPS damping style has the δ^{nl.b:g} law")
    if model.limit_force:
        comments.append("limit_damping: total normal force ≥ 0 (the collision-time reduction)")
    # tangential: LAMMPS's dashpot is x_t times the normal damping prefactor η(δ)
    kind = tl.kind
    tid = model.tangential.id
    eta_n_const = nl.b == 0.0 and nl.eta > 0.0
    if kind == NONE:
        nat.tangential, nat.tangential_args = "linear_nohistory", (0.0, 0.0)
    elif kind in (LTH, ZZY, WALTON):
        return refused("lammps", f"LAMMPS 22Jul2025 has no {model.tangential.seed_name} law "
                                  "(nearest: mindlin_rescale/force, a different law)")
    else:
        mu, f_mu = _mu(model, reasons)
        fid = _worst(fid, f_mu)
        if kind == SLIDING:
            if nl.eta == 0.0:
                return refused("lammps", "simple sliding friction needs linear_nohistory's dashpot, which "
                                          "is x_t × the normal damping, and this normal law has none")
            nat.tangential, nat.tangential_args = "linear_nohistory", (SLIDING_XT, mu)
            fid = _worst(fid, APPROXIMATE)
            reasons.append(f"simple sliding friction as linear_nohistory with x_t = {SLIDING_XT:g}: "
                           "min(x_t η(δ)|v_t|, μ|Fn|) is a regularised slider near v_t = 0")
        elif kind in (VISCOUS, VISCOUS_SLIDING):
            if tl.eta_normal or not eta_n_const:
                return refused("lammps", f"a constant ηt needs a constant normal damping (LAMMPS's ηt = "
                                          f"x_t η(δ)); normal '{nid}' damps with δ^{nl.b:g}"
                                          + (" and has no damping" if nl.eta == 0 else ""))
            x_t = tl.eta / nl.eta
            if kind == VISCOUS and model.limit_force:
                fid = _worst(fid, APPROXIMATE)
                reasons.append("with limit_damping the Coulomb cap μ|Fn| is 0 wherever the normal force is held "
                               "at 0, so the viscous force vanishes there too")
            nat.tangential = "linear_nohistory"
            nat.tangential_args = (x_t, HUGE_MU if kind == VISCOUS else mu)
            comments.append(f"linear_nohistory x_t = ηt/ηn = {x_t:.10g}"
                            + (f", μ = {HUGE_MU:g} (no Coulomb limit)" if kind == VISCOUS else ""))
        elif kind == SPRING:
            if tl.eta_normal:  # TTIt: ηt = ηn
                if nid != "tti":
                    return refused("lammps", "TTIt's ηt = ηn needs TTIn's normal damping")
                x_t = tl.eta
            elif tl.eta == 0.0:
                x_t = 0.0
            elif eta_n_const:
                x_t = tl.eta / nl.eta
            else:
                return refused("lammps", f"a constant ηt needs a constant normal damping (LAMMPS's ηt = "
                                          f"x_t η(δ)); normal '{nid}' damps with δ^{nl.b:g}")
            if tl.kt_sqrt:
                nat.tangential, nat.tangential_args = "mindlin", (tl.kt, x_t, mu)
                comments.append(f"mindlin k_t = {tl.kt:.10g} Pa (Kt = k_t √(R̄δ)), x_t = {x_t:.10g}")
            else:
                nat.tangential, nat.tangential_args = "linear_history", (tl.kt, x_t, mu)
                comments.append(f"linear_history Kt = {tl.kt:.10g} N/m, x_t = {x_t:.10g}")
            if tl.truncation != TRUNC_MAW and x_t > 0.0:
                fid = _worst(fid, APPROXIMATE)
                name = {TRUNC_CAP: "force", TRUNC_SPRING: "spring"}[tl.truncation]
                reasons.append(f"LAMMPS limits the history after Maw (truncation = overlap: ξ such that |Kt ξ + "
                               f"ηt v_t| = μ|Fn|); the case asks for truncation = {name}")
        else:
            return refused("lammps", f"no LAMMPS equivalent of tangential '{tid}'")
    nat.comments = comments
    return Mapping("lammps", fid, reasons, nat)


def _map_liggghts(model: ResolvedModel, cp: dict) -> Mapping:
    nl, tl, pair = model.normal_law, model.tangential_law, model.pair
    m, r = pair.m_eff, pair.r_eff
    reasons: list[str] = []
    comments: list[str] = []
    nid = model.normal.id
    nat = Native("liggghts", normal="", limit=model.limit_force)
    fid = EXACT
    p = nat.props
    if nl.kind == HYSTERETIC:
        if nl.ku == 0.0:
            return refused("liggghts", "HLS with variable unloading (K_U = K_L + S·F_max) maps to luding "
                                        "only while δ_max < δ_lim; that route is not generated")
        # edinburgh, linear (overlapExponent 1), no adhesion, e = 1: loading K_L = 2E*R̄, unloading r·K_L
        nat.normal = "edinburgh"
        p.update(kl=nl.kl, unloading=nl.ku / nl.kl, adhesion=0.0, pulloff=0.0, surface_energy=0.0,
                 restitution=1.0)
        comments.append(f"edinburgh (fixKc on, overlapExponent 1, no adhesion, coefficientRestitution 1): "
                        f"K_L = 2E*R̄ = {nl.kl:.10g} N/m through the types' Young's moduli, UnloadingStiffness = "
                        f"K_U/K_L = {nl.ku / nl.kl:.17g}")
        if tl.kind != NONE:
            return refused("liggghts", "edinburgh's tangential stiffness is 2E*√(R̄δ) with E* set for K_L; "
                                        "no seed tangential law shares it")
        nat.tangential = "off"
        nat.comments = comments
        return Mapping("liggghts", fid, reasons, nat)
    if nid == "lsd":
        nat.normal = "hooke/stiffness"
        p.update(kn=nl.k, gamman=nl.eta / m, kt=0.0, gammat=0.0)
        comments.append(f"hooke/stiffness kn = {nl.k:.10g} N/m, gamman = ηn/m̄ = {nl.eta / m:.10g} 1/s (per pair, "
                        f"m̄ = {m:.10g} kg)")
    elif nid in ("hertz", "bshp", "kk"):
        nat.normal = "hertz/stiffness"
        gamman = nl.eta / (m * math.sqrt(r))
        p.update(kn=nl.k / math.sqrt(r), gamman=gamman, kt=0.0, gammat=0.0)
        comments.append(f"hertz/stiffness kn = (4/3)Ē = {nl.k / math.sqrt(r):.10g} Pa, gamman = ηn/(m̄√R̄) = "
                        f"{gamman:.10g} (per pair, m̄ = {m:.10g} kg, R̄ = {r:.10g} m)")
    elif nid == "tti":
        nat.normal = "hertz"
        e_prime = twins.restitution_for_eta(nl.eta / math.sqrt(m * nl.k), math.sqrt(5.0))
        if not (0.05 < e_prime <= 1.0):
            return refused("liggghts", f"TTIn's ηn = {nl.eta:g} needs coefficientRestitution e′ = "
                                        f"{e_prime:.4g}, outside LIGGGHTS's 0.05 < e ≤ 1")
        # E*, G* as LIGGGHTS mixes the types' moduli (a rigid wall is a type of modulus 1e30 Pa: the same
        # to round-off)
        p.update(restitution=e_prime, youngs_eff=pair.e_eff, shear_eff=pair.g_eff)
        comments.append(f"hertz coefficientRestitution e′ = {e_prime:.17g}: TTIn's ηn = {nl.eta:.10g} through "
                        "√5 β(e′)√(m̄K_HZ) (ENGINES.md §3)")
    else:
        return refused("liggghts", f"no LIGGGHTS model for normal '{nid}'")
    if model.limit_force:
        comments.append("limitForce on: total normal force ≥ 0")
    kind = tl.kind
    tid = model.tangential.id
    stiff = nat.normal == "hooke/stiffness"
    if kind == NONE:
        nat.tangential = "off"
    elif kind in (LTH, ZZY, WALTON):
        return refused("liggghts", f"LIGGGHTS 3.8.0 has no {model.tangential.seed_name} law")
    else:
        mu, f_mu = _mu(model, reasons)
        fid = _worst(fid, f_mu)
        p["friction"] = mu
        if kind in (SLIDING, VISCOUS, VISCOUS_SLIDING):
            if not stiff:
                return refused("liggghts", f"no_history's dashpot follows the model's δ-law; a constant ηt "
                                            f"needs hooke/stiffness, i.e. normal 'lsd' (not '{nid}')")
            nat.tangential = "no_history"
            if kind == SLIDING:
                p["gammat"] = SLIDING_XT * max(nl.eta, 1.0) / m
                fid = _worst(fid, APPROXIMATE)
                reasons.append(f"simple sliding friction as no_history with gammat = {p['gammat']:.4g} 1/s: a "
                               "regularised slider near v_t = 0")
            else:
                p["gammat"] = tl.eta / m
                if kind == VISCOUS:
                    p["friction"] = HUGE_MU
                    if model.limit_force:
                        fid = _worst(fid, APPROXIMATE)
                        reasons.append("with limitForce the Coulomb cap μ|Fn| is 0 wherever the normal force is "
                                       "held at 0, so the viscous force vanishes there too")
                comments.append(f"no_history gammat = ηt/m̄ = {p['gammat']:.10g} 1/s"
                                + (f", coefficientFriction = {HUGE_MU:g} (no Coulomb limit)" if kind == VISCOUS
                                   else ""))
        elif kind == SPRING:
            nat.tangential = "history"
            if tl.eta_normal:  # TTIt on the hertz model: same Kt, γt = γn √(4G*/E*), dashpot outside the cap
                if nid != "tti":
                    return refused("liggghts", "TTIt's ηt = ηn needs TTIn's normal damping")
                fid = _worst(fid, APPROXIMATE)
                ratio = math.sqrt(4.0 * pair.g_eff / pair.e_eff)
                reasons.append(f"hertz + history: Kt = 8G*√(R̄δ) as TTIt, but ηt = {ratio:.4f} ηn (√(4G*/E*)) and "
                               "the dashpot lies outside the Coulomb cap (spring-only truncation)")
            elif tl.kt_sqrt:  # DDt on hertz/stiffness
                if nat.normal != "hertz/stiffness":
                    return refused("liggghts", "Kt ∝ √δ (DDt) needs hertz/stiffness, whose normal law is "
                                                f"Hertz-type; normal '{nid}' is not")
                if tl.eta > 0.0:
                    return refused("liggghts", "DDt's constant ηt: hertz/stiffness damps with √(R̄δ)")
                p["kt"] = tl.kt
                nat.tangential_damping = False
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
                    fid = _worst(fid, APPROXIMATE)
                    name = {TRUNC_CAP: "force", TRUNC_MAW: "overlap"}[tl.truncation]
                    reasons.append("LIGGGHTS caps the spring only (truncation = spring: the dashpot is added "
                                   f"uncapped while sticking and dropped while slipping); the case asks for "
                                   f"truncation = {name}")
        else:
            return refused("liggghts", f"no LIGGGHTS equivalent of tangential '{tid}'")
    nat.comments = comments
    return Mapping("liggghts", fid, reasons, nat)


def twin_model(model: ResolvedModel, native: Native) -> ResolvedModel:
    """The resolved model whose laws are the engine configuration's twin (for the reference solvers)."""
    nl, tl = native.twin(model.pair.m_eff, model.pair.r_eff)
    return replace(model, normal_law=nl, tangential_law=tl, limit_force=native.limit)


def table(examples: list[tuple[str, str]] | None = None) -> list[dict]:
    """The mapping of every registered model for ``demcheck models`` and docs/models.md: each normal model
    with tangential none, each tangential model with its natural normal partner, on the glass pair."""
    from .. import case as C
    from ..reference import normal as N, tangential as T
    from ..reference.model import resolve

    import copy
    import tomllib

    base = tomllib.loads(_TABLE_CASE)
    rows = []
    combos = examples or ([(n, "none", {}) for n in N.REGISTRY] + [
        (_PARTNER.get(t, "lsd"), t, {}) for t in T.REGISTRY if t != "none"] + _VARIANTS)
    for combo in combos:
        normal, tangential, extra = combo if len(combo) == 3 else (*combo, {})
        params = {**N.REGISTRY[normal].example, **T.REGISTRY[tangential].example, **extra}
        params.pop("friction", None)
        sets = [f"contact.normal={normal}", f"contact.tangential={tangential}"]
        sets += [f"contact.{k}={_toml(v)}" for k, v in params.items()]
        case = C.from_dict(C.apply_overrides(copy.deepcopy(base), sets))
        model = resolve(case)
        row = {"normal": normal, "tangential": tangential,
               "variant": ", ".join(f"{k} = {_toml(v)}" for k, v in extra.items())}
        for engine in ENGINES:
            mp = map_model(model, engine, case.contact.params)
            row[engine] = mp.fidelity
            row[f"{engine}_config"] = native_summary(mp.native) if mp.native else ""
            row[f"{engine}_reason"] = "; ".join(mp.reasons)
        rows.append(row)
    return rows


_PARTNER = {"tti": "tti", "ddt": "hertz"}
# parameter variants whose mapping differs from the model's default row
_VARIANTS = [("hls", "none", {"unloading": "variable", "S": 1e4, "kl": 3e6}),
             ("lsd", "viscous", {"limit_force": True}),
             ("lsd", "lsd_sliding", {"truncation": "overlap"}), ("lsd", "lsd_sliding", {"truncation": "spring"}),
             ("tti", "tti", {"truncation": "overlap"}), ("kk", "ddt", {})]
_TABLE_CASE = """
name = "mapping-table"
[materials.glass]
density = 2500.0
youngs_modulus = 71e9
poisson_ratio = 0.22
restitution = 0.9
friction = 0.3
dissipative_constant = 1e-7
tangential_restitution = 0.5
[[particles]]
material = "glass"
radius = 1.59e-3
position = [-1.59e-3, 0.0, 0.0]
velocity = [1.0, 0.0, 0.0]
[[particles]]
material = "glass"
radius = 1.59e-3
position = [1.59e-3, 0.0, 0.0]
[contact]
normal = "lsd"
"""


def _toml(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return f'"{v}"' if isinstance(v, str) else repr(v)


def by_model() -> dict:
    """{(slot, id): {engine: {fidelity, config, reason, with}}} from :func:`table` (``with``: the partner
    model of the other slot the row was evaluated with)."""
    out = {}
    for row in table():
        if row["variant"] or (row["tangential"] == "ddt" and row["normal"] != "hertz"):
            continue
        for slot, other in (("normal", "tangential"), ("tangential", "normal")):
            if slot == "normal" and row["tangential"] != "none":
                continue
            if slot == "tangential" and row["tangential"] == "none" and row["normal"] != "lsd":
                continue
            out[(slot, row[slot])] = {e: {"fidelity": row[e], "config": row[f"{e}_config"],
                                          "reason": row[f"{e}_reason"], "with": f"{other} {row[other]}"}
                                      for e in ENGINES}
    return out


def native_summary(nat: Native) -> str:
    if nat.engine == "lammps":
        parts = [nat.normal, f"damping {nat.damping}", f"tangential {nat.tangential}"]
        if nat.limit:
            parts.append("limit_damping")
        return " ".join(parts)
    parts = [f"model {nat.normal}", f"tangential {nat.tangential}"]
    if nat.tangential == "history" and not nat.tangential_damping:
        parts.append("tangential_damping off")
    if nat.limit:
        parts.append("limitForce on")
    return " ".join(parts)


def markdown_table() -> str:
    """The mapping table as docs/models.md carries it (tests/test_docs.py keeps the two equal)."""
    lines = ["| normal | tangential | LAMMPS 22Jul2025 | LIGGGHTS 3.8.0 |", "|---|---|---|---|"]
    for row in table():
        cells = []
        for e in ENGINES:
            text = f"**{row[e]}**"
            if row[f"{e}_config"]:
                text += f": `{row[f'{e}_config']}`"
            if row[f"{e}_reason"]:
                text += f" — {row[f'{e}_reason']}"
            cells.append(text.replace("|", "\\|"))
        variant = f" ({row['variant']})" if row["variant"] else ""
        lines.append(f"| `{row['normal']}` | `{row['tangential']}`{variant} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines) + "\n"
