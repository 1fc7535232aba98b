"""The reference's own results in the run cache: a warm ``verify`` solves nothing costly it solved before.

An engine run is cached by its deck (engines/cache.py); what demcheck computes itself — the reference's adaptive
solve of a case (the suite's converged answer: Walton's sticking variants take seconds), an engine's twin and the
seed model's verlet run at an engine's step (their metrics), a scenario's reference solve — is a pure function of
the case, of demcheck's code and of the numerical libraries on this CPU. Each is cached under a key made of what
it is (``kind``: the source's label and what fixes its run), the case's hash and
:func:`engines.cache.code_fingerprint` (every source file of demcheck, numpy's, numba's and scipy's versions and
the CPU the kernels are compiled for): a changed law, scheme, metric or case never reads an old result.

The entries of one fingerprint live in a folder of their own, ``results/FINGERPRINT/`` in the cache; a campaign
removes the folders of other fingerprints but the newest one (:func:`prune`), so the cache holds the results of at
most two versions of demcheck, not one per edit of its source. A Result is one entry: its contact and events tables
(what verify reads of it; not its particles) side by side, their columns' dtypes and an events table's labels in
the metadata with the Result's fields; it is stored only when its status is ok and its tables are finite, and read
back as the same arrays (tests/test_result_cache.py: the suite's entries of a case run cold and warm are equal).
Metrics alone (twins, seed runs) are one row (engines/cache.py ``put_metrics``).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pandas as pd

from ..engines.cache import code_fingerprint, get_metrics, key, put_metrics
from ..result import TABLES, Result

FIELDS = ("source", "method", "case_name", "case_hash", "model", "params", "dt", "rtol", "engine_version",
          "status", "message", "meta")
FOLDER = "results"
KEPT = ("contact", "events")  # the tables verify reads of a reference result


def result_key(kind: str, case) -> str:
    """The entry of the result ``kind`` (a source's label and what fixes its run, e.g. its step) of ``case``, in
    the folder of the current source fingerprint."""
    fingerprint = code_fingerprint()
    h = key("demcheck", fingerprint, json.dumps({"kind": kind, "case": case.hash}), {})
    return f"{FOLDER}/{fingerprint}/{h}"


def prune(cache) -> list[str]:
    """Remove the result folders of other source fingerprints than the current one, but the newest of them (a
    second version in use beside this one keeps its results); returns the folders removed. Only folders this
    version does not read are removed, whether or not the cache was opened with ``refresh``."""
    import shutil

    root = Path(cache.dir) / FOLDER
    if not root.is_dir():
        return []
    others = sorted((p for p in root.iterdir() if p.is_dir() and p.name != code_fingerprint()),
                    key=lambda p: p.stat().st_mtime, reverse=True)
    for old in others[1:]:
        shutil.rmtree(old, ignore_errors=True)
    return [p.name for p in others[1:]]


def cached_result(cache, kind: str, case, compute) -> Result:
    """``compute()``'s Result for ``case`` (``kind``: :func:`result_key`), from ``cache`` when it holds it; a
    result computed here is stored when it is ok and finite. ``cache`` None: computed."""
    if cache is None:
        return compute()
    k = result_key(kind, case)
    started = time.perf_counter()
    hit = load(cache, k)
    if hit is not None:
        hit.wall_time = time.perf_counter() - started
        hit.meta = {**hit.meta, "cached": True}
        return hit
    res = compute()
    if res.ok:
        store(cache, k, res)
    return res


def cached_metrics(cache, kind: str, case, compute) -> dict:
    """``compute()``'s metrics (a dict of floats) for ``case``, from ``cache`` when it holds them (a metric that
    is not finite kept as such)."""
    if cache is None:
        return compute()
    k = result_key(kind, case)
    hit = get_metrics(cache, k)
    if hit is not None:
        return hit[0]
    metrics = compute()
    put_metrics(cache, k, metrics, {})
    return metrics


def cached_json(cache, kind: str, case, compute):
    """(``compute()``'s value — what JSON holds: numbers (NaN and ±inf too), text, lists, objects — for ``case``,
    whether it came from ``cache``). A value computed here is stored and returned as read back (a tuple as a list),
    so a cold and a warm run hand their callers the same thing. ``cache`` None: computed."""
    if cache is None:
        return compute(), False
    k = result_key(kind, case)
    hit = cache.get(k, columns=("stored",), meta_keys=("value",))
    if hit is not None:
        return hit[1]["value"], True
    value = compute()
    try:
        meta = json.loads(json.dumps({"value": value}))
    except (TypeError, ValueError):  # not JSON as it is: used, not stored
        return value, False
    cache.put(k, pd.DataFrame({"stored": [1.0]}), meta)
    return meta["value"], False


def store(cache, k: str, res: Result) -> bool:
    """``res`` under ``k``, one entry: its contact and events tables side by side (each column named
    ``table.column``, the shorter tables padded with zeros, each table's rows, dtypes and labels in the metadata)
    and its fields. False when anything is not storable (a field JSON cannot hold, a table value that is not
    finite)."""
    parts, layouts = {}, {}
    for name in KEPT:
        cols = res.table(name)
        if cols is None:
            continue
        encoded, layout = _encode(cols)
        if encoded is None:
            return False
        layouts[name] = layout
        parts.update({f"{name}.{c}": v for c, v in encoded.items()})
    rows = max([1, *(lay["rows"] for lay in layouts.values())])
    frame = pd.DataFrame({c: np.pad(v, (0, rows - len(v))) for c, v in parts.items()} or {"empty": np.zeros(1)})
    try:  # NaN and ±inf kept as JSON's NaN and Infinity tokens (Python's json reads them back)
        meta = json.loads(json.dumps({"fields": {f: getattr(res, f) for f in FIELDS}, "tables": layouts,
                                      "wall_time": res.wall_time}))
    except (TypeError, ValueError):  # a field JSON cannot hold as it is (a numpy array): not cached
        return False
    return cache.put(k, frame, meta)


def load(cache, k: str) -> Result | None:
    """The Result :func:`store` kept under ``k``, or None (no entry, or an entry that does not give it back)."""
    hit = cache.get(k, meta_keys=("fields", "tables"), check=_complete)
    if hit is None:
        return None
    frame, meta = hit
    tables = {name: _decode(frame, name, layout) for name, layout in meta["tables"].items()}
    return Result(**meta["fields"], **{name: tables.get(name) for name in TABLES},
                  wall_time=float(meta.get("wall_time", 0.0)))


def _complete(frame: pd.DataFrame, meta: dict) -> str | None:
    """What makes a stored entry unreadable as a Result (cache.get's check: such an entry is a logged miss)."""
    fields, layouts = meta["fields"], meta["tables"]
    if not isinstance(fields, dict) or set(fields) != set(FIELDS):
        return "the result's fields are not all there"
    if not isinstance(layouts, dict) or not set(layouts) <= set(KEPT):
        return "no table layout"
    for name, lay in layouts.items():
        cols = lay.get("columns") if isinstance(lay, dict) else None
        if not isinstance(cols, list) or not isinstance(lay.get("rows"), int) or lay["rows"] > len(frame):
            return f"the {name} table's layout is damaged"
        for c in cols:
            dtype = lay["dtypes"].get(c)
            if f"{name}.{c}" not in frame or not (dtype == "text" or dtype in _NUMERIC):
                return f"the {name} table's column {c} is missing or of an unknown type"
            if dtype == "text" and not _labels_ok(frame[f"{name}.{c}"].to_numpy()[:lay["rows"]],
                                                   lay["labels"].get(c)):
                return f"the {name} table's column {c} has labels out of range"
    return None


_NUMERIC = {np.dtype(t).str for t in (np.float64, np.int64, np.bool_)}


def _labels_ok(values: np.ndarray, labels) -> bool:
    if not isinstance(labels, list) or not all(isinstance(s, str) for s in labels):
        return False
    idx = values.astype(np.int64)
    return bool(np.array_equal(idx, values) and (not len(idx) or (idx.min() >= 0 and idx.max() < len(labels))))


def _encode(cols: dict) -> tuple[dict | None, dict]:
    """A table's columns as float64 arrays and what gives them back: its rows, each column's dtype (float64,
    int64 or bool), a text column's labels (stored as their indices)."""
    data = {}
    layout = {"columns": list(cols), "rows": len(next(iter(cols.values()))) if cols else 0, "dtypes": {},
              "labels": {}}
    for c, values in cols.items():
        a = np.asarray(values)
        if a.dtype.kind in "OUS":
            labels = sorted({str(v) for v in a})
            index = {v: i for i, v in enumerate(labels)}
            data[c] = np.array([index[str(v)] for v in a], dtype=float)
            layout["labels"][c] = labels
            layout["dtypes"][c] = "text"
            continue
        if a.dtype.str not in _NUMERIC or (a.dtype.kind == "i" and np.abs(a).max(initial=0) >= 2 ** 53):
            return None, layout
        data[c] = a.astype(float)
        layout["dtypes"][c] = a.dtype.str
    return data, layout


def _decode(frame: pd.DataFrame, name: str, layout: dict) -> dict:
    out = {}
    for c in layout["columns"]:
        values, dtype = frame[f"{name}.{c}"].to_numpy(dtype=float)[:layout["rows"]], layout["dtypes"][c]
        if dtype == "text":
            out[c] = np.array([layout["labels"][c][i] for i in values.astype(np.int64)], dtype=object)
        else:
            out[c] = values.astype(np.dtype(dtype))
    return out
