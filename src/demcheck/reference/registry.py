"""A registry of models of one slot (normal or tangential): ids and aliases, unique, case-insensitive."""

from __future__ import annotations


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
