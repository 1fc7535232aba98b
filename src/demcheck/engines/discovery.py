"""Finding the engines and their versions.

Each registered engine names its executables (``Engine.candidates``): ``$DEMCHECK_<NAME>`` when set, else
its executables beside this Python (a wheel's) and on PATH. The version is read from the engine's own banner (``-h``), so it is the one that will actually run: in a
temporary directory (LIGGGHTS writes log.liggghts even for ``-h``), in a process group of its own, killed
with everything it started if it has not answered within ``$DEMCHECK_DISCOVERY_TIMEOUT`` seconds (default
DISCOVERY_TIMEOUT), and judged by its exit, not by its output pipe's end.

An engine the user named (``--engines lammps,liggghts``, ``--engine liggghts``) is required: ``resolve`` (every
command's engine list goes through it) or ``require`` tries discovery twice and fails with the reason when it is
not found. Only engines of default discovery (the option left at its default) may be skipped as missing.
"""

from __future__ import annotations

import functools
import math
import os
import re
import signal
import subprocess
import tempfile
from dataclasses import dataclass

from . import registry
from .serve import ESCAPES, plain_text

DISCOVERY_TIMEOUT = 5.0  # s: a banner takes well under a second
# the environment of every engine process (discovery's ``-h``, runs and workers: engines/run.py): one thread each
# (the runs are the parallelism), and Open MPI's singleton start without its helper daemon (a run without mpirun is
# one rank that spawns nothing; the daemon's start is what fails on a loaded machine, "Unable to start a daemon on
# the local node", a LIGGGHTS run then ending with exit code 1 before it reads its deck)
ENGINE_ENV = {"OMP_NUM_THREADS": "1", "OMPI_MCA_ess_singleton_isolated": "1"}

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


def engine_env() -> dict[str, str]:
    """This process's environment with ENGINE_ENV: what every engine process is started with."""
    return dict(os.environ, **ENGINE_ENV)


def end_group(pgid: int, within: float = 10.0) -> None:
    """Kill the process group ``pgid`` (a run's session: an engine and whatever it started) and wait until none of
    its processes runs (each gone or a zombie: its files closed), at most ``within`` seconds."""
    import time

    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        return
    deadline = time.monotonic() + within
    while _group_running(pgid) and time.monotonic() < deadline:
        time.sleep(0.01)


def _group_running(pgid: int) -> bool:
    """Whether a process of group ``pgid`` is running (/proc; not a zombie)."""
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/stat", "rb") as fh:
                fields = fh.read().rsplit(b")", 1)[1].split()
        except OSError:
            continue
        if len(fields) > 2 and int(fields[2]) == pgid and fields[0] != b"Z":
            return True
    return False


def _banner(exe: str, seconds: float) -> tuple[str | None, str]:
    """(``exe -h``'s output, "") or (None, why) if it does not start or answer in time (``output_of``)."""
    return output_of([exe, "-h"], seconds, "`-h`")


def output_of(argv: list[str], seconds: float, what: str = "") -> tuple[str | None, str]:
    """(what ``argv`` printed, stdout and stderr, "") or (None, why) if it does not start or end within
    ``seconds``: an engine's question (its banner, its version), asked in a temporary directory with ENGINE_ENV.
    Its answer is judged by the process's exit, not by its output pipe's end (its output goes to a file: a helper
    it leaves behind may hold a pipe open); whatever it leaves running in its process group is killed. The text is
    ``serve.plain_text``'s: no escape sequence of the engine's reaches a report or a terminal."""
    with tempfile.TemporaryDirectory(prefix="demcheck-discovery-") as cwd:
        out_path = os.path.join(cwd, "output.txt")
        try:
            with open(out_path, "wb") as out:
                proc = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out,
                                        stderr=subprocess.STDOUT, start_new_session=True, env=engine_env())
        except OSError as exc:
            return None, f"does not start ({exc.strerror or exc})"
        try:
            proc.wait(timeout=seconds)
        except subprocess.TimeoutExpired:
            return None, f"did not answer {what or 'its question'} within {seconds:g} s (DEMCHECK_DISCOVERY_TIMEOUT)"
        finally:  # answered, timed out or interrupted: nothing it started survives
            end_group(proc.pid)
            proc.wait()
        with open(out_path, encoding="utf-8", errors="replace") as fh:
            return plain_text(fh.read()), ""


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
        if match and (version := plain_version(match.group(1))):
            return EngineInfo(name, exe, version)
        problems.append(f"{exe} {why or f'prints no {name} banner for `-h`'}")
    if problems:
        _WHY[name] = "; ".join(problems)
    return None


_CONTROLS = re.compile(r"[\x00-\x1f\x7f-\x9f]")


def plain_version(text: str) -> str:
    """A version read off a banner as plain text: a build that colours its banner (ANSI escapes: serve.ESCAPES, the
    one pattern every engine text goes through) or prints control characters in it gives its version without them —
    it goes into reports, cache keys and expected differences."""
    return " ".join(_CONTROLS.sub(" ", ESCAPES.sub("", text)).split())


def resolve(text: str, key: str = "--engines", required: bool | None = None) -> list[str]:
    """The sources of an ``--engines`` list: engines and builds (``lammps,lammps@2024=/opt/lmp-2024/lmp``,
    engines/builds.py), each build registered under its label and its version read from its own binary
    before any work; a build whose executable prints no banner of its engine is a ConfigError naming
    ``key``. Returns the labels, in order.

    ``required``: every source must be found (``require``), else EngineNotFound before any work — the rule for
    an engine the user named. None: required when ``key`` was given on the command line (``named``), not when
    the list is the option's default (default discovery: an engine it does not find is skipped as missing)."""
    from ..errors import ConfigError
    from . import builds

    labels = []
    for b in builds.parse_list(text, key):
        labels.append(builds.register(b))
        find.cache_clear()  # the label may have named another executable before
        if b.executable is not None and find(b.label) is None:
            drop(b.label)
            raise ConfigError(key, f"{b.label}={b.executable}", f"is not a usable {b.engine} build: {_WHY.get(b.label, '')}")
    if required if required is not None else named(key):
        for label in labels:
            require(label, key)
    return labels


def named(key: str) -> bool:
    """Whether the option ``key`` (``--engines``, ``--engine``) was given on the command line of the click command
    running now; True outside one (a caller of the Python API names its engines)."""
    try:
        import click
    except ImportError:  # pragma: no cover - click is a dependency
        return True
    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return True
    for param in ctx.command.params:
        if key in getattr(param, "opts", ()):
            source = ctx.get_parameter_source(param.name)
            return source not in (click.core.ParameterSource.DEFAULT, click.core.ParameterSource.DEFAULT_MAP)
    return True


def require(name: str, key: str | None = None) -> EngineInfo:
    """The engine ``name`` the user named, found — discovery tried twice (a banner that missed its time on a
    loaded machine is a transient) — else EngineNotFound saying why: a named engine is never skipped."""
    info = find(name)
    if info is None:
        getattr(find, "cache_clear", lambda: None)()
        info = find(name)
    if info is None:
        from ..errors import EngineNotFound

        named_by = f"{key} names {name}, which " if key else f"{name} "
        raise EngineNotFound(f"{named_by}cannot run (discovery tried twice): {missing(name)}")
    return info


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
