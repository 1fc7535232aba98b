"""The four slots beyond sliding in a case: ``[contact] rolling``, ``twisting``, ``adhesion`` and ``heat`` (each
``none`` by default), their ``[contact]`` parameters, and their records resolved for a pair.

Each law's case keys are its record's field names (laws/rolling.py, twisting.py, adhesion.py, heat.py); what the
pair fixes (the radii, E*, a wall) is taken from the pair, never from the case. A choice stored as an int in the
record (``cap``, ``break_at``, ``area``) is written as its name in the case. Every key is checked like the other
``[contact]`` keys: a bad one is a ConfigError naming the key, the value and the rule.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import ConfigError
from . import adhesion as _adhesion
from . import heat as _heat
from . import rolling as _rolling
from . import twisting as _twisting
from .base import SUBMODELS, SubModel
from .contact import Pair
from .registry import contact_number

BEYOND_SLOTS = ("rolling", "twisting", "adhesion", "heat")


@dataclass(frozen=True)
class Key:
    """One case key of a law: a number (``rule``/``check``), a flag (``flag``) or a choice (``choices``: name → the
    record's int); ``default`` None: required (or, with ``from_pair``, taken from the pair when absent)."""

    name: str
    meaning: str
    rule: str = "must be >= 0"
    check: object = None  # None: >= 0
    default: object = None
    flag: bool = False
    choices: dict | None = None
    from_pair: bool = False


def _pos(v):
    return v > 0


def _nonneg(v):
    return v >= 0


_MU_R = Key("mu_r", "coefficient of rolling resistance (limit torque μr Rr |Fn|)")
_R_ROLL = Key("r_roll", "rolling radius Rr (m; default R̄, the sphere's radius on a wall)", "must be > 0 (m)", _pos,
              from_pair=True)
_C_R = Key("c_r", "rolling damping coefficient Cr (N·m·s/rad)", default=0.0)

KEYS: dict[tuple[str, str], tuple[Key, ...]] = {
    ("rolling", "constant_torque"): (
        _MU_R, _R_ROLL,
        Key("full_direction", "direction from all of ω0 − ω1 (LIGGGHTS cdt), not its rolling part", default=False,
            flag=True)),
    ("rolling", "viscous"): (Key("c_r", "rolling damping coefficient Cr (N·m·s/rad)", "must be > 0", _pos),),
    ("rolling", "epsd"): (
        _MU_R, _R_ROLL, Key("k_r", "rolling stiffness kr (N·m/rad)", "must be > 0", _pos), _C_R,
        Key("cap", "what the limit caps: the spring (Ai et al.) or spring + dashpot (LAMMPS sds)", default="spring",
            choices={"spring": _rolling.CAP_SPRING, "total": _rolling.CAP_TOTAL}),
        Key("slack_zero", "no torque while the spring is unstretched and the dashpot alone exceeds the limit",
            default=False, flag=True)),
    ("twisting", "sds"): (
        Key("k_tw", "twisting stiffness (N·m/rad)", "must be > 0", _pos),
        Key("gamma_tw", "twisting damping (N·m·s/rad)", default=0.0),
        Key("mu_tw", "twisting limit coefficient (m: μtw |Fn| is a torque)")),
    ("twisting", "marshall"): (
        Key("kt", "the tangential stiffness the twist is built from (N/m)", "must be > 0", _pos),
        Key("gamma_t", "the tangential damping (N·s/m)", default=0.0),
        Key("mu_t", "the tangential friction coefficient (default the pair's friction)", from_pair=True)),
    ("adhesion", "jkr"): (
        Key("w", "work of adhesion (J/m²; 2γ for like surfaces)", "must be > 0 (J/m²)", _pos),
        Key("break_at", "where the contact breaks: δ_f (imposed displacement) or δ_c (imposed load, LAMMPS)",
            default="displacement",
            choices={"displacement": _adhesion.BREAK_DISPLACEMENT, "load": _adhesion.BREAK_LOAD})),
    ("adhesion", "dmt"): (Key("w", "work of adhesion (J/m²)", "must be > 0 (J/m²)", _pos),),
    ("adhesion", "sjkr"): (
        Key("k_c", "cohesion energy density (J/m³)", "must be > 0 (J/m³)", _pos),
        Key("area", "contact area: lens (sjkr) or band 2πRxδ (sjkr2)", default="lens",
            choices={"lens": _adhesion.AREA_LENS, "band": _adhesion.AREA_BAND})),
    ("heat", "radius"): (Key("k", "conductivity ks (W/(m·K))", "must be > 0", _pos),),
    ("heat", "area"): (Key("k", "contact conductance per area hs (W/(m²·K))", "must be > 0", _pos),),
    ("heat", "lens"): (Key("k", "conductivity ks = 2k0k1/(k0+k1) (W/(m·K))", "must be > 0", _pos),),
}


# (slot, id) → (formula, source): `demcheck models` and docs/models.md ("Beyond sliding")
DOCS = {
    ("rolling", "constant_torque"): ("M = −μr Rr |Fn| ŵt (wt the rolling part of ω0 − ω1)",
                                     "Ai, Chen, Rotter & Ooi, Powder Technol. 206 (2011) 269, model A"),
    ("rolling", "viscous"): ("M = −Cr wt", "Ai et al. 2011, model B"),
    ("rolling", "epsd"): ("Mk ← Mk − kr wt dt, |Mk| ≤ μr Rr |Fn|; Md = −Cr wt (off at the limit, or the sum capped)",
                          "Ai et al. 2011, model C (Iwashita & Oda 1998); LAMMPS rolling sds"),
    ("twisting", "sds"): ("Mt = −ktw φ − γtw φ̇, |Mt| ≤ μtw |Fn|",
                          "Marshall, J. Comput. Phys. 228 (2009) 1541; LAMMPS twisting sds"),
    ("twisting", "marshall"): ("sds with ktw = kt a²/2, γtw = γt a²/2, μtw = 2aμt/3 (a the contact radius)",
                               "Marshall 2009; LAMMPS twisting marshall"),
    ("adhesion", "jkr"): ("δ = a²/R̄ − √(2πwa/E*), F = 4E*a³/(3R̄) − √(8πwE*a³); breaks at δ_f (or δ_c)",
                          "Johnson, Kendall & Roberts, Proc. R. Soc. A 324 (1971) 301"),
    ("adhesion", "dmt"): ("F = (4/3)E*√R̄ δ^{3/2} − 2πwR̄ (δ ≥ 0)",
                          "Derjaguin, Muller & Toporov, J. Colloid Interface Sci. 53 (1975) 314"),
    ("adhesion", "sjkr"): ("F = −kc A added to the normal law (A: the spheres' intersection circle, or 2πRxδ)",
                           "simplified JKR: LIGGGHTS cohesion sjkr / sjkr2"),
    ("heat", "radius"): ("Q = 2 ks a (T1 − T0), a = √(R̄δ)", "Batchelor & O'Brien, Proc. R. Soc. A 355 (1977) 313"),
    ("heat", "area"): ("Q = hs π a² (T1 − T0)", "LAMMPS pair granular heat area"),
    ("heat", "lens"): ("Q = 2 ks √A (T1 − T0), A the spheres' intersection circle",
                       "LIGGGHTS fix heat/gran/conduction"),
}


def law_ids(slot: str) -> list[str]:
    """The ids a case may name in ``slot`` (``none`` first)."""
    return ["none", *sorted(i for s, i in KEYS if s == slot)]


def check_id(slot: str, value) -> str:
    if not isinstance(value, str) or value.strip().lower() not in law_ids(slot):
        raise ConfigError(f"contact.{slot}", value, f"must be one of {', '.join(law_ids(slot))}")
    return value.strip().lower()


def keys_of(ids: dict) -> dict[str, Key]:
    """The case keys the named laws read ({name: Key}); laws sharing a key name share its value."""
    out = {}
    for slot, id_ in ids.items():
        for key in KEYS.get((slot, id_), ()):
            out.setdefault(key.name, key)
    return out


def _value(params: dict, key: Key, law: str, default):
    if key.flag:
        v = params.get(key.name, key.default)
        if not isinstance(v, bool):
            raise ConfigError(f"contact.{key.name}", v, "must be true or false")
        return v
    if key.choices is not None:
        v = params.get(key.name, key.default)
        if not isinstance(v, str) or v not in key.choices:
            raise ConfigError(f"contact.{key.name}", v, f"must be one of {', '.join(key.choices)}")
        return key.choices[v]
    required = None if (key.default is not None or default is not None) else law
    v = contact_number(params, key.name, rule=key.rule, check=key.check or _nonneg, required_by=required)
    if v is None:
        v = default if default is not None else key.default
    return v


def record(slot: str, id_: str, params: dict, pair: Pair, radii: tuple[float, float]) -> SubModel:
    """The record of law ``id_`` in ``slot`` for ``pair`` (``radii``: the two bodies' radii, the second 0 on a
    wall), its numbers read from ``params`` ([contact]); a missing or bad one is a ConfigError."""
    cls = SUBMODELS[(slot, id_)]
    if id_ == "none":
        return cls()
    law = f"{slot} model '{id_}'"
    pair_defaults = {"r_roll": pair.r_eff, "mu_t": pair.friction}
    values = {key.name: _value(params, key, law, pair_defaults.get(key.name) if key.from_pair else None)
              for key in KEYS[(slot, id_)]}
    fields = set(cls.param_names())
    geometry = {"r_eff": pair.r_eff, "e_eff": pair.e_eff, "r0": radii[0], "r1": radii[1], "wall": pair.wall}
    values.update({k: v for k, v in geometry.items() if k in fields})
    if id_ in ("lens", "sjkr") and pair.wall:
        values["r1"] = 0.0
    return cls(**values)


def records(ids: dict, params: dict, pair: Pair, radii: tuple[float, float]) -> dict[str, SubModel]:
    return {slot: record(slot, ids.get(slot, "none"), params, pair, radii) for slot in BEYOND_SLOTS}


def finite(rec: SubModel) -> bool:
    return all(math.isfinite(x) for x in rec.array())


# make sure every law module registered its records (imported above)
_LAWS = (_rolling, _twisting, _adhesion, _heat)
