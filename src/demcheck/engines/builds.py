"""Several builds of one engine in one run: ``--engines lammps,lammps@2024=/opt/lammps-2024/bin/lmp``.

A :class:`Build` is an engine (a registered name), a label (the source's name in every report column, plot,
cache key and comparison: ``lammps@2024``) and an executable. ``lammps`` alone is the engine as discovery
finds it; ``lammps=/path/to/lmp`` replaces that executable under the engine's own name; ``lammps@LABEL=/path``
adds a source of its own beside it. Each build's version is read from its own binary's banner
(``discovery.find``), so expected differences (matched by version) and the run cache (keyed by label, version
and the binary's identity) follow the build, not the engine.

A labelled build enters the registry as a :class:`BuildEngine`: the engine's own object seen through a label
and an executable — its vocabulary, decks, twin and rules are the engine's, unchanged — so every part of
demcheck that looks an engine up by its source name (mappings, runs, twins, discovery, reports) runs it with
no change to the engine's package. The engine's deck writers are handed the build itself
(:attr:`BuildEngine.HANDED`): a build's decks are written by the build, never by the engine registered under the
engine's name.
"""

from __future__ import annotations

import os
import re
import shutil
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import ConfigError
from . import registry
from .base import Style

_LABEL = re.compile(r"^[a-z][a-z0-9_]*(@[A-Za-z0-9][A-Za-z0-9._-]{0,39})?$")
_MARKERS = ("v", "<", ">", "P", "*", "h")  # a build's marker: its engine's colour, another marker, dotted


@dataclass(frozen=True)
class Build:
    engine: str  # the registered engine
    label: str  # the source's name: the engine's, or engine@LABEL
    executable: str | None = None  # None: the engine's own discovery ($DEMCHECK_<NAME>, beside Python, PATH)


class BuildEngine:
    """A registered engine under a build's label with the build's executable; everything else is the
    engine's own."""

    def __init__(self, base, label: str, executable: str, index: int = 0):
        self.base = base
        self.name = label
        self.executable = executable
        self.title = f"{base.title} ({label.partition('@')[2] or label})"
        s = base.style
        self.style = Style(s.colour, _MARKERS[index % len(_MARKERS)], ":")

    def candidates(self) -> list[str]:
        return [self.base.build_executable(self.executable)]

    # the engine's methods that hand the engine object to its package's writers (base.PackageEngine): run as the
    # build, so that the writers get the build (its label, title, version), not the engine it wraps
    HANDED = ("collision_deck", "packing_deck", "scenario_mapping", "scenario_twin_laws", "scenario_deck",
              "read_scenario")

    def __getattr__(self, attr):  # the vocabulary, decks, launch, rules, banner: the engine's
        if attr in self.HANDED:
            return getattr(type(self.base), attr).__get__(self)
        return getattr(self.base, attr)


def parse(spec: str, key: str = "--engines") -> Build:
    """``engine``, ``engine=PATH`` or ``engine@LABEL=PATH`` as a Build (checked: a registered engine, a
    label of letters, digits and ._-, an executable file); else ConfigError naming ``key``, the value and the
    rule."""
    text = spec.strip()
    label, eq, path = text.partition("=")
    label, path = label.strip(), path.strip()
    if not _LABEL.match(label) or (eq and not path):
        raise ConfigError(key, text, "must be ENGINE, ENGINE=PATH or ENGINE@LABEL=PATH (LABEL: letters, digits, "
                                     "._-; e.g. lammps@2024=/opt/lammps-2024/bin/lmp)")
    engine = label.partition("@")[0]
    if engine not in _engines():
        raise ConfigError(key, text, f"must be {', '.join(_engines())} (comma-separated), a build of one "
                                     "(ENGINE=PATH or ENGINE@LABEL=PATH), or none")
    if "@" in label and not eq:
        raise ConfigError(key, text, f"a labelled build needs its executable: {label}=PATH")
    if not eq:
        return Build(engine, label)
    exe = Path(path).expanduser()
    if not exe.is_file() or not os.access(exe, os.X_OK):
        raise ConfigError(key, text, f"{path} is not an executable file")
    return Build(engine, label, str(exe.absolute()))


def parse_list(text: str, key: str = "--engines") -> list[Build]:
    """A comma-separated list of builds (``none`` for no engine); a label given twice is an error."""
    if text.strip().lower() == "none":
        return []
    out: list[Build] = []
    for spec in filter(None, (s.strip() for s in text.split(","))):
        b = parse(spec, key)
        if any(o.label == b.label for o in out):
            raise ConfigError(key, spec, f"names the source {b.label} twice")
        out.append(b)
    return out


def with_precision(text: str, precision: str | None, key: str = "--precision") -> str:
    """The list ``text`` with each engine that has a build of ``precision`` (``Engine.precisions``: Yade's
    float128 and mpfr150) named as that build, ``yade`` → ``yade@float128=/usr/bin/yade-float128`` (found on
    PATH); other entries as they are. ConfigError naming ``key`` when no engine of the list has that precision
    or its program is not installed."""
    if not precision:
        return text
    out, found = [], False
    for spec in filter(None, (s.strip() for s in text.split(","))):
        programs = getattr(registry.get(spec), "precisions", {}) if spec in _engines() else {}
        if precision in programs:
            path = shutil.which(programs[precision])
            if path is None:
                raise ConfigError(key, precision, f"needs {programs[precision]}, which is not installed "
                                                  f"(apt-get install {programs[precision]})")
            spec, found = f"{spec}@{precision}={path}", True
        out.append(spec)
    if not found:
        have = {n: sorted(registry.get(n).precisions) for n in _engines() if getattr(registry.get(n), "precisions", {})}
        raise ConfigError(key, precision, "is a build of no engine in the list (" + "; ".join(
            f"{n}: {', '.join(p)}" for n, p in have.items()) + ")")
    return ",".join(out)


def _engines() -> list[str]:
    return [n for n in registry.names() if "@" not in n]


def register(build: Build) -> str:
    """Make the build a source: a labelled build enters the registry under its label; ``engine=PATH`` runs
    that executable under the engine's own name. Returns the source's name (the label). (discovery.resolve
    registers the builds of a command line and reads their versions.)"""
    if build.executable is None:
        return build.label
    base = registry.get(build.engine)
    base = base.base if isinstance(base, BuildEngine) else base
    index = sum(isinstance(registry.get(n), BuildEngine) for n in registry.names())
    registry._ENGINES[build.label] = BuildEngine(base, build.label, build.executable, index)  # noqa: SLF001
    return build.label


def unregister(label: str) -> None:
    """Remove a build (and put the engine's own object back under its name); discovery.drop also forgets its
    version."""
    eng = registry._ENGINES.get(label)  # noqa: SLF001
    if isinstance(eng, BuildEngine):
        if label == eng.base.name:
            registry._ENGINES[label] = eng.base  # noqa: SLF001
        else:
            del registry._ENGINES[label]  # noqa: SLF001


def engine_of(source: str) -> str:
    """The engine a source runs: ``lammps`` for ``lammps@2024``; the name itself otherwise."""
    try:
        eng = registry.get(source)
    except ValueError:
        return source
    return eng.base.name if isinstance(eng, BuildEngine) else source


def executable_of(source: str) -> str | None:
    """A build's own executable (None for an engine found by discovery)."""
    try:
        eng = registry.get(source)
    except ValueError:
        return None
    return eng.executable if isinstance(eng, BuildEngine) else None


def identity(source: str) -> str:
    """What distinguishes a build's binary beyond its banner (a rebuilt development binary prints the same
    version): its path, size and modification time; "" for an engine found by discovery."""
    exe = executable_of(source)
    if exe is None:
        return ""
    try:
        st = os.stat(exe)
    except OSError:
        return exe
    return f"{exe}\0{st.st_size}\0{st.st_mtime_ns}"


def expected_for(expected: list, sources) -> list:
    """The expected differences (verdicts.ExpectedDifference) with each one that names an engine repeated
    for every labelled build of it: a build's difference is expected when its own version matches."""
    import fnmatch

    out = list(expected)
    for src in sources:
        engine = engine_of(src)
        if engine == src:
            continue
        out += [replace(e, engine=src) for e in expected if fnmatch.fnmatchcase(engine, e.engine)]
    return out
