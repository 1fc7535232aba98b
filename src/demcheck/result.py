"""Result: what any source (the reference, an engine, an engine's twin) returns for a case.

A Result holds its series as numpy arrays — one 1-D float64 array per column, all of one length (a
``dict``: :func:`table`) — and the metrics are computed on them. The pandas tables are built from the
arrays on first access and kept: ``result.contact``, ``result.particles`` and ``result.events`` read as
DataFrames for the callers that want one (reports, plots, CSV), and :meth:`Result.to_frame` gives a copy.
A source may also hand a DataFrame in (the engines' dumps are read as tables); its arrays are then read off it.
The frame built from arrays is a copy: to change a Result's series assign a new table (``result.contact =
…``), which also drops its memoised metrics.

The tables, in SI units:

* ``contact``: one row per output time of the contact of interest:
  t, delta (overlap, > 0 in contact), delta_dot (approach rate of the contact points along the normal),
  fn (normal force on the pair, + repulsive); 3-D runs add tangential columns.
* ``particles``: t, id, x, y, z, vx, vy, vz, wx, wy, wz (and fx.. when the source has them).
* ``events``: exact event points of the adaptive method (t, event, delta, delta_dot, fn), else empty.

``status`` (with the reason in ``message``; only "ok" is trusted):

* ``ok``;
* ``failed``: NaN or infinite values in the state or in an engine's output (never cached);
* ``unresolved``: the time step does not resolve the contact (too few steps inside it); the message names
  dt and the steps per elastic contact time;
* ``unstable``: a time-stepped run created energy (the scheme is unstable at its step);
* ``out-of-range``: the overlap passed half the smaller radius, in any method: the contact law left its
  range of small overlaps (too fast an impact, too soft a material);
* ``no-contact``: the bodies never touched; ``no-separation``: the contact did not end within the run;
* ``tolerance``: the adaptive method could not meet its tolerance; ``too-many-steps``: the solver ran out
  of room for output points.

The rules are reference/health.py's, the same for the reference's verlet method and every engine.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

TABLES = ("contact", "particles", "events")


def frame_of(columns: dict):
    """A DataFrame of a table of arrays, in its column order. The float64 columns go into one block (one
    2-D array: no consolidation pass), the others (ids, flags, event names) are inserted at their places."""
    names = list(columns)
    floats = [k for k in names if isinstance(columns[k], np.ndarray) and columns[k].dtype == np.float64]
    if len(floats) == len(names):
        block = np.column_stack([columns[k] for k in names]) if names else np.empty((0, 0))
        return pd.DataFrame(block, columns=names, copy=False)
    if not floats:
        return pd.DataFrame(columns)
    frame = pd.DataFrame(np.column_stack([columns[k] for k in floats]), columns=floats, copy=False)
    for i, k in enumerate(names):
        if k not in frame:
            frame.insert(i, k, columns[k])
    return frame


def columns_of(frame) -> dict:
    """The arrays of a DataFrame's columns (views where pandas allows)."""
    return {k: frame[k].to_numpy() for k in frame.columns}


class _Table:
    """A Result's table slot: stores what a source gives (a dict of arrays, a DataFrame, or None); reads as a
    DataFrame, built from the arrays once."""

    def __init__(self, name: str):
        self.name = name
        self.store, self.frame = f"_{name}_table", f"_{name}_frame"

    def __get__(self, obj, owner=None):
        if obj is None:
            return None  # the dataclass default (None) of particles and events
        d = obj.__dict__
        value = d.get(self.store)
        if isinstance(value, dict):
            frame = d.get(self.frame)
            if frame is None:
                frame = d[self.frame] = frame_of(value)
            return frame
        return value

    def __set__(self, obj, value):
        obj.__dict__[self.store] = value
        obj.__dict__.pop(self.frame, None)


@dataclass
class Result:
    source: str  # reference | lammps | liggghts
    method: str  # adaptive | verlet | engine
    case_name: str
    case_hash: str
    model: dict
    params: dict
    contact: Any  # a dict of arrays or a DataFrame; reads as a DataFrame
    particles: Any = None
    events: Any = None
    dt: float | None = None
    rtol: float | None = None
    wall_time: float = 0.0
    engine_version: str | None = None
    status: str = "ok"  # see the module docstring
    message: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def table(self, name: str = "contact") -> dict | None:
        """A table's columns as numpy arrays ({column: 1-D array}, in the table's order), None when the source
        has none. Read-only: assign a new table to change it."""
        if name not in TABLES:
            raise KeyError(name)
        value = self.__dict__.get(f"_{name}_table")
        if value is None or isinstance(value, dict):
            return value
        memo = self.__dict__.get(f"_{name}_columns")
        if memo is None or memo[0] is not value:
            memo = self.__dict__[f"_{name}_columns"] = (value, columns_of(value))
        return memo[1]

    def to_frame(self, name: str = "contact"):
        """A table as a pandas DataFrame of its own (a copy)."""
        frame = getattr(self, name)
        return None if frame is None else frame.copy()

    def metrics(self) -> dict:
        """The metrics (computed once per contact table: a pure function of it)."""
        from .metrics import compute

        d = self.__dict__
        contact, events = d.get("_contact_table"), d.get("_events_table")
        memo = d.get("_metrics_memo")
        if memo is None or memo[0] is not contact or memo[1] is not events:
            memo = (contact, events, compute(self))
            d["_metrics_memo"] = memo
        return dict(memo[2])

    def summary(self) -> dict:
        """JSON-ready: metrics under their DESIGN names, the model, the resolved parameters, method, dt."""
        return {
            "source": self.source,
            "method": self.method,
            "case": self.case_name,
            "case_hash": self.case_hash,
            "model": self.model,
            "params": self.params,
            "dt": self.dt,
            "rtol": self.rtol,
            "engine_version": self.engine_version,
            "status": self.status,
            "message": self.message,
            "wall_time": self.wall_time,
            "metrics": self.metrics(),
            "final": self.final_state(),
        }

    def final_state(self) -> list[dict]:
        """Every body's velocity and angular velocity (vectors, SI) at the end of the run, whatever solved it
        (a law that was skipped — no tangential force can act — passes the initial spins through)."""
        p = self.table("particles")
        if p is None or not {"t", "id", "vx", "wx"} <= set(p) or not len(p["t"]):
            return []
        t, ids = p["t"], p["id"]
        out = []
        for pid in np.unique(ids):
            rows = np.flatnonzero(ids == pid)
            last = rows[np.argsort(t[rows], kind="stable")[-1]]  # the latest row (the last of equal times)
            out.append({"id": int(pid), "t": float(t[last]),
                        "velocity": [float(p[c][last]) for c in ("vx", "vy", "vz")],
                        "angular_velocity": [float(p[c][last]) for c in ("wx", "wy", "wz")]})
        return out

    def __getstate__(self):
        """Pickled without the frames built from arrays (they are rebuilt on access)."""
        return {k: v for k, v in self.__dict__.items() if not k.endswith(("_frame", "_columns"))}

    def __setstate__(self, state):
        self.__dict__.update(state)


for _name in TABLES:
    setattr(Result, _name, _Table(_name))
del _name
