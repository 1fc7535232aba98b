"""The shipped cases and data (demcheck.resources): one discovery for every command and the API."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from demcheck import resources
from demcheck.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "src" / "demcheck" / "cases"


def test_the_shipped_cases_are_the_packages_own_files():
    assert resources.cases_dir().resolve() == SHIPPED.resolve()
    assert (resources.data_dir() / "tolerances.toml").is_file()
    names = resources.shipped_cases()
    files = sorted(SHIPPED.rglob("*.toml"))
    assert len(names) == len(files)  # every file by a name of its own: no two share a stem
    assert next(iter(names.values())).parent == resources.cases_dir()  # the default suite's top folder first


@pytest.mark.parametrize("text, expected", [
    ("glass-pair", "glass-pair.toml"),
    ("glass-pair.toml", "glass-pair.toml"),
    ("packing/poured", "packing/poured.toml"),
    ("cases/packing/poured.toml", "packing/poured.toml"),
    ("chung-ooi-4-al-oxide-tti", "benchmarks/chung-ooi-4-al-oxide-tti.toml"),
])
def test_a_case_by_its_name_from_any_directory(text, expected, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert resources.case_path(text) == resources.cases_dir() / expected


def test_a_given_path_is_taken_as_given_even_where_a_shipped_case_has_its_name(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "glass-pair.toml").write_text("name = 'mine'\n")
    assert resources.case_path("glass-pair.toml") == Path("glass-pair.toml")


@pytest.mark.parametrize("text, rule", [("no-such-case", "no such case file, nor a shipped case"),
                                        ("../glass-pair", "no such case file"),
                                        (str(SHIPPED / "packing"), "is a directory, not a case file")])
def test_a_case_that_is_not_there_is_one_line_naming_it(text, rule):
    with pytest.raises(ConfigError) as e:
        resources.case_path(text)
    assert rule in str(e.value) and text in str(e.value) and "\n" not in str(e.value)


def test_one_discovery_for_the_cli_and_the_api():
    from demcheck import api, cli

    suite = resources.case_files([])
    assert not any(resources.NAMED_ONLY & set(f.relative_to(SHIPPED).parts) for f in suite)
    assert {f.parent.name for f in suite} >= {"cases", "suite", "packing"}
    assert cli._case_files([str(SHIPPED)]) == api._case_files(str(SHIPPED)) == suite
    bench = resources.case_files([str(SHIPPED / "benchmarks")])  # named, a named-only folder runs
    assert bench and all("benchmarks" in f.parts for f in bench)


def test_demcheck_cases_lists_and_prints_a_shipped_case(tmp_path):
    from click.testing import CliRunner

    from demcheck.cli import cli

    os.chdir(tmp_path)
    out = CliRunner().invoke(cli, ["cases"])
    assert out.exit_code == 0 and "glass-pair" in out.output and "benchmarks/ (" in out.output
    text = CliRunner().invoke(cli, ["cases", "glass-pair"])
    assert text.exit_code == 0 and text.output == (SHIPPED / "glass-pair.toml").read_text()


def test_a_case_by_the_name_its_file_gives_and_a_near_miss_suggested():
    assert resources.case_path("suite-hertz-wall") == SHIPPED / "suite" / "normal-hertz-wall.toml"
    with pytest.raises(ConfigError) as e:
        resources.case_path("glas-pair")
    assert str(e.value).endswith("did you mean 'glass-pair'?")


def test_the_engine_run_cache_follows_xdg_cache_home_like_the_kernels(monkeypatch, tmp_path):
    from demcheck.engines import cache

    monkeypatch.delenv("DEMCHECK_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache.default_dir() == tmp_path / "demcheck" / "engine-runs"
    monkeypatch.setenv("DEMCHECK_CACHE", str(tmp_path / "mine"))
    assert cache.default_dir() == tmp_path / "mine"
