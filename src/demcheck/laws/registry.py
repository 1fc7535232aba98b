"""A registry of models of one slot (normal or tangential): ids and aliases, unique, case-insensitive; and the
reader of the models' numeric ``[contact]`` parameters."""

from __future__ import annotations

import math

from ..errors import ConfigError


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
