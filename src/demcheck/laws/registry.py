"""A registry of models of one slot (normal or tangential): ids and aliases, unique, case-insensitive; the
reader of the models' numeric ``[contact]`` parameters; and, for the slots beyond sliding (rolling, twisting,
adhesion, heat), a law's case keys (:class:`Key`) and its slot's compiled force functions (:class:`Kernels`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from ..errors import ConfigError
from .base import SubModel


def contact_number(params: dict, key: str, *, rule: str, check=None, required_by: str | None = None):
    """``[contact].key`` as a float, None when absent; a missing required or bad value is a ConfigError naming
    the key, the value and the rule. ``required_by`` reads like "normal model 'kk'"."""
    v = params.get(key)
    if v is None:
        if required_by:
            raise ConfigError(f"contact.{key}", None, f"missing: required by {required_by}")
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ConfigError(f"contact.{key}", v, "must be a finite number")
    if check is not None and not check(v):
        raise ConfigError(f"contact.{key}", v, rule)
    return float(v)


class Registry(dict):
    def __init__(self, slot: str):
        super().__init__()
        self.slot = slot

    def register(self, model):
        for key in (model.id, *model.aliases):
            if key in self.names():
                raise ValueError(f"{self.slot} model id {key!r} registered twice")
        self[model.id] = model
        return model

    def lookup(self, name: str):
        key = name.strip().lower()
        for m in self.values():
            if key == m.id or key in (a.lower() for a in m.aliases):
                return m
        raise KeyError(name)

    def names(self) -> list[str]:
        """Every id and alias (for suggestions of the nearest name)."""
        out = []
        for m in self.values():
            out.append(m.id)
            out.extend(a.lower() for a in m.aliases)
        return out


def positive(v) -> bool:
    """A Key's check: > 0."""
    return v > 0


@dataclass(frozen=True)
class Key:
    """One case key of a law beyond sliding: a number (``rule``/``check``), a flag (``flag``) or a choice
    (``choices``: name → the record's int); ``default`` None: required (or, with ``from_pair``, taken from the pair
    when absent). A law's record lists its keys (``keys``); laws/slots.py reads them."""

    name: str
    meaning: str
    rule: str = "must be >= 0"
    check: object = None  # None: >= 0
    default: object = None
    flag: bool = False
    choices: dict | None = None
    from_pair: bool = False


class Kernels(dict):
    """One slot's compiled force functions by record class: each law module registers its own
    (``KERNELS.register(Record, <id>_<slot>_force)``); the solvers call :meth:`of` a record, never an id."""

    def __init__(self, slot: str):
        super().__init__()
        self.slot = slot

    def register(self, record: type, force) -> type:
        if record.slot != self.slot:
            raise ValueError(f"{record.__name__} is a {record.slot} law, not a {self.slot} law")
        if self.get(record, force) is not force:
            raise ValueError(f"{self.slot} law {record.id!r} registered twice with other force functions")
        self[record] = force
        return record

    def of(self, law):
        """The compiled force function of ``law`` (a record), None for no law or one without a force."""
        return None if law is None else self.get(type(law))


@dataclass(frozen=True)
class BeyondSubModel(SubModel):
    """A law of a slot beyond sliding (rolling, twisting, adhesion, heat): its record also names its case keys
    (``keys``: :class:`Key` s, the record's field names), its formula and source (``demcheck models``,
    docs/models.md) and the parameters an engine listing tries it with where a suite case runs another law of the
    slot (``example``). Each slot's base (``laws/<slot>_laws/slot.py``) adds the traits its solvers ask."""

    keys: ClassVar[tuple] = ()
    # the scenarios beyond sliding (run.scenario) that measure this law: case.py accepts it in those
    scenarios: ClassVar[tuple] = ()
    formula: ClassVar[str] = ""
    source: ClassVar[str] = ""
    example: ClassVar[dict] = {}
