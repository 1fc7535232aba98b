"""Running an engine: one subprocess per run, in its own work directory, with a timeout.

LAMMPS and LIGGGHTS export the same C symbols, so they never share a process. A run is judged by its process's
exit and its files, never by the end of an output pipe (what a process prints goes to ``output.txt`` in its work
directory: a helper it leaves behind may hold a pipe open long after it ended); what a run leaves running in its
session is killed when it ends. Every engine process and worker starts with ``discovery.ENGINE_ENV`` (one thread;
Open MPI's singleton start without its helper daemon, whose start fails on a loaded machine).

The engine says which files its log is in, what in it is an error or a warning and how long its loop took
(``Engine.log_files``, ``errors``, ``warnings``, ``loop_time``): this module knows no engine's log.

A failed run keeps its work directory — the deck and its files, the log, the screen, what the process printed,
the dump's last frames, each within ``keep_for_diagnosis``'s bound — and its error names the directory and its
files and quotes the log's tail, or says plainly that the engine wrote nothing and what demcheck saw (an exit
code, a signal, what a worker answered). A failure without an error of the engine's (``Engine.errors`` finds none in
its log: a crash, a silent exit, a worker that died or did not start) is a fault of the process, not of the
deck: the run is made once more on a fresh process or worker, and fails only if that fails too (both reasons
given). A run past its timeout is killed and reported as such (not run again).

Each engine runs in its own session (a process group of its own, with its MPI ranks), so a terminal's
Ctrl-C does not reach it: an interrupt of demcheck (SIGINT, or SIGTERM or SIGHUP once ``handle_sigterm`` is installed)
kills the group of every running engine (``kill_all``), starts no new one, and each run killed so raises
EngineInterrupted — "interrupted", never "failed".

``run(..., worker=True)`` runs the deck in a long-lived worker process of the engine instead, when the engine
has one for the executable discovery found (``Engine.worker_argv``: LAMMPS, LIGGGHTS, Yade and Kratos each have
one, ``engines/<name>/worker.py``; the worker's side of the protocol is engines/serve.py) and ``mpi`` is 1;
otherwise it is the subprocess above. The worker loads the engine once and runs deck after deck, each in its
work directory as above, with the same timeout, interrupt and failure rules and the same RunOutput: a run past
its timeout or stopped by an interrupt kills the worker's process group (the next run starts a new worker; its
start is not counted in the run's timeout), an engine error is EngineFailed with the log's tail and leaves the
worker usable, a worker that died is replaced — also one an engine error ends (LIGGGHTS's library exits): that
run fails with its log's error and tail, as a process's does. Each worker serves one run at a
time: concurrent jobs take one each (a pool per engine and command). A worker runs in a session of its own,
as a run's process does, and dies with the thread that started it (a job's, or the main thread); an
interrupt kills the workers that are running, ``shutdown_workers`` (also run at exit) ends the idle ones.
"""

from __future__ import annotations

import atexit
import json
import os
import re
import select
import signal
import subprocess
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import EngineFailed, EngineInterrupted
from . import discovery, registry
from .serve import plain_text

DEFAULT_TIMEOUT = 600.0


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
    # s of the engine's own stepping loop (``loop_time``); None where neither its log nor its worker says
    loop_time: float | None = None


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised in the main thread where SIGINT raises KeyboardInterrupt (see
    ``handle_sigterm``); ``signum`` the signal."""

    def __init__(self, signum: int = signal.SIGTERM):
        super().__init__()
        self.signum = int(signum)


# the signals that stop demcheck as SIGINT does: a kill, and a hang-up (a closed terminal, a dropped ssh session)
STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


def handle_sigterm() -> None:
    """Make SIGTERM and SIGHUP interrupt demcheck as SIGINT does: ``Terminated`` is raised in the main thread,
    so the same handlers stop the engines and write the partial report (exit 143 or 129 instead of 130). A
    SIGHUP that is ignored (``nohup``) stays ignored."""

    def raise_terminated(signum, frame):
        raise Terminated(signum)

    for sig in STOP_SIGNALS:
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, raise_terminated)


def interrupt_exit_code(exc: BaseException | None) -> int:
    """128 + the signal: 143 for a SIGTERM, 129 for a SIGHUP (``Terminated``, also as the cause of a wrapping
    exception), 130 for a SIGINT."""
    while exc is not None:
        if isinstance(exc, Terminated):
            return 128 + getattr(exc, "signum", signal.SIGTERM)
        exc = exc.__cause__ or exc.__context__
    return 128 + signal.SIGINT


def interrupt_in(exc: BaseException | None) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt (or ``Terminated``) behind ``exc``: itself, or one among its causes and contexts —
    numba raises a pending signal inside its own callback as it returns from a compiled kernel and reports it as
    ``SystemError: CPUDispatcher(...) returned a result with an exception set`` caused by the interrupt, so a
    handler of Exception around a kernel must ask this before it calls the interrupt a failure."""
    todo, seen = [exc], set()
    while todo:
        e = todo.pop()
        if e is None or id(e) in seen:
            continue
        seen.add(id(e))
        if isinstance(e, KeyboardInterrupt):
            return e
        todo += [e.__cause__, e.__context__]
    return None


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


def loop_time(engine: str, log: str, measured: float | None = None) -> float | None:
    """The seconds of the engine's own stepping loop in a run: what its log says (``Engine.loop_time``: LAMMPS,
    LIGGGHTS), else what its worker measured (``measured``: Yade the script, Kratos its RunSolutionLoop), else
    None."""
    said = registry.get(engine).loop_time(log)
    if said is not None:
        return said
    return None if measured is None else float(measured)


def _output(engine: str, info, wd: Path, log: str, wall: float, measured: float | None = None) -> RunOutput:
    """A run's RunOutput: the engine's own warnings and loop time read off its log."""
    return RunOutput(engine, info.version, wd, log, wall, registry.get(engine).warnings(log),
                     loop_time(engine, log, measured))


def mpi_launcher(engine: str, executable: str, ranks: int) -> list[str]:
    """The MPI launcher of an engine's own MPI (its package knows which)."""
    return registry.get(engine).mpi_launcher(executable, ranks)


SCREEN = "screen.txt"  # a worker's stdout and stderr in a run's work directory (engines/serve.py)
OUTPUT = "output.txt"  # what a run's process printed on stdout and stderr (its screen, or what came before one)


def run(engine: str, deck: str, *, workdir: str | Path | None = None, timeout: float = DEFAULT_TIMEOUT,
        files: dict[str, str] | None = None, mpi: int = 1, worker: bool = False) -> RunOutput:
    """Write ``deck`` (and ``files``) into a work directory and run ``engine`` on it (``mpi`` ranks: the
    engine's own domain decomposition); ``worker``: in the engine's long-lived worker where it has one (see
    the module's notes), else as a process of its own. A run that fails without an error of the engine's (a
    crash, an exit with none in its log, Engine.errors; a worker that died or did not start: a fault of the
    process, not of the deck) is run once more on a fresh process or worker before it is called failed."""
    info = discovery.require(engine)  # named by the caller: tried twice, EngineNotFound with the reason
    if _STOP.is_set():
        raise EngineInterrupted(f"{engine}: not started: demcheck was interrupted")
    registry.get(engine).check_deck(deck, files)  # a deck is code the engine executes: only what demcheck writes
    wd = Path(workdir) if workdir else Path(tempfile.mkdtemp(prefix=f"demcheck-{engine}-"))
    wd.mkdir(parents=True, exist_ok=True)
    for name, text in {"in.deck": deck, **(files or {})}.items():
        (wd / name).write_text(text)
    argv = registry.get(engine).worker_argv(info.executable) if worker and mpi == 1 else None
    before = {p.name for p in wd.iterdir()} - {*_logs(engine), OUTPUT}  # the caller's: never removed

    def in_process() -> RunOutput:
        return _run_process(engine, info, wd, workdir, timeout, mpi)

    if argv is None:
        return _retried(engine, in_process, wd, before)
    if worker == OR_PROCESS:
        return _worker_or_process(engine, info, list(argv), wd, workdir, timeout, before, in_process)
    return _retried(engine, lambda: _run_in_worker(engine, info, list(argv), wd, workdir, timeout), wd, before)


def _retried(engine: str, attempt, wd: Path, before: set) -> RunOutput:
    """``attempt()``, made once more when it fails without an error of the engine's (a fault of the process)."""
    try:
        return attempt()
    except EngineFailed as first:
        if not getattr(first, "fault", False) or isinstance(first, EngineInterrupted):
            raise
        _clear_outputs(wd, before)  # the second attempt writes its own log, screen and dump
        try:
            out = attempt()
        except EngineFailed as again:
            if isinstance(again, EngineInterrupted):
                raise
            again.args = (f"{again}\n(a first attempt, on another process, had failed too: {first.what})",)
            raise again from None
        tail = getattr(first, "tail", "")
        out.warnings.append(f"{engine}: a first attempt failed without an error of the engine's ({first.what}); "
                            f"it was run again on a fresh process{'; its last lines: ' + tail if tail else ''}")
        return out


OR_PROCESS = "or-process"  # run(worker=OR_PROCESS): in the worker, a failed worker run made again as a process
WORKER_ATTEMPT = "worker-attempt"  # where such a run's work directory keeps what its worker attempt wrote


def _worker_or_process(engine: str, info, argv: list[str], wd: Path, workdir, timeout: float, before: set,
                       in_process) -> RunOutput:
    """``run(..., worker=OR_PROCESS)``: the run in the engine's worker; if that fails in any way but its timeout or
    an interrupt (a deck's error, a worker that died or did not start, a version it does not serve), it is made
    once more as a process of its own, whose outcome is the run's (a process per run is what the worker stands
    in for). What the worker attempt wrote is kept in the work directory's WORKER_ATTEMPT folder; its reason and
    last lines go into the process run's warnings, or, if that fails too, into its error."""
    try:
        return _run_in_worker(engine, info, argv, wd, workdir, timeout)
    except EngineFailed as first:
        if isinstance(first, (EngineInterrupted, EngineTimeout)):
            raise
        worker_failure = first
    kept = wd / WORKER_ATTEMPT
    kept.mkdir(exist_ok=True)
    for p in wd.iterdir():
        if p.name not in before and p.name != WORKER_ATTEMPT:
            p.rename(kept / p.name)
    what = getattr(worker_failure, "what", str(worker_failure).splitlines()[0])
    try:  # the deck (checked) and its files are in place; a fault of the process is retried as run() does
        out = _retried(engine, in_process, wd, before | {WORKER_ATTEMPT})
    except EngineInterrupted:
        raise
    except EngineFailed as again:
        again.args = (f"{again}\n(the run in {engine}'s worker had failed first: {what}; what it wrote is kept in "
                      f"{kept})",)
        raise
    tail = getattr(worker_failure, "tail", "")
    out.warnings.append(f"{engine}: the run in its worker failed ({what}); it was run again as a process"
                        f"{'; the worker’s last lines: ' + tail if tail else ''}")
    return out


def _run_process(engine: str, info, wd: Path, workdir, timeout: float, mpi: int) -> RunOutput:
    """One attempt as a process of its own (its MPI launcher's with ``mpi`` > 1), its output into OUTPUT. The
    run is judged by the process's exit and its files, never by the end of an output pipe (a helper the
    engine leaves behind may hold one open); what it leaves running in its session is killed when it ends."""
    cmd = registry.get(engine).argv(info.executable, "in.deck")
    if mpi > 1:
        cmd = mpi_launcher(engine, info.executable, mpi) + cmd
    started = time.perf_counter()
    with _LOCK:  # an interrupt (kill_all) either sees this run or stops it from starting
        if _STOP.is_set():
            raise _interrupted(engine, wd, workdir, interrupt_exit_code(None), "not started: demcheck was interrupted")
        with open(wd / OUTPUT, "wb") as output:
            proc = subprocess.Popen(cmd, cwd=wd, stdin=subprocess.DEVNULL, stdout=output, stderr=subprocess.STDOUT,
                                    env=discovery.engine_env(), start_new_session=True)
        _RUNNING.add(proc)
    try:
        proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        _kill_group(proc)
        proc.wait()
        raise _timed_out(engine, wd, timeout, proc.pid) from None
    except KeyboardInterrupt as exc:  # SIGINT or SIGTERM while waiting on the engine: stop it, and the others
        kill_all()
        proc.wait()
        raise _interrupted(engine, wd, workdir, interrupt_exit_code(exc)) from exc
    finally:
        with _LOCK:
            _RUNNING.discard(proc)
        discovery.end_group(proc.pid)  # whatever the run left running in its session (a helper, a daemon)
    if proc in _KILLED:  # stopped by an interrupt handled elsewhere (another thread's kill_all)
        raise _interrupted(engine, wd, workdir, interrupt_exit_code(None))
    wall = time.perf_counter() - started
    log = _read_log(wd, None, engine)
    errors = registry.get(engine).errors(log)
    if proc.returncode != 0 or errors:
        raise _failed(engine, wd, log, _exit_words(proc.returncode), deck_error=bool(errors))
    return _output(engine, info, wd, log, wall)


def _exit_words(code: int | None) -> str:
    """How a process ended, in words: "exit code 1", "killed by SIGSEGV"."""
    if code is not None and code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit code {code}"


_MPI_START = re.compile(r"MPI_INIT failed|error occurred in MPI_Init|Returned \"([^\"]+)\"")


def _failed(engine: str, wd: Path, log: str, seen: str, deck_error: bool) -> EngineFailed:
    """The error of a failed run: the engine's first error (Engine.errors; else what the process or worker showed:
    ``seen``), the
    work directory kept for a diagnosis (its files named, each within its bound: keep_for_diagnosis) and the log's
    tail, or a plain sentence that the engine wrote none. ``fault``: not the deck's error (run.py retries once)."""
    errors = registry.get(engine).errors(log)
    what = errors[0].strip() if errors else seen
    mpi = _MPI_START.findall(log)
    if not errors and mpi:
        detail = next((m for m in mpi if m), "")
        what = f"MPI did not start{': ' + detail if detail else ''}; {seen}"
    kept = keep_for_diagnosis(wd)
    tail = log_tail(log) if log.strip() else (f"({engine} wrote no log and printed nothing; what demcheck saw: "
                                              f"{seen})")
    exc = EngineFailed(f"{engine} failed ({what}); work directory kept: {wd}\nkept there: {', '.join(kept) or 'nothing'}"
                       f"\n{tail}")
    exc.what, exc.fault = what, not deck_error
    exc.tail = " | ".join(ln.strip() for ln in log_tail(log, 6).splitlines() if ln.strip())[:600]
    return exc


def _timed_out(engine: str, wd: Path, timeout: float, pid: int | None) -> EngineTimeout:
    log = _read_log(wd, None, engine)
    kept = keep_for_diagnosis(wd)
    tail = log_tail(log) if log.strip() else f"({engine} wrote no log and printed nothing)"
    return EngineTimeout(f"{engine} ran past its timeout of {timeout:g} s and was stopped; work directory kept: "
                         f"{wd}\nkept there: {', '.join(kept) or 'nothing'}\n{tail}", pid=pid)


def _clear_outputs(wd: Path, keep: set) -> None:
    """What a failed attempt wrote into ``wd``, removed: every entry but those of ``keep`` (the deck, its files and
    whatever the directory held before the run)."""
    import shutil

    for p in wd.iterdir():
        if p.name not in keep:
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p, ignore_errors=True)
            else:
                p.unlink(missing_ok=True)


# a kept work directory's bound: each file at most KEEP_FILE_BYTES (a dump cut to its last whole frames, a log or
# screen to its last lines), KEEP_DIR_BYTES in all (the largest files cut further, then dropped)
KEEP_FILE_BYTES = 4 << 20
KEEP_DIR_BYTES = 16 << 20
_FRAME = b"ITEM: TIMESTEP"


def keep_for_diagnosis(wd: Path) -> list[str]:
    """Bound a failed run's work directory (what a diagnosis needs: the deck and its files, the log, the screen,
    the dump's last frames): each file cut to its last KEEP_FILE_BYTES (at a frame of a dump, at a line
    otherwise), the whole within KEEP_DIR_BYTES. The names kept, with their cuts."""
    names = []
    try:
        entries = sorted((p for p in wd.rglob("*") if p.is_file() and not p.is_symlink()),
                         key=lambda p: (p.name != "in.deck", p.stat().st_size))
    except OSError:
        return names
    left = KEEP_DIR_BYTES
    for p in entries:
        try:
            size = p.stat().st_size
            bound = min(KEEP_FILE_BYTES, max(left, 0))
            rel = str(p.relative_to(wd))
            if size > bound:
                if bound < 4096:
                    p.unlink()
                    names.append(f"{rel} removed ({size} bytes: past the directory's bound)")
                    continue
                _cut(p, bound)
                names.append(f"{rel}: its last {p.stat().st_size} of {size} bytes")
            else:
                names.append(rel)
            left -= p.stat().st_size
        except OSError:
            continue
    return names


def _cut(path: Path, bound: int) -> None:
    """``path`` cut to its end within ``bound`` bytes, from a dump frame's start (else a line's), atomically."""
    size = path.stat().st_size
    with open(path, "rb") as fh:
        fh.seek(size - bound)
        tail = fh.read()
    at = tail.find(b"\n" + _FRAME) + 1  # a frame's first line (0: none within the bound)
    if at == 0:
        at = tail.find(b"\n") + 1
    tmp = path.with_name(path.name + ".cut")
    tmp.write_bytes(tail[at:])
    os.replace(tmp, path)


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


def _logs(engine: str | None) -> tuple[str, ...]:
    """The files a run's log may be in: the engine's own (Engine.log_files), then a worker's screen."""
    own = registry.get(engine).log_files if engine else ()
    return (*own, *((SCREEN,) if SCREEN not in own else ()))


def _read_log(wd: Path, out: str | None, engine: str | None = None) -> str:
    """What a run wrote: the longest of its log files (``engine``'s own and a worker's screen: they carry the same
    lines), after what its process printed besides (``output.txt``: MPI's messages, a crash's; a Python engine's
    whole output) and ``out``."""
    texts = {}
    for name in (*_logs(engine), OUTPUT):
        p = wd / name
        if p.exists():
            texts[name] = p.read_text(errors="replace")
    log = max((texts.get(name, "") for name in _logs(engine)), key=len)
    extra = [t for t in (texts.get(OUTPUT, ""), out or "") if t.strip() and t.strip() not in log]
    return plain_text("\n".join([*extra, log] if log else extra))  # an engine's colours never reach a report


# ----------------------------------------------------------------------------- long-lived workers

WORKER_START_TIMEOUT = 120.0  # s for a worker to load its engine and answer (a loaded machine included)
WORKER_STOP_TIMEOUT = 10.0  # s for a worker to end after its input is closed, before it is killed
WORKER_POLL = 0.5  # s between looks at whether a worker waited on has ended
_IDLE: dict[tuple, list] = {}  # (engine, worker command) → workers waiting for a run
_WORKERS: set = set()  # every worker started and not yet ended
_POOL = threading.Lock()
_AT_EXIT = []


class _Worker:
    """One worker process: its own session (as a run's process), requests on its stdin, one JSON answer a
    line on its stdout."""

    def __init__(self, engine: str, argv: list[str]):
        self.engine = engine
        self.buffer = b""
        self.version = ""
        self.proc = subprocess.Popen(argv + ["--parent", str(os.getpid())], cwd=tempfile.gettempdir(),
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     env=discovery.engine_env(), start_new_session=True, bufsize=0)

    def send(self, request: dict) -> bool:
        """False when the worker is gone (its input closed)."""
        try:
            self.proc.stdin.write((json.dumps(request) + "\n").encode())
            self.proc.stdin.flush()
            return True
        except (BrokenPipeError, OSError):
            return False

    def receive(self, timeout: float, greeting: bool = False) -> dict | None:
        """The next answer; None when the worker ended first (its process's exit, not its pipe's end: a process
        it left behind may hold that open); TimeoutError past ``timeout`` seconds. ``greeting``: the first answer;
        lines before it that are not a JSON object are what the engine printed as it started (Yade's welcome),
        skipped."""
        deadline = time.monotonic() + timeout
        fd = self.proc.stdout.fileno()
        while True:
            while b"\n" not in self.buffer:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError
                ended = self.proc.poll() is not None  # read before the last look at the pipe: nothing comes after
                ready, _, _ = select.select([fd], [], [], 0.0 if ended else min(left, WORKER_POLL))
                if ready:
                    chunk = os.read(fd, 65536)
                    if not chunk:
                        return None
                    self.buffer += chunk
                elif ended:
                    return None
            line, _, self.buffer = self.buffer.partition(b"\n")
            if not greeting or line.lstrip().startswith(b"{"):
                break
        try:
            return json.loads(line)
        except ValueError:
            return {"ok": False, "error": f"the worker answered {line[:200]!r}"}

    def alive(self) -> bool:
        return self.proc.poll() is None

    def end(self, kill: bool = False) -> int | None:
        """Stop the worker (its input closed, then its group killed if it has not ended within
        WORKER_STOP_TIMEOUT s, or at once with ``kill``) and reap it; its exit code."""
        if kill:
            _kill_group(self.proc)
        for pipe in (self.proc.stdin, self.proc.stderr):
            try:
                if pipe is not None:
                    pipe.close()
            except OSError:
                pass
        try:
            self.proc.wait(timeout=WORKER_STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            pass
        _kill_group(self.proc)  # not ended in time, or ended leaving something in its session
        self.proc.wait()
        try:
            self.proc.stdout.close()
        except OSError:
            pass
        with _POOL:
            _WORKERS.discard(self)
        return self.proc.returncode


def _available(fd: int, limit: int = 1 << 20) -> bytes:
    """What can be read from ``fd`` now (at most ``limit`` bytes), without waiting for its end of file."""
    data = b""
    while len(data) < limit and select.select([fd], [], [], 0)[0]:
        chunk = os.read(fd, 65536)
        if not chunk:
            break
        data += chunk
    return data


def _start_worker(engine: str, argv: list[str], info) -> _Worker:
    """A new worker, ready: its engine loaded, its version the one discovery read from the executable. It is
    a running engine while it starts (an interrupt kills it)."""
    with _LOCK:
        if _STOP.is_set():
            raise EngineInterrupted(f"{engine}: not started: demcheck was interrupted")
        try:
            w = _Worker(engine, argv)
        except OSError as exc:
            raise _fault(f"{engine}'s worker did not start: {argv[0]}: {exc.strerror or exc}") from None
        _RUNNING.add(w.proc)
    with _POOL:
        _WORKERS.add(w)
        if not _AT_EXIT:
            _AT_EXIT.append(atexit.register(shutdown_workers))
    try:
        hello = w.receive(WORKER_START_TIMEOUT, greeting=True)
    except TimeoutError:
        w.end(kill=True)
        raise _fault(f"{engine}'s worker did not start within {WORKER_START_TIMEOUT:g} s") from None
    except KeyboardInterrupt as exc:
        kill_all()
        w.end(kill=True)
        exc2 = EngineInterrupted(f"{engine} was stopped by the interrupt")
        exc2.exit_code = interrupt_exit_code(exc)
        raise exc2 from exc
    finally:
        with _LOCK:
            _RUNNING.discard(w.proc)
    if w.proc in _KILLED:
        w.end(kill=True)
        raise EngineInterrupted(f"{engine}: not started: demcheck was interrupted")
    if not hello or not hello.get("ready"):
        why = (hello or {}).get("error") or ""
        if not why:
            w.proc.stdin.close()
            code = w.proc.wait()  # it ended (no greeting): what it wrote on stderr, not waiting for the pipe's end
            said = plain_text(_available(w.proc.stderr.fileno()).decode(errors="replace"))
            why = log_tail(said, 1) or _exit_words(code)
        w.end(kill=True)
        raise _fault(f"{engine}'s worker did not start: {why}")
    w.version = str(hello.get("version", ""))
    w.proc.stderr.close()  # the worker's own stderr now points at /dev/null or a run's screen.txt
    if w.version != info.version:
        w.end(kill=True)
        raise EngineFailed(f"{engine}'s worker loads version {w.version!r}, but {info.executable} is "
                           f"{info.version!r}: run it without the worker")
    return w


def _fault(message: str) -> EngineFailed:
    """A worker's failure before any deck ran (it did not start): a fault of the process, run.py retries once."""
    exc = EngineFailed(message)
    exc.what, exc.fault = message, True
    return exc


def _checkout(engine: str, argv: list[str], info) -> _Worker:
    """An idle live worker of this engine and command, or a new one."""
    key = (engine, tuple(argv))
    while True:
        with _POOL:
            idle = _IDLE.get(key)
            w = idle.pop() if idle else None
        if w is None:
            return _start_worker(engine, argv, info)
        if w.alive():
            return w
        w.end()  # died while idle (killed, or its parent thread ended): replaced


def _checkin(w: _Worker, argv: list[str]) -> None:
    if w.alive():
        with _POOL:
            if w in _WORKERS:
                _IDLE.setdefault((w.engine, tuple(argv)), []).append(w)
                return
    w.end()


def shutdown_workers() -> None:
    """End every worker this process has started and that no run is using (their input closed; killed if
    they have not ended within WORKER_STOP_TIMEOUT s)."""
    with _POOL:
        idle = [w for ws in _IDLE.values() for w in ws]
        _IDLE.clear()
    for w in idle:
        w.end()


def workers() -> list[int]:
    """The process ids of the workers alive now (idle or running)."""
    with _POOL:
        return sorted(w.proc.pid for w in _WORKERS if w.alive())


class _NotTaken(Exception):
    """The worker ended before it took the run (no log, no screen in the work directory)."""


def _run_in_worker(engine: str, info, argv: list[str], wd: Path, workdir, timeout: float) -> RunOutput:
    """``in.deck`` in ``wd`` run by a worker: the subprocess path's RunOutput and errors. A worker handed out
    while it was dying (killed while idle: a process whose first thread is a zombie still reads as running
    until its other threads have ended) never takes the run: it is given once more to a new worker."""
    try:
        return _worker_attempt(engine, info, argv, wd, workdir, timeout)
    except _NotTaken:
        pass
    try:
        return _worker_attempt(engine, info, argv, wd, workdir, timeout)
    except _NotTaken as exc:
        raise _failed(engine, wd, "", f"two workers ended before they took the run ({exc})", deck_error=False) from None


def _worker_attempt(engine: str, info, argv: list[str], wd: Path, workdir, timeout: float) -> RunOutput:
    w = _checkout(engine, argv, info)
    try:
        with _LOCK:  # as a process's start: an interrupt either sees this run or stops it from starting
            if _STOP.is_set():
                raise _interrupted(engine, wd, workdir, interrupt_exit_code(None),
                                   "not started: demcheck was interrupted")
            _RUNNING.add(w.proc)
        started = time.perf_counter()
        try:
            answer = w.receive(timeout) if w.send({"workdir": str(wd.resolve()), "deck": "in.deck"}) else None
        except TimeoutError:
            w.end(kill=True)
            raise _timed_out(engine, wd, timeout, w.proc.pid) from None
        except KeyboardInterrupt as exc:  # SIGINT or SIGTERM while waiting on the engine: stop it, and the others
            kill_all()
            w.end(kill=True)
            raise _interrupted(engine, wd, workdir, interrupt_exit_code(exc)) from exc
        finally:
            with _LOCK:
                _RUNNING.discard(w.proc)
        if w.proc in _KILLED:  # stopped by an interrupt handled elsewhere (another thread's kill_all)
            w.end(kill=True)
            raise _interrupted(engine, wd, workdir, interrupt_exit_code(None))
        wall = time.perf_counter() - started
        log = _read_log(wd, None, engine)
        errors = registry.get(engine).errors(log)
        if answer is None and not any((wd / name).exists() for name in _logs(engine)):
            code = w.end(kill=True)
            raise _NotTaken(f"its worker process ended: {_exit_words(code)}")
        if answer is None:  # the worker died during the run: the next run starts a new one
            code = w.end(kill=True)
            raise _failed(engine, wd, log, f"its worker process ended: {_exit_words(code)}", deck_error=bool(errors))
        if not answer.get("ok") or errors:
            message = str(answer.get("error") or "").strip()
            seen = f"its worker answered: {message.splitlines()[0]}" if message else "its worker answered no message"
            raise _failed(engine, wd, log or message, seen, deck_error=True)
        return _output(engine, info, wd, log, wall, answer.get("loop"))
    finally:
        _checkin(w, argv)
