"""One verify: ``demcheck verify`` is a click layer over ``demcheck.verify`` — the same case discovery (a
directory without its optin/ and benchmarks/), the same engines and builds, the same expected differences (a
build's repeated under its label), and so the same results on the same files."""

from __future__ import annotations

import json
import math

import pytest
from click.testing import CliRunner

import demcheck
from demcheck.cli import cli
from demcheck.comparisons import suite
from demcheck.comparisons.records import Summary
from demcheck.engines import builds, discovery
from demcheck.errors import ConfigError

from .conftest import CASES


def _captured(monkeypatch) -> list:
    """run_suite replaced by a recorder: what each face hands the suite."""
    calls = []

    def record(files, report_root, opts, quiet=False, junit=None, argv=None, link="latest"):
        calls.append({"files": [str(f) for f in files], "engines": opts.engines, "expected": opts.expected,
                      "timeout": opts.timeout, "jobs": opts.jobs, "refresh": getattr(opts.cache, "refresh", None),
                      "baseline": opts.baseline is not None, "junit": junit})
        return Summary(report=str(report_root))

    monkeypatch.setattr(suite, "run_suite", record)
    return calls


@pytest.mark.engine("lammps")
def test_the_command_and_the_api_hand_the_suite_the_same_files_builds_and_expected_differences(monkeypatch, tmp_path):
    exe = discovery.require("lammps").executable
    spec = f"lammps,lammps@again={exe}"
    calls = _captured(monkeypatch)
    try:
        p = CliRunner().invoke(cli, ["verify", str(CASES), "--engines", spec, "--jobs", "1", "--report", str(tmp_path / "r"),
                                     "--json"])
        assert p.exit_code == 0, p.output
        demcheck.verify(str(CASES), engines=spec, report=tmp_path / "r")
    finally:
        discovery.drop("lammps@again")
    cli_call, api_call = calls
    assert cli_call == api_call
    assert cli_call["engines"] == ("lammps", "lammps@again")
    # a directory: the default suite's files, never the opt-in or benchmark ones
    assert cli_call["files"] and not any("/optin/" in f or "/benchmarks/" in f for f in cli_call["files"])
    # the build's expected differences: every lammps one, under its label
    mine = [e for e in cli_call["expected"] if e.engine == "lammps"]
    assert mine and [e.reason for e in cli_call["expected"] if e.engine == "lammps@again"] == [e.reason for e in mine]


def test_the_api_refreshes_and_takes_a_baseline_as_the_command_does(monkeypatch, tmp_path):
    calls = _captured(monkeypatch)
    base = tmp_path / "base.json"
    base.write_text(json.dumps({"cases": [], "failed": 0}))
    CliRunner().invoke(cli, ["verify", str(CASES / "hertz-wall.toml"), "--engines", "none", "--no-cache", "--jobs", "1",
                             "--baseline", str(base), "--report", str(tmp_path / "r")])
    demcheck.verify(CASES / "hertz-wall.toml", engines="none", refresh=True, baseline=base, report=tmp_path / "r")
    assert len(calls) == 2 and calls[0] == calls[1] and calls[0]["refresh"] is True and calls[0]["baseline"]


def _verdicts(summary: dict) -> list:
    out = []
    for c in summary["cases"]:
        for k in c["comparisons"]:
            value = k["value"]
            out.append((c["case"], k["source"], k["metric"], k["verdict"],
                        None if value is None or (isinstance(value, float) and math.isnan(value)) else value))
    return out


@pytest.mark.engine("lammps")
def test_the_command_and_the_api_give_the_same_results_on_the_same_files(tmp_path):
    files = [str(CASES / "hertz-wall.toml"), str(CASES / "tti-pair.toml")]
    p = CliRunner().invoke(cli, ["verify", *files, "--engines", "lammps", "--report", str(tmp_path / "cli"),
                                 "--json"])
    assert p.exit_code == 0, p.output
    by_cli = json.loads((tmp_path / "cli" / "latest" / "results.json").read_text())
    by_api = demcheck.verify(files, engines="lammps")
    assert _verdicts(by_cli) and _verdicts(by_cli) == _verdicts(by_api)
    assert [c["sources"].keys() for c in by_cli["cases"]] == [c["sources"].keys() for c in by_api["cases"]]


def test_a_bad_engine_list_is_named_by_each_face(tmp_path):
    p = CliRunner().invoke(cli, ["verify", str(CASES / "hertz-wall.toml"), "--engines", "lammpz",
                                 "--report", str(tmp_path)])
    assert isinstance(p.exception, ConfigError) and str(p.exception).startswith("--engines = ")
    with pytest.raises(ConfigError, match="^engines = .lammpz.: must be lammps"):
        demcheck.verify(CASES / "hertz-wall.toml", engines="lammpz")
    assert builds  # the builds module is what both faces parse the list with


@pytest.mark.parametrize("named", [True, False])
def test_a_dask_worker_lacking_a_named_engine_fails_the_case(monkeypatch, named):
    """Issue 32: an engine the user named is never skipped — on a Dask worker that lacks it, its source fails in the
    cases the worker ran (the worker named); an engine of default discovery is reported missing there, as on the
    client."""
    from demcheck.case import load
    from demcheck.comparisons import dispatch, verdicts

    why = "lammps is missing on the Dask worker tcp://w:1 (host w): lammps is not installed"
    monkeypatch.setattr(dispatch, "missing_here", lambda engines: {e: why for e in engines if e == "lammps"})
    found = {"lammps": {"found": True, "version": "x", "executable": "lmp", "how_to_install": "", "why": None}}
    opts = suite.Options(engines=("lammps",), named=named, cache=None)
    entry = suite.case_task(load(CASES / "hertz-wall.toml"), str(CASES / "hertz-wall.toml"), opts, found).to_json()
    if named:
        assert entry["sources"]["lammps"] == {"status": verdicts.FAILED, "message": why}
        assert entry["status"] == "failed" and entry["sources"]["reference"]["status"] == "ok"
    else:
        assert entry["sources"]["lammps"] == {"status": verdicts.MISSING, "message": why}
        assert entry["status"] == "ok"
