"""The scenario twins' step loops made fast without changing a number (reference/beyond.py: its own 3-vector
cross product and norm, the laws' coefficients laid out once) and their metrics cached as the engine runs are
(engines/scenario.cached_metrics: keyed by the case, the engine and demcheck's source)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from demcheck.case import load
from demcheck.engines import scenario
from demcheck.engines.cache import Cache
from demcheck.laws.rolling import rolling_torque
from demcheck.laws.twisting import twisting_torque
from demcheck.reference import beyond
from demcheck.resources import case_path


def test_cross_and_norm_are_numpys_to_the_bit():
    rng = np.random.default_rng(7)
    for _ in range(2000):
        a, b = rng.normal(size=3) * 10.0 ** rng.uniform(-12, 3), rng.normal(size=3) * 10.0 ** rng.uniform(-12, 3)
        assert np.array_equal(beyond._cross(a, b), np.cross(a, b))
        assert beyond._norm(a) == float(np.linalg.norm(a))


@pytest.mark.parametrize("name", ["rolling", "incline", "incline-linear", "twist"])
def test_laid_out_kernels_are_the_laws_torques(name):
    """The wall twins' rolling and twisting calls give what rolling_torque and twisting_torque give."""
    from demcheck.laws.model import resolve

    model = resolve(load(case_path(f"suite/beyond-{name}.toml")))
    rng = np.random.default_rng(3)
    roll, tw = model.slot("rolling"), model.slot("twisting")
    at_r, at_t = beyond._rolling_kernel(roll), beyond._twisting_kernel(tw)
    for _ in range(200):
        w, n, h = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3) * 1e-3
        n /= np.linalg.norm(n)
        fn, dt, a, phi = abs(rng.normal()), 1e-5, 1e-3, rng.normal() * 1e-3
        for got, want in zip(at_r(w, n, fn, dt, h), rolling_torque(roll, w, n, fn, dt, h)):
            assert np.array_equal(got, want)
        for got, want in zip(at_t(w, n, fn, a, dt, phi), twisting_torque(tw, w, n, fn, a, dt, phi)):
            assert np.array_equal(got, want)


@pytest.mark.engine("lammps")
def test_twin_and_seed_metrics_are_cached_bit_identical(tmp_path, monkeypatch):
    """A second call is served from the cache with the same metrics, bit for bit, without stepping; a changed
    source fingerprint steps again."""
    c = load(case_path("suite/beyond-twist.toml"))
    cache = Cache(tmp_path)
    first = {k: scenario.cached_metrics(k, c, "lammps", cache) for k in ("twin", "seed")}
    assert first["twin"] == scenario.twin(c, "lammps").metrics()
    assert first["seed"] == scenario.seed(c, "lammps").metrics()
    assert cache.misses == 2 and cache.hits == 0

    def no_step(*a, **k):
        raise AssertionError("stepped although cached")

    monkeypatch.setattr(scenario, "step", no_step)
    again = {k: scenario.cached_metrics(k, c, "lammps", cache) for k in ("twin", "seed")}
    assert again == first and cache.hits == 2
    monkeypatch.setattr(scenario, "code_fingerprint", lambda: "changed-source")
    with pytest.raises(AssertionError, match="stepped although cached"):
        scenario.cached_metrics("twin", c, "lammps", cache)


def test_a_metric_that_is_not_finite_is_cached_as_not_finite(tmp_path, monkeypatch):
    """A captured impact has no capture velocity: the cache gives back nan, never the 0 it stores beside its flag."""
    c = load(case_path("suite/beyond-adhesive-impact.toml"))
    cache = Cache(tmp_path)

    class Fake:
        def metrics(self):
            return {"restitution": 0.0, "capture_velocity": math.nan}

    monkeypatch.setattr(scenario, "twin", lambda case, engine: Fake())
    monkeypatch.setattr(scenario, "_engine", lambda engine: type("E", (), {"name": "lammps"})())
    first = scenario.cached_metrics("twin", c, "lammps", cache)
    monkeypatch.setattr(scenario, "twin", lambda case, engine: (_ for _ in ()).throw(AssertionError("ran")))
    again = scenario.cached_metrics("twin", c, "lammps", cache)
    assert cache.hits == 1 and again["restitution"] == 0.0 and math.isnan(again["capture_velocity"])
    assert math.isnan(first["capture_velocity"])


@pytest.mark.engine("lammps")
def test_a_scenario_engine_run_is_cached_by_its_deck(tmp_path, monkeypatch):
    """An ok engine run is kept as what the engine's reader made of its output (keyed by the deck's commands and the
    engine's version): the second run of the same deck reads it and computes the same metrics (the same numbers,
    the engine's version, ok) without running the engine; another deck runs."""
    from demcheck.engines import run as runner

    c = load(case_path("suite/beyond-conduction.toml"))
    cache = Cache(tmp_path)
    first = scenario.run(c, "lammps", cache=cache)
    assert first.ok and cache.misses == 1

    def no_run(*a, **k):
        raise AssertionError("ran although cached")

    monkeypatch.setattr(runner, "run", no_run)
    again = scenario.run(c, "lammps", cache=cache)
    assert again.ok and again.metrics() == first.metrics() and again.engine_version == first.engine_version
    assert again.meta["cached"] and cache.hits == 1
    other = load(case_path("suite/beyond-conduction.toml"), ["run.overlap=2e-6"])
    with pytest.raises(AssertionError, match="ran although cached"):
        scenario.run(other, "lammps", cache=cache)


def test_a_scenario_run_is_kept_under_its_readers_code(monkeypatch):
    """The kept data is what demcheck's reader made of the engine's output: a change to that reader (the engine's
    scenario part, the dump readers, this module's table layout) must key the run anew, else a fixed reader would be
    served its old reading; the digest changes with each of them and is the same for the same code."""
    import inspect

    from demcheck.engines import dumps, family_read, registry
    from demcheck.engines import scenario as S

    eng = registry.get("lammps")
    before = S._reader_digest(eng)
    assert S._reader_digest(eng) == before
    real = inspect.getsource
    for changed in (eng._part("scenario"), dumps, family_read, S):
        monkeypatch.setattr(inspect, "getsource", lambda m, c=changed: real(m) + ("\n# fixed" if m is c else ""))
        assert S._reader_digest(eng) != before, changed.__name__
    monkeypatch.setattr(inspect, "getsource", real)
    assert S._reader_digest(registry.get("yade")) != before  # each engine its own reader
