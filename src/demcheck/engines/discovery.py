"""Finding the engines and their versions.

Each registered engine names its executables (``Engine.candidates``): ``$DEMCHECK_<NAME>`` when set, else
its executables beside this Python (a wheel's) and on PATH. The version is read from the engine's own banner (``-h``), so it is the one that will actually run: in a
temporary directory (LIGGGHTS writes log.liggghts even for ``-h``), in a process group of its own, killed
with everything it started if it has not answered within ``$DEMCHECK_DISCOVERY_TIMEOUT`` seconds (default
DISCOVERY_TIMEOUT).
"""

from __future__ import annotations

import functools
import math
import os
import signal
import subprocess
import tempfile
from dataclasses import dataclass

from . import registry

DISCOVERY_TIMEOUT = 5.0  # s: a banner takes well under a second

# why the last search for an engine found none (each candidate and what went wrong), for the messages
_WHY: dict[str, str] = {}


@dataclass(frozen=True)
class EngineInfo:
    name: str
    executable: str
    version: str


def timeout() -> float:
    """Seconds an engine has to print its banner: ``$DEMCHECK_DISCOVERY_TIMEOUT``, else DISCOVERY_TIMEOUT."""
    text = os.environ.get("DEMCHECK_DISCOVERY_TIMEOUT")
    if not text:
        return DISCOVERY_TIMEOUT
    from ..errors import ConfigError

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0 < value <= 3600):
        raise ConfigError("DEMCHECK_DISCOVERY_TIMEOUT", text, "must be a number of seconds in (0, 3600]")
    return value


def _banner(exe: str, seconds: float) -> tuple[str | None, str]:
    """(``exe -h``'s output, "") or (None, why) if it does not start or answer in time."""
    with tempfile.TemporaryDirectory(prefix="demcheck-discovery-") as cwd:
        try:
            proc = subprocess.Popen([exe, "-h"], cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True, errors="replace",
                                    start_new_session=True)
        except OSError as exc:
            return None, f"does not start ({exc.strerror or exc})"
        answered = False
        try:
            out, _ = proc.communicate(timeout=seconds)
            answered = True
            return out, ""
        except subprocess.TimeoutExpired:
            return None, f"did not answer `-h` within {seconds:g} s (DEMCHECK_DISCOVERY_TIMEOUT)"
        finally:
            if not answered:  # timed out, or interrupted: nothing it started survives
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except (ProcessLookupError, PermissionError):
                    pass
                proc.communicate()


@functools.lru_cache(maxsize=None)
def find(name: str) -> EngineInfo | None:
    """The engine ``name`` (lammps | liggghts) with its version, or None if it is not installed, does
    not start, or does not print its banner within ``timeout()`` seconds."""
    engine = registry.get(name)  # ValueError for an engine that is not registered
    seconds = timeout()
    _WHY.pop(name, None)
    problems = []
    for exe in engine.candidates():
        out, why = _banner(exe, seconds)
        match = engine.banner.search(out) if out is not None else None
        if match:
            return EngineInfo(name, exe, match.group(1).strip())
        problems.append(f"{exe} {why or f'prints no {name} banner for `-h`'}")
    if problems:
        _WHY[name] = "; ".join(problems)
    return None


def resolve(text: str, key: str = "--engines") -> list[str]:
    """The sources of an ``--engines`` list: engines and builds (``lammps,lammps@2024=/opt/lmp-2024/lmp``,
    engines/builds.py), each build registered under its label and its version read from its own binary
    before any work; a build whose executable prints no banner of its engine is a ConfigError naming
    ``key``. Returns the labels, in order."""
    from ..errors import ConfigError
    from . import builds

    labels = []
    for b in builds.parse_list(text, key):
        labels.append(builds.register(b))
        find.cache_clear()  # the label may have named another executable before
        if b.executable is not None and find(b.label) is None:
            drop(b.label)
            raise ConfigError(key, f"{b.label}={b.executable}", f"is not a usable {b.engine} build: {_WHY.get(b.label, '')}")
    return labels


def drop(label: str) -> None:
    """Remove a build registered by ``resolve`` and forget the versions found."""
    from . import builds

    builds.unregister(label)
    find.cache_clear()


def missing(name: str) -> str:
    """Why ``name`` cannot run: not installed (and how to install it), or the candidates that failed."""
    why = _WHY.get(name)
    if why:
        return f"{name} is not usable: {why} ({how_to_install(name)})"
    return f"{name} is not installed: {how_to_install(name)}"


def how_to_install(name: str) -> str:
    return registry.get(name).how_to_install
