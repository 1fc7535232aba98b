"""`demcheck audit` of a Kratos DEM project beyond sliding (engines/kratos/audit.py, probed by
comparisons/audit_beyond.py in engines/kratos/scenario.py's scenarios): a relation on the cohesive law
DEM_D_Hertz_viscous_Coulomb_DMT / _JKR with its PARTICLE_COHESION gets the pull-off probe (JKR also the adhesive
impact), a wall relation's DEMRollingFrictionModelConstantTorque with ROLLING_FRICTION_WITH_WALLS (and the project's
RollingFrictionOption) a sphere rolling on a level wall. Each runs in Kratos and its twin.

Golden values from closed forms written here, never from the code under test: DMT's pull-off force 2πwR̄; JKR's
(3/2)πwR̄ (Kratos' Hertz-radius JKR reaches it, docs/kratos.md) and Thornton & Ning's capture velocity; type A's
stop time 7v0/(5μr g) (the angular momentum (7/5)mRv0 about the contact point over the torque μr R m g).

Measured (Kratos 10.4.4): DMT pull-off engine = twin (0), 3.5e-7 below 2πwR̄; JKR pull-off engine − twin 1.2e-16,
5.6e-9 below (3/2)πwR̄, its impact at 0.02 m/s e = 1.000001 against 0.898 (v_s 0 against 8.8e-3 m/s): the trap
beyond-adhesive-impact; the rolling wall (ConstantTorque, μr 0.1, v0 0.02 m/s, dt 1.82e-6 s) engine − twin 2.0e-13,
the stop 3.48e-5 after 7v0/(5μr g) (the distance 6.4e-5 beyond 7v0²/(10μr g)): within 1%, no trap."""

from __future__ import annotations

import json
import math

import pytest

from demcheck.comparisons import audit as A

from .test_audit_kratos import _project

E_RUB, NU_RUB, RHO_RUB, W, R = 5e6, 0.45, 1100.0, 0.05, 1e-3
E_STEEL, NU_STEEL = 2.0e11, 0.3
MU_R, MU, V0, G = 0.1, 0.3, 0.02, 9.81


def _viscous_torque_roll(tmp_path, c: float, v0: float) -> dict:
    """The wall's rolling row of an audit of the Kratos project with ViscousTorque, ROLLING_FRICTION_WITH_WALLS c,
    at the characteristic speed v0."""
    path = _kratos(tmp_path, pair_law="DEM_D_Hertz_viscous_Coulomb", model="DEMRollingFrictionModelViscousTorque")
    mats = json.loads((tmp_path / "MaterialsDEM.json").read_text())
    mats["material_relations"][1]["Variables"]["ROLLING_FRICTION_WITH_WALLS"] = c
    (tmp_path / "MaterialsDEM.json").write_text(json.dumps(mats))
    r = A.audit(path, speed=v0, run_engine=False, beyond_engine=True)
    return _rows(r["pairs"][1])["rolling"]


def _kratos(tmp_path, *, pair_law="DEM_D_Hertz_viscous_Coulomb_DMT", model="DEMRollingFrictionModelConstantTorque",
            rolling_option=True, wall_law="DEM_D_Linear_viscous_Coulomb"):
    """Kratos' own test-project layout (test_audit_kratos's two spheres of R = 1 mm and a floor), the spheres of a
    soft rubber, the pair on a cohesive law, the floor relation with rolling friction (as in Kratos'
    a_simple_3D_DEM_case: DEM_ROLLING_FRICTION_MODEL_NAME, ROLLING_FRICTION, ROLLING_FRICTION_WITH_WALLS)."""
    path = _project(tmp_path, extra={"RollingFrictionOption": rolling_option, "RotationOption": True})
    wall_vars = {"DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME": wall_law, "COEFFICIENT_OF_RESTITUTION": 0.9,
                 "STATIC_FRICTION": MU, "DYNAMIC_FRICTION": MU, "FRICTION_DECAY": 0.0,
                 "ROLLING_FRICTION": 0.05, "ROLLING_FRICTION_WITH_WALLS": MU_R}
    if model:
        wall_vars["DEM_ROLLING_FRICTION_MODEL_NAME"] = model
    mats = {"materials": [
        {"material_name": "rubber", "material_id": 1,
         "Variables": {"PARTICLE_DENSITY": RHO_RUB, "YOUNG_MODULUS": E_RUB, "POISSON_RATIO": NU_RUB}},
        {"material_name": "steel", "material_id": 2,
         "Variables": {"YOUNG_MODULUS": E_STEEL, "POISSON_RATIO": NU_STEEL}}],
        "material_relations": [
            {"material_names_list": ["rubber", "rubber"], "material_ids_list": [1, 1],
             "Variables": {"DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME": pair_law, "COEFFICIENT_OF_RESTITUTION": 0.5,
                           "PARTICLE_COHESION": W, "STATIC_FRICTION": 0.0, "DYNAMIC_FRICTION": 0.0,
                           "DEM_ROLLING_FRICTION_MODEL_NAME": "DEMRollingFrictionModelConstantTorque"}},
            {"material_names_list": ["rubber", "steel"], "material_ids_list": [1, 2], "Variables": wall_vars}],
        "material_assignation_table": [["SpheresPart.Balls", "rubber"], ["RigidFacePart.Floor", "steel"]]}
    (tmp_path / "MaterialsDEM.json").write_text(json.dumps(mats, indent=1))
    return path


def _rows(pair):
    return {b["slot"]: b for b in pair.get("beyond", [])}


def test_the_reader_keeps_the_cohesive_law_and_the_wall_rolling_model(tmp_path):
    setup = A.read(_kratos(tmp_path))
    pair, wall = setup.pairs
    e_star = E_RUB / (2 * (1 - NU_RUB ** 2))
    law, (e, nu, w) = pair.beyond["adhesion"]["law"], pair.beyond["adhesion"]["args"]
    assert law == "dmt" and e == pytest.approx(e_star, rel=1e-14) and (nu, w) == (NU_RUB, W)
    sub = wall.beyond["rolling"]
    assert sub["law"] == "constant_torque" and sub["args"][:2] == (MU_R, MU) and not sub["refused"]
    # Kratos' Kt/Kn = 4G*/E*, G* = 1/((2 − ν₁)/G₁ + (2 − ν₂)/G₂)
    g1, g2 = E_RUB / (2 * (1 + NU_RUB)), E_STEEL / (2 * (1 + NU_STEEL))
    e_wall = 1 / ((1 - NU_RUB ** 2) / E_RUB + (1 - NU_STEEL ** 2) / E_STEEL)
    assert sub["args"][2] == pytest.approx(4 / ((2 - NU_RUB) / g1 + (2 - NU_STEEL) / g2) / e_wall, rel=1e-12)
    assert "rolling" not in pair.beyond  # particle–particle: ROLLING_FRICTION 0
    assert not any("no twin of its rolling" in why for _, _, why in setup.not_audited)
    assert any("rolling probe" in why for _, _, why in setup.not_audited)


@pytest.mark.parametrize("model, why", [(None, "DEMRollingFrictionModelBounded"),
                                        ("DEMRollingFrictionModelBounded", "has no demcheck law")])
def test_the_bounded_model_is_listed_with_its_reason(tmp_path, model, why):
    setup = A.read(_kratos(tmp_path, model=model))
    sub = setup.pairs[1].beyond["rolling"]
    assert why in sub["refused"] and "DEMRollingFrictionModelBounded" in sub["words"]


def test_a_hertz_wall_relations_rolling_is_listed_with_its_reason(tmp_path):
    setup = A.read(_kratos(tmp_path, wall_law="DEM_D_Hertz_viscous_Coulomb"))
    assert "wired for DEM_D_Linear_viscous_Coulomb only" in setup.pairs[1].beyond["rolling"]["refused"]


def test_rolling_friction_without_the_option_is_a_note(tmp_path):
    setup = A.read(_kratos(tmp_path, rolling_option=False))
    wall = setup.pairs[1]
    assert "rolling" not in wall.beyond
    assert [f.code for f in wall.findings] == ["rolling-friction-off"] and wall.findings[0].size == {
        "rolling_friction": MU_R}


@pytest.mark.engine("kratos")
def test_the_dmt_pull_off_and_the_rolling_wall_run_in_kratos_and_meet_their_twins(tmp_path):
    r = A.audit(_kratos(tmp_path), speed=V0, run_engine=False, beyond_engine=True)
    pair, wall = r["pairs"]
    pull, roll = _rows(pair)["adhesion"], _rows(wall)["rolling"]
    assert pull["status"] == roll["status"] == "ok", (pull.get("why"), roll.get("why"))
    assert pull["fidelity"] == "exact" and roll["fidelity"] == "approximate"
    assert pull["engine_vs_twin"] <= 1e-9 and roll["engine_vs_twin"] <= 1e-9
    force = pull["metrics"]["pull_off_force"]
    assert force["reference"] == pytest.approx(2 * math.pi * W * R / 2, rel=1e-14)  # 2πwR̄, R̄ = R/2
    assert abs(force["engine"] / force["reference"] - 1) < 1e-6  # measured 3.5e-7 (the Hertz force at the end)
    stop = roll["metrics"]["rolling_stop_time"]
    assert stop["reference"] == pytest.approx(7 * V0 / (5 * MU_R * G), rel=1e-12)
    # late by the runner's first half step without torque (½dt = 3.19e-5 of it here) and Kratos' arm R − δ
    # (docs/kratos.md): measured 3.48e-5, engine − twin 2.0e-13
    assert 3.0e-5 < stop["engine"] / stop["reference"] - 1 < 4.5e-5
    assert not [f for f in wall["findings"] if f["code"].startswith("beyond-")]
    assert not [f for f in pair["findings"] if f["code"].startswith("beyond-")]
    assert r["coverage"].get("beyond-sliding probes", {}).get("probed") == 2


@pytest.mark.engine("kratos")
def test_kratos_jkr_impact_is_a_trap_with_its_numbers(tmp_path):
    """Kratos' JKR: the largest tension is (3/2)πwR̄ (agree), but an impact loses nothing to adhesion (e = 1
    against Thornton & Ning's √(1 − (v_s/v)²)): the trap names the restitution."""
    r = A.audit(_kratos(tmp_path, pair_law="DEM_D_Hertz_viscous_Coulomb_JKR"), speed=V0, run_engine=False,
                beyond_engine=True)
    pair = r["pairs"][0]
    rows = {b["probe"].split(" (")[0]: b for b in pair["beyond"]}
    pull, hit = rows["pull-off"], rows["adhesive impact"]
    assert pull["status"] == hit["status"] == "ok", (pull.get("why"), hit.get("why"))
    assert pull["engine_vs_twin"] <= 1e-9 and hit["engine_vs_twin"] <= 1e-9
    force = pull["metrics"]["pull_off_force"]
    assert force["reference"] == pytest.approx(1.5 * math.pi * W * R / 2, rel=1e-12)
    assert abs(force["engine"] / force["reference"] - 1) < 1e-5
    assert hit["metrics"]["restitution"]["engine"] == pytest.approx(1.0, abs=1e-5)
    traps = [f for f in pair["findings"] if f["code"] == "beyond-adhesive-impact"]
    assert len(traps) == 1 and "restitution" in traps[0]["text"]


@pytest.mark.engine("kratos")
def test_the_viscous_torque_wall_decays_at_the_closed_form_time_constant(tmp_path):
    """DEMRollingFrictionModelViscousTorque, ROLLING_FRICTION_WITH_WALLS c: Kratos' moment c|Fn|(R − δ)²ω is type B
    with Cr = cWR², so v decays as exp(−t/T), T = (7/5)mR²/Cr = 1.4/(c g). c = 50 and v0 = 2 mm/s keep the run
    short and the roll without slip (the friction it needs, (5/7)c v0·W = 0.07 W, is below μs W = 0.3 W)."""
    c, v0 = 50.0, 0.002
    roll = _viscous_torque_roll(tmp_path, c, v0)
    assert roll["status"] == "ok" and roll["fidelity"] == "approximate", roll.get("why")
    assert roll["engine_vs_twin"] <= 1e-9  # measured 1.5e-12
    tau = roll["metrics"]["rolling_time_constant"]
    assert tau["reference"] == pytest.approx(1.4 / (c * G), rel=1e-12)
    assert abs(tau["engine"] / tau["reference"] - 1) < 1e-4  # measured 3.5e-5 below


@pytest.mark.engine("kratos")
def test_a_viscous_torque_wall_past_the_no_slip_bound_is_probed_at_half_the_bound(tmp_path):
    """ViscousTorque with c = 500 at the characteristic 2 mm/s: the roll would need the friction (5/7)c v0·W = 0.71 W,
    above μs W = 0.3 W — the sphere would slide, and the rolling scenario's case would be refused (case.py
    rolling_grip). The probe rolls at half the bound 1.4 μ/c instead (0.42 mm/s), says so in a note, and the deck's
    law is exercised: Kratos against its twin and the closed form (before: "not probed", no finding — a deck whose
    rolling law was never run could come out clean; on 166af39 the row failed at run time)."""
    c, v0, mu = 500.0, 0.002, MU
    path = _kratos(tmp_path, pair_law="DEM_D_Hertz_viscous_Coulomb", model="DEMRollingFrictionModelViscousTorque")
    mats = json.loads((tmp_path / "MaterialsDEM.json").read_text())
    mats["material_relations"][1]["Variables"]["ROLLING_FRICTION_WITH_WALLS"] = c
    (tmp_path / "MaterialsDEM.json").write_text(json.dumps(mats))
    r = A.audit(path, speed=v0, run_engine=False, beyond_engine=True)
    roll = _rows(r["pairs"][1])["rolling"]
    assert roll["status"] == "ok", roll
    assert any(f"rolling at {0.7 * mu / c:.6g} m/s" in n and "half the no-slip bound" in n for n in roll["notes"]), roll
    assert roll["engine_vs_twin"] <= 1e-9
    tau = roll["metrics"]["rolling_time_constant"]
    # approximate (Cr ∝ the oscillating |Fn|): T = 0.285 ms is short beside the contact's own oscillation here,
    # measured 0.90 % off the closed form (3.5e-5 at c = 50 above)
    assert abs(tau["engine"] / tau["reference"] - 1) < 0.02
