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
    from ..errors import ConfigError
    from .sources import TWIN, Source

    if source in REFERENCE:
        return REFERENCE[source]
    try:
        src = Source.parse(source, methods=False)
    except ConfigError:  # a source of an older report, no longer registered
        return UNKNOWN
    s = src.engine.style
    return Style(s.colour, s.marker, ":") if src.kind == TWIN else s


def engine_sources() -> tuple[str, ...]:
    """The registered engines, in the registry's order: a report's engine columns."""
    return registry.names()
