"""The registry of engines: the built-in packages, then plug-ins.

Plug-ins: modules named in ``$DEMCHECK_ENGINE_PLUGINS`` (comma-separated, importable), and the entry points
of the group ``demcheck.engines`` of installed distributions. A plug-in module registers its engine on
import (``registry.register(MyEngine())``). Order is registration order: the built-ins first, as a report
lists its columns.
"""

from __future__ import annotations

import importlib
import os

from .base import Engine

BUILTIN = ("demcheck.engines.lammps", "demcheck.engines.liggghts", "demcheck.engines.kratos", "demcheck.engines.yade")
_ENGINES: dict[str, Engine] = {}
_loaded = False


def register(engine: Engine) -> Engine:
    """Add (or replace) an engine under its name."""
    if not engine.name or not engine.name.isidentifier() or engine.name != engine.name.lower():
        raise ValueError(f"an engine's name must be a lower-case identifier, not {engine.name!r}")
    if engine.name in ("reference", "all", "none"):
        raise ValueError(f"{engine.name!r} is a reserved source name")
    _ENGINES[engine.name] = engine
    return engine


def _load() -> None:
    global _loaded
    if _loaded:
        return
    for module in BUILTIN:
        importlib.import_module(module)
    text = os.environ.get("DEMCHECK_ENGINE_PLUGINS", "")
    for module in filter(None, (m.strip() for m in text.split(","))):
        try:
            importlib.import_module(module)
        except Exception as exc:  # noqa: BLE001 - whatever the plug-in's fault, one line names it
            from ..errors import ConfigError

            raise ConfigError("DEMCHECK_ENGINE_PLUGINS", text, f"module {module!r} cannot be imported "
                              f"({type(exc).__name__}: {exc})") from None
    _loaded = True
    from importlib.metadata import entry_points

    for ep in entry_points(group="demcheck.engines"):
        try:
            ep.load()
        except Exception as exc:  # noqa: BLE001 - a broken third-party plug-in must not stop the built-ins
            import logging

            logging.getLogger("demcheck.engines").warning("engine plug-in %s not loaded: %s", ep.name, exc)


def _rank(engine: Engine) -> int:
    """A built-in's place in BUILTIN (its package, whatever imported it first); a plug-in's after them all."""
    module = type(engine).__module__
    for k, package in enumerate(BUILTIN):
        if module == package or module.startswith(package + "."):
            return k
    return len(BUILTIN)


def _ordered() -> tuple[Engine, ...]:
    """The built-ins in BUILTIN's order, then plug-ins in registration order: a test or a user that imports
    one engine's package before the registry loads must not reorder a report's columns."""
    return tuple(sorted(_ENGINES.values(), key=_rank))


def names() -> tuple[str, ...]:
    _load()
    return tuple(e.name for e in _ordered())


def all_engines() -> tuple[Engine, ...]:
    _load()
    return _ordered()


def get(name: str) -> Engine:
    _load()
    try:
        return _ENGINES[name]
    except KeyError:
        raise ValueError(f"unknown engine {name!r} (registered: {', '.join(_ENGINES)})") from None
