"""A LIGGGHTS worker: one process that loads LIGGGHTS's C library once and runs deck after deck (engines/serve.py's
protocol).

Debian has no Python binding of LIGGGHTS; its ``libliggghts3`` package ships the shared library the ``liggghts``
executable runs, ``libliggghts.so.3``, which exports LAMMPS's C library interface (``lammps_open_no_mpi``,
``lammps_command``, ``lammps_file``, ``lammps_close``). ``python -m demcheck.engines.liggghts.worker --library
PATH --parent PID`` loads that file with ctypes (``RTLD_GLOBAL``: Open MPI's plug-ins look up its symbols),
opens one instance (MPI initialised on its own, one rank) with ``-echo none`` as runs have it, and runs each
deck as serve.InputServer does: ``log log.txt``, the deck read as ``liggghts -in`` reads it, the log closed,
C's stdout (LIGGGHTS's screen, ``screen.txt``) flushed, ``clear`` between runs. The library and the executable
run the same code on the same deck text: the dumps are the same bytes (tests/test_engine_workers.py).

An error does not come back through the library: LIGGGHTS 3.8.0 has no C++ exceptions, its ``Error::all`` writes
``ERROR: …`` to the screen and the log, finalises MPI and calls ``exit(1)``. The worker ends with it; the run
then fails as a process's does (engines/run.py: the log's ERROR line and tail), and the next run starts a new
worker.

This module imports only the standard library at module level: the engine object asks :func:`library` without
loading LIGGGHTS.
"""

from __future__ import annotations

import functools
import re
import sys
from pathlib import Path

from ..serve import InputServer, serve

MODULE = "demcheck.engines.liggghts.worker"
_LINKED = re.compile(r"^\s*(libliggghts\.so[.0-9]*)\s+=>\s+(/\S+)", re.M)
# the instance's first log line, which ``liggghts -h`` prints too: group 1 the words discovery reads there
_HEADER = re.compile(r"^LIGGGHTS \(Version (LIGGGHTS-PUBLIC [^,)]+)", re.M)


@functools.lru_cache(maxsize=None)
def library(executable: str) -> str | None:
    """The LIGGGHTS library ``executable`` runs (Debian's: /usr/lib/x86_64-linux-gnu/libliggghts.so.3.8.0), as
    the dynamic loader resolves it (``ldd``); None for an executable that loads none (a static build, a
    wrapper script): that build runs as a process of its own."""
    from ..discovery import output_of

    out, _ = output_of(["ldd", str(Path(executable).resolve())], 30, "ldd")  # judged by its exit, as a banner
    match = _LINKED.search(out) if out is not None else None
    return str(Path(match.group(2)).resolve()) if match else None


class _Instance:
    """One LIGGGHTS instance through the C library interface: ``command`` and ``file`` as LAMMPS's Python
    module has them."""

    def __init__(self, lib, args: list[str]):
        import ctypes

        self.lib = lib
        words = [b"liggghts", *(a.encode() for a in args)]
        argv = (ctypes.c_char_p * len(words))(*words)
        self.handle = ctypes.c_void_p()
        lib.lammps_open_no_mpi(len(words), argv, ctypes.byref(self.handle))

    def command(self, text: str) -> None:
        self.lib.lammps_command(self.handle, text.encode())

    def file(self, path: str) -> None:
        self.lib.lammps_file(self.handle, path.encode())

    def close(self) -> None:
        self.lib.lammps_close(self.handle)


class Server(InputServer):
    """Debian's LIGGGHTS library, through ctypes."""

    title = "LIGGGHTS"
    header = _HEADER

    def __init__(self, path: str):
        super().__init__()
        self.path = path
        self.lib = None

    def start(self) -> str:
        import ctypes

        lib = ctypes.CDLL(self.path, mode=ctypes.RTLD_GLOBAL)
        lib.lammps_open_no_mpi.argtypes = [ctypes.c_int, ctypes.POINTER(ctypes.c_char_p),
                                           ctypes.POINTER(ctypes.c_void_p)]
        lib.lammps_open_no_mpi.restype = None
        lib.lammps_command.argtypes = lib.lammps_file.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
        lib.lammps_command.restype = ctypes.c_char_p  # the command's name
        lib.lammps_file.restype = None
        lib.lammps_close.argtypes = [ctypes.c_void_p]
        lib.lammps_close.restype = None
        self.lib = lib
        return super().start()

    def open(self, args: list[str]) -> _Instance:
        return _Instance(self.lib, [*args, "-echo", "none"])

    def finalize(self, engine) -> None:
        self.lib.MPI_Finalize()


def main(argv: list[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if "--library" not in args:
        print("usage: python -m demcheck.engines.liggghts.worker --library PATH [--parent PID]", file=sys.stderr)
        return 2
    return serve(Server(args[args.index("--library") + 1]), args)


if __name__ == "__main__":
    sys.exit(main())
