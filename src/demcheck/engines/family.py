"""What LAMMPS and LIGGGHTS share, and no other engine: one input language (inputs/common.py writes it and its guard
checks it), one command line (``-in DECK -log log.txt -screen screen.txt``), one collision output (a ``dump
custom`` of every body every step, read by engines/dumps.py). Their packages subclass :class:`LammpsFamily`; an
engine of another family implements these three methods itself (engines/base.py)."""

from __future__ import annotations

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


def read_state_dump(workdir: Path):
    """A collision run's bodies, step by step, from the LAMMPS-style dump the family's decks write (and Yade's and
    Kratos's collision scripts write in the same columns)."""
    from ..inputs import common
    from .dumps import read_dump

    return read_dump(Path(workdir) / common.DUMP_FILE, columns=common.DUMP_COLUMNS)
