"""The engine-run cache: an engine never runs the same deck twice.

Key: SHA-256 of the engine's name and version, the deck and the files it reads. Value: the parsed dump
(every column, float64) and the run's metadata, in one ``.npz`` written atomically, so an interrupted run
never leaves a half-written entry. Location: ``$DEMCHECK_CACHE``, else ``~/.cache/demcheck/engine-runs``.

Only finite tables are stored (NaN or infinite output is a failed run, never reused). An entry that fails
to load or to validate (truncated, changed bytes, no metadata keys, columns missing, non-finite values)
is a miss, logged once (logger ``demcheck.cache``: one line naming the file and the fault), and the next
``put`` writes over it. ``Cache(refresh=True)`` never reads an entry and writes fresh results over old
ones (``--no-cache``).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import atomic_path

log = logging.getLogger("demcheck.cache")


def default_dir() -> Path:
    env = os.environ.get("DEMCHECK_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "demcheck" / "engine-runs"


def key(engine: str, version: str, deck: str, files: dict[str, str]) -> str:
    h = hashlib.sha256()
    for part in (engine, version, deck, *(f"{n}\0{t}" for n, t in sorted(files.items()))):
        h.update(part.encode())
        h.update(b"\0\0")
    return h.hexdigest()


class Damaged(Exception):
    """An entry that loads but does not validate."""


class Cache:
    def __init__(self, directory: str | Path | None = None, refresh: bool = False):
        self.dir = Path(directory) if directory else default_dir()
        self.refresh = refresh
        self.hits = 0
        self.misses = 0
        self._logged: set[Path] = set()

    def _path(self, k: str) -> Path:
        return self.dir / k[:2] / f"{k}.npz"

    def get(self, k: str, columns: tuple[str, ...] = (), meta_keys: tuple[str, ...] = ()
            ) -> tuple[pd.DataFrame, dict] | None:
        """(table, meta) of entry ``k``, or None: no entry, ``refresh``, or an entry that fails to load or
        to validate — finite values, the ``columns`` and ``meta_keys`` the caller needs."""
        path = self._path(k)
        if self.refresh or not path.exists():
            self.misses += 1
            return None
        try:
            table, meta = _load(path, columns, meta_keys)
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
        """Store ``table`` and ``meta`` under ``k`` (over any old entry); a table with NaN or infinite values
        is not stored (False)."""
        data = table.to_numpy(dtype=float)
        if not np.isfinite(data).all():
            return False
        path = self._path(k)
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, columns=np.array(list(table.columns)), data=data, meta=np.array(json.dumps(meta)))
        self._logged.discard(path)
        return True


def _load(path: Path, columns, meta_keys) -> tuple[pd.DataFrame, dict]:
    with np.load(path, allow_pickle=False) as z:
        names = [str(c) for c in z["columns"]]
        data = np.asarray(z["data"], dtype=float)
        meta = json.loads(str(z["meta"]))
    if data.ndim != 2 or data.shape[1] != len(names):
        raise Damaged(f"data of shape {data.shape} for {len(names)} columns")
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
    table = pd.DataFrame(data, columns=names)
    for c in ("step", "id", "type"):
        if c in table:
            table[c] = table[c].astype(np.int64)
    return table, meta
