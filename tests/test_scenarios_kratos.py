"""The scenarios beyond sliding in Kratos DEM 10.4.4, run for real from the deck demcheck writes
(engines/kratos/scenario.py), read into the scenario's metrics, and judged as the suite judges them
(comparisons/scenario_rows.py): the engine against its twin (Kratos' cohesive laws stepped with its
Velocity_Verlet: reference/beyond_kratos.py) at ≤ 1e-9, and against the reference's solve with a verdict.

Closed forms the golden values come from (never from the code under test): DMT's pull-off force 2πwR̄ (Kratos'
DMT is the seed's law: exact); Kratos' JKR with the Hertz radius, F = Ax² − Bx in x = δ^{3/4}
(A = (4/3)E*√R̄, B = √(8πwE*)R̄^{3/4}), whose largest tension is B²/4A = (3/2)πwR̄ — JKR's pull-off force — at
δ* = (B/2A)^{4/3} > 0, the contact ending at δ = 0; without hysteresis an impact keeps its energy (e = 1).

Measured (Kratos 10.4.4; engine vs twin, engine vs reference):

* pull-off (JKR, approximate): 0 and 0 from the twin; the force 1e-16 from (3/2)πwR̄ — agree; the separation
  2.3e-10 m against δ_f = −8.09e-7 m — differs as expected;
* adhesive-impact (JKR, approximate): e 1.0000005 (twin 5e-14 apart) against 0.9128; v_s 0 against 0.408 m/s —
  differs as expected;
* pull-off with DMT (exact): engine = twin to the bit; 2πwR̄ less the Hertz force at the last overlap in contact;
* rolling-linear (ConstantTorque, approximate): engine = twin to 7e-11 of each series' largest value in every
  sample (x, v, ω) and 1e-15 in the stop time; the stop is the closed form t = 7v0/(5μr g) lengthened by the arm
  R − δ (× 1/(1 − δ/R), δ/R = 2.6e-6) and ½dt late (the runner's start: the first half step has no torque): 8e-9
  from that, 2.3e-5 from the bare closed form (agree), the distance 4.05e-5 from it (differs as expected);
* the same sphere under ViscousTorque (type B, Cr = 1e-8 N·m·s): engine = twin likewise; the e-fold time 2.0e-7
  from 1.4mR²/Cr;
* beyond-incline-linear with type A (kt = 1e6 N/m, so that Kratos' Linear law holds it): engine = twin to 2e-11 in
  every sample, the angle 5.5e-7 from atan μr.

The rolling closed forms: the angular momentum about the contact point L = (7/5) m R v (rolling without slip)
falls at the rate of the rolling torque M = μr Rr |Fn| (the friction force has no moment about that point), so
the sphere stops at t = L0/M = 7 v0 R/(5 μr Rr g) (Ai et al. 2011); a viscous torque −Cr ω gives
v = v0 exp(−t/T), T = (7/5) m R²/Cr.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from demcheck.case import load, loads
from demcheck.comparisons.verdicts import AGREE, EXPECTED
from demcheck.errors import ConfigError
from demcheck.resources import case_path
from tests.scenario_rows import engine_scenario_rows

# case → {metric: verdict}, the fidelity of the mapping
EXPECT = {
    "pull-off": ({"pull_off_force": AGREE, "separation_at_pull_off": EXPECTED}, "approximate"),
    "adhesive-impact": ({"restitution": EXPECTED, "capture_velocity": EXPECTED}, "approximate"),
}
W, R_BAR = 0.05, 0.5e-3  # the pull-off case's work of adhesion (J/m²) and R̄ = R/2 (m)


def case(name):
    return load(case_path(f"suite/beyond-{name}.toml"))


def dmt_pull():
    return loads(case_path("suite/beyond-pull-off.toml").read_text().replace('adhesion = "jkr"', 'adhesion = "dmt"'))


@functools.lru_cache(maxsize=None)
def rows(name):
    return engine_scenario_rows(case(name), "kratos")


@pytest.mark.engine("kratos")
@pytest.mark.parametrize("name", sorted(EXPECT))
def test_kratos_runs_the_adhesive_case_and_meets_its_twin(name):
    verdicts, fidelity = EXPECT[name]
    entry, comps = rows(name)
    src = entry["sources"]["kratos"]
    assert src["status"] == "ok" and src["fidelity"] == fidelity, src
    assert {x.metric: x.verdict for x in comps} == verdicts, [(x.metric, x.verdict, x.reason) for x in comps]
    for x in comps:
        twin = src["twin_metrics"][x.metric]
        assert math.isfinite(x.value) and math.isfinite(twin)
        assert abs(x.value - twin) <= 1e-9 * max(abs(twin), 1e-300) or abs(x.value - twin) <= 1e-12
        if x.verdict == EXPECTED:
            assert x.reason.startswith("approximate mapping: ")


@pytest.mark.engine("kratos")
def test_kratos_jkr_pull_off_is_jkrs_force_at_a_positive_overlap():
    """Kratos' JKR (the Hertz radius) reaches JKR's (3/2)πwR̄ exactly, but breaks at δ = 0 (no neck)."""
    entry, _ = rows("pull-off")
    got = entry["sources"]["kratos"]["metrics"]
    assert abs(got["pull_off_force"] / (1.5 * math.pi * W * R_BAR) - 1) < 1e-6
    assert 0.0 <= got["separation_at_pull_off"] < 1e-9  # the last overlap in contact: within a step of 0


@pytest.mark.engine("kratos")
def test_kratos_jkr_impact_keeps_its_energy():
    entry, _ = rows("adhesive-impact")
    got = entry["sources"]["kratos"]["metrics"]
    assert abs(got["restitution"] - 1.0) < 1e-5 and got["capture_velocity"] < 5e-3


@pytest.mark.engine("kratos")
def test_kratos_dmt_is_exact_and_its_run_is_its_twin():
    from demcheck.engines import scenario

    c = dmt_pull()
    mp = scenario.mapping(c, "kratos")
    assert mp.fidelity == "exact" and not mp.reasons
    eng = scenario.run(c, "kratos")
    assert eng.ok, eng.message
    got, twin = eng.metrics(), scenario.twin(c, "kratos").metrics()
    assert abs(got["pull_off_force"] - twin["pull_off_force"]) <= 1e-9 * twin["pull_off_force"]
    assert abs(got["separation_at_pull_off"] - twin["separation_at_pull_off"]) <= 1e-12
    # DMT's closed form at the last overlap in contact δ_l > 0 (the largest tension of the sampled path):
    # 2πwR̄ − (4/3)E*√R̄ δ_l^{3/2}, E* = E/(2(1 − ν²)) of the case's rubber (measured 1.0e-6 below 2πwR̄)
    e_star = 5e6 / (2.0 * (1.0 - 0.45 ** 2))
    d_l = got["separation_at_pull_off"]
    assert 0.0 < d_l < 1e-9
    closed = 2.0 * math.pi * W * R_BAR - 4.0 / 3.0 * e_star * math.sqrt(R_BAR) * d_l ** 1.5
    assert abs(got["pull_off_force"] / closed - 1) < 1e-12


@pytest.mark.parametrize("name, why", [
    ("rolling", "the sphere's contact with the wall: Kratos' tangential force is part of its normal law"),
    ("incline", "has no rolling spring (type C, 'epsd')"), ("incline-linear", "DEMRollingFrictionModelBounded"),
    ("twist", "no twisting torque model"), ("conduction", "ThermalDEMApplication"),
])
def test_kratos_says_why_it_does_not_run_the_others(name, why):
    from demcheck.engines import scenario

    mp = scenario.mapping(case(name), "kratos")
    assert mp.native is None and why in mp.reasons[0], mp.reasons


def test_the_pull_deck_is_checked_before_it_runs():
    from demcheck.engines import scenario
    from demcheck.engines.kratos.deck import check
    from demcheck.errors import UnsupportedByEngine

    d = scenario.deck(case("pull-off"), "kratos")
    check(d.text, d.files)
    assert "'fixed': [[1, [0.0, 0.0, 0.0]], [2, [" in d.text
    import json

    mats = json.loads(d.files["MaterialsDEM.json"])  # w on the relation: Kratos reads it there (not the materials)
    assert [r["Variables"]["PARTICLE_COHESION"] for r in mats["material_relations"]] == [0.05] * 3
    assert not any("PARTICLE_COHESION" in m["Variables"] for m in mats["materials"])
    assert {r["Variables"]["DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME"] for r in mats["material_relations"]} == {
        "DEM_D_Hertz_viscous_Coulomb_JKR"}
    with pytest.raises(UnsupportedByEngine, match="held velocities"):
        check(d.text.replace("'fixed': [[1,", "'fixed': [[7,"), d.files)


# ----------------------------------------------------------------------------- a sphere rolling on a wall

G, V0, MU_R, R_GLASS, RHO_GLASS = 9.81, 0.02, 0.1, 1.59e-3, 2500.0  # the rolling cases' numbers (their .toml)
MASS = RHO_GLASS * 4.0 / 3.0 * math.pi * R_GLASS ** 3
C_R = 1e-8  # the viscous variant's Cr (N·m·s): small enough that the sphere rolls without slip (Cr ω0 < μ m g R)


def incline_type_a():
    """beyond-incline-linear with type A and a tangential spring Kratos' Linear law can hold (kt = Kn: ν = 0)."""
    return loads(case_path("suite/beyond-incline-linear.toml").read_text().replace(
        'rolling = "epsd"\nmu_r = 0.1\nk_r = 0.1', 'rolling = "constant_torque"\nmu_r = 0.1').replace(
        "kt = 1e5", "kt = 1e6"))


def viscous_rolling():
    return loads(case_path("suite/beyond-rolling-linear.toml").read_text().replace(
        'rolling = "constant_torque"\nmu_r = 0.1', f'rolling = "viscous"\nc_r = {C_R}'))


@functools.lru_cache(maxsize=None)
def sampled(which):
    """(case, layout, the engine's samples, the twin's samples) of a rolling case run from its deck."""
    from demcheck.engines import registry, scenario
    from demcheck.engines import run as runner

    c = {"constant": case("rolling-linear"), "viscous": viscous_rolling(), "incline": incline_type_a()}[which]
    eng = registry.get("kratos")
    mp, nat, lay, dk = scenario._planned_deck(c, eng)
    out = runner.run("kratos", dk.text, files=dk.files, timeout=900)
    got = eng.read_scenario(c, lay, out.workdir)
    import shutil

    shutil.rmtree(out.workdir, ignore_errors=True)
    return c, lay, got, scenario.step(c, eng.scenario_twin_laws(c, nat), lay)


def test_kratos_maps_the_rolling_models_it_has():
    """Type A → ConstantTorque, type B → ViscousTorque (both approximate, each with its reason), type C → none."""
    from demcheck.engines import scenario

    mp = scenario.mapping(case("rolling-linear"), "kratos")
    assert mp.fidelity == "approximate" and mp.native.props["rolling"] == ("DEMRollingFrictionModelConstantTorque", 0.1)
    assert any("(R − δ)·ω/|ω|" in r and "δ/R = 2.6e-06" in r for r in mp.reasons), mp.reasons
    assert any("½dt late" in r for r in mp.reasons)
    mp = scenario.mapping(viscous_rolling(), "kratos")
    weight = MASS * G
    assert mp.fidelity == "approximate" and mp.native.props["rolling"][0] == "DEMRollingFrictionModelViscousTorque"
    assert abs(mp.native.props["rolling"][1] / (C_R / (weight * R_GLASS ** 2)) - 1) < 1e-12
    assert any("(R − δ)²·ω" in r for r in mp.reasons)
    assert scenario.mapping(case("incline-linear"), "kratos").fidelity == "none"


def test_the_rolling_deck_turns_rolling_friction_on_and_says_its_fidelity():
    """The deck's header carries the scenario mapping's fidelity and reasons, not 'native' (the writer is handed
    the configuration directly)."""
    import json

    from demcheck.engines import scenario
    from demcheck.engines.kratos.deck import check

    d = scenario.deck(case("rolling-linear"), "kratos")
    check(d.text, d.files)
    assert "# mapping fidelity: approximate" in d.text and "native" not in d.text.split("import json")[0]
    assert "DEMRollingFrictionModelConstantTorque on a wall" in d.text
    assert json.loads(d.files["ProjectParameters.json"])["RollingFrictionOption"] is True
    rel = json.loads(d.files["MaterialsDEM.json"])["material_relations"]
    assert {(r["Variables"]["DEM_ROLLING_FRICTION_MODEL_NAME"], r["Variables"]["ROLLING_FRICTION_WITH_WALLS"])
            for r in rel} == {("DEMRollingFrictionModelConstantTorque", 0.1)}
    from demcheck.errors import UnsupportedByEngine

    with pytest.raises(UnsupportedByEngine, match="holds the string"):
        check(d.text, {**d.files, "MaterialsDEM.json": d.files["MaterialsDEM.json"].replace(
            "DEMRollingFrictionModelConstantTorque", "DEMRollingFrictionModelElse")})


def test_the_scenario_decks_header_states_the_scenario_mappings_fidelity():
    """The adhesive decks too: JKR's approximate mapping with its reason, DMT's exact one — never 'native' (the
    writer is handed the configuration directly, which alone would make it say so)."""
    from demcheck.engines import scenario

    head = scenario.deck(case("pull-off"), "kratos").text.split("import json")[0]
    assert "# mapping fidelity: approximate" in head and "the Hertz radius a = √(R̄δ)" in head
    assert "native" not in head
    head = scenario.deck(dmt_pull(), "kratos").text.split("import json")[0]
    assert "# mapping fidelity: exact" in head and "native" not in head


def test_the_twin_turns_the_arm_with_kratos_low_angle_quaternion():
    """Kratos' OrientationFromRotationAngle below its threshold ((θ/2)⁴/24 < ε) builds q = (1 + φ²/2, …): the arm
    turns by θ(1 − θ²/4), its tip θ³a/4 short of an exact rotation; above it, an exact rotation."""
    from demcheck.reference.beyond_kratos import kratos_arm_turn
    from demcheck.reference.twins_kratos import rotate

    a = 1.59e-3
    arm = np.array([0.0, 0.0, -a])
    y = np.array([0.0, 1.0, 0.0])
    for theta in (1.44e-5, 1e-4):  # the rolling case's ω dt, and a larger step still in the low-angle branch
        got = kratos_arm_turn(arm, np.array([0.0, theta, 0.0]))
        exact = arm - rotate(arm, y, -theta)
        assert abs(exact[0] / (a * math.sin(theta)) + 1) < 1e-12  # the exact tip moves by a sin θ (along −x)
        assert abs((got[0] - exact[0]) / (a * theta ** 3 / 4) - 1) < 1e-3
    got = kratos_arm_turn(arm, np.array([0.0, 0.1, 0.0]))  # past the threshold: cos and sin, exact
    assert np.allclose(got, arm - rotate(arm, y, -0.1), rtol=1e-13, atol=1e-19)


@pytest.mark.engine("kratos")
@pytest.mark.parametrize("which", ["constant", "viscous", "incline"])
def test_kratos_rolling_run_is_its_twin_in_every_sample(which):
    c, lay, got, twin = sampled(which)
    assert got["x"].shape == twin["x"].shape == (lay.steps // lay.every + 1, 3)
    # relative to the series' largest component (v_z, ω_x, ω_z, the total force's z are round-off); the force and
    # the moment hold the tangential increment, where Kratos' low-angle quaternion shows (kratos_arm_turn: with an
    # exact rotation the force missed by 1.9e-8)
    stopped = np.nonzero(twin["v"][:, 0] <= 0.0)[0]  # a roll's stop (the incline starts at rest and never stops)
    stop = int(stopped[0]) if stopped.size and twin["v"][0, 0] > 0.0 else len(twin["v"])
    for key in ("x", "v", "omega", "f", "torque"):
        scale = abs(twin[key]).max()
        diff = abs(got[key] - twin[key]).max(axis=1) / scale
        assert scale > 0 and diff[:stop].max() <= 1e-9, (key, diff[:stop].max(), int(diff[:stop].argmax()))
        # past the stop type A chatters about ω = 0 and its direction ω/|ω| tilts by Kratos' round-off spin about x
        # (ω_x −5.5e-12 rad/s against ω_y 3.1e-4 rad/s at the worst sample): the moment's x part, 1.2e-8 of its scale
        assert diff.max() <= (1e-7 if key == "torque" else 1e-9), (key, diff.max(), int(diff.argmax()))
    from demcheck.reference.scenarios import stepped_metrics

    e, t = stepped_metrics(c, got), stepped_metrics(c, twin)
    for k in e:
        assert math.isfinite(e[k]) and abs(e[k] - t[k]) <= 1e-9 * abs(t[k]), (k, e[k], t[k])


@pytest.mark.engine("kratos")
def test_kratos_rolling_stops_at_the_closed_form_half_a_step_late():
    """t = 7v0/(5μr g) (Rr = R): Kratos' arm R − δ lengthens it by 1/(1 − δ/R), the runner's start by ½dt (the
    first half step has no torque); the distance v0²/(2a) likewise plus ½dt·v0."""
    from demcheck.reference.scenarios import stepped_metrics

    c, lay, got, _ = sampled("constant")
    m = stepped_metrics(c, got)
    delta = R_GLASS - lay.positions[0][2]
    assert 0 < delta / R_GLASS < 1e-5
    a = 5.0 / 7.0 * MU_R * G * (1.0 - delta / R_GLASS)
    t_bare, s_bare = V0 / (5.0 / 7.0 * MU_R * G), V0 * V0 / (2.0 * 5.0 / 7.0 * MU_R * G)
    assert abs(m["rolling_stop_time"] / (V0 / a + 0.5 * lay.dt) - 1) < 1e-7  # measured 8e-9
    assert abs(m["rolling_distance"] / (V0 * V0 / (2 * a) + 0.5 * lay.dt * V0) - 1) < 1e-5  # measured 2.3e-6
    assert 2e-5 < m["rolling_stop_time"] / t_bare - 1 < 2.5e-5  # the half step is 2.0e-5, the arm 2.6e-6
    assert 3.5e-5 < m["rolling_distance"] / s_bare - 1 < 4.5e-5


@pytest.mark.engine("kratos")
def test_kratos_type_a_incline_gives_the_closed_form_angle():
    """On a 10° slope a type A sphere rolls from rest (ConstantTorque is 0 while ω = 0) with a = (5/7) g (sin θ −
    μr cos θ): its angle atan μr (the torque's arm R − δ lengthens μr by δ/R, 1e-6 here)."""
    from demcheck.reference.scenarios import stepped_metrics

    c, lay, got, _ = sampled("incline")
    got = stepped_metrics(c, got)["incline_critical_angle"]
    assert abs(got / math.atan(MU_R) - 1) < 1e-5  # measured 5.5e-7


@pytest.mark.engine("kratos")
def test_kratos_viscous_rolling_decays_at_the_closed_form_time_constant():
    from demcheck.reference.scenarios import stepped_metrics

    c, lay, got, _ = sampled("viscous")
    tau = stepped_metrics(c, got)["rolling_time_constant"]
    assert abs(tau / (1.4 * MASS * R_GLASS ** 2 / C_R) - 1) < 1e-5  # measured 2.0e-7


@pytest.mark.engine("kratos")
def test_kratos_runs_the_rolling_case_in_the_suite():
    entry, comps = rows("rolling-linear")
    src = entry["sources"]["kratos"]
    assert src["status"] == "ok" and src["fidelity"] == "approximate", src
    verdicts = {x.metric: x.verdict for x in comps}
    assert verdicts == {"rolling_stop_time": AGREE, "rolling_distance": EXPECTED}, verdicts
    for x in comps:
        assert abs(x.value - src["twin_metrics"][x.metric]) <= 1e-9 * abs(x.value)


def sliding_viscous_rolling(c_r: str = "1e-7"):
    """The rolling sphere under Cr = 1e-7 N·m·s, 4.6× the largest it rolls under without slip (1.4 μ m g R²/v0 =
    2.19e-8): the torque would decelerate the roll at 13.4 m/s² where friction gives μ g = 2.94 m/s²."""
    return loads(case_path("suite/beyond-rolling-linear.toml").read_text().replace(
        'rolling = "constant_torque"\nmu_r = 0.1', f'rolling = "viscous"\nc_r = {c_r}'))


def test_a_sliding_viscous_roll_is_refused_when_the_case_loads():
    """A sphere that would slide is no rolling scenario (its closed form v0 e^{−t/T} assumes the roll): the case is
    refused as it loads, before any run — one ConfigError naming contact.c_r, its value and the bound with its number
    (before, issue 30: the twin's, the seed's and Kratos' runs failed at run time, "the sphere slides"). Just below
    the bound it loads."""
    bound = 1.4 * 0.3 * MASS * G * R_GLASS ** 2 / V0
    with pytest.raises(ConfigError) as info:
        sliding_viscous_rolling()
    e = info.value
    assert e.key == "contact.c_r" and e.value == 1e-7 and e.exit_code == 2 and "\n" not in str(e)
    assert f"must be at most {bound:.6g} N·m·s" in e.rule and "μ g = 2.94 m/s²" in e.rule, e.rule
    with pytest.raises(ConfigError):
        sliding_viscous_rolling(f"{bound * 1.001:.6e}")
    assert sliding_viscous_rolling(f"{bound * 0.999:.6e}").contact.params["c_r"] < bound
