"""A contact model = one normal model + one tangential model + options, resolved for a pair."""

from __future__ import annotations

import difflib
from dataclasses import dataclass, field
from functools import cached_property

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the case layer sits above the laws: types only
    from ..case import Case
from ..errors import ConfigError
from . import normal as _normal
from . import slots as _slots
from . import tangential as _tangential
from .base import Contact, SubModel
from .contact import PAIR_RULES, Pair, pair_of, pair_params

# keys of [contact] that belong to the pair rather than to a model (allowed where a model of the case reads them:
# each declares it among its parameters)
PAIR_KEYS = frozenset(PAIR_RULES)


@dataclass(frozen=True)
class ResolvedModel:
    normal: _normal.NormalModel
    tangential: _tangential.TangentialModel
    pair: Pair
    normal_law: _normal.NormalLaw
    tangential_law: _tangential.TangentialLaw
    params: dict
    limit_force: bool
    gravity: tuple[float, float, float] = (0.0, 0.0, 0.0)  # the case's run.gravity (m/s²)
    beyond: dict = field(default_factory=dict)  # slot → record of the slots beyond sliding (laws/slots.py)

    def describe(self) -> dict:
        out = {"normal": self.normal.id, "tangential": self.tangential.id, "limit_force": self.limit_force}
        out.update({slot: rec.id for slot, rec in self.beyond.items() if rec.id != "none"})
        return out

    def slot(self, name: str) -> SubModel | None:
        """The record of a slot beyond sliding (None when the case names none)."""
        rec = self.beyond.get(name)
        return None if rec is None or rec.id == "none" else rec

    @cached_property
    def contact(self) -> Contact:
        """The resolved laws as slot records (laws/base.py): what the engines' vocabularies map, by id."""
        normal, damping = self.normal_law.slots()
        return Contact(normal, damping, self.tangential_law.slot(), limit_force=self.limit_force, **self.beyond)


def _lookup(registry_lookup, names, slot: str, value: str):
    try:
        return registry_lookup(value)
    except KeyError:
        near = difflib.get_close_matches(value.lower(), names, n=1, cutoff=0.5)
        hint = f"; did you mean '{near[0]}'?" if near else ""
        raise ConfigError(f"contact.{slot}", value,
                          f"unknown {slot} model{hint} (known: {', '.join(sorted(names))})") from None


def models_of(case: Case):
    normal = _lookup(_normal.lookup, _normal.REGISTRY.names(), "normal", case.contact.normal)
    tangential = _lookup(_tangential.lookup, _tangential.REGISTRY.names(), "tangential", case.contact.tangential)
    return normal, tangential


def resolve(case: Case, i: int = 0, j: int | None = 1) -> ResolvedModel:
    """The case's model resolved for the pair (i, j) (j None: particle i on a wall), once per case and pair: the
    reference, each engine's mapping, decks, twins and verdicts all read the same object."""
    if len(case.particles) == 1:
        j = None
    key = ("model", i, j)
    model = case.prepared.get(key)
    if model is None:
        model = case.prepared[key] = _resolve(case, i, j)
    return model


def _resolve(case: Case, i: int, j: int | None) -> ResolvedModel:
    normal, tangential = models_of(case)
    pair = pair_of(case, i, j)
    params = case.contact.params
    normal_law, normal_out = normal.resolve(pair, params, case.contact.limit_force)
    tangential_law, tangential_out = tangential.resolve(pair, params, normal_law)
    resolved = {"m_eff": pair.m_eff, "r_eff": pair.r_eff, "e_eff": pair.e_eff, "g_eff": pair.g_eff,
                "impact_speed": pair.impact_speed, **normal_out, **tangential_out}
    if pair.restitution is not None:
        resolved.setdefault("restitution", pair.restitution)
    beyond = _slots.records(_beyond_ids(case), params, pair, _radii(case, i, None if pair.wall else j))
    for slot, rec in beyond.items():
        if rec.id != "none":
            resolved.update({f"{slot}.{k}": v for k, v in rec.describe().items() if k not in ("slot", "id")})
    return ResolvedModel(normal, tangential, pair, normal_law, tangential_law, resolved,
                         case.contact.limit_force, tuple(case.run.gravity), beyond)


def _beyond_ids(case: Case) -> dict:
    return {slot: getattr(case.contact, slot, "none") for slot in _slots.BEYOND_SLOTS}


def _radii(case: Case, i: int, j: int | None) -> tuple[float, float]:
    return case.particles[i].radius, (0.0 if j is None else case.particles[j].radius)


def check_contact(case: Case) -> None:
    """Validate model ids and parameters, for every kind of case before anything runs: a key that neither model
    reads (a pair key too: restitution with an elastic Hertz law) is unknown (with the nearest known one); the
    pair's coefficients obey the materials' rules (contact.PAIR_RULES); string parameters are among their
    choices; a collision's laws resolve (numbers in range, nothing missing)."""
    normal, tangential = models_of(case)
    params = case.contact.params
    ids = _beyond_ids(case)
    allowed = {p.name for p in normal.params} | {p.name for p in tangential.params} | set(_slots.keys_of(ids))
    named = "".join(f", {slot} '{id_}'" for slot, id_ in ids.items() if id_ != "none")
    for key, value in params.items():
        if key not in allowed:
            near = difflib.get_close_matches(key, sorted(allowed), n=1)
            hint = f"; did you mean '{near[0]}'?" if near else ""
            raise ConfigError(f"contact.{key}", value,
                              f"is not a parameter of normal '{normal.id}' or tangential '{tangential.id}'"
                              f"{named}{hint}")
    _check_wired(case, ids)
    pair_params(params)
    _normal.check_choices(normal, params)
    _normal.check_choices(tangential, params)
    if case.kind == "collision":
        resolve(case)


# the slots beyond sliding the packing solver runs (reference/packing.py: every law of the slot, by its record)
PACKING_SLOTS = ("rolling",)


def _check_wired(case: Case, ids: dict) -> None:
    """The slots beyond sliding reach the scenario solvers (reference/scenarios.py), and the packing solver the
    rolling slot (PACKING_SLOTS); a collision or a packing that names another would silently ignore it, so it is
    refused."""
    if getattr(case.run, "scenario", "collision") != "collision":
        return
    for slot, id_ in ids.items():
        if id_ != "none" and not (case.kind == "packing" and slot in PACKING_SLOTS):
            where = ("the collision solvers do not model it yet" if slot in PACKING_SLOTS else
                     "the collision and packing solvers do not model it yet")
            raise ConfigError(f"contact.{slot}", id_, "is solved in the scenarios beyond sliding only (run.scenario = "
                              "rolling, incline, twist, pull_off, adhesive_impact or conduction)"
                              f"{' and in packings' if slot in PACKING_SLOTS else ''}; {where}")


def characteristic_time(model: ResolvedModel) -> float:
    """The elastic contact time of the model's spring at the impact speed (dt = auto, solver scales)."""
    v = model.pair.impact_speed
    if not (v > 0):
        raise ConfigError("particles", "(initial state)", "the bodies never meet: no collision to solve")
    return model.normal_law.characteristic_time(model.pair.m_eff, v)
