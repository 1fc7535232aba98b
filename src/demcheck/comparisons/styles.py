"""How every plot draws a source: one colour, marker and line style per source, the same in every panel
(the reference's sources here; each engine's from its package, ``Engine.style``; an engine's twin in its
engine's colour, dotted)."""

from __future__ import annotations

from ..engines import registry
from ..engines.base import Style

REFERENCE = {
    "reference": Style(colour="#000000", marker="o", linestyle="-"),
    "reference-adaptive": Style(colour="#000000", marker="o", linestyle="-"),
    "reference-verlet": Style(colour="#7f7f7f", marker="s", linestyle=":"),
    "closed-form": Style(colour="#2ca02c", marker="D", linestyle="-"),
}
UNKNOWN = Style(colour="#8c564b", marker="x", linestyle="-")


def style(source: str) -> Style:
    if source in REFERENCE:
        return REFERENCE[source]
    name, _, twin = source.partition("-twin")
    if name in registry.names():
        s = registry.get(name).style
        return Style(s.colour, s.marker, ":") if twin == "" and source.endswith("-twin") else s
    return UNKNOWN


def engine_sources() -> tuple[str, ...]:
    """The registered engines, in the registry's order: a report's engine columns."""
    return registry.names()
