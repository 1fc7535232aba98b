"""Each engine reads its own output into one in-memory record (engines/output.py), and the drivers read the record,
never a file (issue 29 item 6): the LAMMPS family's file names, log lines and dump reader are the family's alone; run.py
asks the Engine for its log files, errors, warnings and loop time."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from demcheck.engines import registry, run as runner
from demcheck.engines.output import STATE_COLUMNS, CollisionOutput, PackingOutput

ENGINES = Path(__file__).resolve().parents[1] / "src" / "demcheck" / "engines"
# what only the LAMMPS family knows: its log file, its log's lines, its dumps and their reader (a worker's screen.txt
# is engines/serve.py's, every engine's)
FAMILY_WORDS = re.compile(r"log\.txt|\bERROR\b|Loop time of|^read_dump$|^DUMP_FILE$|^DUMP_COLUMNS$|^CONTACT_DUMP$|"
                          r"^read_contact_dump$|^read_final_dump$|^thermo_ke$|^read_contacts$")
NEUTRAL = ("base.py", "run.py", "collide.py", "packing.py", "output.py", "registry.py", "builds.py", "cache.py",
           "states.py")


@pytest.mark.parametrize("name", NEUTRAL)
def test_the_neutral_engine_modules_name_none_of_the_lammps_familys_conventions(name):
    found = sorted({w for w in _code_words(ENGINES / name) if FAMILY_WORDS.search(w)})
    assert not found, f"engines/{name} names {found}: the LAMMPS family's (engines/family.py)"


def _code_words(path: Path) -> set[str]:
    """The names, attributes, imported names and string constants of a module's code (its docstrings aside)."""
    tree = ast.parse(path.read_text())
    docs = {id(n.body[0].value) for n in ast.walk(tree) if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef))
            and n.body and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            out.add(node.value)
        elif isinstance(node, ast.Name):
            out.add(node.id)
        elif isinstance(node, ast.Attribute):
            out.add(node.attr)
        elif isinstance(node, ast.alias):
            out.add(node.name.rpartition(".")[2])
    return out


def test_the_family_answers_its_log_conventions_and_the_others_their_own():
    lammps, yade, kratos = map(registry.get, ("lammps", "yade", "kratos"))
    log = "WARNING: a\nERROR: the deck is wrong (src/input.cpp:1)\nLoop time of 0.5 on 1 procs\n"
    assert lammps.log_files == ("log.txt", "screen.txt")
    assert lammps.errors(log) == ["the deck is wrong (src/input.cpp:1)"] and lammps.warnings(log) == ["a"]
    assert lammps.loop_time(log) == 0.5
    for eng in (yade, kratos):  # a Python-scripted engine: no LAMMPS log line is its error or its timing
        assert eng.log_files == () and eng.errors(log) == [] and eng.loop_time(log) is None
    py = "starting\nTraceback (most recent call last):\n  File \"in.deck\", line 3, in <module>\nNameError: x\n"
    assert yade.errors(py) == kratos.errors(py) == ["NameError: x"]
    assert yade.warnings("<WARNING> Law2.cpp:12 go: slow\n") == ["WARNING: Law2.cpp:12 go: slow"]


def test_a_failed_python_run_is_named_by_its_exception(tmp_path):
    log = "Traceback (most recent call last):\n  File \"in.deck\", line 1\nValueError: bad number\n"
    exc = runner._failed("kratos", tmp_path, log, "exit code 1", deck_error=True)
    assert exc.what == "ValueError: bad number" and not exc.fault


def test_the_log_is_read_from_the_engines_own_files(tmp_path):
    (tmp_path / "log.txt").write_text("the family's log, longer than its screen\n")
    (tmp_path / runner.SCREEN).write_text("screen\n")
    assert "family's log" in runner._read_log(tmp_path, None, "lammps")
    assert runner._read_log(tmp_path, None, "kratos") == "screen\n".strip() or \
        "family's log" not in runner._read_log(tmp_path, None, "kratos")


def _states(n_steps: int = 3) -> pd.DataFrame:
    rows = []
    for step in range(n_steps):
        for body in (1, 2):
            x = -2e-3 + 1e-3 * step if body == 1 else 2e-3 - 1e-3 * step
            rows.append({"step": step, **{c: 0.0 for c in STATE_COLUMNS}, "id": body, "type": body,
                         "radius": 1.59e-3, "mass": 4.2e-5, "x": x, "vx": 1.0 if body == 1 else -1.0})
    return pd.DataFrame(rows)


def test_collide_reads_the_engines_record_not_a_file(monkeypatch, tmp_path):
    """A collision driven through an engine whose reader hands a record it built in memory (no file in the work
    directory): collide's particles are the record's states."""
    from demcheck.api import load
    from demcheck.engines import collide

    case = load(str(Path(__file__).resolve().parents[1] / "src" / "demcheck" / "cases" / "glass-pair.toml"))
    lammps = registry.get("lammps")
    handed = CollisionOutput(_states(), "the log")
    seen = {}

    def read(workdir, log=""):
        seen["log"] = log
        return handed

    monkeypatch.setattr(lammps, "read_collision", read)
    monkeypatch.setattr(runner, "run", lambda engine, deck, **k: runner.RunOutput(engine, "v", tmp_path, "the log",
                                                                                   0.1))
    res = collide.collide(case, lammps, workdir=tmp_path)
    assert seen["log"] == "the log"
    assert np.array_equal(res.particles["x"].to_numpy(), handed.states["x"].to_numpy())
    assert list(tmp_path.iterdir()) == []  # nothing was read from disk: there is nothing there


def test_the_records_refuse_a_table_without_their_columns():
    from demcheck.errors import ParseError

    with pytest.raises(ParseError, match="tqz"):
        CollisionOutput(_states().drop(columns="tqz"))
    with pytest.raises(ParseError, match="fn"):
        PackingOutput(_states().drop(columns=["tqx", "tqy", "tqz"]), pd.DataFrame({"i": [], "j": []}))


def test_yade_writes_and_reads_its_own_state_table_not_a_lammps_dump(tmp_path):
    """Yade's collision script writes its own table (a header of the record's columns, a row per body per step), and
    Yade's reader turns it into the record with every double as written; a cut row is a ParseError."""
    from demcheck.api import load
    from demcheck.engines.yade import deck as yade_deck
    from demcheck.errors import ParseError

    case = load(str(Path(__file__).resolve().parents[1] / "src" / "demcheck" / "cases" / "oblique-lsd-wall.toml"))
    text = registry.get("yade").collision_deck(case).text
    assert "ITEM:" not in text and "dump.txt" in text
    states = _states()
    states["x"] += 0.1  # doubles with 17 significant digits
    rows = [yade_deck.ROW % tuple(r) for r in states[["step", *STATE_COLUMNS]].itertuples(index=False)]
    (tmp_path / "dump.txt").write_text(yade_deck.HEAD + "".join(rows))
    got = registry.get("yade").read_collision(tmp_path, "its log")
    assert got.log == "its log" and got.states.dtypes["id"] == np.int64
    assert np.array_equal(got.states.to_numpy(float), states[["step", *STATE_COLUMNS]].to_numpy(float))
    (tmp_path / "dump.txt").write_text(yade_deck.HEAD + "".join(rows)[:-40])
    with pytest.raises(ParseError, match="cut short"):
        registry.get("yade").read_collision(tmp_path)
