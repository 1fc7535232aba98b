"""The engine-run cache: an engine never runs the same deck twice.

Key: SHA-256 of the engine's name and version, the deck and the files it reads. Value: the parsed dump
(every column, float64) and the run's metadata, in one ``.npz`` written atomically, so an interrupted run
never leaves a half-written entry. Location: ``$DEMCHECK_CACHE``, else ``~/.cache/demcheck/engine-runs``.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import atomic_path


def default_dir() -> Path:
    env = os.environ.get("DEMCHECK_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "demcheck" / "engine-runs"


def key(engine: str, version: str, deck: str, files: dict[str, str]) -> str:
    h = hashlib.sha256()
    for part in (engine, version, deck, *(f"{n}\0{t}" for n, t in sorted(files.items()))):
        h.update(part.encode())
        h.update(b"\0\0")
    return h.hexdigest()


class Cache:
    def __init__(self, directory: str | Path | None = None):
        self.dir = Path(directory) if directory else default_dir()
        self.hits = 0
        self.misses = 0

    def _path(self, k: str) -> Path:
        return self.dir / k[:2] / f"{k}.npz"

    def get(self, k: str) -> tuple[pd.DataFrame, dict] | None:
        path = self._path(k)
        if not path.exists():
            self.misses += 1
            return None
        try:
            with np.load(path, allow_pickle=False) as z:
                columns = [str(c) for c in z["columns"]]
                table = pd.DataFrame(z["data"], columns=columns)
                meta = json.loads(str(z["meta"]))
        except (OSError, ValueError, KeyError):  # a damaged entry is a miss, and is replaced
            self.misses += 1
            return None
        for c in ("step", "id", "type"):
            if c in table:
                table[c] = table[c].astype(np.int64)
        self.hits += 1
        return table, meta

    def put(self, k: str, table: pd.DataFrame, meta: dict) -> None:
        path = self._path(k)
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as fh:
                np.savez(fh, columns=np.array(list(table.columns)), data=table.to_numpy(dtype=float),
                         meta=np.array(json.dumps(meta)))
