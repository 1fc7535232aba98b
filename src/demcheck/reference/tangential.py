"""Tangential contact models (seed 000 §4), as a registry. (Filled in with the tangential issue.)"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .contact import Pair
from .normal import NormalLaw, Param

NONE = 0


@dataclass(frozen=True)
class TangentialLaw:
    kind: int = NONE

    def array(self) -> np.ndarray:
        return np.array([float(self.kind)])


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


REGISTRY: dict[str, TangentialModel] = {}


def register(model: TangentialModel) -> TangentialModel:
    for key in (model.id, *model.aliases):
        if key in REGISTRY:
            raise ValueError(f"tangential model id {key!r} registered twice")
    REGISTRY[model.id] = model
    return model


def lookup(name: str) -> TangentialModel:
    key = name.strip().lower()
    for m in REGISTRY.values():
        if key == m.id or key in (a.lower() for a in m.aliases):
            return m
    raise KeyError(name)


register(TangentialModel(
    id="none", seed_name="—", title="Frictionless", formula="Ft = 0",
    source="—", params=(), resolve=lambda pair, params, normal: (TangentialLaw(NONE), {}),
    aliases=("off", "frictionless"),
))
