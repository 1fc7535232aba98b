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


INPUTS = ENGINES.parent / "inputs"
# the LAMMPS input language's pieces (engines/family_deck.py): its guard, its command and style lists, its data file
FAMILY_DECK = frozenset({"check_deck", "check_data", "COMMANDS", "STYLES", "FILE_ARGUMENT", "SAFE_FILE", "DATA_WORDS",
                         "data_file", "batch_layout", "offset"})
# commands of the LAMMPS input language that the family's decks write (and no other engine's script has)
LAMMPS_COMMANDS = frozenset({"units", "atom_style", "atom_modify", "create_box", "read_data", "pair_style", "pair_coeff",
                             "neigh_modify", "fix", "compute", "dump", "dump_modify", "write_dump", "timestep",
                             "thermo_style"})


@pytest.mark.parametrize("name", ("common.py", "packing_decks.py"))
def test_inputs_holds_what_every_engine_uses_and_no_lammps_command(name):
    """inputs/ (below engines/ in the layers) holds what every engine's deck writer uses: no piece of the LAMMPS
    family's language, no command of it (inputs/script.py, the reader of a user's LAMMPS-family deck, aside)."""
    tree = ast.parse((INPUTS / name).read_text())
    defined = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    defined |= {t.id for n in tree.body if isinstance(n, (ast.Assign, ast.AnnAssign))
                for t in (n.targets if isinstance(n, ast.Assign) else [n.target]) if isinstance(t, ast.Name)}
    assert not defined & FAMILY_DECK, f"inputs/{name} defines {sorted(defined & FAMILY_DECK)}: engines/family_deck.py's"
    strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    assert not strings & LAMMPS_COMMANDS, f"inputs/{name} names the LAMMPS commands {sorted(strings & LAMMPS_COMMANDS)}"


def test_a_deck_has_no_default_guard():
    """Deck.check is each engine's own: a deck without it is refused, not checked as a LAMMPS deck."""
    import dataclasses

    from demcheck.inputs.common import Deck

    check = next(f for f in dataclasses.fields(Deck) if f.name == "check")
    assert check.default is dataclasses.MISSING and check.default_factory is dataclasses.MISSING
    with pytest.raises(TypeError):
        Deck("lammps", "units si\n", {})


def test_the_familys_writers_pass_the_familys_guard():
    """Each deck the LAMMPS family writes (collision, batch, scenario, packing) carries engines/family_deck's guard."""
    from demcheck.api import load
    from demcheck.engines import family_deck as FD, scenario

    root = Path(__file__).resolve().parents[1] / "cases"
    pair, packing = load(str(root / "glass-pair.toml")), load(str(root / "packing" / "poured.toml"))
    beyond = load(str(root / "suite" / "beyond-conduction.toml"))
    for name in ("lammps", "liggghts"):
        eng = registry.get(name)
        decks = [eng.collision_deck(pair), eng.collision_deck(pair, copies=2), eng.packing_deck(packing),
                 scenario.deck(beyond, eng)]
        assert all(dk.check is FD.check_deck for dk in decks), name
    assert LAMMPS_COMMANDS <= FD.COMMANDS  # the static check above names commands the family's guard admits


def test_kratos_writes_and_reads_its_own_state_table(tmp_path):
    """Kratos' runner writes the record's state table (engines/output.py: a header, a row per body per step, %.17g),
    not the LAMMPS dump layout, and its collisions and scenarios read it through kratos/deck.read_states."""
    for name in ("kratos/deck.py", "kratos/scenario.py"):
        found = sorted({w[:40] for w in _code_words(ENGINES / name) if re.search(r"^read_dump$|ITEM: ", w)})
        assert not found, f"engines/{name} names {found}: the LAMMPS family's dump layout and its reader"
    from demcheck.engines.kratos import deck as KD
    from demcheck.engines.output import STATE_HEAD, STATE_ROW

    assert repr(STATE_HEAD) in KD.TEMPLATE and repr(STATE_ROW) in KD.TEMPLATE
    states = _states()
    rows = [STATE_ROW % (r.step, r.id, r.type, *(getattr(r, c) for c in STATE_COLUMNS[2:])) for r in
            states.itertuples()]
    (tmp_path / "dump.txt").write_text(STATE_HEAD + "".join(rows))
    got = registry.get("kratos").read_collision(tmp_path).states
    assert np.array_equal(got.to_numpy(), states[["step", *STATE_COLUMNS]].to_numpy())
    assert got["id"].dtype == np.int64
