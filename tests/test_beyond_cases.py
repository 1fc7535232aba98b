"""The slots beyond sliding in case files: [contact] rolling / twisting / adhesion / heat with their parameters,
[run] scenario, and `collide` / `models` on them. The scenario metrics of the shipped cases are checked against
their closed forms (reference/beyond.py), each at the solver's tolerance (rtol 1e-11 → 1e-9)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from demcheck import api
from demcheck import case as C
from demcheck.errors import ConfigError, UnsupportedByEngine
from demcheck.laws.adhesion import JkrAdhesion
from demcheck.laws.rolling import CAP_TOTAL, ConstantTorqueRolling, EpsdRolling
from demcheck.laws.twisting import SdsTwisting
from demcheck.reference import beyond as b
from demcheck.reference.scenarios import SCENARIO_METRICS, scenario_metrics
from demcheck.resources import case_path

SCENARIO_CASES = {"rolling": "beyond-rolling", "incline": "beyond-incline", "twist": "beyond-twist",
                  "pull_off": "beyond-pull-off", "adhesive_impact": "beyond-adhesive-impact",
                  "conduction": "beyond-conduction"}


def load(scenario, *overrides):
    return C.load(case_path(f"suite/{SCENARIO_CASES[scenario]}.toml"), list(overrides))


def test_the_contact_carries_the_records_resolved_for_the_pair():
    from demcheck.laws.model import resolve

    c = resolve(load("rolling")).contact
    assert c.rolling == ConstantTorqueRolling(mu_r=0.1, r_roll=1.59e-3, full_direction=False)
    assert c.ids() == {"normal": "hertz", "damping": "none", "tangential": "spring", "rolling": "constant_torque",
                       "twisting": "none", "adhesion": "none", "heat": "none"}
    inc = resolve(load("incline", "contact.cap=total")).contact.rolling
    assert isinstance(inc, EpsdRolling) and inc.cap == CAP_TOTAL and inc.k_r == 1e-3 and inc.r_roll == 2e-3
    jkr = resolve(load("pull_off")).contact.adhesion
    assert jkr == JkrAdhesion(r_eff=5e-4, e_eff=1.0 / (2 * (1 - 0.45 ** 2) / 5e6), w=0.05)
    assert resolve(load("twist")).contact.twisting == SdsTwisting(1e-3, 0.0, 5e-4)


@pytest.mark.parametrize("scenario", sorted(SCENARIO_CASES))
def test_each_shipped_scenario_against_its_closed_form(scenario):
    case = load(scenario)
    got, closed = scenario_metrics(case), scenario_metrics(case, closed=True)
    assert set(got) == set(SCENARIO_METRICS[scenario])
    for k, v in closed.items():
        assert math.isfinite(got[k]) and abs(got[k] - v) <= 1e-9 * abs(v), (k, got[k], v)


def test_closed_forms_are_the_textbook_numbers():
    """Independent of the records' plumbing: the shipped cases' numbers into the formulas by hand."""
    m = 2500.0 * 4 / 3 * math.pi * 1.59e-3 ** 3
    got = scenario_metrics(load("rolling"))
    a = 5 / 7 * 0.1 * 9.81
    assert abs(got["rolling_stop_time"] - 0.02 / a) < 1e-9 * 0.02 / a
    assert abs(got["rolling_distance"] - 0.02 ** 2 / (2 * a)) < 1e-9 * 0.02 ** 2 / (2 * a)
    assert abs(scenario_metrics(load("incline"))["incline_critical_angle"] - math.atan(0.1)) < 1e-12
    t = 0.4 * m * 1.59e-3 ** 2 * 50.0 / (5e-4 * m * 9.81)
    assert abs(scenario_metrics(load("twist"))["twist_stop_time"] - t) < 1e-9 * t
    assert abs(scenario_metrics(load("pull_off"))["pull_off_force"] - 1.5 * math.pi * 0.05 * 5e-4) < 1e-15
    ms = 7800.0 * 4 / 3 * math.pi * 8e-9
    h = 2 * 45.0 * math.sqrt(1e-3 * 1e-6)
    tau = 1 / (h * 2 / (ms * 500.0))
    assert abs(scenario_metrics(load("conduction"))["heat_time_constant"] - tau) < 1e-9 * tau


def test_collide_prints_the_scenario_metrics():
    p = subprocess.run([sys.executable, "-m", "demcheck", "collide", "beyond-rolling", "--json"],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["status"] == "ok" and d["model"]["rolling"] == "constant_torque"
    t, s = b.rolling_stop_closed(0.1, 1.59e-3, 1.59e-3, 0.02, 9.81)
    assert abs(d["metrics"]["rolling_stop_time"] - t) < 1e-9 * t and abs(d["metrics"]["rolling_distance"] - s) < 1e-9 * s
    assert api.collide(case_path("suite/beyond-conduction.toml")).metrics()["heat_time_constant"] > 0


@pytest.mark.parametrize("overrides, key, rule", [
    (["contact.rolling=foo"], "contact.rolling",
     "must be one of none, ai_epsd, ai_viscous, constant_torque, epsd, viscous"),
    (["contact.mu_r=-1"], "contact.mu_r", "must be >= 0"),
    (["contact.mu_r=true"], "contact.mu_r", "must be a finite number"),
    (["contact.full_direction=1"], "contact.full_direction", "must be true or false"),
    (["contact.k_tw=1"], "contact.k_tw", "is not a parameter of normal 'hertz' or tangential 'spring_sliding', rolling"),
    (["run.scenario=collision"], "contact.rolling", "is solved in the scenarios beyond sliding only"),
    (["run.scenario=spin"], "run.scenario", "must be one of collision, rolling"),
    (["run.scenario=twist"], "contact.twisting", "needs twisting = \"sds\" or \"marshall\""),
    (["run.overlap=1e-6"], "run.overlap", "is read by run.scenario = \"conduction\" only"),
    (["particles.0.position=[0,0,2e-3]"], "particles.0.position", "rests on the wall"),
    (["particles.0.velocity=[0,0,0]"], "particles.0.velocity", "needs a velocity along the wall"),
    (["run.gravity=[0,0,9.81]"], "run.gravity", "needs gravity pressing the sphere onto the wall"),
    (["run.gravity=[1,0,-9.81]"], "run.gravity", "is on a level wall"),
])
def test_bad_rolling_input_is_one_line_naming_key_value_and_rule(overrides, key, rule):
    with pytest.raises(ConfigError) as e:
        load("rolling", *overrides)
    assert e.value.key == key and rule in e.value.rule


@pytest.mark.parametrize("scenario, overrides, key, rule", [
    ("incline", ["contact.cap=x"], "contact.cap", "must be one of spring, total"),
    ("incline", ["contact.k_r=0"], "contact.k_r", "must be > 0"),
    ("twist", ["contact.mu_tw=-1"], "contact.mu_tw", "must be >= 0"),
    ("twist", ["particles.0.angular_velocity=[1,0,0]"], "particles.0.angular_velocity", "spin about the wall"),
    ("pull_off", ["contact.w=0"], "contact.w", "must be > 0"),
    ("pull_off", ["contact.break_at=never"], "contact.break_at", "must be one of displacement, load"),
    ("adhesive_impact", ["contact.adhesion=dmt"], "contact.adhesion", "needs adhesion = \"jkr\""),
    ("conduction", ["materials.steel.specific_heat=0"], "materials.steel.specific_heat", "must be > 0"),
    ("conduction", ["run.temperatures=[300]"], "run.temperatures", "must be two temperatures"),
    ("conduction", ["contact.k=-1"], "contact.k", "must be > 0"),
    ("conduction", ["contact.heat=none"], "contact.k", "is not a parameter of normal 'hertz'"),
])
def test_bad_scenario_input_is_refused_before_any_work(scenario, overrides, key, rule):
    with pytest.raises(ConfigError) as e:
        load(scenario, *overrides)
    assert e.value.key == key and rule in e.value.rule, e.value


def test_a_missing_required_parameter_is_named():
    text = case_path("suite/beyond-pull-off.toml").read_text().replace("w = 0.05\n", "")
    with pytest.raises(ConfigError) as e:
        C.loads(text)
    assert e.value.key == "contact.w" and "required by adhesion model 'jkr'" in e.value.rule


def test_an_adhesive_impact_of_a_cohesion_is_refused():
    """sjkr has its pull-off (added to an elastic Hertz law, tests/test_laws_beyond.py), not an impact's closed
    form."""
    text = case_path("suite/beyond-adhesive-impact.toml").read_text().replace('adhesion = "jkr"\nw = 0.05',
                                                                             'adhesion = "sjkr"\nk_c = 1e3')
    with pytest.raises(ConfigError) as e:
        C.loads(text)
    assert e.value.key == "contact.adhesion" and 'needs adhesion = "jkr"' in e.value.rule


def test_marshall_takes_mu_t_from_the_pairs_friction():
    from demcheck.laws.model import resolve

    text = case_path("suite/beyond-twist.toml").read_text().replace(
        'twisting = "sds"\nk_tw = 1e-3\ngamma_tw = 0.0\nmu_tw = 5e-4', 'twisting = "marshall"\nkt = 1e3')
    law = resolve(C.loads(text)).contact.twisting
    assert law.id == "marshall" and law.mu_t == 0.3 and law.kt == 1e3
    got, closed = (scenario_metrics(C.loads(text), closed=x)["twist_stop_time"] for x in (False, True))
    assert abs(got - closed) < 1e-9 * closed


def test_engines_refuse_a_scenario_they_do_not_run():
    from demcheck.comparisons.sources import Source

    with pytest.raises(UnsupportedByEngine, match="the sphere.s contact with the wall: Kratos. tangential force is"):
        api.collide(case_path("suite/beyond-rolling.toml"), source="kratos")
    with pytest.raises(ConfigError, match="adaptive reference only"):
        Source.reference("verlet").run(load("twist"))


def test_models_lists_the_new_laws():
    rows = {(r["slot"], r["id"]): r for r in api.models()}
    for key in [("rolling", "constant_torque"), ("rolling", "viscous"), ("rolling", "epsd"), ("twisting", "sds"),
                ("twisting", "marshall"), ("adhesion", "jkr"), ("adhesion", "dmt"), ("adhesion", "sjkr"),
                ("heat", "radius"), ("heat", "area"), ("heat", "lens")]:
        assert key in rows and rows[key]["source"] and rows[key]["formula"]
    assert set(rows[("adhesion", "jkr")]["params"]) == {"w", "break_at"}
    assert [r["slot"] for r in api.models("marshall")] == ["twisting"]
    p = subprocess.run([sys.executable, "-m", "demcheck", "models"], capture_output=True, text=True)
    assert p.returncode == 0 and "constant_torque" in p.stdout and "sjkr" in p.stdout


# ----------------------------------------------------------------------------- the suite


def _verify(tmp_path, files):
    return api.verify([str(f) for f in files], engines=(), report=tmp_path / "r")


def test_verify_judges_each_scenario_against_its_closed_form(tmp_path):
    files = [case_path(f"suite/{name}.toml") for name in SCENARIO_CASES.values()]
    res = _verify(tmp_path, files)
    assert res["failed"] == 0 and len(res["cases"]) == 6
    for entry in res["cases"]:
        comps = entry["comparisons"]
        assert entry["status"] == "ok" and entry["scenario"] in SCENARIO_CASES
        assert sorted(c["metric"] for c in comps) == sorted(SCENARIO_METRICS[entry["scenario"]])
        assert all(c["source"] == "closed-form" and c["verdict"] == "agree" and c["rel_diff"] <= 1e-9
                   for c in comps), comps
    assert "(rolling)" in (Path(res["report"]) / "report.md").read_text()


def test_verify_fails_a_scenario_whose_solve_misses_its_closed_form(tmp_path, monkeypatch):
    from demcheck.reference import scenarios

    real = scenarios._b.twist_decay
    monkeypatch.setattr(scenarios._b, "twist_decay",
                        lambda *a, **k: {"twist_stop_time": real(*a, **k)["twist_stop_time"] * (1 + 1e-6)})
    res = _verify(tmp_path, [case_path("suite/beyond-twist.toml")])
    (entry,) = res["cases"]
    assert res["failed"] == 1 and entry["status"] == "unexpected"


@pytest.mark.parametrize("name, solver, metric", [("pull-off-sjkr", "cohesive_pull_off", "pull_off_force"),
                                                   ("rolling-viscous", "efold_time", None)])
def test_verify_fails_sjkr_and_viscous_solves_that_miss_their_closed_forms(tmp_path, monkeypatch, name, solver,
                                                                           metric):
    """A planted error of 1e-6 in the sjkr pull's tension or in type B's time constant fails verify."""
    from demcheck.reference import scenarios

    real = getattr(scenarios._b, solver)
    if metric:
        monkeypatch.setattr(scenarios._b, solver, lambda *a, **k: {**real(*a, **k),
                                                                     metric: real(*a, **k)[metric] * (1 + 1e-6)})
    else:
        monkeypatch.setattr(scenarios._b, solver, lambda *a, **k: real(*a, **k) * (1 + 1e-6))
    res = _verify(tmp_path, [case_path(f"suite/beyond-{name}.toml")])
    (entry,) = res["cases"]
    assert res["failed"] == 1 and entry["status"] == "unexpected"


def test_verify_never_agrees_on_a_scenario_that_computed_nothing(tmp_path, monkeypatch):
    from demcheck.reference import scenarios

    monkeypatch.setattr(scenarios._b, "rolling_on_plane", lambda *a, **k: {})  # no stop found
    res = _verify(tmp_path, [case_path("suite/beyond-rolling.toml")])
    (entry,) = res["cases"]
    assert res["failed"] == 1 and entry["status"] == "failed" and entry["sources"]["reference"]["status"] == "failed"


def test_sweep_solves_a_scenario_at_each_point_and_dt_refuses_one():
    p = subprocess.run([sys.executable, "-m", "demcheck", "sweep", "beyond-rolling", "--vary", "contact.mu_r=0.01:0.04:2",
                        "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)["rows"]
    for row in rows:
        t, _ = b.rolling_stop_closed(row["contact.mu_r"], 1.59e-3, 1.59e-3, 0.02, 9.81)
        assert row["status"] == "ok" and abs(row["rolling_stop_time"] - t) < 1e-9 * t
    d = subprocess.run([sys.executable, "-m", "demcheck", "dt", "beyond-twist"], capture_output=True, text=True)
    assert d.returncode == 2 and "run.scenario = 'twist': must be \"collision\": a time step is recommended" in d.stderr
