"""The scenario cases beyond sliding in Yade 2023.02a: a sphere on a wall (rolling, incline, twist) runs for real
from the script demcheck writes (engines/yade/scenario.py: CohFrictMat + Law2_ScGeom6D_CohFrictPhys_CohesionMoment,
incremental, on a fixed box) and meets its twin (reference/beyond_yade.py: Yade's leap-frog, whose first step
already loads the histories) — measured 8e-15 (incline-linear), 8.7e-13 (twist), 1.4e-12 (rolling-linear). The
twin's laws are checked against the closed forms here, never against the engine's numbers: type C at its limit
rolls down the incline at tan θc = μr, the twisting spring at its limit stops the spin at I ω0/(μtw m g).
Pull-off, adhesive impact and conduction are not expressible, each with its reason."""

from __future__ import annotations

import math

import pytest

from demcheck.case import load
from demcheck.comparisons.sources import plan
from demcheck.comparisons.verdicts import AGREE, EXPECTED, NOT_EXPRESSIBLE
from demcheck.engines import scenario
from demcheck.resources import case_path
from tests.scenario_rows import engine_scenario_rows

# the dashpot-free variants of the suite's linear cases: Yade's CohFrictPhys expresses them exactly
EXACT_CASES = {
    "incline-linear": ["materials.steel.restitution=1.0"],
    "twist": ["contact.normal=lsd", "contact.kn=1e5", "materials.glass.restitution=1.0"],
}


def case(name, sets=()):
    return load(case_path(f"suite/beyond-{name}.toml"), list(sets))


@pytest.mark.parametrize("name", sorted(EXACT_CASES))
def test_the_dashpot_free_linear_cases_map_exactly(name):
    mp = scenario.mapping(case(name, EXACT_CASES[name]), "yade")
    assert mp.fidelity == "exact", mp.reasons


@pytest.mark.engine("yade")
@pytest.mark.parametrize("name", sorted(EXACT_CASES))
def test_yade_meets_its_twin_on_each_exact_mapping(name):
    c = case(name, EXACT_CASES[name])
    got, twin = scenario.run(c, "yade"), scenario.twin(c, "yade")
    assert got.ok and twin.ok, got.message
    for k, v in got.meta["scenario_metrics"].items():
        assert math.isfinite(v) and abs(v / twin.meta["scenario_metrics"][k] - 1) <= 1e-9, (k, v)


def test_the_yade_twin_meets_the_closed_forms():
    """The twin's law (not the engine's numbers) against the closed forms: the incline's critical angle atan μr
    and the twist's stop I ω0/(μtw m g) (the spring winds up first: a few steps late)."""
    c = case("incline-linear", EXACT_CASES["incline-linear"])
    angle = scenario.twin(c, "yade").meta["scenario_metrics"]["incline_critical_angle"]
    assert abs(angle / math.atan(0.1) - 1) < 2e-5
    c = case("twist", EXACT_CASES["twist"])
    t = scenario.twin(c, "yade").meta["scenario_metrics"]["twist_stop_time"]
    p = c.particles[0]
    closed = 0.4 * c.mass(0) * p.radius ** 2 * 50.0 / (5e-4 * c.mass(0) * 9.81)
    assert abs(t / closed - 1) < 1e-3


def rows(c):
    return engine_scenario_rows(c, "yade")


@pytest.mark.engine("yade")
@pytest.mark.parametrize("name, verdicts", [
    ("rolling-linear", {"rolling_stop_time": AGREE, "rolling_distance": EXPECTED}),
    ("rolling", {"rolling_stop_time": AGREE, "rolling_distance": EXPECTED}),
    ("incline-linear", {"incline_critical_angle": AGREE}),
    ("incline", {"incline_critical_angle": EXPECTED}),
    ("twist", {"twist_stop_time": AGREE}),
])
def test_the_suite_rows_of_yade(name, verdicts):
    entry, comps = rows(case(name))
    src = entry["sources"]["yade"]
    assert src["status"] == "ok" and src["fidelity"] == "approximate"
    assert {x.metric: x.verdict for x in comps} == verdicts, [(x.metric, x.rel_diff, x.reason) for x in comps]
    for x in comps:
        assert abs(x.value - src["twin_metrics"][x.metric]) <= 1e-9 * abs(x.value)


@pytest.mark.parametrize("name, why", [
    ("pull-off", "no JKR or DMT normal law"),
    ("adhesive-impact", "no JKR or DMT normal law"),
    ("conduction", "ThermalEngine"),
])
def test_yade_says_why_it_cannot_run_the_others(name, why):
    planned = {p.source.label: p for p in plan(case(name))}
    assert planned["yade"].status == NOT_EXPRESSIBLE and why in planned["yade"].why


def test_the_yade_scenario_guard_refuses_a_changed_script():
    from demcheck.errors import DemcheckError

    c = case("incline-linear")
    text = scenario.deck(c, "yade").text
    with pytest.raises(DemcheckError):
        scenario.deck(c, "yade").check(text.replace("O.step()", "__import__('os')"), {})


def _run_script(tmp_path, text):
    import subprocess

    from demcheck.engines import discovery

    (tmp_path / "s.py").write_text(text)
    exe = discovery.find("yade").executable
    r = subprocess.run([exe, "-x", "-n", "s.py"], cwd=tmp_path, env=discovery.engine_env(), capture_output=True,
                       text=True, timeout=900)
    assert r.returncode == 0, (r.stdout + r.stderr)[-2000:]


@pytest.mark.engine("yade")
@pytest.mark.parametrize("change", ["no always_use_moment_law", "poisson 0"])
def test_yade_traps_of_the_cohesion_moment_law(tmp_path, change):
    """Run by hand (the guard refuses a changed script): without always_use_moment_law a contact without cohesion
    gets no moments, and ν = 0 leaves no shear, rolling or twisting stiffness — the incline's sphere rolls freely
    (θc ≈ 0, measured 8.6e-7) or slides without turning (ω = 0), far from atan μr."""
    import re

    from demcheck.engines import registry
    from demcheck.reference.scenarios import stepped_metrics

    c = case("incline-linear", EXACT_CASES["incline-linear"])
    dk = scenario.deck(c, "yade")
    text = dk.text.replace("always_use_moment_law=True", "always_use_moment_law=False") \
        if change.startswith("no") else re.sub(r"poisson=[0-9.e-]+", "poisson=0.0", dk.text)
    assert text != dk.text
    _run_script(tmp_path, text)
    eng = registry.get("yade")
    laws = eng.scenario_twin_laws(c, scenario.mapping(c, eng).require())
    data = eng.read_scenario(c, scenario.layout(c, laws), tmp_path)
    angle = stepped_metrics(c, data)["incline_critical_angle"]
    assert abs(angle) < 0.5 * math.atan(0.1) or angle < 0.0, angle
    if change == "poisson 0":
        assert abs(data["omega"][-1]).max() == 0.0
