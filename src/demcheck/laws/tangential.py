"""Tangential contact models (seed 000 §4), as a registry of the users' names over the tangential laws.

Each law is one module of ``laws/tangential_laws/`` (its record, family id and compiled functions; a plug-in
law is a module named in ``$DEMCHECK_LAW_PLUGINS``, imported at the end of this one). Each seed model here
turns a pair's properties, the ``[contact]`` parameters and the resolved normal law into a
:class:`TangentialLaw`: plain numbers for the compiled 3-D kernels. The built-in laws:

* ``sliding``          F = −μ|Fn| t̂ (simple sliding friction; sticks when the slip stops and μs|Fn| holds it)
* ``viscous``          F = −ηt v_t
* ``viscous_sliding``  F = −min(ηt|v_t|, μ|Fn|) t̂
* ``spring``           trial F = −Kt ξ − ηt v_t on a history ξ (tangential overlap), Coulomb-limited by a
                       truncation rule: ``force`` (cap |F| at μ|Fn| and leave ξ alone, Cundall & Strack),
                       ``overlap`` (adjust ξ so that |Kt ξ + ηt v_t| = μ|Fn|, Maw et al.; what LAMMPS does) or
                       ``spring`` (cap the spring only, drop the dashpot while slipping; what LIGGGHTS does).
                       Kt constant, or c√(R̄δn) (``sqrt_spring``: DDt, TTIt). ηt constant, or a factor times the
                       normal law's damping prefactor (TTIt: ηt = ηn).
* ``lth`` / ``zzy``    the Langston et al. / Zheng et al. nonlinear laws on ξ with δt_max = μ(2−ν)/(2(1−ν)) δn
* ``walton``           incrementally slipping friction (Walton & Braun 1986) on the tangential load L

Coulomb: static μs (``friction``) decides when sticking ends; kinetic μk (``friction_kinetic``, default μs)
limits the force while slipping.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ConfigError
from .contact import Pair, kinetic_rule
from .registry import Registry, contact_number
from .normal import HYSTERETIC, NormalLaw, Param, contact_choice

from .tangential_slot import (T_ETA, T_ETA1, T_ETA_NORMAL, T_FAMILY, T_FORCE, T_G, T_K0, T_KT,  # noqa: F401
                              T_KT_SQRT, T_M, T_MU_K, T_MU_S, T_NEAR_LIMIT, T_P0, T_PARAMS, T_R, T_RESCALE, T_RIDE_BAND,
                              T_SIZE, T_TRAITS, T_TRUNC, T_UNLOAD_MARGIN, T_XI,
                              TRUNC_CAP, TRUNC_MAW, TRUNC_SPRING, TRUNCATIONS, TangentialSubModel, load_plugins,
                              record_class)
from .tangential_laws.lth import LTH, LthTangential  # noqa: F401  (the built-in laws, one module each)
from .tangential_laws.none import NONE, NoTangential  # noqa: F401
from .tangential_laws.sliding import SLIDING, SlidingTangential  # noqa: F401
from .tangential_laws.spring import SPRING, SpringTangential, SqrtSpringTangential  # noqa: F401
from .tangential_laws.viscous import VISCOUS, ViscousTangential  # noqa: F401
from .tangential_laws.viscous_sliding import VISCOUS_SLIDING, ViscousSlidingTangential  # noqa: F401
from .tangential_laws.walton import WALTON, WaltonTangential  # noqa: F401
from .tangential_laws.zzy import ZZY, ZzyTangential  # noqa: F401

_NAMED = 16  # the columns TangentialLaw names; T_P0.. hold a law's other numbers (``params``)


@dataclass(frozen=True)
class TangentialLaw:
    """The composed law array the compiled kernels read (the ``T_*`` columns of laws/tangential_slot.py): the
    family id of the law's record and the union of the records' numbers; a record's numbers that no column names
    are ``params`` (T_P0 on, in the record's field order)."""

    family: int = NONE
    kt: float = 0.0  # constant Kt, or c in Kt = c √(R̄ δn) when kt_sqrt
    kt_sqrt: bool = False
    eta: float = 0.0  # constant ηt, or a factor of the normal damping prefactor when eta_normal
    eta_normal: bool = False
    mu_s: float = 0.0
    mu_k: float = 0.0
    truncation: int = TRUNC_MAW
    r_eff: float = 0.0
    m_eff: float = 0.0
    xi_coef: float = 0.0  # LTH/ZZY: δt_max = xi_coef · δn
    eta1: float = 0.0  # ZZY viscosity η₁
    g_i: float = 0.0  # ZZY shear modulus G_i
    k0: float = 0.0  # Walton initial stiffness
    force_history: bool = False  # engine twin: the history is the elastic force, incremented by −Kt v_t dt
    rescale_history: bool = False  # engine twin: history × a/a_prev when the contact radius a shrinks
    params: tuple[float, ...] = ()  # a law's own numbers (T_P0 on)

    def __post_init__(self):
        if len(self.params) > T_PARAMS:
            raise ValueError(f"a tangential law has at most {T_PARAMS} numbers of its own, not {len(self.params)}")

    def array(self) -> np.ndarray:
        extra = [float(x) for x in self.params] + [0.0] * (T_PARAMS - len(self.params))
        return np.array([self.family, self.kt, float(self.kt_sqrt), self.eta, float(self.eta_normal), self.mu_s,
                         self.mu_k, self.truncation, self.r_eff, self.m_eff, self.xi_coef, self.eta1, self.g_i,
                         self.k0, float(self.force_history), float(self.rescale_history), *extra,
                         *self._as_record().trait_columns()])

    @classmethod
    def from_array(cls, law) -> "TangentialLaw":
        """The law of an ``array()`` (the inverse, exactly: ``params`` as long as the record has numbers of its own)."""
        values = [float(x) for x in law]
        (family, kt, kt_sqrt, eta, eta_normal, mu_s, mu_k, truncation, r_eff, m_eff, xi_coef, eta1, g_i, k0,
         force_history, rescale_history) = values[:_NAMED]
        own = len(_own_fields(record_class(int(family), kt_sqrt != 0.0)))
        return cls(int(family), kt=kt, kt_sqrt=kt_sqrt != 0.0, eta=eta, eta_normal=eta_normal != 0.0, mu_s=mu_s,
                   mu_k=mu_k, truncation=int(truncation), r_eff=r_eff, m_eff=m_eff, xi_coef=xi_coef, eta1=eta1,
                   g_i=g_i, k0=k0, force_history=force_history != 0.0, rescale_history=rescale_history != 0.0,
                   params=tuple(values[_NAMED:_NAMED + own]))

    def _record(self) -> type:
        return record_class(self.family, self.kt_sqrt)

    @property
    def has_history(self) -> bool:
        return self._record().history_size > 0

    @property
    def passive(self) -> bool:
        """Whether the law can only store or dissipate energy (its record's ``passive``)."""
        return self._as_record().passive

    @property
    def pushes_at_onset(self) -> bool:
        """Whether the friction can push along the slip at contact onset (its record's ``pushes_at_onset``)."""
        return self._as_record().pushes_at_onset

    @property
    def history_is_load(self) -> bool:
        """Whether its history is a force (a load), not a displacement (its record's ``history_is_load``)."""
        return self._record().history_is_load

    @property
    def caps(self) -> bool:
        """Whether the law limits |Ft| by Coulomb (μ|Fn|) in its slip state."""
        return self._record().caps

    def _as_record(self):
        cls = self._record()
        own = _own_fields(cls)
        named = {n: getattr(self, n) for n in cls.param_names() if n not in own}
        return cls(**named, **dict(zip(own, self.params)))

    def slot(self) -> "TangentialSubModel":
        """The law as its tangential slot's record; ValueError where the law sets a number its record has no
        field for (the record would lose it)."""
        cls = self._record()
        names = set(cls.param_names())
        default = TangentialLaw()
        lost = [f.name for f in dataclasses.fields(self) if f.name not in names | {"family", "kt_sqrt", "params"}
                and getattr(self, f.name) != getattr(default, f.name)]
        if len(self.params) > len(_own_fields(cls)):
            lost.append("params")
        if lost:
            raise ValueError(f"tangential record {cls.id!r} has no field for {', '.join(lost)}")
        return self._as_record()

    @classmethod
    def from_slot(cls, record: "TangentialSubModel") -> "TangentialLaw":
        """The kernels' law of a tangential record (the inverse of :meth:`slot`)."""
        own = _own_fields(type(record))
        fields = {name: getattr(record, name) for name in record.param_names() if name not in own}
        return cls(record.family, kt_sqrt=record.kt_sqrt, **fields,
                   params=tuple(float(getattr(record, name)) for name in own))


def _own_fields(record: type) -> tuple[str, ...]:
    """A record's numbers that no named column of the law array holds (they go to ``params``)."""
    named = {f.name for f in dataclasses.fields(TangentialLaw)} - {"family", "kt_sqrt", "params"}
    return tuple(n for n in record.param_names() if n not in named)


@dataclass(frozen=True)
class TangentialModel:
    id: str
    seed_name: str
    title: str
    formula: str
    source: str
    params: tuple[Param, ...]
    resolve: Callable[[Pair, dict, NormalLaw], tuple[TangentialLaw, dict]] = field(repr=False)
    aliases: tuple[str, ...] = ()
    example: dict = field(default_factory=dict)


REGISTRY = Registry("tangential")
register = REGISTRY.register
lookup = REGISTRY.lookup


# ----------------------------------------------------------------------------- parameter helpers


def _num(params: dict, key: str, rule: str, check, *, required_by: str | None = None):
    return contact_number(params, key, rule=rule, check=check,
                          required_by=f"tangential model '{required_by}'" if required_by else None)


def _friction(pair: Pair, model: str) -> tuple[float, float]:
    if pair.friction is None:
        raise ConfigError("materials.*.friction", None, f"missing: tangential model '{model}' needs a friction "
                          "coefficient (materials' friction or contact.friction)")
    mu_s = float(pair.friction)
    mu_k = float(pair.friction_kinetic) if pair.friction_kinetic is not None else mu_s
    if mu_k > mu_s:
        raise ConfigError("contact.friction_kinetic", mu_k, kinetic_rule(mu_s))
    return mu_s, mu_k


def mindlin_ratio(nu: float) -> float:
    """Kt/Kn = (1 − ν)/(1 − ν/2) (Mindlin 1949)."""
    return (1.0 - nu) / (1.0 - 0.5 * nu)


def deen_eta(m: float, kt: float, et: float) -> float:
    """Deen et al. (2007): ηt = −2 ln εt √((2/7) m̄ Kt)/√(ln²εt + π²); 2√((2/7) m̄ Kt) at εt = 0.
    (Seed 000 prints √(2/7) m̄ Kt under one root sign only; η must scale with √(m̄Kt).)"""
    if et <= 0.0:
        return 2.0 * math.sqrt(2.0 / 7.0 * m * kt)
    if et >= 1.0:
        return 0.0
    le = math.log(et)
    return -2.0 * le * math.sqrt(2.0 / 7.0 * m * kt) / math.sqrt(le * le + math.pi**2)


def _linear_kn(normal: NormalLaw) -> float | None:
    if normal.family == HYSTERETIC:
        return normal.kl
    if normal.a == 1.0:
        return normal.k
    return None


def _linear_kt(pair: Pair, params: dict, normal: NormalLaw, model: str) -> tuple[float, dict]:
    kt = _num(params, "kt", "must be > 0 (N/m)", lambda x: x > 0)
    if kt is not None:
        return kt, {"kt": kt}
    kn = _linear_kn(normal)
    if kn is None:
        raise ConfigError("contact.kt", None, f"missing: tangential model '{model}' with a nonlinear normal model "
                          "needs an explicit kt (the Mindlin ratio applies to a linear Kn)")
    kt = mindlin_ratio(pair.poisson_ratio) * kn
    return kt, {"kt": kt, "kt_over_kn": mindlin_ratio(pair.poisson_ratio)}


def _eta_t(pair: Pair, params: dict, kt: float | None, model: str, *, required: bool) -> tuple[float, dict]:
    eta = _num(params, "eta_t", "must be >= 0", lambda x: x >= 0)
    if eta is not None:
        return eta, {"eta_t": eta}
    ratio = _num(params, "eta_t_ratio", "must be >= 0 (s)", lambda x: x >= 0)
    if ratio is not None and kt is not None:  # Cundall & Strack: ηt ∝ Kt
        return ratio * kt, {"eta_t": ratio * kt, "eta_t_ratio": ratio}
    if pair.tangential_restitution is not None and kt is not None:
        eta = deen_eta(pair.m_eff, kt, pair.tangential_restitution)
        return eta, {"eta_t": eta, "tangential_restitution": pair.tangential_restitution}
    if required:
        raise ConfigError("contact.eta_t", None, f"missing: required by tangential model '{model}' "
                          "(or eta_t_ratio, or a tangential_restitution)")
    return 0.0, {"eta_t": 0.0}


def _base(pair: Pair, mu: tuple[float, float]) -> dict:
    return {"mu_s": mu[0], "mu_k": mu[1], "r_eff": pair.r_eff, "m_eff": pair.m_eff}


def _truncation(params: dict, default: str = "force") -> int:
    return TRUNCATIONS[contact_choice(params, "truncation", tuple(TRUNCATIONS), default)]


# ----------------------------------------------------------------------------- resolvers


def _none(pair, params, normal):
    return TangentialLaw(NONE), {}


def _sliding(pair, params, normal):
    mu = _friction(pair, "sliding")
    return TangentialLaw(SLIDING, **_base(pair, mu)), {"friction": mu[0], "friction_kinetic": mu[1]}


def _viscous(pair, params, normal):
    eta, out = _eta_t(pair, params, None, "viscous", required=True)
    return TangentialLaw(VISCOUS, eta=eta, r_eff=pair.r_eff, m_eff=pair.m_eff), out


def _viscous_sliding(pair, params, normal):
    mu = _friction(pair, "viscous_sliding")
    eta, out = _eta_t(pair, params, None, "viscous_sliding", required=True)
    return TangentialLaw(VISCOUS_SLIDING, eta=eta, **_base(pair, mu)), {**out, "friction": mu[0],
                                                                         "friction_kinetic": mu[1]}


def _spring_sliding(pair, params, normal):
    mu = _friction(pair, "spring_sliding")
    kt, out = _linear_kt(pair, params, normal, "spring_sliding")
    return TangentialLaw(SPRING, kt=kt, truncation=TRUNC_MAW, **_base(pair, mu)), {**out, "friction": mu[0],
                                                                                      "friction_kinetic": mu[1]}


def _lsd_sliding(pair, params, normal):
    mu = _friction(pair, "lsd_sliding")
    kt, out = _linear_kt(pair, params, normal, "lsd_sliding")
    eta, eo = _eta_t(pair, params, kt, "lsd_sliding", required=True)
    trunc = _truncation(params)
    return (TangentialLaw(SPRING, kt=kt, eta=eta, truncation=trunc, **_base(pair, mu)),
            {**out, **eo, "truncation": params.get("truncation", "force"), "friction": mu[0],
             "friction_kinetic": mu[1]})


def _ddt(pair, params, normal):
    mu = _friction(pair, "ddt")
    c = 16.0 / 3.0 * pair.g_eff
    eta, eo = _eta_t(pair, params, None, "ddt", required=False)
    return (TangentialLaw(SPRING, kt=c, kt_sqrt=True, eta=eta, truncation=TRUNC_MAW, **_base(pair, mu)),
            {"kt_coefficient": c, **eo, "friction": mu[0], "friction_kinetic": mu[1]})


def _xi_coef(pair: Pair, mu: float) -> float:
    nu = pair.poisson_ratio
    return mu * (2.0 - nu) / (2.0 * (1.0 - nu))


def _lth(pair, params, normal):
    mu = _friction(pair, "lth")
    eta = _num(params, "eta_t", "must be >= 0 (dimensionless)", lambda x: x >= 0) or 0.0
    return (TangentialLaw(LTH, eta=eta, xi_coef=_xi_coef(pair, mu[1]), **_base(pair, mu)),
            {"eta_t": eta, "xi_max_over_delta_n": _xi_coef(pair, mu[1]), "friction": mu[0], "friction_kinetic": mu[1]})


def _zzy(pair, params, normal):
    mu = _friction(pair, "zzy")
    eta1 = _num(params, "eta_1", "must be >= 0 (Pa·s)", lambda x: x >= 0, required_by="zzy")
    g_i = pair.youngs_modulus / (2.0 * (1.0 + pair.poisson_ratio))
    return (TangentialLaw(ZZY, eta1=eta1, g_i=g_i, xi_coef=_xi_coef(pair, mu[1]), **_base(pair, mu)),
            {"eta_1": eta1, "g_i": g_i, "xi_max_over_delta_n": _xi_coef(pair, mu[1]), "friction": mu[0],
             "friction_kinetic": mu[1]})


def _tti(pair, params, normal):
    mu = _friction(pair, "tti")
    c = 8.0 * pair.g_eff  # = √(2R)E/((2−ν)(1+ν)) √δn for like spheres of radius R (seed 000)
    if normal.family == HYSTERETIC:
        raise ConfigError("contact.normal", "hls", "tangential model 'tti' takes ηt = ηn from a viscoelastic normal model")
    trunc = _truncation(params)
    return (TangentialLaw(SPRING, kt=c, kt_sqrt=True, eta=1.0, eta_normal=True, truncation=trunc,
                          **_base(pair, mu)),
            {"kt_coefficient": c, "eta_t": "eta_n", "truncation": params.get("truncation", "force"),
             "friction": mu[0], "friction_kinetic": mu[1]})


def _walton(pair, params, normal):
    mu = _friction(pair, "walton")
    k0, out = _linear_kt(pair, params, normal, "walton")
    return TangentialLaw(WALTON, k0=k0, **_base(pair, mu)), {"k0": k0, **{k: v for k, v in out.items() if k != "kt"},
                                                              "friction": mu[0], "friction_kinetic": mu[1]}


_TRUNCATION = Param("truncation", "force | overlap | spring", "force", choices=tuple(TRUNCATIONS))
_MU = (Param("friction", "μ (static); default: the smaller of the materials'"),
       Param("friction_kinetic", "μk while slipping; default μ"))
_ETA = (Param("eta_t", "ηt (N·s/m)"), Param("eta_t_ratio", "ηt = ratio·Kt (Cundall & Strack; s)"),
        Param("tangential_restitution", "εt: ηt from Deen et al. (2007)"))
_KT = (Param("kt", "Kt (N/m); default (1−ν)/(1−ν/2)·Kn of a linear normal model"),)

register(TangentialModel(
    id="none", seed_name="—", title="Frictionless", formula="Ft = 0", source="—", params=(), resolve=_none,
    aliases=("off", "frictionless"),
))
register(TangentialModel(
    id="sliding", seed_name="Simple sliding friction", title="Simple sliding friction",
    formula="Ft = −μ|Fn| t̂ (sticks at zero slip while μ|Fn| can hold it)",
    source="seed 000 §4.2 'Simple Sliding Friction'", params=_MU, resolve=_sliding, example={"friction": 0.3},
))
register(TangentialModel(
    id="viscous", seed_name="Simple viscous damping", title="Simple viscous damping", formula="Ft = −ηt v_t",
    source="seed 000 §4.3 'Simple Viscous Damping'", params=(_ETA[0],), resolve=_viscous,
    example={"eta_t": 2.0},
))
register(TangentialModel(
    id="viscous_sliding", seed_name="Viscous damping with sliding friction", title="Viscous damping with sliding friction",
    formula="Ft = −min(ηt|v_t|, μ|Fn|) t̂", source="seed 000 §4.4 'Viscous Damping with Sliding Friction'",
    params=(_ETA[0], *_MU), resolve=_viscous_sliding, example={"eta_t": 2.0, "friction": 0.3},
))
register(TangentialModel(
    id="spring_sliding", seed_name="Linear spring with sliding friction", title="Linear spring with sliding friction",
    formula="Ft = −Kt ξ, |Ft| ≤ μ|Fn| (ξ truncated while slipping)",
    source="seed 000 §4.5 'Linear Spring with Sliding Friction'", params=(*_KT, *_MU), resolve=_spring_sliding,
    example={"friction": 0.3},
))
register(TangentialModel(
    id="lsd_sliding", seed_name="LSDt", aliases=("lsdt",), title="Linear spring-dashpot with sliding friction",
    formula="Ft = min(|Kt ξ + ηt v_t|, μ|Fn|); truncation = force (cap only) or overlap (Maw: ξ such that "
            "Kt ξ + ηt δ̇t = μ|Fn|)",
    source="seed 000 §4.6 'Linear Spring-Dashpot with Sliding Friction'",
    params=(*_KT, *_ETA, _TRUNCATION, *_MU), resolve=_lsd_sliding,
    example={"friction": 0.3, "tangential_restitution": 0.5},
))
register(TangentialModel(
    id="ddt", seed_name="DDt", title="Di Renzo & Di Maio nonlinear spring",
    formula="Ft = −Kt ξ (− ηt v_t), Kt = (16/3) Ḡ √(R̄ δn), |Ft| ≤ μ|Fn|",
    source="seed 000 §4.7 '1) DDt model'", params=(_ETA[0], *_MU), resolve=_ddt, example={"friction": 0.3},
))
register(TangentialModel(
    id="lth", seed_name="LTH", title="Langston, Tüzün & Heyes",
    formula="Ft,el = μ|Fn|(1 − (1 − min(|ξ|,ξm)/ξm)^{3/2}), Ft,vis = ηt (6m̄μ|Fn|√(1 − min(|ξ|,ξm)/ξm)/ξm)^{1/2} δ̇t, "
            "ξm = μ(2−ν)/(2(1−ν)) δn",
    source="seed 000 §4.7 '2) LTH model'", params=(Param("eta_t", "ηt (dimensionless)", 0.0), *_MU), resolve=_lth,
    example={"friction": 0.3, "eta_t": 0.5},
))
register(TangentialModel(
    id="zzy", seed_name="ZZYt", aliases=("zzyt",), title="Zheng, Zhu & Yu",
    formula="Ft,el as LTH; Ft,vis = η₁/(2Gᵢξm)(1 − 0.4η₁|δ̇t|/(2Gᵢξm))(1.5μ|Fn|√(1 − min(|ξ|,ξm)/ξm)) δ̇t",
    source="seed 000 §4.7 '3) ZZYt model'", params=(Param("eta_1", "η₁ (Pa·s)"), *_MU), resolve=_zzy,
    example={"friction": 0.3, "eta_1": 1e-4},
))
register(TangentialModel(
    id="tti", seed_name="TTIt", aliases=("ttit",), title="Tsuji, Tanaka & Ishida tangential",
    formula="Ft = −Kt ξ − ηn δn^{b} v_t, Kt = 8Ḡ√(R̄δn) (= √(2R)E/((2−ν)(1+ν))√δn for like spheres), |Ft| ≤ μ|Fn|",
    source="seed 000 §4.7 '4) TTIt model'", params=(_TRUNCATION, *_MU),
    resolve=_tti, example={"friction": 0.3},
))
register(TangentialModel(
    id="walton", seed_name="Incrementally slipping friction", aliases=("walton_braun",),
    title="Incrementally slipping friction (Walton & Braun)",
    formula="ΔFt = Kt Δδt, Kt = K0 (1 − s(Ft − F*)/(μ|Fn| − sF*))^{1/3}; F* = Ft at the last slip reversal",
    source="seed 000 §4.8 'Incrementally Slipping Friction'", params=(*_KT, *_MU), resolve=_walton,
    example={"friction": 0.3},
))


# plug-in laws last: each registers its record, its compiled functions and its users' name as a built-in does
load_plugins()
