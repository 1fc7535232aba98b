"""Issue 31 item 3: `demcheck audit` of a Kratos DEM project (ProjectParametersDEM.json + MaterialsDEM.json +
.mdpa files, in the layout Kratos' own test projects use), probed with real Kratos runs from demcheck's own
deck. The γ each relation carries is Kratos' own for its COEFFICIENT_OF_RESTITUTION (read back from Kratos);
the golden γ values are the ones recorded in docs/kratos.md from Kratos' sphere_strategy, not from this code."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from demcheck.comparisons import audit as A
from demcheck.inputs.script import ScriptError

from .conftest import ROOT

E_GLASS, NU_GLASS, E_STEEL, NU_STEEL = 7.0e10, 0.22, 2.0e11, 0.3


def _project(root: Path, *, dt=5e-8, law_pair="DEM_D_Hertz_viscous_Coulomb", cor_pair=0.5,
             law_wall="DEM_D_Linear_viscous_Coulomb", cor_wall=0.9, extra=None) -> Path:
    params = {"Dimension": 3, "GravityX": 0.0, "GravityY": 0.0, "GravityZ": -9.81, "RotationOption": True,
              "GlobalDamping": 0.0, "TranslationalIntegrationScheme": "Velocity_Verlet", "MaxTimeStep": dt,
              "FinalTime": 0.01, "solver_settings": {"strategy": "sphere_strategy",
                                                     "material_import_settings": {"materials_filename":
                                                                                  "MaterialsDEM.json"}},
              "problem_name": "impact", **(extra or {})}
    mats = {"materials": [
        {"material_name": "glass", "material_id": 1,
         "Variables": {"PARTICLE_DENSITY": 2500.0, "YOUNG_MODULUS": E_GLASS, "POISSON_RATIO": NU_GLASS}},
        {"material_name": "steel", "material_id": 2,
         "Variables": {"YOUNG_MODULUS": E_STEEL, "POISSON_RATIO": NU_STEEL}}],
        "material_relations": [
            {"material_names_list": ["glass", "glass"], "material_ids_list": [1, 1],
             "Variables": {"DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME": law_pair, "COEFFICIENT_OF_RESTITUTION": cor_pair,
                           "STATIC_FRICTION": 0.4, "DYNAMIC_FRICTION": 0.3, "FRICTION_DECAY": 500,
                           "ROLLING_FRICTION": 0.0}},
            {"material_names_list": ["glass", "steel"], "material_ids_list": [1, 2],
             "Variables": {"DEM_DISCONTINUUM_CONSTITUTIVE_LAW_NAME": law_wall, "COEFFICIENT_OF_RESTITUTION": cor_wall,
                           "STATIC_FRICTION": 0.0, "DYNAMIC_FRICTION": 0.0}}],
        "material_assignation_table": [["SpheresPart.Balls", "glass"], ["RigidFacePart.Floor", "steel"]]}
    spheres = """Begin ModelPartData
End ModelPartData
Begin Properties 0
End Properties
Begin Nodes
1 0.0 0.0 0.01
2 0.0 0.0 0.0125
End Nodes
Begin Elements SphericParticle3D// GUI group identifier: Balls
1 0 1
2 0 2
End Elements
Begin NodalData RADIUS // GUI group identifier: Balls
1 0 0.001
2 0 0.001
End NodalData
Begin NodalData VELOCITY_Z
1 0 1.0
2 0 -1.0
End NodalData
Begin SubModelPart Balls // Group Balls // Subtree DEMParts
  Begin SubModelPartNodes
  1
  2
  End SubModelPartNodes
  Begin SubModelPartElements
  1
  2
  End SubModelPartElements
End SubModelPart
"""
    boundary = """Begin ModelPartData
End ModelPartData
Begin Properties 0
End Properties
Begin Nodes
10 -1 -1 0
11 1 -1 0
12 0 1 0
End Nodes
Begin Conditions RigidFace3D3N// GUI group identifier: Floor
1 0 10 11 12
End Conditions
Begin SubModelPart Floor // DEM-FEM-Wall - group identifier: Floor
  Begin SubModelPartNodes
  10
  11
  12
  End SubModelPartNodes
  Begin SubModelPartConditions
  1
  End SubModelPartConditions
End SubModelPart
"""
    (root / "ProjectParametersDEM.json").write_text(json.dumps(params, indent=1))
    (root / "MaterialsDEM.json").write_text(json.dumps(mats, indent=1))
    (root / "impactDEM.mdpa").write_text(spheres)
    (root / "impactDEM_FEM_boundary.mdpa").write_text(boundary)
    return root / "ProjectParametersDEM.json"


@pytest.mark.engine("kratos")  # Kratos' own γ is read from Kratos
def test_a_kratos_project_is_read_with_each_relations_law_and_kratos_gamma(tmp_path):
    """The reader: one pair and one wall, E* as Kratos combines two materials, DAMPING_GAMMA Kratos' own —
    0.23302 for e = 0.5 by Thornton's fit (Hertz) and 0.034271 for e = 0.9 by its bisection (linear), the values
    docs/kratos.md records from Kratos' sphere_strategy; friction listed as not audited."""
    setup = A.read(_project(tmp_path))
    assert setup.engine == "kratos" and setup.dt == 5e-8
    pair, wall = setup.pairs
    assert (pair.i, pair.j, wall.i, wall.j) == (1, 1, 1, None)
    assert pair.native.normal == "DEM_D_Hertz_viscous_Coulomb"
    assert pair.native.normal_args[0] == pytest.approx(E_GLASS / (2 * (1 - NU_GLASS ** 2)), rel=1e-12)
    e_star_wall = E_GLASS * E_STEEL / (E_GLASS * (1 - NU_STEEL ** 2) + E_STEEL * (1 - NU_GLASS ** 2))
    assert wall.native.normal_args[0] == pytest.approx(e_star_wall, rel=1e-12) and wall.native.props["wall"]
    assert pair.native.damping_coeff == pytest.approx(0.23302, abs=2e-5)
    assert wall.native.damping_coeff == pytest.approx(0.034271, abs=2e-6)
    assert pair.asked == {"restitution": 0.5} and wall.asked == {"restitution": 0.9}
    assert setup.bodies[1].radius == 0.001 and setup.bodies[1].density == 2500.0
    assert any("friction" in t and "no oblique probe" in why for _, t, why in setup.not_audited)


@pytest.mark.engine("kratos")
def test_a_kratos_project_is_audited_with_kratos_runs(tmp_path):
    """Real Kratos runs from demcheck's deck with the project's law, E* and Kratos' γ: the engine equals its
    twin to 1e-9 on the pair and the wall; the realised restitution stands against the requested COR (the
    linear law's bisection inverts the law it runs: 0.9 to 2e-3 at 200 steps a contact)."""
    r = A.audit(_project(tmp_path, dt=5e-9), speed=1.0)
    assert r["engine"] == "kratos" and r["coverage"]["pairs"]["probed"] == 1 and r["coverage"]["walls"]["probed"] == 1
    for p in r["pairs"]:
        assert len(p["probes"]) == 1  # head-on only: no oblique probe of Kratos' tangential law
        q = p["probes"][0]
        assert q["engine"]["status"] == "ok" and q["engine_vs_twin"] <= 1e-9, q
    wall = next(p for p in r["pairs"] if p["wall"])
    e = wall["probes"][0]["engine"]["restitution"]
    assert e == pytest.approx(0.9, abs=2e-3)
    assert not any(f["code"] == "restitution" for f in wall["findings"])
    assert any("not audited" not in n and "no oblique probe of Kratos' tangential" in n for n in wall["notes"])


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "demcheck", *args], capture_output=True, text=True, cwd=ROOT)


@pytest.mark.parametrize("bad, key", [({"MaxTimeStep": -1e-6}, "MaxTimeStep"),
                                      ({"TranslationalIntegrationScheme": 3}, "TranslationalIntegrationScheme")])
def test_a_bad_project_is_one_line_and_exit_2(tmp_path, bad, key):
    p = _project(tmp_path, extra=bad)
    out = _cli("audit", str(p))
    assert out.returncode == 2, out.stdout + out.stderr
    assert len(out.stderr.strip().splitlines()) == 1 and key in out.stderr


def test_a_relation_out_of_range_is_refused(tmp_path):
    with pytest.raises(ScriptError, match="COEFFICIENT_OF_RESTITUTION"):
        A.read(_project(tmp_path, cor_wall=1.5))


def test_a_law_without_twin_is_listed_not_probed(tmp_path):
    setup = A.read(_project(tmp_path, law_pair="DEM_D_Stress_Dependent_Cohesive"))
    pair = setup.pairs[0]
    assert not pair.probe and any("no twin of Kratos' DEM_D_Stress_Dependent_Cohesive" in n for n in pair.notes)


@pytest.mark.engine("kratos")  # Kratos' own γ is read from Kratos
def test_a_law_the_twin_steps_its_own_way_is_converged_by_its_own_kernel(tmp_path):
    """Where an engine's twin steps a law with a kernel of its own (Engine.own_twin: Kratos' Coulomb tangential
    force, Yade's Luding law), the probe's converged answer is that kernel at dt/16, not the adaptive solver of the
    law's description. The Kratos audit reads no tangential law yet (its natives are frictionless), so the pair's
    native is given Kratos' friction here: the converged restitution is then the own kernel's, within its O(dt²)
    error of the twin at dt; the frictionless native keeps the adaptive solver."""
    import copy

    from demcheck.engines.kratos.mapping import FRICTION

    setup = A.read(_project(tmp_path, dt=5e-9))
    pair = setup.pairs[0]
    w = A.probe(setup, pair, 1.0, 0.0, run_engine=False)
    assert w["converged"]["by"].startswith("the adaptive solver")
    pair.native = copy.deepcopy(pair.native)
    pair.native.tangential = FRICTION
    pair.native.props.update(poisson=NU_GLASS, mu_s=0.4, mu_d=0.3, decay=500.0)
    q = A.probe(setup, pair, 1.0, 0.0, run_engine=False)
    assert q["converged"]["status"] == "ok" and q["converged"]["by"] == "the engine's own law stepped at dt/16"
    assert q["converged"]["restitution"] == pytest.approx(q["twin"]["restitution"], rel=1e-4)
