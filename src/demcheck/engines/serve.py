"""The worker's side of engines/run.py's long-lived workers: one engine loaded once, deck after deck.

A worker is a process ``<program> … --parent PID`` that serves one engine (a :class:`Server`): it loads the
engine, then reads requests on stdin, one JSON object a line (``{"workdir": DIR, "deck": "in.deck"}``), and
answers each on its own stdout, one JSON object a line:

* the first answer, before any request: ``{"ready": true, "version": …, "pid": …}``, the version in the words
  discovery reads from the engine's executable, or ``{"ready": false, "error": …}``; lines an engine prints on
  stdout before it (Yade's welcome) are not JSON objects and the caller skips them;
* a run: into the work directory (``os.chdir``: decks name their files by plain names), stdout and stderr into
  ``screen.txt`` there (descriptors 1 and 2: the engine's C-level output and Python's alike), the deck run by
  the server, its output flushed; the answer ``{"ok": true}`` or ``{"ok": false, "error": the engine's
  message}``, with ``"loop"`` (seconds of the engine's stepping loop) where the server measures it; then the
  server's reset (while the caller reads the run's output): an engine error leaves the worker usable;
* end of stdin: the engine stopped, exit 0.

The answers keep a descriptor of their own (a copy of the original stdout): descriptors 1 and 2 point at the
current run's ``screen.txt``, or at /dev/null between runs, so nothing the engine prints can corrupt them. A
worker dies with the process that started it (``PR_SET_PDEATHSIG``); timeouts and interrupts are the caller's
(run.py kills the worker's process group).

This module imports only the standard library: Yade's worker runs it in Yade's own Python, loaded by path.
"""

from __future__ import annotations

import json
import os
import re
import sys
import time
import traceback


# what an engine prints for a terminal, not as text (ECMA-48): a control sequence (CSI: colours, cursor moves), a
# control string ended by BEL or ST (OSC, DCS, APC, PM, SOS: a window's title) or at its line's end, an escape
ESCAPES = re.compile(r"(?:\x1b\[|\x9b)[0-?]*[ -/]*[@-~]"
                     r"|(?:\x1b[\]PX^_]|[\x90\x98\x9d-\x9f])[^\n]*?(?:\x07|\x1b\\|\x9c|(?=\n)|\Z)"
                     r"|\x1b[ -/]*[0-~]")
_CONTROL = {c: f"\\x{c:02x}" for c in [*range(0, 9), *range(11, 32), 127, *range(128, 160)]}  # a tab, a line stay


def plain_text(text: str) -> str:
    """An engine's text as text: its escape sequences (a build's coloured banner) removed, a line ended by CR or
    CR LF ended by LF, any other control character shown as \\xNN. Every engine text demcheck reads (banners,
    versions, a worker's version and errors) goes through it before a report, JSON or a terminal sees it."""
    text = ESCAPES.sub("", text.replace("\r\n", "\n"))
    return text.replace("\r", "\n").translate(_CONTROL)


class Server:
    """One engine in a worker. ``run`` is called in the run's work directory, with descriptors 1 and 2 on its
    ``screen.txt``; it raises on an engine error (the exception's text is the answer's error)."""

    def start(self) -> str:
        """Load the engine; its version, as discovery reads it from the engine's executable."""
        raise NotImplementedError

    def run(self, deck: str) -> float | None:
        """Run ``deck`` (a file in the current directory); the seconds of the engine's stepping loop where the
        server measures them (None: the engine's log says it)."""
        raise NotImplementedError

    def flush(self) -> None:
        """Write out what the engine buffers (its log, its screen): the caller reads them on the answer."""

    def reset(self, failed: bool) -> None:
        """Between runs: the next one starts from the engine's state at start (``failed``: this one raised)."""

    def stop(self) -> None:
        """End of input: the engine closed."""


class ScriptFailed(Exception):
    """A Python deck raised: its message is the exception as its traceback ends (the whole traceback is in the
    screen)."""


def run_script(path: str, namespace: dict) -> float:
    """Execute the Python script ``path`` in ``namespace`` as its interpreter runs a script: an exception's
    traceback printed on stderr (the run's screen), then raised as ScriptFailed. The seconds it took."""
    with open(path, encoding="utf-8") as fh:
        code = compile(fh.read(), path, "exec")
    started = time.perf_counter()
    try:
        exec(code, namespace)  # noqa: S102 - a deck demcheck wrote and its engine's guard checked (run.py)
    except Exception as exc:  # noqa: BLE001 - whatever the deck raises is the run's error
        traceback.print_exception(type(exc), exc, exc.__traceback__.tb_next)  # from the script's frame on
        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        raise ScriptFailed(last) from exc
    return time.perf_counter() - started


def die_with_parent(parent: int) -> None:
    """SIGKILL this process when its parent dies (Linux), and exit now if it already has."""
    import ctypes
    import signal

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if parent and os.getppid() != parent:
        os._exit(1)


def _point_output_at(fd: int) -> None:
    """Python's and C's output buffers written out (an engine's screen through C's stdout, C++'s std::cout),
    then descriptors 1 and 2 on ``fd``."""
    import ctypes

    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass
    os.dup2(fd, 1)
    os.dup2(fd, 2)


def _run(server: Server, workdir: str, deck: str, home: str, devnull: int) -> tuple[dict, bool | None]:
    """One request: (the answer; whether the engine raised, None when it did not run)."""
    try:
        os.chdir(workdir)
        screen = os.open("screen.txt", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    except OSError as exc:  # the work directory: the caller's side, not the engine's
        os.chdir(home)
        return {"ok": False, "error": f"the work directory {workdir}: {exc.strerror or exc}"}, None
    _point_output_at(screen)
    os.close(screen)
    answer = {"ok": True, "error": ""}
    try:
        loop = server.run(deck)
        if loop is not None:
            answer["loop"] = loop
    except Exception as exc:  # noqa: BLE001 - the engine's error, whatever its type: the answer says it
        answer = {"ok": False, "error": plain_text(str(exc)).strip() or type(exc).__name__}
    finally:
        try:
            server.flush()
        except Exception:  # noqa: BLE001 - an engine broken by an error: its reset replaces it
            pass
        _point_output_at(devnull)
        os.chdir(home)
    return answer, not answer["ok"]


def serve(server: Server, argv: list[str] | None = None) -> int:
    """The worker's main loop (see the module's notes); its exit code."""
    args = list(sys.argv[1:] if argv is None else argv)
    parent = int(args[args.index("--parent") + 1]) if "--parent" in args else 0
    die_with_parent(parent)
    answers = os.fdopen(os.dup(1), "w", buffering=1, encoding="utf-8")
    devnull = os.open(os.devnull, os.O_WRONLY)
    sys.stdout.flush()
    os.dup2(devnull, 1)
    home = os.getcwd()

    def send(obj: dict) -> None:
        answers.write(json.dumps(obj) + "\n")
        answers.flush()

    try:
        version = server.start()
    except BaseException as exc:  # noqa: BLE001 - whatever stops it, the caller gets one line
        send({"ready": False, "error": plain_text(f"{type(exc).__name__}: {exc}")})
        return 1
    send({"ready": True, "version": plain_text(version).strip(), "pid": os.getpid()})
    _point_output_at(devnull)  # stderr too: the caller reads only the answers
    for line in sys.stdin:
        if not line.strip():
            continue
        try:
            request = json.loads(line)
            workdir, deck = str(request["workdir"]), str(request["deck"])
        except (ValueError, KeyError, TypeError):
            send({"ok": False, "error": f"not a request: {line.strip()[:200]}"})
            continue
        answer, failed = _run(server, workdir, deck, home, devnull)
        send(answer)
        if failed is not None:
            server.reset(failed)  # while the caller reads the run's output
    server.stop()
    return 0


class InputServer(Server):
    """An engine driven through the LAMMPS input language by an instance with ``command(text)`` and
    ``file(path)`` (LAMMPS's Python module, LIGGGHTS's C library): ``log log.txt`` and the deck read as
    ``-in`` reads it; the log closed after it; ``clear`` between runs (every setting back to its default, every
    atom and fix gone), a fresh instance after an error. Subclasses open and close instances and name the
    header that carries the version."""

    header: re.Pattern  # group 1 of its match on the instance's first log is the version
    title = "the engine"

    def __init__(self):
        self.engine = None

    def open(self, args: list[str]):
        """A new instance with these command-line arguments."""
        raise NotImplementedError

    def close(self, engine) -> None:
        engine.close()

    def flush_output(self) -> None:
        """The instance's screen written out."""

    def finalize(self, engine) -> None:
        """After the last instance, ``engine``, is closed at the end: MPI ended."""

    def start(self) -> str:
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory(prefix="demcheck-worker-") as tmp:
            head = Path(tmp) / "head.txt"
            self.engine = self.open(["-log", str(head)])
            self.engine.command("log none")
            match = self.header.search(head.read_text(errors="replace"))
        if match is None:
            raise RuntimeError(f"{self.title} printed no version header")
        return match.group(1).strip()

    def run(self, deck: str) -> None:
        if self.engine is None:
            self.engine = self.open(["-log", "none"])
        self.engine.command("log log.txt")
        self.engine.file(deck)
        return None

    def flush(self) -> None:
        if self.engine is not None:
            for step in (self.flush_output, lambda: self.engine.command("log none")):
                try:
                    step()
                except Exception:  # noqa: BLE001 - an instance broken by an error: it is replaced next
                    pass

    def reset(self, failed: bool) -> None:
        if self.engine is None:
            return
        if not failed:
            try:
                self.engine.command("clear")
                return
            except Exception:  # noqa: BLE001
                pass
        try:
            self.close(self.engine)
        except Exception:  # noqa: BLE001
            pass
        self.engine = None

    def stop(self) -> None:
        if self.engine is not None:
            self.close(self.engine)
            self.finalize(self.engine)
            self.engine = None
