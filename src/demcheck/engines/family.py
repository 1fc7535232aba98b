"""What LAMMPS and LIGGGHTS share, and no other engine: one input language (inputs/common.py writes it and its guard
checks it), one command line (``-in DECK -log log.txt -screen screen.txt``), one collision output (a ``dump
custom`` of every body every step, read by engines/dumps.py). Their packages subclass :class:`LammpsFamily`; an
engine of another family implements these three methods itself (engines/base.py)."""

from __future__ import annotations

import re
from pathlib import Path

from .base import PackageEngine


class LammpsFamily(PackageEngine):
    def argv(self, executable: str, deck: str) -> list[str]:
        """The command that runs ``deck`` (a file name in the work directory) with its log files there."""
        return [executable, "-in", deck, "-log", "log.txt", "-screen", "screen.txt"]

    def check_deck(self, text: str, files: dict | None = None) -> None:
        """The LAMMPS input language's guard (inputs.common.check_deck): every line one demcheck writes."""
        from ..inputs.common import check_deck

        check_deck(text, files)

    def read_collision(self, workdir: Path):
        """The collision deck's ``dump custom`` (inputs/common.py DUMP_FILE, DUMP_COLUMNS)."""
        return read_state_dump(workdir)

    def read_packing(self, workdir: Path, log: str):
        """The packing deck's final ``dump custom`` and its thermo lines' kinetic energy
        (:func:`read_packing_output`)."""
        return read_packing_output(workdir, log)


def read_state_dump(workdir: Path):
    """A collision run's bodies, step by step, from the LAMMPS-style dump the family's decks write (and Yade's and
    Kratos's collision scripts write in the same columns)."""
    from ..inputs import common
    from .dumps import read_dump

    return read_dump(Path(workdir) / common.DUMP_FILE, columns=common.DUMP_COLUMNS)


# a packing deck's thermo line: step, kinetic energy, atoms (inputs/packing_decks.py writes ``thermo_style custom step
# ke atoms``; Yade's packing script prints the same columns)
_THERMO = re.compile(r"^\s*(\d+)\s+(\S+)\s+\d+\s*$", re.M)


def read_packing_output(workdir: Path, log: str):
    """(final table, kinetic energy series) of a packing run: the last block of the final dump
    (inputs/packing_decks.py FINAL_DUMP, FINAL_COLUMNS; row k is particle id k + 1) and [(step, ke)] from the
    thermo lines of ``log``."""
    from ..inputs.packing_decks import FINAL_COLUMNS, FINAL_DUMP
    from .dumps import read_dump

    table = read_dump(Path(workdir) / FINAL_DUMP, columns=FINAL_COLUMNS)
    table = table[table["step"] == table["step"].max()].sort_values("id").reset_index(drop=True)
    return table, [(int(m.group(1)), float(m.group(2))) for m in _THERMO.finditer(log)]
