"""``demcheck deck CASE --engine E`` writes the deck that ``demcheck collide CASE --engine E`` runs: a case's
``[engine.NAME]`` native setting (not the engine's mapping of the seed model) at the native law's own step — for
every engine that takes native settings, with the engine run for real and the deck it was given recorded."""

from __future__ import annotations

import json

import pytest

from demcheck.engines import registry

from .conftest import CASES
from .helpers import cli_main, record_engine_runs
from .test_native import TSUJI, _case, to_toml


NATIVE = {  # per engine that takes native settings: its table, and a word of it the deck must hold
    "lammps": ({"pair_coeff": TSUJI}, "damping tsuji"),
    "liggghts": ({"pair_style": "gran model hertz tangential history limitForce on"}, "limitForce on"),
}


def test_every_engine_that_takes_native_settings_is_covered():
    """An engine whose package reads [engine.NAME] tables overrides native_from_case: each is tested below."""
    from demcheck.engines.base import Engine

    takes = {name for name in registry.names()
             if type(registry.get(name)).native_from_case is not Engine.native_from_case}
    assert takes == set(NATIVE)


@pytest.mark.parametrize("dt", [None, "2e-8"])
@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in NATIVE])
def test_the_deck_written_is_the_deck_collide_ran(engine, dt, tmp_path, capsys, monkeypatch):
    table, word = NATIVE[engine]
    path = tmp_path / "native.toml"
    path.write_text(to_toml(_case({engine: table})))
    extra = ["--dt", dt] if dt else []
    out_dir = tmp_path / "deck"
    code, _, err = cli_main(["deck", str(path), "--engine", engine, "-o", str(out_dir / "in.deck"), *extra], capsys)
    assert code == 0, err
    written = (out_dir / "in.deck").read_text()
    beside = {f.name: f.read_text() for f in out_dir.iterdir() if f.name != "in.deck"}

    ran = record_engine_runs(monkeypatch)
    code, out, err = cli_main(["collide", str(path), "--engine", engine, "--json", *extra], capsys)
    assert code == 0, err
    assert ran, "collide ran no deck"
    assert written == ran[0][0]  # byte for byte: the native law at the step collide used
    assert beside == ran[0][1]  # and the files it reads (LIGGGHTS's data file)
    assert word in written and "# mapping fidelity: native" in written
    summary = json.loads(out)
    assert summary["params"]["mapping"] == "native" and summary["status"] == "ok"
    if dt:
        assert summary["dt"] == float(dt)


ALL = ["lammps", "liggghts", "yade", "kratos"]


@pytest.mark.parametrize("engine", [pytest.param(e, marks=pytest.mark.engine(e)) for e in ALL])
def test_a_seed_models_deck_is_the_deck_collide_ran(engine, tmp_path, capsys, monkeypatch):
    """No native setting, two unequal spheres: collide wrote every type pair with the contact pair's
    configuration and called it "native", while deck mapped each type pair — the same run now, byte for byte."""
    from demcheck.engines.collide import collide as run_engine
    import demcheck

    case = demcheck.load(CASES / "tti-pair.toml", {"particles.1.radius": 2e-3}) if engine != "kratos" else \
        demcheck.load(CASES / "glass-pair.toml", {"particles.1.radius": 2e-3, "contact.normal": "lsd",
                                                "contact.kn": 1e5, "contact.limit_force": True})
    from demcheck.engines.collide import setting_deck

    written = setting_deck(case, engine)
    ran = record_engine_runs(monkeypatch)
    res = run_engine(case, engine)
    assert ran and (written.text, dict(written.files)) == ran[0]
    assert res.ok, res.message
    assert "native" not in res.params["mapping"] and "# mapping fidelity: native" not in written.text
