"""Normal contact models (seed 000 §3, seed 001), as a registry.

Each model turns a pair's effective properties and the case's ``[contact]`` parameters into a
:class:`NormalLaw`: plain numbers that the compiled kernels (``kernels.py``) evaluate. Two families
cover every law of the notes:

* viscoelastic power law   F = k δ^a + η δ^b δ̇        (LSDn a=1 b=0; Hertz η=0; BSHPn, KKn b=½; TTIn b=¼)
* hysteretic linear spring F = min(K_L δ, K_U (δ − δ₀)) ≥ 0, δ₀ = δ_max (1 − K_L/K_U)

``limit_force`` (the "collision time reduction") clips the total F at 0.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, ClassVar

import numpy as np

from ..errors import ConfigError
from . import analytic
from .base import SubModel
from .contact import Pair
from .damping import RECORDS, SEED_FAMILIES, Damping, NoDamping, damping_of
from .registry import Registry, contact_number

from .normal_laws.hls import FAMILY as HYSTERETIC  # the law array's family ids (laws/normal_laws/)
from .normal_laws.viscoelastic import FAMILY as VISCOELASTIC


@dataclass(frozen=True)
class NormalLaw:
    family: int
    k: float = 0.0
    a: float = 1.0
    eta: float = 0.0
    b: float = 0.0
    kl: float = 0.0
    ku: float = 0.0  # > 0: constant unloading stiffness; 0: K_U = K_L + s·F_max
    s: float = 0.0
    limit: bool = False
    # the damping law's family id (laws/damping_laws/): a seed dashpot's is the one its exponent names (damping_of),
    # whatever is given; None where no record has the exponent (then array() raises, slots() too)
    damping: int | None = None

    def __post_init__(self):
        if self.damping is None or self.damping in SEED_FAMILIES:
            object.__setattr__(self, "damping", _seed_damping(self))

    def array(self) -> np.ndarray:
        """The law as the compiled kernels read it (kernels.L_FAMILY … L_LIMIT): the only positional form."""
        if self.damping is None:
            self.slots()  # the ValueError naming the exponent no record has
        return np.array([self.family, self.k, self.a, self.eta, self.b, self.kl, self.ku, self.s, self.damping,
                         1.0 if self.limit else 0.0])

    @classmethod
    def from_array(cls, law) -> "NormalLaw":
        family, k, a, eta, b, kl, ku, s, damping, limit = (float(x) for x in law)
        return cls(int(family), k=k, a=a, eta=eta, b=b, kl=kl, ku=ku, s=s, limit=limit != 0.0, damping=int(damping))

    def loading_overlap(self, force: float) -> float:
        """The overlap at which the loading branch carries ``force`` at rest: (F/k)^{1/a}, or F/K_L for HLS."""
        if self.family == HYSTERETIC:
            return force / self.kl
        return (force / self.k) ** (1.0 / self.a)

    def characteristic_time(self, m: float, v: float) -> float:
        """The elastic contact time of the law's spring at speed v (for dt = auto and solver scales)."""
        if self.family == HYSTERETIC:
            return analytic.power_law_duration(self.kl, 1.0, m, v)
        return analytic.power_law_duration(self.k, self.a, m, v)

    def slots(self) -> tuple[NormalSubModel, Damping]:
        """The law as the records of its two slots, normal and damping (ValueError for a spring or dashpot
        exponent no record has)."""
        if self.family == HYSTERETIC:
            if self.eta != 0.0:
                raise ValueError("a hysteretic normal law has no dashpot")
            return HysteresisNormal(kl=self.kl, ku=self.ku, s=self.s), NoDamping()
        if self.a not in ELASTIC_BY_EXPONENT:
            raise ValueError(f"no normal record has the δ^{self.a:g} spring (known: hooke δ^1, hertz δ^1.5)")
        if self.damping is not None and self.damping not in SEED_FAMILIES:
            return ELASTIC_BY_EXPONENT[self.a](k=self.k), RECORDS[self.damping](eta=self.eta)
        return ELASTIC_BY_EXPONENT[self.a](k=self.k), damping_of(self.eta, self.b)

    @classmethod
    def from_slots(cls, normal: NormalSubModel, damping: Damping, limit: bool) -> "NormalLaw":
        """The kernels' law of a normal and a damping record (the inverse of :meth:`slots`)."""
        if isinstance(normal, HysteresisNormal):
            if not isinstance(damping, NoDamping):
                raise ValueError(f"the hysteretic normal law takes no dashpot (damping {damping.id!r})")
            return cls(HYSTERETIC, kl=normal.kl, ku=normal.ku, s=normal.s, limit=limit)
        return cls(VISCOELASTIC, k=normal.k, a=normal.exponent, eta=getattr(damping, "eta", 0.0),
                   b=damping.exponent, limit=limit, damping=damping.family)


def _seed_damping(law: NormalLaw) -> int | None:
    """The family of a seed law's dashpot: none for the hysteretic spring, else the record its (η, b) name."""
    if law.family == HYSTERETIC:
        return NoDamping.family
    try:
        return damping_of(law.eta, law.b).family
    except ValueError:
        return None


# ----------------------------------------------------------------------------- the normal slot's records


@dataclass(frozen=True)
class NormalSubModel(SubModel):
    slot: ClassVar[str] = "normal"


@dataclass(frozen=True)
class HookeNormal(NormalSubModel):
    """F = k δ (a linear spring)."""

    id: ClassVar[str] = "hooke"
    title: ClassVar[str] = "linear spring k δ"
    exponent: ClassVar[float] = 1.0
    k: float = 0.0  # N/m


@dataclass(frozen=True)
class HertzNormal(NormalSubModel):
    """F = k δ^{3/2}, k = (4/3) Ē √R̄ for the seed's Hertz law."""

    id: ClassVar[str] = "hertz"
    title: ClassVar[str] = "Hertz spring k δ^{3/2}"
    exponent: ClassVar[float] = 1.5
    k: float = 0.0  # N/m^1.5


@dataclass(frozen=True)
class HysteresisNormal(NormalSubModel):
    """F = min(K_L δ, K_U (δ − δ₀)) ≥ 0 with K_U = ku (> 0), or K_L + s·F_max (ku = 0); its history is the
    largest overlap δ_max."""

    id: ClassVar[str] = "hls"
    title: ClassVar[str] = "hysteretic linear spring"
    history_size: ClassVar[int] = 1
    kl: float = 0.0  # N/m
    ku: float = 0.0  # N/m; 0: variable unloading
    s: float = 0.0  # 1/m


# the elastic records by their exponent (the one place an exponent names a record: NormalLaw.slots)
ELASTIC_BY_EXPONENT = {cls.exponent: cls for cls in (HookeNormal, HertzNormal)}


@dataclass(frozen=True)
class Param:
    name: str
    meaning: str
    default: object = None
    choices: tuple[str, ...] = ()  # a string parameter: its allowed values (checked by contact_choice)
    numeric: bool = False  # with choices: a number > 0 is allowed too


@dataclass(frozen=True)
class NormalModel:
    id: str
    seed_name: str
    title: str
    formula: str
    source: str
    params: tuple[Param, ...]
    resolve: Callable[[Pair, dict, bool], tuple[NormalLaw, dict]] = field(repr=False)
    aliases: tuple[str, ...] = ()
    dissipative: bool = True
    velocity_dependent_restitution: bool = False
    example: dict = field(default_factory=dict)  # [contact] parameters of a typical use (docs, contract tests)


REGISTRY = Registry("normal")
register = REGISTRY.register
lookup = REGISTRY.lookup


# ----------------------------------------------------------------------------- parameter helpers


def _get(params: dict, key: str, *, rule: str, check=None, required_by: str | None = None):
    return contact_number(params, key, rule=rule, check=check,
                          required_by=f"normal model '{required_by}'" if required_by else None)


def contact_choice(params: dict, key: str, choices: tuple[str, ...], default=None, *, numeric: bool = False,
                   hint: str = ""):
    """``[contact].key`` (``default`` when absent): one of the strings ``choices``, or with ``numeric`` a number
    > 0 (as a float); anything else (another string, a number, a list, a table, missing) is a ConfigError naming
    the key, the value and the rule."""
    rule = f"must be one of {', '.join(choices)}" + (" or a number > 0" if numeric else "") + hint
    v = params.get(key, default)
    if isinstance(v, str) and v in choices:
        return v
    if numeric and isinstance(v, (int, float)) and not isinstance(v, bool):
        return contact_number(params, key, rule=rule, check=_positive)
    raise ConfigError(f"contact.{key}", v, rule)


def check_choices(model, params: dict) -> None:
    """Every string parameter of ``model`` given in ``params`` is one of its choices (whether or not the
    resolved law reads it: a stiffness_method beside an explicit kn)."""
    for p in model.params:
        if p.choices and p.name in params:
            contact_choice(params, p.name, p.choices, numeric=p.numeric)


def _restitution(pair: Pair, model: str) -> float:
    if pair.restitution is None:
        raise ConfigError("materials.*.restitution", None,
                          f"missing: normal model '{model}' needs a restitution (or contact.eta_n)")
    return pair.restitution


def _reference_velocity(pair: Pair, params: dict, model: str) -> float:
    v = _get(params, "reference_velocity", rule="must be > 0 (m/s)", check=lambda x: x > 0)
    if v is None:
        v = pair.impact_speed
        if not (v > 0):
            raise ConfigError("contact.reference_velocity", None,
                              f"missing: model '{model}' calibrates its stiffness at a reference velocity, "
                              "and the bodies of this case never meet")
    return v


def _method(params: dict, model: str) -> str:
    return contact_choice(params, "stiffness_method", analytic.STIFFNESS_METHODS, hint=" (or give contact.kn/kl)")


DURATION_CONSTANTS = {"exact": analytic.HERTZ_DURATION_CONSTANT, "notes": analytic.HERTZ_DURATION_CONSTANT_NOTES}
UNLOADINGS = ("constant", "variable")


def _duration_constant(params: dict) -> float:
    c = contact_choice(params, "duration_constant", tuple(DURATION_CONSTANTS), "exact", numeric=True)
    return DURATION_CONSTANTS[c] if isinstance(c, str) else c


def _positive(x):
    return x > 0


def _nonneg(x):
    return x >= 0


# ----------------------------------------------------------------------------- the models


def _resolve_lsd(pair: Pair, params: dict, limit: bool):
    kn = _get(params, "kn", rule="must be > 0 (N/m)", check=_positive)
    out = {}
    if kn is None:
        method = _method(params, "lsd")
        v = _reference_velocity(pair, params, "lsd")
        e = _restitution(pair, "lsd") if params.get("eta_n") is None else (pair.restitution or 1.0)
        kn = analytic.lsd_stiffness(method, pair.m_eff, pair.r_eff, pair.e_eff, v, e, _duration_constant(params))
        out.update(stiffness_method=method, reference_velocity=v)
    eta = _get(params, "eta_n", rule="must be >= 0 (N·s/m)", check=_nonneg)
    if eta is None:
        eta = analytic.lsd_eta_from_restitution(pair.m_eff, kn, _restitution(pair, "lsd"))
    elif eta * eta >= 4.0 * pair.m_eff * kn:
        raise ConfigError("contact.eta_n", eta,
                          f"must be below the critical damping 2√(m̄Kn) = {2 * math.sqrt(pair.m_eff * kn):.6g}")
    out.update(kn=kn, eta_n=eta)
    return NormalLaw(VISCOELASTIC, k=kn, a=1.0, eta=eta, b=0.0, limit=limit), out


def _resolve_hertz(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    return NormalLaw(VISCOELASTIC, k=k, a=1.5, limit=limit), {"k_hz": k}


def _resolve_bshp(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    a_bar = _get(params, "dissipative_constant", rule="must be >= 0 (s)", check=_nonneg)
    if a_bar is None:
        a_bar = pair.dissipative_constant
    if a_bar is None:
        raise ConfigError("materials.*.dissipative_constant", None,
                          "missing: normal model 'bshp' needs the materials' dissipative constant A (s)")
    return (NormalLaw(VISCOELASTIC, k=k, a=1.5, eta=k * a_bar, b=0.5, limit=limit),
            {"k_hz": k, "dissipative_constant": a_bar, "eta_n": k * a_bar})


def _resolve_kk(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    eta = _get(params, "eta_n", rule="must be >= 0 (N·s/m^1.5)", check=_nonneg)
    if eta is None:
        if pair.dissipative_constant is None:
            raise ConfigError("contact.eta_n", None,
                              "missing: required by normal model 'kk' (or the materials' dissipative_constant)")
        eta = k * pair.dissipative_constant
    return NormalLaw(VISCOELASTIC, k=k, a=1.5, eta=eta, b=0.5, limit=limit), {"k_hz": k, "eta_n": eta}


def _resolve_tti(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    eta = _get(params, "eta_n", rule="must be >= 0 (N·s/m^1.25)", check=_nonneg)
    if eta is None:
        eta = analytic.tti_eta_from_restitution(pair.m_eff, k, _restitution(pair, "tti"))
    return NormalLaw(VISCOELASTIC, k=k, a=1.5, eta=eta, b=0.25, limit=limit), {"k_hz": k, "eta_n": eta}


def _resolve_hls(pair: Pair, params: dict, limit: bool):
    unloading = contact_choice(params, "unloading", UNLOADINGS, "constant")
    s = None
    e = None
    if unloading == "variable":
        s = _get(params, "S", rule="must be > 0 (1/m)", check=_positive, required_by="hls")
    else:
        e = _restitution(pair, "hls")
    kl = _get(params, "kl", rule="must be > 0 (N/m)", check=_positive)
    out = {"unloading": unloading}
    if kl is None:
        method = _method(params, "hls")
        v = _reference_velocity(pair, params, "hls")
        kl = analytic.hls_stiffness(method, pair.m_eff, pair.r_eff, pair.e_eff, v, e=e, s=s,
                                    duration_constant=_duration_constant(params))
        out.update(stiffness_method=method, reference_velocity=v)
    out["kl"] = kl
    if s is not None:
        out["S"] = s
        law = NormalLaw(HYSTERETIC, kl=kl, ku=0.0, s=s, limit=limit)
    else:
        ku = kl / (e * e)
        out["ku"] = ku
        law = NormalLaw(HYSTERETIC, kl=kl, ku=ku, limit=limit)
    return law, out


_COMMON = (Param("restitution", "normal coefficient of restitution of the pair (default: the materials')"),)
_STIFFNESS_METHOD = Param("stiffness_method", "calibrate Kn to Hertz: duration | overlap | energy",
                          choices=analytic.STIFFNESS_METHODS)
_REFERENCE_VELOCITY = Param("reference_velocity", "impact speed of the calibration (m/s; default: the case's)")
_DURATION_CONSTANT = Param("duration_constant", "Hertz duration constant of the duration calibration", "exact",
                           choices=tuple(DURATION_CONSTANTS), numeric=True)

register(NormalModel(
    id="lsd", seed_name="LSDn", aliases=("lsdn", "linear", "hooke"),
    title="Linear spring-dashpot",
    formula="F = Kn δ + ηn δ̇; ηn = −2 ln ε √(m̄Kn)/√(ln²ε + π²)",
    source="seed 000 §3.3 'Normal Linear Spring-Dashpot (LSDn)'; seed 001 'Damped Linear Spring'",
    params=(Param("kn", "spring stiffness Kn (N/m)"),
            _STIFFNESS_METHOD, _REFERENCE_VELOCITY, _DURATION_CONSTANT,
            Param("eta_n", "damping ηn (N·s/m; default: from restitution)"), *_COMMON),
    resolve=_resolve_lsd,
    example={"stiffness_method": "energy"},
))
register(NormalModel(
    id="hertz", seed_name="Hertz", aliases=("nsdn-elastic",),
    title="Hertz (elastic)",
    formula="F = K_HZ δ^{3/2}, K_HZ = (4/3) Ē √R̄",
    source="seed 000 §3.4 'Nonlinear elastic force'; seed 001 'Hertzian Contact'",
    params=(), resolve=_resolve_hertz, dissipative=False,
    example={},
))
register(NormalModel(
    id="bshp", seed_name="BSHPn", aliases=("bshpn",),
    title="Brilliantov et al. damped Hertz",
    formula="F = K_HZ δ^{3/2} + K_HZ Ā δ^{1/2} δ̇, Ā = (A₁ + A₂)/2",
    source="seed 000 §3.4 '1) BSHPn Model'",
    params=(Param("dissipative_constant", "Ā (s); default: mean of the materials' dissipative_constant"),),
    resolve=_resolve_bshp, velocity_dependent_restitution=True,
    example={"dissipative_constant": 1e-7},
))
register(NormalModel(
    id="kk", seed_name="KKn", aliases=("kkn",),
    title="Kuwabara & Kono damped Hertz",
    formula="F = K_HZ δ^{3/2} + ηn δ^{1/2} δ̇",
    source="seed 000 §3.4 '2) KKn Model'",
    params=(Param("eta_n", "damping ηn (N·s/m^{3/2}); default: K_HZ·Ā from the materials"),),
    resolve=_resolve_kk, velocity_dependent_restitution=True,
    example={"eta_n": 20.0},
))
register(NormalModel(
    id="tti", seed_name="TTIn", aliases=("ttin",),
    title="Tsuji et al. damped Hertz",
    formula="F = K_HZ δ^{3/2} + ηn δ^{1/4} δ̇; ηn = −2.2664 ln ε √(m̄K_HZ)/√(ln²ε + 10.1354) (Norouzi)",
    source="seed 000 §3.4 '3) TTIn Model'",
    params=(Param("eta_n", "damping ηn (N·s/m^{5/4}); default: Norouzi's correlation"), *_COMMON),
    resolve=_resolve_tti,
    example={},
))
register(NormalModel(
    id="hls", seed_name="HLS", aliases=("hysteretic",),
    title="Hysteretic linear spring (elastic–perfectly plastic)",
    formula="F = min(K_L δ, K_U (δ − δ_res)) ≥ 0; K_U = K_L/ε² (constant) or K_L + S F_max (variable)",
    source="seed 000 §3.5 'Hysteric Linear Spring (HLS)'",
    params=(Param("kl", "loading stiffness K_L (N/m)"),
            dataclasses.replace(_STIFFNESS_METHOD, meaning="calibrate K_L to Hertz: duration | overlap | energy"),
            _REFERENCE_VELOCITY, _DURATION_CONSTANT,
            Param("unloading", "constant | variable", "constant", choices=UNLOADINGS),
            Param("S", "variable unloading: K_U = K_L + S·F_max (1/m)"), *_COMMON),
    resolve=_resolve_hls,
    example={"stiffness_method": "overlap"},
))
