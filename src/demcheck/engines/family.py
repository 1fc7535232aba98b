"""What LAMMPS and LIGGGHTS share, and no other engine: one input language (engines/family_deck.py: its guard and
the data file), one command line (``-in DECK -log log.txt -screen screen.txt``), one log (``ERROR`` and ``WARNING``
lines, ``Loop time of`` a run's loop, a packing deck's thermo lines), one output (a ``dump custom`` of every body
every step, a ``dump local`` of the contacts, read by engines/dumps.py). Their packages subclass
:class:`LammpsFamily`, which reads that output into the records of engines/output.py; an engine of another family
answers each of these itself (engines/base.py)."""

from __future__ import annotations

import re

import numpy as np
from pathlib import Path

from .base import PackageEngine
from .output import FINAL_COLUMNS, STATE_COLUMNS, CollisionOutput, PackingOutput, touching

LOG, SCREEN = "log.txt", "screen.txt"
# the collision decks' ``dump custom`` columns: the record's (engines/output.py), named as LAMMPS names them
DUMP_COLUMNS = STATE_COLUMNS
_WARNING = re.compile(r"^WARNING:?\s*(.*)$", re.M)
_ERROR = re.compile(r"^(?:ERROR|ERROR on proc \d+):?\s*(.*)$", re.M)
_LOOP = re.compile(r"^Loop time of ([0-9.eE+-]+) on", re.M)
# a packing deck's thermo line: step, kinetic energy, atoms (inputs/packing_decks.py writes ``thermo_style custom step
# ke atoms``)
_THERMO = re.compile(r"^\s*(\d+)\s+(\S+)\s+\d+\s*$", re.M)


class LammpsFamily(PackageEngine):
    log_files = (LOG, SCREEN)

    def argv(self, executable: str, deck: str) -> list[str]:
        """The command that runs ``deck`` (a file name in the work directory) with its log files there."""
        return [executable, "-in", deck, "-log", LOG, "-screen", SCREEN]

    def check_deck(self, text: str, files: dict | None = None) -> None:
        """The LAMMPS input language's guard (engines/family_deck.check_deck): every line one demcheck writes."""
        from .family_deck import check_deck

        check_deck(text, files)

    def errors(self, log: str) -> list[str]:
        """The log's ``ERROR:`` lines (``ERROR on proc N:`` under MPI)."""
        return [e.strip() for e in _ERROR.findall(log)]

    def warnings(self, log: str) -> list[str]:
        return [w.strip() for w in _WARNING.findall(log)]

    def loop_time(self, log: str) -> float | None:
        """The sum of the log's ``Loop time of`` lines (the loop and its dump output)."""
        found = _LOOP.findall(log)
        return sum(float(x) for x in found) if found else None

    def read_collision(self, workdir: Path, log: str = "") -> CollisionOutput:
        """The collision deck's ``dump custom`` (inputs/common.py DUMP_FILE, :data:`DUMP_COLUMNS`)."""
        from ..inputs import common
        from .dumps import read_dump

        table = read_dump(Path(workdir) / common.DUMP_FILE, columns=STATE_COLUMNS)
        return CollisionOutput(table, log, self.loop_time(log))

    def read_packing(self, workdir: Path, log: str, box=None) -> PackingOutput:
        """The packing deck's final ``dump custom``, its contacts' ``dump local`` (:func:`read_contact_dump`, through
        :meth:`read_contacts`) and its thermo lines' kinetic energy."""
        from ..inputs.packing_decks import CONTACT_DUMP, FINAL_DUMP

        final = read_final_dump(Path(workdir) / FINAL_DUMP)
        contacts = read_contact_dump(self, Path(workdir) / CONTACT_DUMP, final["radius"].to_numpy(),
                                     final[["x", "y", "z"]].to_numpy(), box)
        return PackingOutput(final, contacts, thermo_ke(log), log)


def read_final_dump(path: Path):
    """The last block of a packing's final dump (FINAL_COLUMNS), sorted by id: row k is particle id k + 1 (the data
    file numbers the particles 1…N)."""
    from .dumps import read_dump

    table = read_dump(path, columns=FINAL_COLUMNS)
    return table[table["step"] == table["step"].max()].sort_values("id").reset_index(drop=True)


def thermo_ke(log: str) -> list:
    """[(step, ke)] of a packing deck's thermo lines (``step ke atoms``)."""
    return [(int(m.group(1)), float(m.group(2))) for m in _THERMO.finditer(log)]


def read_contact_dump(engine, path, radius, x=None, box=None):
    """A per-contact ``dump local`` (its last block) as engines.output.CONTACT_COLUMNS: the first two columns the
    pair's ids, the others turned into (overlap, Fn, |Ft|) by the engine's ``read_contacts``. ``radius`` (and ``x``):
    per particle, indexed by id − 1; ``box``: the periodic [lx, ly]."""
    from .dumps import read_dump

    raw = read_dump(path)
    raw = raw[raw["step"] == raw["step"].max()] if len(raw) else raw
    v = raw.drop(columns="step").to_numpy(float)
    i, j = v[:, 0].astype(np.int64) - 1, v[:, 1].astype(np.int64) - 1
    return touching(i, j, *engine.read_contacts(v, i, j, radius, x, box))
