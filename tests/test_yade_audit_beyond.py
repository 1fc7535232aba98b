"""`demcheck audit` of a Yade script beyond sliding (engines/yade/audit.py, probed by comparisons/audit_beyond.py):
Mindlin's DMT (`Ip2_FrictMat_FrictMat_MindlinPhys(gamma)` with `Law2_ScGeom_MindlinPhys_Mindlin(includeAdhesion=
True)`) gets a pull-off probe, `ThermalEngine` a held-pair conduction probe, both run in Yade and twinned
(engines/yade/pair.py). Golden values from closed forms written here: DMT's pull-off 2πwR̄ with w = 2γ, and the
ratio of Batchelor & O'Brien's conductance 2k√(R̄δ) to ThermalEngine's 4kR²/(2R − δ) (like spheres), which sets
the time constants' ratio (to forward Euler's dt/(2τ)).

Measured (Yade 2023.02a): the pull-off engine = twin (0), 3.5e-7 below 2πwR̄ (the Hertz force at the last overlap);
the conduction engine = twin (0), τ 0.0700× the closed form's at the head-on probe's overlap (14.3× the
conductance)."""

from __future__ import annotations

import math

import pytest

from demcheck.comparisons import audit as A

SCRIPT = """from yade import utils
R = 1e-3
O.materials.append(FrictMat(young=5e6, poisson=0.45, frictionAngle=0.0, density=1100, label='rubber'))
O.bodies.append([sphere((0, 0, 0), R), sphere((0, 0, 2.2e-3), R)])
O.bodies[1].state.vel = (0, 0, -0.1)
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom()],
                             [Ip2_FrictMat_FrictMat_MindlinPhys(gamma=0.025)],
                             [Law2_ScGeom_MindlinPhys_Mindlin(includeAdhesion=True)]),
             FlowEngine(dead=True),
             ThermalEngine(advection=False, fluidConduction=False, particleK=45.0, particleCp=500.0),
             NewtonIntegrator(damping=0.0)]
O.dt = 1e-7
"""
GAMMA, K, R = 0.025, 45.0, 1e-3


def _script(tmp_path, text):
    p = tmp_path / "run.py"
    p.write_text(text)
    return p


def test_the_reader_keeps_mindlins_dmt_and_thermal_engine(tmp_path):
    setup = A.read(_script(tmp_path, SCRIPT))
    (ps,) = setup.pairs
    assert ps.beyond["adhesion"]["law"] == "dmt" and ps.beyond["adhesion"]["args"] == (5e6, 0.0, 0.45, GAMMA)
    assert ps.beyond["heat"]["law"] == "radius" and ps.beyond["heat"]["args"] == (K,)
    assert setup.heat["cp_all"] == 500.0
    assert not ps.findings


def test_gamma_without_include_adhesion_is_a_trap(tmp_path):
    setup = A.read(_script(tmp_path, SCRIPT.replace("includeAdhesion=True", "")))
    (ps,) = setup.pairs
    assert "adhesion" not in ps.beyond
    assert [f.code for f in ps.findings] == ["yade-adhesion-off"] and ps.findings[0].size == {"gamma": GAMMA}


@pytest.mark.parametrize("flag", ["useKernMethod", "useHertzMethod"])
def test_thermal_engines_other_conductances_are_listed_not_probed(tmp_path, flag):
    setup = A.read(_script(tmp_path, SCRIPT.replace("particleCp=500.0", f"particleCp=500.0, {flag}=True")))
    assert flag in setup.pairs[0].beyond["heat"]["refused"]


@pytest.mark.engine("yade")
def test_the_yade_beyond_probes_run_in_yade_and_meet_their_twins(tmp_path):
    r = A.audit(_script(tmp_path, SCRIPT), run_engine=False, beyond_engine=True)
    (pair,) = r["pairs"]
    rows = {b["slot"]: b for b in pair["beyond"]}
    pull, heat = rows["adhesion"], rows["heat"]
    assert pull["status"] == heat["status"] == "ok", (pull.get("why"), heat.get("why"))
    assert pull["fidelity"] == "exact" and heat["fidelity"] == "approximate"
    assert pull["engine_vs_twin"] <= 1e-9 and heat["engine_vs_twin"] <= 1e-9
    force = pull["metrics"]["pull_off_force"]
    assert force["reference"] == pytest.approx(2 * math.pi * 2 * GAMMA * R / 2, rel=1e-15)
    assert abs(force["engine"] / force["reference"] - 1) < 1e-6
    # the held pair at the head-on probe's largest overlap: τ scales as 1/H
    delta = heat["case"]["run"]["overlap"]
    ratio = (2 * K * math.sqrt(R / 2 * delta)) / (4 * K * R * R / (2 * R - delta))
    assert abs(heat["engine_vs_reference"]["heat_time_constant"] / ratio - 1) < 2e-3
    traps = [f for f in pair["findings"] if f["code"] == "beyond-conduction"]
    assert len(traps) == 1 and "ignores the contact's size" in traps[0]["text"]
    assert not [f for f in pair["findings"] if f["code"] == "beyond-pull-off"]
