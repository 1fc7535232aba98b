"""Issue 33 item 4: an engine's dump is parsed all at once (dumps._well_formed) where it is as the engines write
it, with the values of the line-by-line reader bit for bit; anything else goes through the line-by-line reader,
which names what is wrong and where (tests/test_dumps_and_runs.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from demcheck.engines import dumps

DATA = Path(__file__).parent / "data" / "dumps"

# a LAMMPS dump custom (no space after the last value) and a LIGGGHTS one (a space after it), as the decks write them
LAMMPS = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS pp pp ff
-4.7699999999999999e-03 4.7699999999999999e-03
-4.7699999999999999e-03 4.7699999999999999e-03
-4.7699999999999999e-03 6.4128458228438264e-03
ITEM: ATOMS id type x vx fx
1 1 0.0016314124087049404 0.99999950181851294 -1.2345678901234567e-05
2 1 -0.0015899999523162842 0.49999999999999994 nan
ITEM: TIMESTEP
10
ITEM: NUMBER OF ATOMS
1
ITEM: BOX BOUNDS pp pp ff
0 1
0 1
0 1
ITEM: ATOMS id type x vx fx
1 1 1e-300 -inf 4.9406564584124654e-324
"""
# every block the same size (a collision's dumps: the same bodies every step), read a header line at a time
SAME_SIZE = LAMMPS.replace("ITEM: NUMBER OF ATOMS\n1\n", "ITEM: NUMBER OF ATOMS\n2\n").replace(
    "4.9406564584124654e-324\n", "4.9406564584124654e-324\n2 1 0.5 0.25 -0\n")
LIGGGHTS = "\n".join(line + " " if line[:1].isdigit() and line.count(" ") == 4 else line
                     for line in LAMMPS.split("\n"))


def _bits(t):
    return {c: (t[c].dtype, t[c].to_numpy().view(np.int64).tolist()) for c in t.columns}


@pytest.mark.parametrize("text,steps", [(LAMMPS, [0, 0, 10]), (LIGGGHTS, [0, 0, 10]), (SAME_SIZE, [0, 0, 10, 10])],
                         ids=["lammps", "liggghts", "same-size"])
def test_an_engine_dump_is_read_at_once_with_the_line_readers_values(tmp_path, text, steps, monkeypatch):
    path = tmp_path / "dump.txt"
    path.write_text(text)
    slow = dumps._read_dump_lines(path, None)
    assert (dumps._same_size_blocks(text.split("\n"), len(text.rstrip("\n").split("\n"))) is not None) == \
        (text is SAME_SIZE)
    monkeypatch.setattr(dumps, "_read_dump_lines", lambda *a: pytest.fail("read line by line"))
    fast = dumps.read_dump(path)
    assert list(fast.columns) == list(slow.columns) == ["step", "id", "type", "x", "vx", "fx"]
    assert _bits(fast) == _bits(slow)
    assert fast["step"].tolist() == steps


@pytest.mark.parametrize("name", ["two_blocks.txt", "variable_rows.txt"])
def test_the_fixtures_read_the_same_either_way(name):
    assert _bits(dumps.read_dump(DATA / name)) == _bits(dumps._read_dump_lines(DATA / name, None))


@pytest.mark.parametrize("change", [
    lambda s: s.replace("1 1 1e-300", "1 1  1e-300"),  # two spaces
    lambda s: s.replace(" -inf 4.94", " -inf"),  # a short row
    lambda s: s.replace("-inf", "x"),  # not a number
    lambda s: s.replace("ITEM: BOX BOUNDS pp pp ff\n-4.7", "ITEM: BOX BOUND\n-4.7"),  # a header
])
@pytest.mark.parametrize("text", [LAMMPS, SAME_SIZE], ids=["blocks", "same-size"])
def test_anything_unusual_goes_to_the_line_reader(tmp_path, change, text):
    changed = change(text)
    assert changed != text
    assert dumps._well_formed(changed) is None
