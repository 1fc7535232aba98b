"""Running an engine: one subprocess per run, in its own work directory, with a timeout.

LAMMPS and LIGGGHTS export the same C symbols, so they never share a process. A failed run keeps its work
directory and its error names it and quotes the tail of the log; a run past its timeout is killed and
reported as such.

Each engine runs in its own session (a process group of its own, with its MPI ranks), so a terminal's
Ctrl-C does not reach it: an interrupt of demcheck (SIGINT, or SIGTERM once ``handle_sigterm`` is installed)
kills the group of every running engine (``kill_all``), starts no new one, and each run killed so raises
EngineInterrupted — "interrupted", never "failed".
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import EngineFailed, EngineInterrupted, EngineNotFound
from . import discovery, registry

DEFAULT_TIMEOUT = 600.0
# the engines' own warnings, as they print them
_WARNING = re.compile(r"^WARNING:?\s*(.*)$", re.M)
_ERROR = re.compile(r"^(?:ERROR|ERROR on proc \d+):?\s*(.*)$", re.M)


class EngineTimeout(EngineFailed):
    def __init__(self, message: str, pid: int | None = None):
        super().__init__(message)
        self.pid = pid  # the engine's process (killed, with its process group)


@dataclass
class RunOutput:
    engine: str
    version: str
    workdir: Path
    log: str
    wall_time: float
    warnings: list[str] = field(default_factory=list)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread where SIGINT raises KeyboardInterrupt (see ``handle_sigterm``)."""


def handle_sigterm() -> None:
    """Make SIGTERM interrupt demcheck as SIGINT does: ``Terminated`` is raised in the main thread, so the
    same handlers stop the engines and write the partial report (exit 143 instead of 130)."""

    def raise_terminated(signum, frame):
        raise Terminated()

    signal.signal(signal.SIGTERM, raise_terminated)


def interrupt_exit_code(exc: BaseException | None) -> int:
    """128 + the signal: 143 for a SIGTERM (``Terminated``, also as the cause of a wrapping exception), 130
    for a SIGINT."""
    while exc is not None:
        if isinstance(exc, Terminated):
            return 128 + signal.SIGTERM
        exc = exc.__cause__ or exc.__context__
    return 128 + signal.SIGINT


_RUNNING: set = set()
_KILLED: set = set()  # the runs kill_all stopped: interrupted, not failed
_STOP = threading.Event()  # set by an interrupt: no engine starts until reset()
_LOCK = threading.Lock()


def kill_all() -> None:
    """Stop every engine this process has running (their process groups) and start no new one until
    ``reset()``: an interrupt."""
    with _LOCK:
        _STOP.set()
        procs = list(_RUNNING)
        _KILLED.update(procs)
    for proc in procs:
        _kill_group(proc)


def reset() -> None:
    """Allow engine runs again after an interrupt (a new suite in the same process)."""
    with _LOCK:
        _STOP.clear()
        _KILLED.clear()


def _kill_group(proc) -> None:
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def log_tail(text: str, lines: int = 15) -> str:
    return "\n".join(text.rstrip().splitlines()[-lines:])


def warnings_of(log: str) -> list[str]:
    return [w.strip() for w in _WARNING.findall(log)]


def mpi_launcher(engine: str, executable: str, ranks: int) -> list[str]:
    """The MPI launcher of an engine's own MPI (its package knows which)."""
    return registry.get(engine).mpi_launcher(executable, ranks)


def run(engine: str, deck: str, *, workdir: str | Path | None = None, timeout: float = DEFAULT_TIMEOUT,
        files: dict[str, str] | None = None, mpi: int = 1) -> RunOutput:
    """Write ``deck`` (and ``files``) into a work directory and run ``engine`` on it (``mpi`` ranks: the
    engine's own domain decomposition)."""
    info = discovery.find(engine)
    if info is None:
        raise EngineNotFound(discovery.missing(engine))
    if _STOP.is_set():
        raise EngineInterrupted(f"{engine}: not started: demcheck was interrupted")
    registry.get(engine).check_deck(deck, files)  # a deck is code the engine executes: only what demcheck writes
    wd = Path(workdir) if workdir else Path(tempfile.mkdtemp(prefix=f"demcheck-{engine}-"))
    wd.mkdir(parents=True, exist_ok=True)
    (wd / "in.deck").write_text(deck)
    for name, text in (files or {}).items():
        (wd / name).write_text(text)
    cmd = registry.get(engine).argv(info.executable, "in.deck")
    if mpi > 1:
        cmd = mpi_launcher(engine, info.executable, mpi) + cmd
    env = dict(os.environ, OMP_NUM_THREADS="1")
    started = time.perf_counter()
    with _LOCK:  # an interrupt (kill_all) either sees this run or stops it from starting
        if _STOP.is_set():
            raise _interrupted(engine, wd, workdir, interrupt_exit_code(None), "not started: demcheck was interrupted")
        proc = subprocess.Popen(cmd, cwd=wd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, env=env, start_new_session=True)
        _RUNNING.add(proc)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill_group(proc)
        out, _ = proc.communicate()
        log = _read_log(wd, out)
        raise EngineTimeout(f"{engine} ran past its timeout of {timeout:g} s and was stopped; work directory "
                            f"kept: {wd}\n{log_tail(log)}", pid=proc.pid) from None
    except KeyboardInterrupt as exc:  # SIGINT or SIGTERM while waiting on the engine: stop it, and the others
        kill_all()
        proc.communicate()
        raise _interrupted(engine, wd, workdir, interrupt_exit_code(exc)) from exc
    finally:
        with _LOCK:
            _RUNNING.discard(proc)
    if proc in _KILLED:  # stopped by an interrupt handled elsewhere (another thread's kill_all)
        raise _interrupted(engine, wd, workdir, interrupt_exit_code(None))
    wall = time.perf_counter() - started
    log = _read_log(wd, out)
    errors = _ERROR.findall(log)
    if proc.returncode != 0 or errors:
        what = errors[0] if errors else f"exit code {proc.returncode}"
        raise EngineFailed(f"{engine} failed ({what}); work directory kept: {wd}\n{log_tail(log)}")
    return RunOutput(engine, info.version, wd, log, wall, warnings_of(log))


def _interrupted(engine: str, wd: Path, workdir, code: int, what: str = "was stopped by the interrupt"
                 ) -> EngineInterrupted:
    """The error of a run an interrupt stopped (or kept from starting); its temporary work directory (a
    partial dump) removed."""
    if workdir is None:
        import shutil

        shutil.rmtree(wd, ignore_errors=True)
    exc = EngineInterrupted(f"{engine} {what}")
    exc.exit_code = code
    return exc


def _read_log(wd: Path, out: str | None) -> str:
    parts = []
    for name in ("log.txt", "screen.txt"):
        p = wd / name
        if p.exists():
            parts.append(p.read_text(errors="replace"))
    if out:
        parts.append(out)
    # the log and the screen carry the same lines; keep the longer account
    return max(parts, key=len) if parts else ""
