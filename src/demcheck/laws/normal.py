"""Normal contact models (seed 000 §3, seed 001), as a registry.

Each model turns a pair's effective properties and the case's ``[contact]`` parameters into a
:class:`NormalLaw`: plain numbers that the compiled kernels (laws/normal_force.py) evaluate — the normal law's
record (one module per law, laws/normal_laws/: hooke, hertz, hls) and the damping law's (laws/damping_laws/).
Every law of the notes is one of

* viscoelastic power law   F = k δ^a + η δ^b δ̇        (LSDn a=1 b=0; Hertz η=0; BSHPn, KKn b=½; TTIn b=¼)
* hysteretic linear spring F = min(K_L δ, K_U (δ − δ₀)) ≥ 0, δ₀ = δ_max (1 − K_L/K_U)

``limit_force`` (the "collision time reduction") clips the total F at 0.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import ConfigError
from . import analytic
from .contact import Pair
from .damping import RECORDS, SEED_FAMILIES, Damping, NoDamping, damping_of
from .registry import Registry, contact_number

from . import normal_laws  # noqa: F401  (every normal law registered)
from .normal_laws.common import RECORDS as NORMAL_RECORDS
from .normal_laws.common import NormalSubModel
from .normal_laws.hertz import HertzNormal
from .normal_laws.hls import HYSTERETIC, HysteresisNormal
from .normal_laws.hooke import HookeNormal

# the elastic records by their exponent (the one place an exponent names a record: NormalLaw)
ELASTIC_BY_EXPONENT = {cls.exponent: cls for cls in (HookeNormal, HertzNormal)}
SPRING_FAMILIES = frozenset(cls.family for cls in ELASTIC_BY_EXPONENT.values())
# the seed's power-law spring as one family, as the law array had it: a law of any of SPRING_FAMILIES is the
# record its exponent names (NormalLaw(VISCOELASTIC, a=1.5) is hertz's)
VISCOELASTIC = HookeNormal.family


@dataclass(frozen=True)
class NormalLaw:
    """The normal and damping slots' records as the compiled kernels read them: the normal law's family id
    (laws/normal_laws/) and the union of the records' numbers (a record's numbers fill the columns of their names,
    or its ``columns``), the damping law's family id and η, b, and limit_force."""

    # the normal law's family id: a seed spring's (SPRING_FAMILIES) is the one its exponent ``a`` names, whatever
    # is given; None where no record has the exponent (then array() raises, slots() too)
    family: int | None
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
        if self.family in SPRING_FAMILIES:
            spring = ELASTIC_BY_EXPONENT.get(self.a)
            object.__setattr__(self, "family", None if spring is None else spring.family)
        if self.damping is None or self.damping in SEED_FAMILIES:
            object.__setattr__(self, "damping", _seed_damping(self))

    def array(self) -> np.ndarray:
        """The law as the compiled kernels read it (kernels.L_FAMILY … L_LIMIT): the only positional form."""
        if self.family is None or self.damping is None:
            self.slots()  # the ValueError naming the exponent no record has
        return np.array([self.family, self.k, self.a, self.eta, self.b, self.kl, self.ku, self.s, self.damping,
                         1.0 if self.limit else 0.0])

    @classmethod
    def from_array(cls, law) -> "NormalLaw":
        family, k, a, eta, b, kl, ku, s, damping, limit = (float(x) for x in law)
        return cls(int(family), k=k, a=a, eta=eta, b=b, kl=kl, ku=ku, s=s, limit=limit != 0.0, damping=int(damping))

    def _record(self) -> type[NormalSubModel]:
        """The normal record class of the law's family (ValueError for an exponent or family no record has)."""
        if self.family is None:
            raise ValueError(f"no normal record has the δ^{self.a:g} spring (known: "
                             f"{', '.join(f'{c.id} δ^{e:g}' for e, c in ELASTIC_BY_EXPONENT.items())})")
        if self.family not in NORMAL_RECORDS:
            raise ValueError(f"no normal law has the family id {self.family} (known: "
                             f"{', '.join(f'{c.id} {f}' for f, c in sorted(NORMAL_RECORDS.items()))})")
        return NORMAL_RECORDS[self.family]

    def loading_overlap(self, force: float) -> float:
        """The overlap at which the loading branch carries ``force`` at rest: (F/k)^{1/a}, or F/K_L for a law with
        loading and unloading branches (hls)."""
        if self._record().load_unload:
            return force / self.kl
        return (force / self.k) ** (1.0 / self.a)

    def characteristic_time(self, m: float, v: float) -> float:
        """The elastic contact time of the law's spring at speed v (for dt = auto and solver scales): its loading
        branch's, or its power law k δ^a's."""
        if self._record().load_unload:
            return analytic.power_law_duration(self.kl, 1.0, m, v)
        return analytic.power_law_duration(self.k, self.a, m, v)

    def slots(self) -> tuple[NormalSubModel, Damping]:
        """The law as the records of its two slots, normal and damping (ValueError for a spring or dashpot
        exponent no record has)."""
        record = self._record()
        normal = record.from_law(self)
        if record.load_unload:
            if self.eta != 0.0:
                raise ValueError(f"the normal law {record.id!r} (loading and unloading branches) has no dashpot")
            return normal, NoDamping()
        if self.damping is not None and self.damping not in SEED_FAMILIES:
            return normal, RECORDS[self.damping](eta=self.eta)
        return normal, damping_of(self.eta, self.b)

    @classmethod
    def from_slots(cls, normal: NormalSubModel, damping: Damping, limit: bool) -> "NormalLaw":
        """The kernels' law of a normal and a damping record (the inverse of :meth:`slots`)."""
        record = type(normal)
        if NORMAL_RECORDS.get(record.family) is not record:
            raise ValueError(f"the normal record {record.id!r} has no compiled law (family {record.family!r})")
        if record.load_unload:
            if not isinstance(damping, NoDamping):
                raise ValueError(f"the normal law {record.id!r} (loading and unloading branches) takes no dashpot "
                                 f"(damping {damping.id!r})")
            return cls(record.family, **normal.law_numbers(), limit=limit)
        return cls(record.family, **normal.law_numbers(), eta=getattr(damping, "eta", 0.0), b=damping.exponent,
                   limit=limit, damping=damping.family)


def _seed_damping(law: NormalLaw) -> int | None:
    """The family of a seed law's dashpot: none for a law with loading and unloading branches, else the record its
    (η, b) name."""
    if law.family in NORMAL_RECORDS and NORMAL_RECORDS[law.family].load_unload:
        return NoDamping.family
    try:
        return damping_of(law.eta, law.b).family
    except ValueError:
        return None


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
    return NormalLaw(HookeNormal.family, k=kn, a=1.0, eta=eta, b=0.0, limit=limit), out


def _resolve_hertz(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    return NormalLaw(HertzNormal.family, k=k, a=1.5, limit=limit), {"k_hz": k}


def _resolve_bshp(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    a_bar = _get(params, "dissipative_constant", rule="must be >= 0 (s)", check=_nonneg)
    if a_bar is None:
        a_bar = pair.dissipative_constant
    if a_bar is None:
        raise ConfigError("materials.*.dissipative_constant", None,
                          "missing: normal model 'bshp' needs the materials' dissipative constant A (s)")
    return (NormalLaw(HertzNormal.family, k=k, a=1.5, eta=k * a_bar, b=0.5, limit=limit),
            {"k_hz": k, "dissipative_constant": a_bar, "eta_n": k * a_bar})


def _resolve_kk(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    eta = _get(params, "eta_n", rule="must be >= 0 (N·s/m^1.5)", check=_nonneg)
    if eta is None:
        if pair.dissipative_constant is None:
            raise ConfigError("contact.eta_n", None,
                              "missing: required by normal model 'kk' (or the materials' dissipative_constant)")
        eta = k * pair.dissipative_constant
    return NormalLaw(HertzNormal.family, k=k, a=1.5, eta=eta, b=0.5, limit=limit), {"k_hz": k, "eta_n": eta}


def _resolve_tti(pair: Pair, params: dict, limit: bool):
    k = analytic.hertz_stiffness(pair.r_eff, pair.e_eff)
    eta = _get(params, "eta_n", rule="must be >= 0 (N·s/m^1.25)", check=_nonneg)
    if eta is None:
        eta = analytic.tti_eta_from_restitution(pair.m_eff, k, _restitution(pair, "tti"))
    return NormalLaw(HertzNormal.family, k=k, a=1.5, eta=eta, b=0.25, limit=limit), {"k_hz": k, "eta_n": eta}


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
