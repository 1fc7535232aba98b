"""The engine-run cache: an engine never runs the same deck twice.

Key: SHA-256 of the source's name (an engine, or a build's label) and version (a build with its own
executable also its binary's identity, engines/builds.py), the deck and the files it reads. Value: the parsed dump
(every column, float64) and the run's metadata, in one ``.npz`` written atomically, so an interrupted run
never leaves a half-written entry. Location: ``$DEMCHECK_CACHE``, else ``$XDG_CACHE_HOME/demcheck/engine-runs`` (``~/.cache`` by default, as the kernels').

Only finite tables are stored (NaN or infinite output is a failed run, never reused). An entry that fails
to load or to validate (truncated, changed bytes, metadata keys missing or of the wrong type, columns missing,
fewer rows than the caller needs, non-finite values, the caller's own check) is a miss, logged once (logger
``demcheck.cache``: one line naming the file and the fault), and the next ``put`` writes over it. A ``put`` that cannot write (a file where a directory goes, a directory where the entry goes,
no permission, a full disk) logs once and returns False: the caller keeps its result, uncached.
``Cache(refresh=True)`` never reads an entry and writes fresh results over old ones (``--no-cache``).
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import math
import os
from pathlib import Path
from collections.abc import Callable, Iterable, Mapping

import numpy as np
import pandas as pd

from ..io import atomic_path

log = logging.getLogger("demcheck.cache")


def default_dir() -> Path:
    env = os.environ.get("DEMCHECK_CACHE")
    if env:
        return Path(env)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "demcheck" / "engine-runs"


def key(engine: str, version: str, deck: str, files: dict[str, str]) -> str:
    """The entry of a deck run by ``engine`` (a source's name: an engine, or a build's label) at ``version``;
    a build with its own executable (engines/builds.py) adds its binary's path, size and modification time,
    so a rebuilt binary that prints the same version never reads the old build's runs."""
    from .builds import identity

    h = hashlib.sha256()
    build = identity(engine)
    for part in (engine, version, *((build,) if build else ()), deck,
                 *(f"{n}\0{t}" for n, t in sorted(files.items()))):
        h.update(part.encode())
        h.update(b"\0\0")
    return h.hexdigest()


class Damaged(Exception):
    """An entry that loads but does not validate."""


# checks of metadata values, for ``Cache.get(meta_keys={key: check})``
def text(v) -> bool:
    """A string."""
    return isinstance(v, str)


def number(v) -> bool:
    """A finite number (not a boolean)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def texts(v) -> bool:
    """A list of strings."""
    return isinstance(v, list) and all(isinstance(x, str) for x in v)


def ke_series(v) -> bool:
    """A cached kinetic-energy series: [(step, ke), …] of finite numbers."""
    return isinstance(v, list) and all(isinstance(p, list) and len(p) == 2 and all(map(number, p)) for p in v)


class Cache:
    def __init__(self, directory: str | Path | None = None, refresh: bool = False):
        self.dir = Path(directory) if directory else default_dir()
        self.refresh = refresh
        self.hits = 0
        self.misses = 0
        self._logged: set[Path] = set()
        self._unwritable: set[Path] = set()

    def _path(self, k: str) -> Path:
        """An entry's file: ``k[:2]/k.npz``; a key ``NAMESPACE/NAME/…/HASH`` goes under ``NAMESPACE/NAME/…``
        (the results demcheck computes itself: one folder per source fingerprint, comparisons/result_cache.py)."""
        folder, _, name = k.rpartition("/")
        return self.dir / folder / name[:2] / f"{name}.npz"

    def get(self, k: str, columns: tuple[str, ...] = (), meta_keys: Iterable[str] | Mapping[str, Callable] = (),
            min_rows: int = 0, check: Callable[[pd.DataFrame, dict], str | None] | None = None
            ) -> tuple[pd.DataFrame, dict] | None:
        """(table, meta) of entry ``k``, or None: no entry, ``refresh``, or an entry that fails to load or
        to validate — finite values, the ``columns`` and ``meta_keys`` the caller needs (names, or names → a
        check of the value such as ``text``, ``number``, ``texts``), at least ``min_rows`` rows, and the
        caller's ``check(table, meta)`` (a fault's description, or None)."""
        path = self._path(k)
        if self.refresh or not path.is_file():  # none, or a directory in its place (put says it cannot write)
            self.misses += 1
            return None
        try:
            table, meta = _load(path, columns, meta_keys, min_rows)
            fault = check(table, meta) if check is not None else None
            if fault:
                raise Damaged(fault)
        except Exception as exc:  # noqa: BLE001 — whatever the damage, the entry is a miss and is replaced
            self.misses += 1
            if path not in self._logged:
                self._logged.add(path)
                why = " ".join(str(exc).split())[:200]
                log.warning("demcheck: engine-run cache: ignoring the damaged entry %s (%s: %s); it will be "
                            "replaced", path, type(exc).__name__, why)
            return None
        self.hits += 1
        return table, meta

    def put(self, k: str, table: pd.DataFrame, meta: dict) -> bool:
        """Store ``table`` and ``meta`` under ``k`` (over any old entry): True when stored. A table with NaN or
        infinite values is not stored (False); nor is one the cache cannot write (False, logged once: a file
        where a directory goes, a directory where the entry goes, no permission, a full disk)."""
        data = table.to_numpy(dtype=float)
        if not np.isfinite(data).all():
            return False
        path = self._path(k)
        try:
            with atomic_path(path) as tmp:
                with open(tmp, "wb") as fh:
                    np.savez(fh, columns=np.array(list(table.columns)), data=data,
                             meta=np.array(json.dumps(meta)))
        except OSError as exc:
            if path not in self._unwritable:
                self._unwritable.add(path)
                why = " ".join((exc.strerror or str(exc)).split())[:200]
                log.warning("demcheck: engine-run cache: cannot write the entry %s (%s: %s); the result is used "
                            "but not cached", path, type(exc).__name__, why)
            return False
        self._logged.discard(path)
        self._unwritable.discard(path)
        return True


def _load(path: Path, columns, meta_keys, min_rows: int = 0) -> tuple[pd.DataFrame, dict]:
    with np.load(path, allow_pickle=False) as z:
        names = [str(c) for c in z["columns"]]
        data = np.asarray(z["data"], dtype=float)
        meta = json.loads(str(z["meta"]))
    if data.ndim != 2 or data.shape[1] != len(names):
        raise Damaged(f"data of shape {data.shape} for {len(names)} columns")
    if data.shape[0] < min_rows:
        raise Damaged(f"{data.shape[0]} rows, fewer than {min_rows}")
    if not np.isfinite(data).all():
        raise Damaged("non-finite values")
    missing = [c for c in columns if c not in names]
    if missing:
        raise Damaged(f"missing column(s) {', '.join(missing)}")
    if not isinstance(meta, dict):
        raise Damaged("metadata is not an object")
    missing = [m for m in meta_keys if m not in meta]
    if missing:
        raise Damaged(f"metadata without {', '.join(missing)}")
    if isinstance(meta_keys, Mapping):
        for m, ok in meta_keys.items():
            if not ok(meta[m]):
                doc = (ok.__doc__ or ok.__name__).strip().rstrip(".").lower()
                raise Damaged(f"metadata {m} = {json.dumps(meta[m])[:60]}: not {doc}")
    table = pd.DataFrame(data, columns=names)
    for c in ("step", "id", "type"):
        if c in table:
            table[c] = table[c].astype(np.int64)
    return table, meta


def put_metrics(cache: Cache, k: str, metrics: dict, meta: dict) -> bool:
    """One row under ``k``: each metric, and beside it a flag that it is not finite (stored as 0: a table holds
    finite values only); ``meta`` with the metrics' names."""
    table = {m: [v if math.isfinite(v) else 0.0] for m, v in metrics.items()}
    table.update({f"{m}__nan": [0.0 if math.isfinite(v) else 1.0] for m, v in metrics.items()})
    return cache.put(k, pd.DataFrame(table), {**meta, "metric_names": list(metrics)})


def get_metrics(cache: Cache, k: str, names=None, meta_keys=()) -> tuple[dict, dict] | None:
    """(metrics, meta) of an entry :func:`put_metrics` wrote, or None; ``names`` the metrics the caller needs
    (default: the ones stored)."""
    hit = cache.get(k, columns=tuple(c for m in names or () for c in (m, f"{m}__nan")), min_rows=1,
                    meta_keys=meta_keys, check=None if names else _names_stored)
    if hit is None:
        return None
    row = hit[0].iloc[0]
    names = names or hit[1]["metric_names"]
    return {m: math.nan if row[f"{m}__nan"] else float(row[m]) for m in names}, hit[1]


def _names_stored(table: pd.DataFrame, meta: dict) -> str | None:
    names = meta.get("metric_names")
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        return "no list of metric names"
    missing = [c for m in names for c in (m, f"{m}__nan") if c not in table]
    return f"missing column(s) {', '.join(missing)}" if missing else None


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """A hash of every source file of demcheck (the laws, the reference's schemes, the engines' mappings and
    layouts, the metrics all shape what demcheck computes), of numpy's, numba's and scipy's versions and of the
    CPU the kernels are compiled for: the key part of every result demcheck computes itself and caches."""
    import numba
    import scipy
    from llvmlite import binding

    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha256(f"numpy {np.__version__} numba {numba.__version__} scipy {scipy.__version__} "
                       f"cpu {binding.get_host_cpu_name()}".encode())
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()[:16]
