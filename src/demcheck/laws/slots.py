"""The four slots beyond sliding in a case: ``[contact] rolling``, ``twisting``, ``adhesion`` and ``heat`` (each
``none`` by default), their ``[contact]`` parameters, and their records resolved for a pair.

Each law's case keys are its record's field names, listed by the record (``keys``, in its module under
laws/rolling_laws/, twisting_laws/, adhesion_laws/, heat_laws/), as its formula and source are; what the pair
fixes (the radii, E*, a wall) is taken from the pair, never from the case. A choice stored as an int in the record
(``cap``, ``break_at``, ``area``) is written as its name in the case. Every key is checked like the other
``[contact]`` keys: a bad one is a ConfigError naming the key, the value and the rule.
"""

from __future__ import annotations

import math

from ..errors import ConfigError
from . import adhesion as _adhesion
from . import heat as _heat
from . import rolling as _rolling
from . import twisting as _twisting
from .base import SUBMODELS, SubModel
from .contact import Pair
from .registry import BeyondSubModel, Key, contact_number
from .tangential_slot import load_plugins

BEYOND_SLOTS = ("rolling", "twisting", "adhesion", "heat")
load_plugins()  # a plug-in law of these slots registers itself before KEYS and DOCS are read off the records


def _nonneg(v):
    return v >= 0


def _laws() -> dict:
    """(slot, id) → the record class of every registered law beyond sliding (``none`` aside), slot by slot in
    BEYOND_SLOTS' order, each slot's laws in their registration order (the package's, then the plug-ins')."""
    return {(slot, id_): cls for slot in BEYOND_SLOTS for (s, id_), cls in SUBMODELS.items()
            if s == slot and issubclass(cls, BeyondSubModel)}


# (slot, id) → the law's case keys (its record's ``keys``)
KEYS: dict[tuple[str, str], tuple[Key, ...]] = {k: cls.keys for k, cls in _laws().items()}

# (slot, id) → (formula, source): `demcheck models` and docs/models.md ("Beyond sliding"), from each record
DOCS = {k: (cls.formula, cls.source) for k, cls in _laws().items()}


def law_ids(slot: str) -> list[str]:
    """The ids a case may name in ``slot`` (``none`` first)."""
    return ["none", *sorted(i for s, i in KEYS if s == slot)]


def law_class(slot: str, id_: str) -> type | None:
    """The record class of a registered law beyond sliding, None for ``none`` or an id no law has."""
    return _laws().get((slot, id_))


def scenario_laws(slot: str, scenario: str) -> tuple[str, ...]:
    """The ids of the laws of ``slot`` whose record names ``scenario`` (its ``scenarios``), in registration order."""
    return tuple(id_ for (s, id_), cls in _laws().items() if s == slot and scenario in cls.scenarios)


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
    if not issubclass(cls, BeyondSubModel):  # the slot's ``none``
        return cls()
    law = f"{slot} model '{id_}'"
    pair_defaults = {"r_roll": pair.r_eff, "mu_t": pair.friction}
    values = {key.name: _value(params, key, law, pair_defaults.get(key.name) if key.from_pair else None)
              for key in KEYS[(slot, id_)]}
    fields = set(cls.param_names())
    geometry = {"r_eff": pair.r_eff, "e_eff": pair.e_eff, "r0": radii[0], "r1": radii[1], "wall": pair.wall}
    values.update({k: v for k, v in geometry.items() if k in fields})  # radii[1] is 0 on a wall
    return cls(**values)


def records(ids: dict, params: dict, pair: Pair, radii: tuple[float, float]) -> dict[str, SubModel]:
    return {slot: record(slot, ids.get(slot, "none"), params, pair, radii) for slot in BEYOND_SLOTS}


def finite(rec: SubModel) -> bool:
    return all(math.isfinite(x) for x in rec.array())


# make sure every law module registered its records (imported above)
_LAWS = (_rolling, _twisting, _adhesion, _heat)
