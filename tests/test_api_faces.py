"""Issue 29 item 4: the command line is a click layer over api.py — `collide`, `sweep`, `audit` and `calibrate`
call the API's functions (one path, so the same results), `collide --engine all` asks comparisons.sources.plan
what can run the case, and every command loads its case through api.load."""

from __future__ import annotations

import json
from pathlib import Path

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


def test_cases_and_the_api_give_the_same_listing_and_file():
    """`demcheck cases` is api.case_files: the listing and one file, the same from both faces; an unknown name names
    the argument of each."""
    p = CliRunner().invoke(cli, ["cases", "--json"])
    assert p.exit_code == 0, p.output
    listing = demcheck.case_files()
    assert json.loads(p.output) == json.loads(json.dumps(plain(listing))) and listing["cases"]
    p = CliRunner().invoke(cli, ["cases", "glass-pair", "--json"])
    one = demcheck.case_files("glass-pair")
    assert json.loads(p.output) == one and one["text"].startswith(("#", "name", "["))
    p = CliRunner().invoke(cli, ["cases", "glass-pair"])
    assert p.output == one["text"]
    p = CliRunner().invoke(cli, ["cases", "no-such-case"])
    assert isinstance(p.exception, ConfigError) and p.exception.key == "NAME"
    with pytest.raises(ConfigError) as err:
        demcheck.case_files("no-such-case")
    assert err.value.key == "name"


def test_pack_and_the_api_give_the_same_packing_and_files(tmp_path):
    """`demcheck pack` is api.pack: the same summary and the same settled state written, from the same file."""
    from .test_pack_output import SMALL

    case = tmp_path / "small.toml"
    case.write_text(SMALL)
    p = CliRunner().invoke(cli, ["pack", str(case), "--json", "--csv", str(tmp_path / "cli")])
    assert p.exit_code == 0, p.output
    wrote = []
    got = demcheck.pack(case, csv=tmp_path / "api", wrote=wrote.append)
    assert json.loads(p.stdout) == json.loads(json.dumps(plain(got))) and got["metrics"]
    assert p.stderr.splitlines() == [f"wrote {tmp_path / 'cli' / n}" for n in ("particles.csv", "contacts.csv")]
    assert wrote == [tmp_path / "api" / "particles.csv", tmp_path / "api" / "contacts.csv"]
    for name in ("particles.csv", "contacts.csv"):
        assert (tmp_path / "cli" / name).read_text() == (tmp_path / "api" / name).read_text()


@pytest.mark.parametrize("kwargs, key", [
    ({"mpi": 2}, "mpi"), ({"engine": "lammps", "threads": 2}, "threads"), ({"threads": 0}, "threads"),
    ({"engine": "nosuch"}, "engine"), ({"duration": 1e-300}, "duration"), ({"csv": 3}, "csv"),
])
def test_pack_names_the_apis_arguments_before_any_work(tmp_path, kwargs, key, monkeypatch):
    from demcheck.engines import packing as engine_packing
    from demcheck.reference import packing

    from .test_pack_output import SMALL

    def work(*args, **kwargs):
        raise AssertionError("a packing was started before its arguments were checked")

    monkeypatch.setattr(packing, "simulate", work)
    monkeypatch.setattr(engine_packing, "run_engine", work)
    case = tmp_path / "small.toml"
    case.write_text(SMALL)
    with pytest.raises(ConfigError) as err:
        demcheck.pack(case, **kwargs)
    assert err.value.key == key, str(err.value)
    with pytest.raises(ConfigError) as err:
        demcheck.pack("glass-pair")
    assert err.value.key == "kind"


def test_stress_and_bench_load_their_cases_through_the_api(monkeypatch, tmp_path):
    """One loader: `demcheck stress` and `demcheck bench` build each case with api.load (its [engine.NAME]
    settings read by their engines), never a loader of their own."""
    from demcheck.comparisons import bench, stress

    def work(*args, **kwargs):
        raise AssertionError("a case's work started before its case was loaded by api.load")

    monkeypatch.setattr(stress, "largest_stable", work)
    monkeypatch.setattr(bench, "bench_case", work)
    for argv in (["stress", "glass-pair", "--only", "speed"], ["bench", "glass-pair", "--steps", "10"]):
        calls = _reached(monkeypatch, "load")
        p = CliRunner().invoke(cli, [*argv, "--engines", "none", "--report", str(tmp_path / "r")])
        assert isinstance(p.exception, ConfigError) and p.exception.key.endswith("reached"), (argv, p.exception)
        assert len(calls) == 1


def test_a_sweeps_grid_is_built_in_one_place():
    """api.sweep builds and checks a sweep's grid (api._sweep_points); comparisons/sweep.py solves it and builds
    no case of its own (its unused sweep_points, a second loader with --vary texts, is gone)."""
    from pathlib import Path

    from demcheck.comparisons import sweep

    text = Path(sweep.__file__).read_text()
    assert not hasattr(sweep, "sweep_points")
    assert "from_dict" not in text and "apply_overrides" not in text and "_read(" not in text


def test_no_api_name_is_a_module_or_folder_of_the_package():
    """`demcheck.NAME` is an API function looked up by the package's __getattr__; an import of a submodule or a
    folder of the same name (`import demcheck.cases`: the shipped case files' folder) would set the attribute to
    that module, in its place, for the whole process."""
    import demcheck

    root = Path(demcheck.__file__).parent
    taken = {p.stem for p in root.iterdir() if p.suffix == ".py" or p.is_dir()}
    assert not taken & set(demcheck._API)
    assert callable(demcheck.case_files) and demcheck.case_files()["cases"]


def test_a_case_file_that_is_not_text_is_bad_input_naming_it(tmp_path):
    """`demcheck cases FILE` / demcheck.case_files(FILE) of a binary file: one line naming the argument and the
    file, exit 2 — it was a UnicodeDecodeError traceback, exit 1."""
    f = tmp_path / "binary.toml"
    f.write_bytes(b"\xff\xfe\x00binary")
    with pytest.raises(ConfigError) as err:
        demcheck.case_files(str(f))
    assert err.value.key == "name" and "UTF-8" in err.value.rule
    p = CliRunner().invoke(cli, ["cases", str(f)])
    assert isinstance(p.exception, ConfigError) and p.exception.key == "NAME"
