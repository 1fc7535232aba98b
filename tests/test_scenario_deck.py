"""``demcheck deck CASE --engine E`` of a scenario case beyond sliding writes the deck verify runs for it
(engines/scenario.deck; comparisons/scenario_rows.py runs engines/scenario.run): for every suite case an engine
expresses, the engine run for real through the suite's rows and the deck it was given recorded."""

from __future__ import annotations

import pytest

from demcheck.case import load
from demcheck.engines import scenario
from demcheck.resources import case_path

from .helpers import cli_main, record_engine_runs


NAMES = ("rolling", "rolling-linear", "incline", "incline-linear", "twist", "pull-off", "adhesive-impact",
         "conduction")


def _suite_rows(case, engine):
    from demcheck.comparisons.records import CaseResult
    from demcheck.comparisons.scenario_rows import engine_rows
    from demcheck.comparisons.sources import ADAPTIVE
    from demcheck.comparisons.suite import Options, discover
    from demcheck.laws.model import resolve

    opts = Options(engines=(engine,))
    entry = CaseResult(case.name, model=resolve(case).describe(), scales={})
    engine_rows(case, entry, opts, discover(opts.engines), ADAPTIVE.run(case).metrics())
    return entry.to_json()


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ("lammps", "liggghts")])
def test_the_deck_written_is_the_deck_verify_ran(engine, tmp_path, capsys, monkeypatch):
    ran = record_engine_runs(monkeypatch)
    expressed = 0
    for name in NAMES:
        path = case_path(f"suite/beyond-{name}.toml")
        case = load(path)
        if scenario.mapping(case, engine).native is None:
            code, _, err = cli_main(["deck", str(path), "--engine", engine], capsys)
            assert code != 0 and "cannot express" in err, (name, err)
            continue
        out_dir = tmp_path / name
        code, _, err = cli_main(["deck", str(path), "--engine", engine, "-o", str(out_dir / "in.deck")], capsys)
        assert code == 0, err
        written = (out_dir / "in.deck").read_text()
        beside = {f.name: f.read_text() for f in out_dir.iterdir() if f.name != "in.deck"}
        ran.clear()
        entry = _suite_rows(case, engine)
        assert entry["sources"][engine]["status"] == "ok", (name, entry["sources"][engine])
        assert len(ran) == 1 and ran[0] == (written, beside), name
        code, out, _ = cli_main(["deck", str(path), "--engine", engine], capsys)  # stdout: the same deck
        assert code == 0 and out.startswith(written)
        expressed += 1
    assert expressed >= (8 if engine == "lammps" else 3)


def test_a_scenario_deck_takes_no_dt(capsys):
    code, _, err = cli_main(["deck", str(case_path("suite/beyond-twist.toml")), "--engine", "lammps", "--dt", "1e-6"],
                         capsys)
    assert code == 2 and err.count("\n") == 1 and "--dt" in err and "layout" in err
