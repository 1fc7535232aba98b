"""demcheck: does a DEM contact force model, as LAMMPS, LIGGGHTS, Yade and Kratos DEM implement it, do what the
textbook model does?"""

import hashlib as _hashlib
import os as _os
from pathlib import Path as _Path

__version__ = "0.1.0"


def reference_fingerprint() -> str:
    """A hash of the reference package's source (every compiled kernel lives there)."""
    h = _hashlib.sha256()
    for f in sorted((_Path(__file__).parent / "reference").glob("*.py")):
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:16]


def _numba_cache_dir() -> None:
    """Numba's on-disk cache keys a compiled function by its own file's timestamp only: a kernel that
    inlines a function of another module would be served stale after that module changed (seen here: the
    suite passed on stale 3-D kernels while fresh ones stalled; docs/performance.md). So the kernels cache
    under a directory named by the fingerprint of the whole reference package: any change to any kernel
    source starts afresh.
    Respects a NUMBA_CACHE_DIR set by the user; skipped where the directory cannot be made."""
    if "NUMBA_CACHE_DIR" in _os.environ:
        return
    root = _Path(_os.environ.get("XDG_CACHE_HOME") or _Path.home() / ".cache") / "demcheck" / "numba"
    where = root / reference_fingerprint()
    try:
        where.mkdir(parents=True, exist_ok=True)
    except OSError:
        return
    _os.environ["NUMBA_CACHE_DIR"] = str(where)


_numba_cache_dir()


# the Python API (docs/api.md), looked up on first use: ``import demcheck`` loads no solver, engine or pandas
_API = ("load", "collide", "collide_many", "sweep", "verify", "audit", "calibrate", "sources", "packing_universe")


def __getattr__(name: str):
    if name in _API:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.api"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *_API])
