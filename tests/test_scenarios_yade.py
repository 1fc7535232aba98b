"""The scenario cases beyond sliding in Yade 2023.02a: a sphere on a wall (rolling, incline, twist) runs for real
from the script demcheck writes (engines/yade/scenario.py: CohFrictMat + Law2_ScGeom6D_CohFrictPhys_CohesionMoment,
incremental, on a fixed box) and meets its twin (reference/beyond_yade.py: Yade's leap-frog, whose first step
already loads the histories) — measured 8e-15 (incline-linear), 8.7e-13 (twist), 1.4e-12 (rolling-linear). The
twin's laws are checked against the closed forms here, never against the engine's numbers: type C at its limit
rolls down the incline at tan θc = μr, the twisting spring at its limit stops the spin at I ω0/(μtw m g).

The pair scenarios (engines/yade/pair.py): DMT's pull-off through Mindlin (``gamma`` = w/2, ``includeAdhesion``) is
exact and meets its twin to the bit (measured 0 and 0 on the pull-off case with adhesion = "dmt"), its largest
tension DMT's 2πwR̄ less the Hertz force at the last overlap in contact (1e-12); the conduction through
ThermalEngine is approximate (its conductance 2(k0 + k1)r0r1/d ignores the contact's size: 63× the case's
Batchelor–O'Brien conductance) and meets its twin to the bit, and its time constant is forward Euler's
−dt/ln(1 − dt/τ) of Yade's own H (closed form). JKR, the adhesive impact (JKR's), sjkr and the area conductance
are not expressible, each with its reason."""

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


@pytest.mark.parametrize("name, sets, why", [
    ("pull-off", (), "has no JKR law"),
    ("adhesive-impact", (), "the adhesive impact is JKR's"),
    ("pull-off-sjkr", (), "no cohesion proportional to the contact area"),
    ("conduction", ("contact.heat=area", "contact.k=1e6"), "not a conductance per area"),
])
def test_yade_says_why_it_cannot_run_the_others(name, sets, why):
    planned = {p.source.label: p for p in plan(case(name, sets))}
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


def _run_and_read(tmp_path, c, text):
    """A changed scenario script run by hand, its output read as the engine's run is."""
    from demcheck.engines import registry

    _run_script(tmp_path, text)
    eng = registry.get("yade")
    laws = eng.scenario_twin_laws(c, scenario.mapping(c, eng).require())
    return eng.read_scenario(c, scenario.layout(c, laws), tmp_path)


@pytest.mark.engine("yade")
@pytest.mark.parametrize("change", ["no always_use_moment_law", "poisson 0"])
def test_yade_traps_of_the_cohesion_moment_law(tmp_path, change):
    """Run by hand (the guard refuses a changed script): without always_use_moment_law a contact without cohesion
    gets no moments, and ν = 0 leaves no shear, rolling or twisting stiffness — the incline's sphere rolls freely
    (θc ≈ 0, measured 8.6e-7) or slides without turning (ω = 0), far from atan μr."""
    import re

    from demcheck.reference.scenarios import stepped_metrics

    c = case("incline-linear", EXACT_CASES["incline-linear"])
    dk = scenario.deck(c, "yade")
    text = dk.text.replace("always_use_moment_law=True", "always_use_moment_law=False") \
        if change.startswith("no") else re.sub(r"poisson=[0-9.e-]+", "poisson=0.0", dk.text)
    assert text != dk.text
    data = _run_and_read(tmp_path, c, text)
    angle = stepped_metrics(c, data)["incline_critical_angle"]
    assert abs(angle) < 0.5 * math.atan(0.1) or angle < 0.0, angle
    if change == "poisson 0":
        assert abs(data["omega"][-1]).max() == 0.0


# ----------------------------------------------------------------------------- the pair scenarios

W, R, E, NU = 0.05, 1e-3, 5e6, 0.45  # the pull-off case: work of adhesion, radius, rubber's E and ν
R_BAR, E_STAR = 0.5 * R, E / (2.0 * (1.0 - NU ** 2))


def dmt_pull():
    return case("pull-off", ["contact.adhesion=dmt"])


def test_dmt_maps_exactly_onto_mindlin_with_gamma_half_w():
    mp = scenario.mapping(dmt_pull(), "yade")
    assert mp.fidelity == "exact" and not mp.reasons, mp.reasons
    assert mp.native.props["gamma"] == 0.5 * W


def test_the_yade_dmt_twin_law_is_dmt():
    """Yade's Mindlin constants (its own formulas, reference/beyond_yade.py) against DMT's closed form: kno =
    (4/3)E*√R̄ with E* = E/(2(1 − ν²)), the adhesion 4πR̄γ = 2πwR̄ for γ = w/2; no force below δ = 0."""
    from demcheck.reference import beyond_yade

    kno, adhesion = beyond_yade.mindlin_constants(E, NU, R, E, NU, R, 0.5 * W)
    assert abs(kno / (4.0 / 3.0 * E_STAR * math.sqrt(R_BAR)) - 1) < 1e-15
    assert abs(adhesion / (2.0 * math.pi * W * R_BAR) - 1) < 1e-15
    assert beyond_yade.mindlin_dmt_force(kno, adhesion, 0.0) == -adhesion
    assert beyond_yade.mindlin_dmt_force(kno, adhesion, -1e-12) == 0.0


@pytest.mark.engine("yade")
def test_yade_dmt_pull_is_its_twin_and_dmts_closed_form():
    c = dmt_pull()
    got = scenario.run(c, "yade")
    assert got.ok, got.message
    got, twin = got.metrics(), scenario.twin(c, "yade").metrics()
    assert abs(got["pull_off_force"] - twin["pull_off_force"]) <= 1e-9 * twin["pull_off_force"]
    assert abs(got["separation_at_pull_off"] - twin["separation_at_pull_off"]) <= 1e-12
    # the largest tension is at the last overlap in contact δ_l ≥ 0 (within one step of the pull, 1.4e-10 m):
    # 2πwR̄ − (4/3)E*√R̄ δ_l^{3/2} (measured 7.1e-11 m, 3.5e-7 below 2πwR̄)
    d_l = got["separation_at_pull_off"]
    assert 0.0 <= d_l < 1.5e-10
    closed = 2.0 * math.pi * W * R_BAR - 4.0 / 3.0 * E_STAR * math.sqrt(R_BAR) * d_l ** 1.5
    assert abs(got["pull_off_force"] / closed - 1) < 1e-12


@pytest.mark.engine("yade")
@pytest.mark.parametrize("change, factor", [("includeAdhesion=True", None), ("gamma=", 2.0)])
def test_yade_traps_of_mindlins_dmt(tmp_path, change, factor):
    """Run by hand (the guard refuses a changed script): ``gamma`` without ``includeAdhesion`` adds no adhesion
    (the pull never pulls: no pull-off), and ``gamma`` is a surface energy — set to the work of adhesion w it
    doubles DMT's pull-off force (4πwR̄)."""
    import re

    from demcheck.reference.scenarios import stepped_metrics

    c = dmt_pull()
    text = scenario.deck(c, "yade").text
    if factor is None:
        changed = text.replace(change, "includeAdhesion=0")
    else:
        changed = re.sub(r"gamma=[0-9.e-]+", f"gamma={W!r}", text)
    assert changed != text
    data = _run_and_read(tmp_path, c, changed)
    force = stepped_metrics(c, data)["pull_off_force"]
    if factor is None:
        assert math.isnan(force) and data["fn"].min() >= 0.0
    else:
        assert abs(force / (2.0 * math.pi * W * R_BAR) - factor) < 1e-6


def _thermal_tau(c):
    """Forward Euler's time constant of ThermalEngine's H = 4kR²/(2R − δ) (like spheres), C = m c_p, at the
    layout's step: the difference falls by (1 − dt·H(1/C0 + 1/C1)) a step, so τ = −dt/ln(that)."""
    from demcheck.engines import registry

    eng = registry.get("yade")
    lay = scenario.layout(c, eng.scenario_twin_laws(c, scenario.mapping(c, eng).require()))
    delta, k, cp = c.run.overlap, 45.0, 500.0
    h = 4.0 * k * 2e-3 ** 2 / (2 * 2e-3 - delta)
    cap = c.mass(0) * cp
    return -lay.dt / math.log(1.0 - lay.dt * 2.0 * h / cap), cap / (2.0 * h)


@pytest.mark.engine("yade")
def test_yade_conduction_is_its_twin_and_forward_eulers_closed_form():
    c = case("conduction")
    entry, comps = rows(c)
    src = entry["sources"]["yade"]
    assert src["status"] == "ok" and src["fidelity"] == "approximate"
    assert [(x.metric, x.verdict) for x in comps] == [("heat_time_constant", EXPECTED)]
    tau = comps[0].value
    assert abs(tau / src["twin_metrics"]["heat_time_constant"] - 1) <= 1e-9
    discrete, continuous = _thermal_tau(c)
    assert abs(tau / discrete - 1) < 1e-9
    assert abs(tau / continuous - 1) < 2e-3  # forward Euler's dt/(2τ) = 1.6e-3
    # the case's Batchelor–O'Brien conductance 2 ks √(R̄δ) gives τ 63× longer
    assert 60.0 < comps[0].reference / tau < 66.0


@pytest.mark.engine("yade")
def test_yade_thermal_engine_resets_the_temperatures_at_its_first_step(tmp_path):
    """Run by hand: the temperatures set before ThermalEngine's first call are replaced by particleT0 (the pair
    stays at one temperature: nothing is conducted), which is why the script sets them after that step."""
    c = case("conduction")
    text = scenario.deck(c, "yade").text
    lines = text.split("\n")
    del lines[lines.index("O.step()")]  # the script's first step, before it sets the case's temperatures
    changed = "\n".join(lines)
    data = _run_and_read(tmp_path, c, changed)
    assert data["dT"][0] == 100.0 and (data["dT"][1:] == 0.0).all()


def test_the_yade_pair_guard_refuses_a_changed_script():
    from demcheck.errors import DemcheckError

    for c in (dmt_pull(), case("conduction")):
        dk = scenario.deck(c, "yade")
        dk.check(dk.text, {})
        for bad in (dk.text.replace("O.step()", "__import__('os')"), dk.text.replace("'xyzXYZ'", "'xyz'"),
                    dk.text.replace("O.dt = DT", "O.dt = DT\nO.pause()")):
            with pytest.raises(DemcheckError):
                dk.check(bad, {})
