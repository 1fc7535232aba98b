"""The metrics of a stepped scenario run (reference/scenarios.stepped_metrics and reference/beyond's helpers): one
computation for an engine's output and its twin's, checked here on runs whose answer is known, and never a number
where the run did not show the event (a run that never stops, a pull that never breaks → not finite → a failed
source, never a verdict)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from demcheck.reference import beyond as b


def test_the_stop_of_a_linearly_decelerating_speed_is_exact_between_samples():
    t = np.linspace(0.0, 2.0, 21)
    v = 1.0 - 0.7 * t  # stops at 1/0.7, between samples
    x = t - 0.35 * t * t
    t_stop, s = b.first_stop(t, v, x)
    assert abs(t_stop - 1 / 0.7) < 1e-14
    assert abs(s - 0.5 / 0.7) < 0.35 * 0.1 ** 2  # the position is interpolated linearly: O(Δt²)


def test_efold_time_of_an_exponential_is_exact():
    t = np.arange(0, 400) * 0.01
    tau = 1.2345
    assert abs(b.efold_time(t, 100.0 * np.exp(-t / tau)) - tau) < 1e-12 * tau


def test_the_critical_angle_inverts_the_rolling_acceleration():
    theta, g, mu = math.radians(10.0), 9.81, 0.1
    acc = b.incline_closed(mu, 1.0, 1.0, theta, g)[1]
    assert abs(b.critical_angle_from_acceleration(acc, theta, g) - math.atan(mu)) < 1e-15
    t = np.linspace(0, 1, 101)
    assert abs(b.fitted_acceleration(t, 0.3 + acc * t) - acc) < 1e-13


def test_pull_off_of_a_path_reads_the_largest_tension_and_the_last_contact():
    delta = np.linspace(1.0, -1.0, 201)
    force = np.where(delta > -0.5, delta - 0.2 * (1 - delta * delta), 0.0)
    got = b.pull_off_of_path(delta, force)
    assert got["pull_off_force"] == pytest.approx(-force.min()) and got["separation_at_pull_off"] == delta[149]


@pytest.mark.parametrize("run, metric", [
    ({"t": np.arange(5.0), "v": 1.0 + np.arange(5.0)}, "stop"),  # it never stops
    ({"t": np.arange(5.0), "dT": np.full(5, 100.0)}, "efold"),  # it never cools
])
def test_a_run_that_never_shows_the_event_gives_nan(run, metric):
    if metric == "stop":
        assert all(math.isnan(x) for x in b.first_stop(run["t"], run["v"], run["t"]))
    else:
        assert math.isnan(b.efold_time(run["t"], run["dT"]))
    never_broken = b.pull_off_of_path(np.linspace(1, -1, 5), -np.ones(5))  # still touching at the end
    assert all(math.isnan(v) for v in never_broken.values())


def test_an_engine_run_that_never_stops_is_a_failed_source_and_a_failed_verdict(monkeypatch):
    """The engine's output read back with a sphere that never stops: its Result is failed (not finite), and the
    suite's row says FAILED — no agree, no differs-as-expected, on what was not computed. No engine is run: its
    read is replaced, and its deck is never written to a process (runner.run replaced)."""
    from demcheck.case import load
    from demcheck.comparisons import scenario_rows, verdicts
    from demcheck.comparisons.sources import ADAPTIVE
    from demcheck.comparisons.records import CaseResult
    from demcheck.comparisons.suite import Options
    from demcheck.engines import registry, run as runner
    from demcheck.laws.model import resolve
    from demcheck.resources import case_path

    c = load(case_path("suite/beyond-twist.toml"))
    eng = registry.get("lammps")
    monkeypatch.setattr(runner, "run", lambda *a, **k: runner.RunOutput("lammps", "test", __import__("pathlib").Path(
        "/nonexistent-demcheck-test"), "", 0.0))
    monkeypatch.setattr(type(eng), "read_scenario", lambda self, case, lay, wd: {
        "t": np.arange(10.0), "x": np.zeros((10, 3)), "v": np.zeros((10, 3)),
        "omega": np.tile([0.0, 0.0, 50.0], (10, 1))})
    opts = Options(engines=("lammps",))
    entry = CaseResult(c.name, model=resolve(c).describe(), scales={})
    found = {"lammps": {"found": True}}
    scenario_rows.engine_rows(c, entry, opts, found, ADAPTIVE.run(c).metrics())
    comps = entry.comparisons
    assert entry.sources["lammps"].status == "failed"
    assert [x.verdict for x in comps] == [verdicts.FAILED] and "not finite" in comps[0].reason
