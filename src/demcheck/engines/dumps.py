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
    with _open(path) as fh:
        parsed = _well_formed(fh.read())
    if parsed is None:  # anything unusual: the line-by-line reader, which names what is wrong and where
        return _read_dump_lines(path, columns)
    names, steps, data = parsed
    return _table(path, names, steps, data, columns)


def _well_formed(text: str):
    """(names, steps, blocks) of a dump whose every block is well formed, its numbers parsed all at once (numpy
    converts them as float() does: the line-by-line reader's values, bit for bit, at a fraction of its cost — it
    took 60 % of an engine collision through a worker); None where anything is not as expected, or not as the
    engines write it (one space between values, and perhaps one after the last)."""
    lines = text.split("\n")
    end = len(lines)
    while end and not lines[end - 1].strip():
        end -= 1
    blocks = _same_size_blocks(lines, end)
    if blocks is not None:
        names, counts, rows = blocks
    else:
        names, counts, rows = _walk(lines, end)
    if names is None:
        return None
    spaces = len(names) - 1
    joined = "\n".join(rows)
    if "  " in joined or "\n " in joined or joined.startswith(" ") or \
            any(r.count(" ") != spaces + r.endswith(" ") for r in rows):
        return None
    try:
        data = np.array(joined.split(), dtype=np.float64).reshape(len(rows), len(names))
    except ValueError:
        return None
    steps, sizes = zip(*counts)
    return names, [np.repeat(np.array(steps, dtype=np.int64), sizes)], [data]


def _same_size_blocks(lines: list[str], end: int):
    """(names, [(step, rows)], rows) of a dump whose blocks all have the first block's number of rows and the
    same header lines (a collision's dumps: the two bodies every step), checked a header line at a time across
    all blocks; None otherwise (the block-by-block walk then reads it)."""
    try:
        natoms = int(lines[3].split()[0])
    except (ValueError, IndexError):
        return None
    size = 9 + natoms
    if natoms <= 0 or end % size or end < size:
        return None
    item = lines[8]
    if not lines[0].startswith("ITEM: TIMESTEP") or not lines[2].startswith("ITEM: NUMBER OF ATOMS") \
            or not lines[4].startswith("ITEM: BOX BOUNDS") or not item.startswith("ITEM: ATOMS"):
        return None
    for k in (0, 2, 3, 4, 8):
        if lines[k:end:size].count(lines[k]) != end // size:
            return None
    try:
        steps = [int(x) for x in lines[1:end:size]]
    except ValueError:
        return None
    rows = [r for block in zip(*(lines[k:end:size] for k in range(9, size))) for r in block]
    return tuple(item.split()[2:]), [(s, natoms) for s in steps], rows


def _walk(lines: list[str], end: int):
    """(names, [(step, rows)], rows) block by block; names None where a block is not as expected."""
    i, names, counts, rows = 0, None, [], []
    while i < end:
        if not lines[i].startswith("ITEM: TIMESTEP") or i + 9 > end:
            return None, [], []
        head = lines[i + 2]
        item = "ENTRIES" if head.startswith("ITEM: NUMBER OF ENTRIES") else "ATOMS"
        if not head.startswith(f"ITEM: NUMBER OF {item}") or not lines[i + 4].startswith("ITEM: BOX BOUNDS") \
                or not lines[i + 8].startswith(f"ITEM: {item}"):
            return None, [], []
        try:
            step, natoms = int(lines[i + 1].split()[0]), int(lines[i + 3].split()[0])
        except (ValueError, IndexError):
            return None, [], []
        cols = tuple(lines[i + 8].split()[2:])
        names = names or cols
        if cols != names or natoms < 0 or i + 9 + natoms > end:
            return None, [], []
        rows += lines[i + 9:i + 9 + natoms]
        counts.append((step, natoms))
        i += 9 + natoms
        while i < end and not lines[i].strip():
            i += 1
    return names, counts, rows


def _table(path: Path, names, steps, blocks, columns) -> pd.DataFrame:
    if names is None:
        raise ParseError(f"{path}: empty dump (no ITEM: TIMESTEP block)")
    missing = [c for c in (columns or ()) if c not in names]
    if missing:
        raise ParseError(f"{path}: missing column(s) {', '.join(missing)} (has {' '.join(names)})")
    table = pd.DataFrame(np.concatenate(blocks) if blocks else np.empty((0, len(names))), columns=list(names))
    for c in ("id", "type"):
        if c in table:
            table[c] = table[c].astype(np.int64)
    table.insert(0, "step", np.concatenate(steps) if steps else np.empty(0, dtype=np.int64))
    return table


def _read_dump_lines(path: Path, columns) -> pd.DataFrame:
    """read_dump line by line, with a ParseError naming the line of whatever is malformed."""
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
    return _table(path, names, steps, blocks, columns)


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
