"""demcheck: does a DEM contact force model, as LAMMPS, LIGGGHTS, Yade and Kratos DEM implement it, do what the
textbook model does?"""

import hashlib as _hashlib
import os as _os
from pathlib import Path as _Path

__version__ = "0.1.0"


KERNEL_PACKAGES = ("laws", "reference")  # every compiled kernel lives in one of these


def reference_fingerprint() -> str:
    """A hash of the source of every package that holds compiled kernels (the laws' force functions, their
    sub-packages, and the reference's solvers, which inline them) and of the plug-in law modules named in
    ``$DEMCHECK_LAW_PLUGINS`` (found, not imported)."""
    h = _hashlib.sha256()
    root = _Path(__file__).parent
    for package in KERNEL_PACKAGES:
        for f in sorted((root / package).rglob("*.py")):
            h.update(f"{f.relative_to(root).as_posix()}".encode() + b"\0" + f.read_bytes())
    for name in filter(None, (m.strip() for m in _os.environ.get("DEMCHECK_LAW_PLUGINS", "").split(","))):
        h.update(name.encode() + b"\0" + _plugin_source(name))
    return h.hexdigest()[:16]


def _plugin_source(name: str) -> bytes:
    """A plug-in module's source, without importing it (a top-level module; a dotted one imports its parent);
    b"" where it cannot be found (its import reports that)."""
    import importlib.util

    try:
        spec = importlib.util.find_spec(name)
        return _Path(spec.origin).read_bytes() if spec and spec.origin else b""
    except (ImportError, ValueError, OSError):
        return b""


def _numba_cache_dir() -> bool:
    """Where the compiled kernels are cached; False when nowhere writable (they compile in memory, each run).

    Numba's on-disk cache keys a compiled function by its own file's timestamp only: a kernel that inlines a
    function of another module would be served stale after that module changed (seen here: the suite passed on
    stale 3-D kernels while fresh ones stalled; docs/performance.md). So the kernels cache under a directory
    named by the fingerprint of the laws' and the reference's sources (``$XDG_CACHE_HOME/demcheck/numba/<fingerprint>``,
    ``~/.cache`` by default): any change to any kernel source starts afresh. A NUMBA_CACHE_DIR set by the user
    is used as it is. Never the install tree: where no cache directory takes a file (a read-only home, a
    locked-down container), the kernels are compiled without a cache and one warning line says so."""
    import sys
    import tempfile

    given = _os.environ.get("NUMBA_CACHE_DIR")
    if given:
        where = _Path(given)
    else:
        root = _Path(_os.environ.get("XDG_CACHE_HOME") or _Path.home() / ".cache") / "demcheck" / "numba"
        where = root / reference_fingerprint()
    try:
        where.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=where):
            pass
    except OSError as exc:
        sys.stderr.write(f"demcheck: warning: no writable kernel cache ({where}: {exc.strerror or exc}); the kernels "
                         "compile in memory on every run (set XDG_CACHE_HOME or NUMBA_CACHE_DIR to a writable "
                         "directory)\n")
        return False
    _os.environ["NUMBA_CACHE_DIR"] = str(where)
    return True


# the compiled kernels' ``cache=`` (``@njit(cache=KERNEL_CACHE)``): never numba's default of the source's folder
KERNEL_CACHE = _numba_cache_dir()


# the Python API (docs/api.md), looked up on first use: ``import demcheck`` loads no solver, engine or pandas
_API = ("load", "collide", "collide_many", "sweep", "verify", "audit", "calibrate", "pack", "case_files", "sources",
        "packing_universe", "models")


def __getattr__(name: str):
    if name in _API:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.api"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted([*globals(), *_API])
