"""The reference's own results in the run cache (comparisons/result_cache.py): a warm suite solves nothing it
solved before and gives the same entries; a changed code fingerprint, a damaged entry or a failed result is
solved again."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from demcheck.case import load
from demcheck.comparisons import result_cache, sources, suite
from demcheck.engines import cache as cache_mod
from demcheck.engines.cache import Cache
from demcheck.resources import case_path

# the adaptive solve of an oblique case has all three tables (events with their names); its verlet solve two
OBLIQUE = "suite/oblique-lth.toml"


def _same_tables(a, b):
    for name in result_cache.KEPT:
        ta, tb = a.table(name), b.table(name)
        assert (ta is None) == (tb is None), name
        if ta is None:
            continue
        assert list(ta) == list(tb), name
        for c in ta:
            assert np.asarray(ta[c]).dtype == np.asarray(tb[c]).dtype, (name, c)
            assert np.array_equal(np.asarray(ta[c]), np.asarray(tb[c])), (name, c)


@pytest.mark.parametrize("source", [sources.ADAPTIVE, sources.VERLET])
def test_a_stored_result_reads_back_as_the_same_arrays_and_fields(tmp_path, source):
    case = load(case_path(OBLIQUE))
    res = source.run(case)
    cache = Cache(tmp_path)
    k = result_cache.result_key(source.label, case)
    assert result_cache.store(cache, k, res)
    back = result_cache.load(cache, k)
    _same_tables(res, back)
    assert res.table("particles") is not None and back.table("particles") is None  # verify does not read them
    for f in result_cache.FIELDS:
        assert getattr(back, f) == getattr(res, f), f
    assert back.metrics() == res.metrics()
    if source is sources.ADAPTIVE:
        assert set(back.table("events")["event"]) >= {"contact_start", "contact_end"}


def _strip(o):
    """An entry without what a cache hit changes by design: wall times, the cached flag."""
    if isinstance(o, dict):
        return {k: _strip(v) for k, v in o.items() if k not in ("wall_time", "cached")}
    if isinstance(o, list):
        return [_strip(v) for v in o]
    return "nan" if isinstance(o, float) and math.isnan(o) else o


def _entries(files, cache, engines=()):
    opts = suite.Options(engines=engines, cache=cache)
    found = suite.discover(engines)
    return [suite.run_case(c, f, opts, found).to_json() for f, c in suite.collect(files)]


def test_a_warm_suite_case_solves_nothing_and_gives_the_same_entry(tmp_path, monkeypatch):
    """The adaptive solve comes back as a Result; the verlet run as what the entry keeps of it (its source line,
    series and curve distances)."""
    files = [case_path(OBLIQUE), case_path("suite/normal-hertz-pair.toml"), case_path("suite/beyond-twist.toml")]
    cold = _entries(files, Cache(tmp_path))

    def no_solve(*a, **k):
        raise AssertionError("solved although cached")

    monkeypatch.setattr(sources.Source, "run", no_solve)
    warm_cache = Cache(tmp_path)
    warm = _entries(files, warm_cache)
    assert warm_cache.misses == 0 and warm_cache.hits > 0
    assert json.dumps(_strip(warm), sort_keys=True, default=str) == json.dumps(_strip(cold), sort_keys=True,
                                                                               default=str)
    assert warm[0]["sources"]["reference"]["metrics"]["restitution"] > 0.0


def test_a_changed_fingerprint_or_a_damaged_table_solves_again(tmp_path, monkeypatch):
    case = load(case_path(OBLIQUE))
    cache = Cache(tmp_path)
    calls = []

    def compute():
        calls.append(1)
        return sources.VERLET.run(case)

    first = result_cache.cached_result(cache, "reference-verlet", case, compute)
    result_cache.cached_result(cache, "reference-verlet", case, compute)
    assert len(calls) == 1
    # a damaged table (its bytes cut) is a miss, solved again and stored over
    k = result_cache.result_key("reference-verlet", case)
    path = cache._path(k)
    path.write_bytes(path.read_bytes()[:100])
    again = result_cache.cached_result(Cache(tmp_path), "reference-verlet", case, compute)
    assert len(calls) == 2
    _same_tables(first, again)
    monkeypatch.setattr(result_cache, "code_fingerprint", lambda: "changed-source")
    result_cache.cached_result(cache, "reference-verlet", case, compute)
    assert len(calls) == 3


def test_a_failed_result_is_not_stored(tmp_path):
    case = load(case_path(OBLIQUE))
    cache = Cache(tmp_path)
    res = sources.VERLET.run(case)
    res.status, res.message = "unstable", "planted"
    calls = []

    def compute():
        calls.append(1)
        return res

    for _ in range(2):
        assert result_cache.cached_result(cache, "reference-verlet", case, compute).status == "unstable"
    assert len(calls) == 2


def test_metrics_keep_a_metric_that_is_not_finite(tmp_path):
    case = load(case_path(OBLIQUE))
    cache = Cache(tmp_path)
    got = result_cache.cached_metrics(cache, "x", case, lambda: {"a": 1.5, "b": math.nan})
    back = result_cache.cached_metrics(cache, "x", case, lambda: pytest.fail("computed although cached"))
    assert back["a"] == 1.5 and math.isnan(back["b"]) and list(back) == list(got)


def test_the_fingerprint_names_the_cpu(monkeypatch):
    from llvmlite import binding

    cache_mod.code_fingerprint.cache_clear()
    here = cache_mod.code_fingerprint()
    monkeypatch.setattr(binding, "get_host_cpu_name", lambda: "another-cpu")
    cache_mod.code_fingerprint.cache_clear()
    try:
        assert cache_mod.code_fingerprint() != here
    finally:
        monkeypatch.undo()
        cache_mod.code_fingerprint.cache_clear()


@pytest.mark.parametrize("name", ["suite/beyond-conduction.toml", "suite/beyond-pull-off.toml"])
def test_a_scenario_solve_with_values_that_are_not_finite_in_its_fields_reads_back_the_same(tmp_path, name):
    """A scenario's reference solve keeps NaN or inf among its fields (its meta): stored, and read back equal."""
    case = load(case_path(name))
    res = sources.ADAPTIVE.run(case)
    cache = Cache(tmp_path)
    k = result_cache.result_key("reference-adaptive", case)
    assert result_cache.store(cache, k, res)
    back = result_cache.load(cache, k)
    for f in result_cache.FIELDS:
        assert json.dumps(getattr(back, f), sort_keys=True) == json.dumps(getattr(res, f), sort_keys=True), f
    assert json.dumps(back.metrics()) == json.dumps(res.metrics())


def test_each_fingerprint_has_its_folder_and_a_campaign_keeps_two(tmp_path, monkeypatch):
    """Entries of one source fingerprint live under results/FINGERPRINT/; pruning keeps the current folder and the
    newest other one, and removes the rest (the cache holds at most two versions' results)."""
    import os

    case = load(case_path(OBLIQUE))
    cache = Cache(tmp_path)
    for i, fp in enumerate(("v1", "v2", "v3", "v4")):
        monkeypatch.setattr(result_cache, "code_fingerprint", lambda fp=fp: fp)
        assert result_cache.store(cache, result_cache.result_key("reference-verlet", case), sources.VERLET.run(case))
        folder = tmp_path / "results" / fp
        assert folder.is_dir() and list(folder.rglob("*.npz"))
        os.utime(folder, (1e9 + i, 1e9 + i))  # v1 the oldest, v4 the newest
    monkeypatch.setattr(result_cache, "code_fingerprint", lambda: "v2")  # back to an older version
    assert sorted(result_cache.prune(cache)) == ["v1", "v3"]
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["v2", "v4"]
    assert result_cache.load(cache, result_cache.result_key("reference-verlet", case)) is not None
    assert cache._path("ab12").parent == tmp_path / "ab"  # an engine run's key: as before


def test_a_json_value_comes_back_as_stored_cold_or_warm(tmp_path):
    case = load(case_path(OBLIQUE))
    cache = Cache(tmp_path)
    value = {"a": (1.5, float("nan")), "b": [float("inf"), "x"], "c": None}
    cold, hit = result_cache.cached_json(cache, "j", case, lambda: value)
    assert not hit and cold["a"][0] == 1.5 and isinstance(cold["a"], list)
    warm, hit = result_cache.cached_json(cache, "j", case, lambda: pytest.fail("computed although cached"))
    assert hit and json.dumps(warm) == json.dumps(cold)
