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
* pull-off with DMT (exact): engine = twin to the bit; 2πwR̄ less the Hertz force at the last overlap in contact.
"""

from __future__ import annotations

import functools
import math

import pytest

from demcheck.case import load, loads
from demcheck.comparisons.verdicts import AGREE, EXPECTED
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
    ("rolling", "DEMRollingFrictionModelConstantTorque"), ("rolling-linear", "no Kratos deck is written"),
    ("incline", "a sphere on an incline"), ("incline-linear", "rolling friction models"),
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
