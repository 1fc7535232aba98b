"""Every JSON file demcheck reads (a results.json, a report directory's, a baseline) is checked against its schema
(comparisons/schema.py) before any work: well-formed JSON of the wrong shape is one line naming the file, the place
in it and the rule, exit 2 — for ``demcheck diff`` and for ``verify --baseline`` before any case runs. A failure
after the runs still writes the report of what finished."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from demcheck.comparisons import diff as D
from demcheck.errors import ConfigError, DemcheckError

from .conftest import CASES
from .helpers import cli_main


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """A reference-only run of one case: its results.json and its baseline."""
    import subprocess
    import sys

    tmp = tmp_path_factory.mktemp("json")
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", CASES / "hertz-wall.toml", "--engines", "none",
                        "--report", tmp / "r", "--write-baseline", tmp / "base.json"], capture_output=True, text=True,
                       timeout=600)
    assert p.returncode == 0, p.stderr
    return (json.loads((tmp / "r" / "latest" / "results.json").read_text()),
            json.loads((tmp / "base.json").read_text()))


def _first(cases):
    return cases[0] if isinstance(cases, list) else next(iter(cases.values()))


# (what, which file, the edit, the JSON path the error names)
RESULTS_EDITS = [
    ("a case name that is a number", lambda d: _first(d["cases"]).__setitem__("case", 5), "$.cases[0].case"),
    ("a source that is a number", lambda d: _first(d["cases"])["comparisons"][0].__setitem__("source", 5),
     "$.cases[0].comparisons[0].source"),
    ("metrics as a list", lambda d: _first(d["cases"])["sources"]["reference"].__setitem__("metrics", [1.0]),
     "$.cases[0].sources.reference.metrics"),
    ("a comparison without its metric", lambda d: _first(d["cases"])["comparisons"][0].pop("metric"),
     "$.cases[0].comparisons[0]"),
    ("a scale that is text", lambda d: _first(d["cases"])["scales"].__setitem__("impact_energy", "1"),
     "$.cases[0].scales.impact_energy"),
    ("a scale of 0", lambda d: _first(d["cases"])["scales"].__setitem__("spin", 0), "$.cases[0].scales.spin"),
    ("a verdict not of demcheck's words", lambda d: _first(d["cases"])["comparisons"][0].__setitem__("verdict", "agreed"),
     "$.cases[0].comparisons[0].verdict"),
    ("comparisons as a table", lambda d: _first(d["cases"]).__setitem__("comparisons", {"x": 1}),
     "$.cases[0].comparisons"),
    ("partial as text", lambda d: d.__setitem__("partial", "no"), "$.partial"),
]
BASELINE_EDITS = [
    ("verdicts as a list", lambda d: _first(d["cases"]).__setitem__("verdicts", ["agree"]), "verdicts"),
    ("a source's verdicts as a list", lambda d: _first(d["cases"])["verdicts"].__setitem__("closed-form", ["agree"]),
     "verdicts['closed-form']"),
    ("a verdict not of demcheck's words",
     lambda d: _first(d["cases"])["verdicts"]["closed-form"].__setitem__("restitution", "agreed"),
     "verdicts['closed-form'].restitution"),
    ("a metric that is text", lambda d: _first(d["cases"])["sources"]["reference"]["metrics"].__setitem__(
        "restitution", "1"), "metrics.restitution"),
    ("a scale that is text", lambda d: _first(d["cases"])["scales"].__setitem__("spin", "x"), "scales.spin"),
    ("cases as a list", lambda d: d.__setitem__("cases", [1]), "$.cases"),
    ("no cases", lambda d: d.pop("cases"), "$"),
    ("a tolerance that is text", lambda d: d["tolerances"].__setitem__("metrics", {"restitution": "1e-3"}),
     "$.tolerances.metrics.restitution"),
    ("a negative source tolerance", lambda d: _first(d["cases"])["sources"]["reference"].__setitem__(
        "tolerances", {"restitution": -1}), "tolerances.restitution"),
    ("engines as a list", lambda d: d.__setitem__("engines", ["lammps"]), "$.engines"),
]


def _planted(stored, which: str, edit, tmp_path) -> Path:
    results, base = stored
    data = copy.deepcopy(results if which == "results" else base)
    edit(data)
    path = tmp_path / f"{which}.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("which, what, edit, where", [
    *(("results", w, e, p) for w, e, p in RESULTS_EDITS), *(("baseline", w, e, p) for w, e, p in BASELINE_EDITS)])
def test_json_of_the_wrong_shape_is_one_line_naming_file_place_and_rule(stored, tmp_path, capsys, which, what,
                                                                        edit, where):
    bad = _planted(stored, which, edit, tmp_path)
    good = tmp_path / "good.json"
    good.write_text(json.dumps(stored[0]))
    for argv in (["diff", good, bad], ["diff", bad, good]):
        code, out, err = cli_main(argv, capsys)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1, (what, err)
        assert lines[0].startswith("demcheck: error: ") and str(bad) in lines[0] and where in lines[0], (what, err)


@pytest.mark.parametrize("text, words", [
    ("[" * 100_000 + "]" * 100_000, "nested deeper than demcheck reads"),
    ('{"cases": [], "x": NaN}', "NaN is not a JSON number"),
    ('{"cases": [], "x": 1e999}', "too large for a float"),
    ('{"cases": [], "x": -Infinity}', "-Infinity is not a JSON number"),
])
def test_json_that_is_not_strict_or_too_deep_is_one_line(tmp_path, capsys, text, words):
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    code, _, err = cli_main(["diff", bad, bad], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and words in err, err


@pytest.mark.parametrize("what, edit, where", [
    ("a verdict not of demcheck's words",
     lambda d: _first(d["cases"])["verdicts"]["closed-form"].__setitem__("restitution", "agreed"),
     "verdicts['closed-form'].restitution"),
    ("a comparison without its metric (results.json as the baseline)", None, "$.cases[0].comparisons[0]"),
])
def test_a_bad_baseline_stops_verify_before_any_case_runs(stored, tmp_path, capsys, what, edit, where):
    if edit is None:
        bad = _planted(stored, "results", lambda d: _first(d["cases"])["comparisons"][0].pop("metric"), tmp_path)
    else:
        bad = _planted(stored, "baseline", edit, tmp_path)
    code, _, err = cli_main(["verify", CASES / "hertz-wall.toml", "--engines", "none", "--report", tmp_path / "rep",
                          "--baseline", bad], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and where in err and "--baseline" in err, err
    assert not (tmp_path / "rep").exists()  # nothing ran, no report


def test_a_results_json_judged_against_a_baseline_can_be_diffed(stored, tmp_path):
    """A run judged against a baseline holds two comparisons of one source and metric (its own and the
    baseline's): reading it took the worse verdict through a dict shadowing the verdicts module."""
    results, _ = stored
    data = copy.deepcopy(results)
    case = data["cases"][0]
    first = dict(case["comparisons"][0])
    case["comparisons"].append({**first, "verdict": "differs unexpectedly", "reason": "baseline: moved"})
    path = tmp_path / "judged.json"
    path.write_text(json.dumps(data))
    run = D.load(path)
    assert run["cases"][case["case"]]["verdicts"][first["source"]][first["metric"]] == "differs unexpectedly"


def test_a_baseline_with_a_null_default_tolerance_takes_the_implementation_bar(stored, tmp_path):
    _, base = stored
    data = copy.deepcopy(base)
    data["tolerances"]["default"] = None
    path = tmp_path / "b.json"
    path.write_text(json.dumps(data))
    d = D.compare(D.load(path), D.load(path))
    assert d["regressions"] == 0 and d["default_tolerance"] == D.default_tolerance()


def test_a_failure_after_the_runs_still_writes_the_report(stored, tmp_path):
    """A baseline check that fails after every case ran (a baseline handed in without load's checks) still leaves
    the report of the finished cases, and says where it is."""
    from demcheck.comparisons.suite import Options, run_suite

    base = {"path": "hand-made", "run_id": None, "started": None, "demcheck": None, "partial": False,
            "engines": {}, "tolerances": {}, "cases": {"hertz-wall": {
                "hash": None, "scales": {}, "sources": {},
                "verdicts": {"closed-form": {"restitution": "agreed"}}}}}  # a verdict demcheck has no rank for
    with pytest.raises(DemcheckError) as err:
        run_suite([CASES / "hertz-wall.toml"], tmp_path / "rep", Options(engines=(), baseline=base), quiet=True)
    assert "the report of the finished cases is" in str(err.value)
    results = json.loads((tmp_path / "rep" / "latest" / "results.json").read_text())
    assert [c["case"] for c in results["cases"]] == ["hertz-wall"] and "baseline check failed" in results["baseline_error"]
    assert not isinstance(err.value, ConfigError)
