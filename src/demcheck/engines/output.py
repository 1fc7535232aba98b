"""What an engine's run hands back, in memory: one typed record per scenario, whatever the engine wrote to disk.

Each engine reads its own output into these (``Engine.read_collision``, ``Engine.read_packing``): the LAMMPS family
its ``dump custom`` and thermo lines (engines/family.py), Yade and Kratos the tables their scripts write. The
collision and packing drivers (engines/collide.py, engines/packing.py) read the records, never a file: no engine's
file format is anyone else's contract. The column names are the records', every value as the engine computed it
(float64; ``step``, ``id``, ``type`` int64)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

# a packing's settled particle (the state without the torque) and the contact table every source yields (particle
# indices, 0-based, overlap, normal force repulsive > 0, |Ft|), defined where the comparisons read them
from ..inputs.packing_decks import CONTACT_COLUMNS, FINAL_COLUMNS

# a body's state at one step: id (1-based), type, radius, mass, position, velocity, angular velocity, force (the
# weight included, as the engines integrate it) and torque
STATE_COLUMNS = ("id", "type", "radius", "mass", "x", "y", "z", "vx", "vy", "vz", "omegax", "omegay", "omegaz",
                 "fx", "fy", "fz", "tqx", "tqy", "tqz")


def _require(table: pd.DataFrame, columns, what: str) -> None:
    from ..errors import ParseError

    missing = [c for c in columns if c not in table]
    if missing:
        raise ParseError(f"{what} lacks the column(s) {', '.join(missing)} (has {' '.join(map(str, table.columns))})")


@dataclass
class CollisionOutput:
    """A collision run: ``states`` one row per body per step (``step`` then STATE_COLUMNS), the run's ``log`` (its
    text as the engine wrote it) and ``loop_time`` (s of the engine's own stepping loop where it says; None)."""

    states: pd.DataFrame
    log: str = ""
    loop_time: float | None = None

    def __post_init__(self):
        _require(self.states, ("step",) + STATE_COLUMNS, "a collision run's states")
        self.states = self.states[["step", *STATE_COLUMNS]]


@dataclass
class PackingOutput:
    """A packing run: ``final`` its settled particles (FINAL_COLUMNS, sorted by id: row k is particle id k + 1),
    ``contacts`` its particle-particle contacts (CONTACT_COLUMNS, :func:`touching`), ``ke`` the kinetic energy
    series [(step, ke)] and the run's ``log``."""

    final: pd.DataFrame
    contacts: pd.DataFrame
    ke: list = field(default_factory=list)
    log: str = ""

    def __post_init__(self):
        _require(self.final, FINAL_COLUMNS, "a packing run's final state")
        _require(self.contacts, CONTACT_COLUMNS, "a packing run's contacts")


# a state table (Yade's collision script, Kratos' runner): a header line of the record's column names, then a row per body
# per step: step, id and type as integers, the rest float64 as %.17g (the shortest text that reads back exactly)
STATE_HEAD = "step " + " ".join(STATE_COLUMNS) + "\n"
STATE_ROW = "%d %d %d" + " %.17g" * (len(STATE_COLUMNS) - 2) + "\n"


def read_state_table(path, writer: str) -> pd.DataFrame:
    """A state table (:data:`STATE_HEAD`, then :data:`STATE_ROW` rows) with the record's columns: ``step``, ``id`` and
    ``type`` as integers; ``writer`` names the script that wrote it in the errors."""
    from pathlib import Path

    from ..errors import ParseError

    path = Path(path)
    if not path.exists():
        raise ParseError(f"{path}: no such state table ({writer} wrote none)")
    head, _, body = path.read_text().partition("\n")
    names = head.split()
    if names != ["step", *STATE_COLUMNS]:
        raise ParseError(f"{path}:1: not {writer}'s header ({head[:80]!r})")
    try:
        values = np.array(body.split(), dtype=np.float64)
    except ValueError:
        raise ParseError(f"{path}: a value that is not a number") from None
    if values.size % len(names):
        raise ParseError(f"{path}: its last row is cut short ({values.size % len(names)} of {len(names)} values)")
    table = pd.DataFrame(values.reshape(-1, len(names)), columns=names)
    return table.astype({"step": np.int64, "id": np.int64, "type": np.int64})


def touching(i, j, overlap, fn, ft) -> pd.DataFrame:
    """An engine's per-contact output (0-based particle indices, overlap, Fn repulsive > 0, |Ft|, one entry per
    listed pair) as CONTACT_COLUMNS: touching pairs only (overlap > 0), each once (with newton off a pair across a
    periodic or processor boundary may be listed from both sides), sorted."""
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    out = pd.DataFrame({"i": np.minimum(i, j), "j": np.maximum(i, j), "overlap": overlap, "fn": fn, "ft": ft})
    out = out[out["overlap"] > 0].drop_duplicates(subset=["i", "j"]).sort_values(["i", "j"])
    return out.reset_index(drop=True)
