"""Issue 29 item 4: the command line is a click layer over api.py — `collide`, `sweep`, `audit` and `calibrate`
call the API's functions (one path, so the same results), `collide --engine all` asks comparisons.sources.plan
what can run the case, and every command loads its case through api.load."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

import demcheck
from demcheck import api
from demcheck.cli import cli
from demcheck.errors import ConfigError
from demcheck.io import plain

from .conftest import CASES

VARIANTS = CASES / "suite" / "normal-hertz-pair.toml"  # a file with [variants]


def _reached(monkeypatch, name: str) -> list:
    """api.NAME replaced by a recorder that stops the command with a ConfigError once reached."""
    calls = []

    def record(*args, **kwargs):
        calls.append((args, kwargs))
        raise ConfigError("reached", name, "the API's function")

    monkeypatch.setattr(api, name, record)
    return calls


@pytest.mark.parametrize("name, argv", [
    ("collide", ["collide", "glass-pair", "--dt", "1e-7", "--method", "verlet"]),
    ("sweep", ["sweep", "glass-pair", "--vary", "impact.speed=1:2:2", "--set", "impact.angle=10"]),
    ("audit", ["audit", str(CASES / "glass-pair.toml"), "--speed", "2"]),
    ("calibrate", ["calibrate", "glass-pair", "--engine", "lammps", "--target", "restitution=0.6", "--no-confirm"]),
])
def test_each_command_calls_the_api(monkeypatch, name, argv):
    calls = _reached(monkeypatch, name)
    p = CliRunner().invoke(cli, argv)
    assert isinstance(p.exception, ConfigError) and p.exception.key == "reached", p.output
    (args, kwargs), = calls
    assert "glass-pair" in str(getattr(args[0], "name", args[0]))  # collide hands the API the loaded Case
    if name == "collide":
        assert args[1:4] == ("reference", "verlet", 1e-7)
    if name == "sweep":
        assert args[1] == {"impact.speed": [1.0, 2.0]} and args[5] == ["impact.angle=10"]
        assert kwargs["keys"]["vary"] == "--vary" and kwargs["keys"]["overrides"] == "--set"
    if name == "audit":
        assert args[2] == 2.0
    if name == "calibrate":
        assert args[1:5] == ("lammps", {"restitution": 0.6}, None, False)


def test_collide_and_the_api_give_the_same_metrics():
    p = CliRunner().invoke(cli, ["collide", "glass-pair", "--set", "impact.speed=0.5", "--json"])
    assert p.exit_code == 0, p.output
    by_cli = json.loads(p.output)["metrics"]
    by_api = json.loads(json.dumps(plain(demcheck.collide("glass-pair", impact__speed=0.5).metrics())))
    assert by_cli and by_cli == by_api


def test_sweep_and_the_api_give_the_same_rows():
    p = CliRunner().invoke(cli, ["sweep", "glass-pair", "--vary", "impact.speed=0.5:1.5:2", "--json"])
    assert p.exit_code == 0, p.output
    rows = json.loads(p.output)["rows"]
    table = demcheck.sweep("glass-pair", {"impact.speed": [0.5, 1.5]})
    assert rows and rows == json.loads(json.dumps(plain(table.to_dict(orient="records"))))


def test_collide_all_asks_plan_what_can_run(monkeypatch):
    """What plan says cannot run is skipped with plan's reason; nothing else is tried (here: only the reference)."""
    from demcheck.comparisons import sources
    from demcheck.comparisons.verdicts import NOT_EXPRESSIBLE

    asked = []

    def plan(case, engines=None, found=None, mapping=None):
        asked.append(list(engines))
        return [sources.Planned(sources.Source.of(e), None, None, NOT_EXPRESSIBLE, "stubbed")
                for e in sources.engines_of(engines)]

    monkeypatch.setattr(sources, "plan", plan)
    p = CliRunner().invoke(cli, ["collide", "glass-pair", "--engine", "all", "--json"])
    assert p.exit_code == 0, p.output
    out = json.loads(p.output)
    engines = asked[0]
    assert engines and out["reference"]["status"] == "ok"
    for e in engines:
        assert out[e] == {"source": e, "status": "skipped", "message": f"{e} cannot express this model: stubbed"}


def test_one_loader_names_the_option_and_keeps_a_variants_files_base_case():
    with pytest.raises(ConfigError) as err:
        api.load(VARIANTS)
    assert err.value.key == "variants"
    base = api.load(VARIANTS, base=True)
    from demcheck.cli import _load

    assert _load(str(VARIANTS), ()).raw == base.raw  # the command's single-case loader: the base case
    p = CliRunner().invoke(cli, ["collide", "glass-pair", "--set", "impact.speed"])
    assert isinstance(p.exception, ConfigError) and p.exception.key == "--set"
    with pytest.raises(ConfigError) as err:
        api.load("glass-pair", ["impact.speed"])
    assert err.value.key == "overrides"


def test_sweep_refuses_a_key_varied_twice():
    p = CliRunner().invoke(cli, ["sweep", "glass-pair", "--vary", "impact.speed=1:2:2", "--vary",
                                 "impact.speed=3,4"])
    assert isinstance(p.exception, ConfigError) and p.exception.key == "--vary" and "varied twice" in p.exception.rule
