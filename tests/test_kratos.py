"""Kratos DEM 10.4.4: its mapping's claims against real runs, its deck guard, and its traps.

The runs compare Kratos with its twin (the reference's verlet method with Kratos' law, the same scheme and
dt): an exact twin agrees to ≤ 1e-9 relative on peak force, restitution, contact time and maximum overlap
(measured: ≤ 6e-13). The closed-form checks need no Kratos."""

from __future__ import annotations

import copy
import json
import math
import tomllib

import pytest

from demcheck import case as C
from demcheck.engines import collide as CO, mapping, registry
from demcheck.engines.base import APPROXIMATE, EXACT, NONE_
from demcheck.errors import UnsupportedByEngine
from demcheck.laws import normal as N
from demcheck.laws.model import resolve

METRICS = ("restitution", "contact_time", "max_overlap", "peak_force")


def _case(normal: str, geometry: str, limit: bool = True, **extra) -> C.Case:
    base = tomllib.loads(mapping._TABLE_CASE)
    params = {**N.REGISTRY[normal].example, **extra}
    params.pop("friction", None)
    base["contact"] = {"normal": normal, "tangential": "none", "limit_force": limit, **params}
    if geometry == "unequal":
        base["particles"][1]["radius"] = 1.2e-3
        base["particles"][1]["position"] = [1.2e-3, 0.0, 0.0]
    elif geometry == "wall":
        base["particles"] = [{"material": "glass", "radius": 1.59e-3, "position": [0.0, 0.0, 1.59e-3],
                              "velocity": [0.0, 0.0, -1.0]}]
        base["walls"] = [{"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0], "rigid": True}]
    return C.from_dict(copy.deepcopy(base))


# --------------------------------------------------------------------------- without Kratos

def test_hertz_twin_is_kratos_formula_written_out():
    """DEM_D_Hertz_viscous_Coulomb: Kn = 2E*√(R̄δ), F = ⅔Knδ − 2γ√(m̄Kn) δ̇ → k = (4/3)E*√R̄, η = 2γ√(2m̄E*√R̄) δ^¼."""
    from demcheck.engines.kratos.mapping import HERTZ, twin
    from demcheck.engines.base import Native

    e_star, gamma, m, r = 7.5e10, 0.1, 4e-5, 1e-3
    nl, _ = twin(Native("kratos", HERTZ, (e_star,), "gamma", gamma, tangential="none"), m, r)
    delta = 2e-6
    kn = 2.0 * e_star * math.sqrt(r * delta)
    assert nl.k * delta**nl.a == pytest.approx(2.0 / 3.0 * kn * delta, rel=1e-14)
    assert nl.eta * delta**nl.b == pytest.approx(2.0 * gamma * math.sqrt(m * kn), rel=1e-14)
    assert nl.limit


def test_linear_wall_branch_drops_the_1432_factor():
    """The trap read in DEM_D_Linear_viscous_Coulomb: a wall's Kn lacks the pair's 1.432, so the same materials
    are 1.432× softer against a wall; the mapping compensates with the particle's modulus."""
    from demcheck.engines.kratos.mapping import linear_kn

    assert linear_kn(1e10, 1e-3, False) / linear_kn(1e10, 1e-3, True) == pytest.approx(1.432, rel=1e-15)
    pair = mapping.contact_mapping(_case("lsd", "unequal"), "kratos").native
    wall = mapping.contact_mapping(_case("lsd", "wall"), "kratos").native
    assert pair.normal_args[0] and wall.normal_args[0]


@pytest.mark.parametrize("normal_id,expected", [("hertz", EXACT), ("tti", EXACT), ("lsd", EXACT), ("bshp", NONE_),
                                                ("kk", NONE_), ("hls", NONE_)])
def test_mapping_fidelity(normal_id, expected):
    assert mapping.contact_mapping(_case(normal_id, "equal"), "kratos").fidelity == expected


def test_dashpot_without_limit_is_approximate():
    mp = mapping.contact_mapping(_case("tti", "equal", limit=False), "kratos")
    assert mp.fidelity == APPROXIMATE and "≥ 0" in mp.reasons[0]


def _deck(case=None):
    return registry.get("kratos").collision_deck(case or _case("hertz", "wall"))


def test_deck_guard_accepts_what_demcheck_writes_and_the_files_are_json():
    dk = _deck()
    registry.get("kratos").check_deck(dk.text, dk.files)
    params = json.loads(dk.files["ProjectParameters.json"])
    assert params["TranslationalIntegrationScheme"] == "Velocity_Verlet"
    assert params["GlobalDamping"] == 0.0 and params["RollingFrictionOption"] is False
    rel = json.loads(dk.files["MaterialsDEM.json"])["material_relations"]
    assert all(r["Variables"]["FRICTION_DECAY"] == 0.0 and r["Variables"]["STATIC_FRICTION"] == 0.0 for r in rel)


@pytest.mark.parametrize("edit", [
    lambda t, f: (t.replace("CASE = {", "CASE = {'x': __import__('os').system('true'), ", 1), f),
    lambda t, f: (t.replace("import json\n", "import json, os\n", 1), f),
    lambda t, f: (t + "\nprint('extra')\n", f),
    lambda t, f: (t.replace("'steps': ", "'steps': 'a' * ", 1), f),
    lambda t, f: (t, {**f, "MaterialsDEM.json": f["MaterialsDEM.json"].replace(
        '"DEMRollingFrictionModelBounded"', '"os.system"')}),
    lambda t, f: (t, {**f, "ProjectParameters.json": f["ProjectParameters.json"].replace(
        '"problem_name"', '"python_module"')}),
    lambda t, f: (t, {**f, "caseDEM.mdpa": f["caseDEM.mdpa"] + "Begin Table 1\n"}),
    lambda t, f: (t, {k: v for k, v in f.items() if k != "caseDEM.mdpa"}),
])
def test_deck_guard_refuses_anything_else(edit):
    dk = _deck()
    text, files = edit(dk.text, dict(dk.files))
    with pytest.raises(UnsupportedByEngine):
        registry.get("kratos").check_deck(text, files)


# --------------------------------------------------------------------------- real runs

@pytest.mark.engine("kratos")
@pytest.mark.parametrize("normal_id", ["hertz", "tti", "lsd"])
@pytest.mark.parametrize("geometry", ["wall", "unequal"])
def test_kratos_runs_as_its_twin(normal_id, geometry):
    case = _case(normal_id, geometry)
    res = CO.collide(case, "kratos")
    assert res.ok, res.message
    assert res.engine_version.startswith("10.4.4 (DEMApplication 10.4.4")
    twin = CO.twin_states(case, "kratos", res.dt)
    a, b = res.metrics(), twin.metrics()
    for k in METRICS:
        assert abs(a[k] - b[k]) <= 1e-9 * abs(b[k]), (k, a[k], b[k])  # exact twin: round-off only
    # the mapping is exact: the seed model's own verlet run at this dt is the same numbers
    from demcheck.reference import collision3d

    seed = collision3d.collide(case, resolve(case), "verlet", dt=res.dt, rules=registry.get("kratos").rules).metrics()
    for k in METRICS:
        assert abs(seed[k] - a[k]) <= 1e-9 * abs(seed[k]), (k, seed[k], a[k])


@pytest.mark.engine("kratos")
def test_kratos_hertz_wall_case_file_agrees():
    from pathlib import Path

    case = C.load(Path(__file__).resolve().parents[1] / "cases" / "hertz-wall.toml")
    res = CO.collide(case, "kratos")
    assert res.ok and abs(res.metrics()["restitution"] - 1.0) < 1e-6  # elastic Hertz: e = 1 to O(dt²)
