"""The suite's typed results (comparisons/records.py): built once in the suite, read by attribute, and written at the
JSON edge as results.json always held them — the same keys in the same order — and read back from such a file."""

from __future__ import annotations

import json
import math

from demcheck.comparisons import report, sources, suite, verdicts as V
from demcheck.comparisons.records import CaseResult, SourceResult, Summary
from demcheck.io import plain

from .conftest import CASES

# the keys of a case's entry and of a source's row in results.json, in the order the suite wrote them before the
# records (main 166af39: suite.run_case, suite._safe_case, suite._source)
COLLISION_KEYS = ["case", "file", "case_hash", "kind", "sources", "comparisons", "curves", "series", "walls",
                  "variant", "model", "params", "impact", "scales", "status", "verdict"]
FAILED_KEYS = ["case", "file", "case_hash", "status", "verdict", "message", "sources", "curves", "series",
               "comparisons"]
RUN_KEYS = ["status", "message", "method", "dt", "rtol", "engine_version", "wall_time", "metrics", "cached",
            "warnings"]


def _glass():
    from demcheck.case import load

    return suite.run_case(load(CASES / "glass-pair.toml"), CASES / "glass-pair.toml", suite.Options(engines=()), {})


def test_a_case_is_a_record_whose_json_is_the_entry_results_json_held():
    entry = _glass()
    assert isinstance(entry, CaseResult) and isinstance(entry.sources["reference"], SourceResult)
    assert all(isinstance(c, V.Comparison) for c in entry.comparisons) and entry.comparisons
    assert entry.status == "ok" and entry.verdict == V.AGREE and entry.walls == 0 and entry.variant == []
    d = entry.to_json()
    assert list(d) == COLLISION_KEYS
    assert list(d["sources"]) == ["reference", "reference-verlet"]
    assert all(list(s) == RUN_KEYS for s in d["sources"].values())
    assert d["comparisons"][0] == entry.comparisons[0].as_dict()
    assert "series" not in entry.to_json(series=False) and d["series"]
    # read back: the same record, and the same JSON in the same order
    again = CaseResult.from_json(json.loads(json.dumps(d)))
    assert json.dumps(again.to_json()) == json.dumps(json.loads(json.dumps(d)))
    assert again.sources["reference"].metrics["restitution"] == entry.sources["reference"].metrics["restitution"]


def test_a_case_the_suite_could_not_run_keeps_its_entry_shape(monkeypatch):
    from demcheck.case import load
    from demcheck.errors import DemcheckError

    def broken(*a, **k):
        raise DemcheckError("no such thing")

    monkeypatch.setattr(suite, "run_case", broken)
    entry = suite._safe_case(load(CASES / "hertz-wall.toml"), CASES / "hertz-wall.toml", suite.Options(engines=()), {})
    d = entry.to_json()
    assert list(d) == FAILED_KEYS and d["status"] == "failed" and d["verdict"] == V.FAILED
    assert d["message"] == "no such thing" and [c["source"] for c in d["comparisons"]] == ["reference"]


def test_unavailable_edits_nothing_and_the_case_notes_what_it_returns():
    """verdicts.unavailable returns the native setting and the status comparison; CaseResult.planned records them."""
    from demcheck.case import expand

    case = expand(CASES / "suite" / "oblique-sliding.toml")[0]
    found = {e: {"found": True} for e in ("lammps", "yade")}
    lammps, yade = sources.plan(case, ("lammps", "yade"), found)
    setting, comparison = V.unavailable(lammps)
    assert setting == "hooke damping coeff_restitution tangential linear_nohistory" and comparison is None
    setting, comparison = V.unavailable(yade)
    assert setting is None and comparison.verdict == V.NOT_EXPRESSIBLE and comparison.source == "yade"
    entry = CaseResult(case.name)
    assert entry.note_plan(lammps) is True and entry.note_plan(yade) is False
    assert entry.settings == {"lammps": "hooke damping coeff_restitution tangential linear_nohistory"}
    assert entry.sources["yade"].to_json() == {"status": V.NOT_EXPRESSIBLE, "message": yade.why}
    assert [c.source for c in entry.comparisons] == ["yade"]


def test_a_results_json_of_an_older_release_is_read_with_its_gaps_and_keys_kept():
    old = {"cases": [{"case": "x", "sources": {"reference": {"status": "ok", "metrics": {"restitution": 0.5},
                                                              "plot": [1, 2]}},
                      "comparisons": [{"source": "reference-verlet", "metric": "restitution", "verdict": "agree",
                                       "value": None}], "later": {"a": 1}}], "engines": None}
    s = Summary.from_json(old)
    c = s.cases[0]
    assert c.walls is None and c.variant is None and c.kind is None  # never said: not made up
    assert c.metric("reference", "restitution") == 0.5 and c.metric("lammps", "restitution") is None
    assert c.comparisons[0].setting == "" and c.comparisons[0].value is None and math.isnan(c.comparisons[0].rel_diff)
    assert c.sources["reference"].to_json() == old["cases"][0]["sources"]["reference"]  # its own keys kept
    assert c.to_json()["later"] == {"a": 1} and s.engines == {}


def test_the_renderers_read_a_record_and_its_json_alike(tmp_path):
    s = suite.run_suite([CASES / "glass-pair.toml"], tmp_path / "r", suite.Options(engines=()), quiet=True)
    assert isinstance(s, Summary) and s.failed == 0 and not s.partial and s.planned == 1
    data = json.loads((tmp_path / "r" / "latest" / "results.json").read_text())
    assert data == json.loads(json.dumps(plain(s.to_json(series=False))))
    assert list(data)[:12] == ["demcheck", "run_id", "report", "partial", "started", "command", "engines",
                               "tolerances", "cases", "failed", "planned", "wall_time"]
    assert report.render_markdown(s) == report.render_markdown(data)
    assert report.render_junit(s) == report.render_junit(data)


def _stored_packing() -> dict:
    """A packing entry as results.json stores it (the suite's keys, in their order; panels as packing_suite wrote
    them before the records), with a key a later release might add to a panel."""
    prof = {"z": [1e-3, 2e-3], "solid_fraction": [0.55, 0.6]}
    forces = {"x": [0.5, 1.5], "p": [0.6, 0.4], "n": 120}
    return {"case": "pack", "file": "pack.toml", "kind": "packing", "case_hash": "h",
            "sources": {"reference": {"status": "ok", "metrics": {"solid_fraction": 0.6}}},
            "comparisons": [], "curves": {}, "series": [],
            "packing": {"reference": {"ke": [[0.0, 1e-3], [0.1, 1e-6]], "forces": forces, "profile": prof},
                        "lammps": {"ke": [[0.0, 1e-3]], "forces": forces, "profile": None, "later": 1}},
            "model": {"normal": "lsd", "tangential": "none", "limit_force": False},
            "status": "ok", "verdict": "agree"}


def test_a_packing_entry_holds_its_panels_as_records_and_writes_them_back_as_stored():
    from demcheck.comparisons.records import PackingPanel

    d = _stored_packing()
    entry = CaseResult.from_json(json.loads(json.dumps(d)))
    ref = entry.packing["reference"]
    assert isinstance(ref, PackingPanel)
    assert ref.ke == [[0.0, 1e-3], [0.1, 1e-6]] and ref.forces["n"] == 120 and ref.profile["z"] == [1e-3, 2e-3]
    assert entry.packing["lammps"].profile is None and entry.packing["lammps"].extra == {"later": 1}
    assert entry.to_json() == d and list(entry.to_json()["packing"]["lammps"]) == ["ke", "forces", "profile", "later"]


def test_a_stored_panel_missing_its_data_reads_as_empty_not_as_an_error():
    from demcheck.comparisons.records import PackingPanel

    d = _stored_packing()
    d["packing"]["lammps"] = {"profile": None}  # a results.json from a release that wrote no ke or forces
    p = CaseResult.from_json(d).packing["lammps"]
    assert p == PackingPanel([], {}, None) and p.to_json() == {"ke": [], "forces": {}, "profile": None}
    assert CaseResult.from_json({**d, "packing": None}).packing is None


def test_validation_checks_are_records_written_back_as_results_json_held_them():
    """A validation's checks, series and failures read from results.json into records (Validation, Check) and
    written back key for key, order included: a limit with its law flag, a curve with its regime."""
    from demcheck.comparisons.records import Check, Validation

    limit = {"benchmark": "b", "file": "f", "source": "reference", "kind": "limit", "quantity": "e",
             "expected": "Hertz", "deviation": 0.2, "at": 30.0, "tolerance": 1e-6, "why": "w", "verdict": "misses",
             "points": 2, "law": True}
    curve = {"benchmark": "b", "file": "f", "source": "lammps", "kind": "curve", "quantity": "et",
             "expected": "x.dat [k]", "regime": "", "tolerance": 0.05, "why": "w", "deviation": None, "at": None,
             "verdict": "no data", "points": 0}
    stored = {"benchmarks": [{"name": "b", "title": "t", "files": ["f.toml"]}], "checks": [limit, curve],
              "series": [{"benchmark": "b", "file": "f", "sources": {}}], "failed": [curve]}
    s = Summary.from_json({"cases": [], "validation": json.loads(json.dumps(stored))})
    val = s.validation
    assert isinstance(val, Validation) and all(isinstance(c, Check) for c in val.checks + val.failed)
    assert val.checks[0].law is True and val.checks[1].regime == "" and val.checks[1].deviation is None
    assert val.to_json() == stored and [list(c) for c in val.to_json()["checks"]] == [list(limit), list(curve)]
    assert s.to_json()["validation"] == stored
    # a check built by validate carries the keys validate always wrote, in their order
    assert list(Check("b", "f", "reference", "limit", "e", "Hertz").to_json()) == list(limit)[:-1]
    assert list(Check("b", "f", "reference", "limit", "e", "Hertz", law=True).to_json()) == list(limit)
    assert list(Check("b", "f", "lammps", "curve", "et", "x", regime="").to_json()) == list(curve)
