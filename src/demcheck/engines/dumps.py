"""Reading the engines' text dumps.

Both engines write LAMMPS's ``dump custom`` format: blocks of ``ITEM: TIMESTEP``, ``ITEM: NUMBER OF
ATOMS``, ``ITEM: BOX BOUNDS``, ``ITEM: ATOMS <columns>``, then one row per atom — or ``dump local``'s, the
same with ``ENTRIES`` for ``ATOMS`` and one row per entry (a contact). The column names come
from the block's own header, so decks may order or extend them freely, and the number of rows may change
from block to block.

:func:`read_dump` is demcheck's float64 parser. Two-body comparisons need it: positions are ~10³ times the
overlap, so the float32 coordinates of a general-purpose reader keep only ~4 digits of δ. For packings,
where positions matter to ~1e-7 of the box and a trajectory toolkit is worth having,
:func:`demcheck.engines.packing.universe` reads a dump through MDAnalysis's LAMMPS ``DumpReader`` instead
(float32, in the engines' frame, with radii and masses; docs/packing.md has the measured precision).

Files may be gzip-compressed (``.gz``). A malformed file raises :class:`ParseError` naming the file, the
line and what was expected.
"""

from __future__ import annotations

import gzip
import io
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import ParseError


def _open(path: Path):
    if path.suffix == ".gz":
        return io.TextIOWrapper(gzip.open(path, "rb"), encoding="ascii", errors="replace")
    return open(path, encoding="ascii", errors="replace")


def read_dump(path, columns: tuple[str, ...] | None = None) -> pd.DataFrame:
    """All blocks of a dump as one float64 table with a ``step`` column (the engine's timestep) and the
    dump's own columns (``id`` and ``type`` as integers). ``columns``: ones that must be present."""
    path = Path(path)
    if not path.exists():
        raise ParseError(f"{path}: no such dump file")
    steps, blocks, names = [], [], None
    with _open(path) as fh:
        lines = iter(enumerate(fh, start=1))

        def expect(prefix: str) -> tuple[int, str]:
            try:
                no, line = next(lines)
            except StopIteration:
                raise ParseError(f"{path}: ended early; expected '{prefix}'") from None
            if not line.startswith(prefix):
                raise ParseError(f"{path}:{no}: expected '{prefix}', found {line.strip()[:60]!r}")
            return no, line

        def value_line(what: str) -> tuple[int, str]:
            try:
                return next(lines)
            except StopIteration:
                raise ParseError(f"{path}: ended early inside a block; expected {what}") from None

        while True:
            try:
                no, line = next(lines)
            except StopIteration:
                break
            if not line.strip():
                continue
            if not line.startswith("ITEM: TIMESTEP"):
                raise ParseError(f"{path}:{no}: expected 'ITEM: TIMESTEP', found {line.strip()[:60]!r}")
            no, line = value_line("a timestep")
            try:
                step = int(line.split()[0])
            except (ValueError, IndexError):
                raise ParseError(f"{path}:{no}: timestep is not an integer: {line.strip()[:60]!r}") from None
            no, line = value_line("'ITEM: NUMBER OF ATOMS'")
            if not line.startswith(("ITEM: NUMBER OF ATOMS", "ITEM: NUMBER OF ENTRIES")):
                raise ParseError(f"{path}:{no}: expected 'ITEM: NUMBER OF ATOMS' (or ENTRIES, a dump local), "
                                 f"found {line.strip()[:60]!r}")
            item = "ENTRIES" if "ENTRIES" in line else "ATOMS"  # dump local: one row per entry (contact)
            no, line = value_line("a number of rows")
            try:
                natoms = int(line.split()[0])
            except (ValueError, IndexError):
                raise ParseError(f"{path}:{no}: number of atoms is not an integer: {line.strip()[:60]!r}") from None
            no, line = expect("ITEM: BOX BOUNDS")
            for _ in range(3):
                value_line("box bounds")
            no, line = expect(f"ITEM: {item}")
            cols = tuple(line.split()[2:])
            if names is None:
                names = cols
            elif cols != names:
                raise ParseError(f"{path}:{no}: columns changed from {' '.join(names)} to {' '.join(cols)}")
            rows = []
            for _ in range(natoms):
                no, line = value_line(f"{natoms} {'atom' if item == 'ATOMS' else 'entry'} rows")
                parts = line.split()
                if len(parts) != len(cols):
                    raise ParseError(f"{path}:{no}: {len(parts)} values for {len(cols)} columns")
                try:
                    rows.append([float(x) for x in parts])
                except ValueError:
                    raise ParseError(f"{path}:{no}: not a number in {line.strip()[:60]!r}") from None
            steps.append(np.full(natoms, step, dtype=np.int64))
            blocks.append(np.array(rows, dtype=np.float64).reshape(natoms, len(cols)))
    if names is None:
        raise ParseError(f"{path}: empty dump (no ITEM: TIMESTEP block)")
    missing = [c for c in (columns or ()) if c not in names]
    if missing:
        raise ParseError(f"{path}: missing column(s) {', '.join(missing)} (has {' '.join(names)})")
    table = pd.DataFrame(np.concatenate(blocks) if blocks else np.empty((0, len(names))), columns=list(names))
    for c in ("id", "type"):
        if c in table:
            table[c] = table[c].astype(np.int64)
    table.insert(0, "step", np.concatenate(steps))
    return table


def non_finite(table: pd.DataFrame) -> str:
    """Where a dump first holds NaN or infinite values ("first at step 12, column vx"), or "" (a table without
    steps, such as a contact list, is named by row)."""
    data = table.to_numpy(dtype=float)
    bad = ~np.isfinite(data)
    if not bad.any():
        return ""
    row, col = np.argwhere(bad)[0]
    where = f"step {int(table['step'].iloc[row])}" if "step" in table else f"row {int(row)}"
    return f"first at {where}, column {table.columns[col]}"
