"""`demcheck models` lists each law beyond sliding with each engine's mapping as the scenario mapping gives it
(engines/scenario.law_mappings): exact, approximate with its reasons, or none with its reason — the mapping verify
runs the suite's beyond cases with, never "not wired"."""

from __future__ import annotations

import json

from click.testing import CliRunner

from demcheck import api
from demcheck.case import load
from demcheck.cli import cli
from demcheck.engines import registry, scenario
from demcheck.laws.model import resolve
from demcheck.laws import slots
from demcheck.resources import case_path

BEYOND = ("rolling", "twisting", "adhesion", "heat")


def _beyond_rows():
    return [r for r in api.models() if r["slot"] in BEYOND]


def test_every_beyond_law_has_each_engines_scenario_mapping():
    rows = _beyond_rows()
    assert {(r["slot"], r["id"]) for r in rows} == set(slots.KEYS)
    for r in rows:
        assert set(r["engines"]) == set(registry.names())
        for name, m in r["engines"].items():
            assert m["fidelity"] in ("exact", "approximate", "none"), (r["id"], name, m)
            if m["fidelity"] != "exact":
                assert m["reason"], (r["id"], name)  # approximate and none say why
            else:
                assert m["config"]


def test_the_listed_mapping_is_the_one_verify_runs_the_suite_case_with():
    """Where a row names a suite case, that case's own scenario mapping (what verify runs) is the row's."""
    checked = 0
    for r in _beyond_rows():
        for name, m in r["engines"].items():
            if "suite-beyond-" not in m["with"]:
                continue
            file = m["with"].split("(suite-beyond-")[1].rstrip(")")
            c = load(case_path(f"suite/beyond-{file}.toml"))
            if resolve(c).slot(r["slot"]).id != r["id"]:
                continue  # the law set into another law's case: law_cases' own
            mp = scenario.mapping(c, name)
            assert (m["fidelity"], m["reason"]) == (mp.fidelity, "; ".join(mp.reasons)), (r["id"], name)
            checked += 1
    assert checked >= 10


def test_measured_mappings_of_lammps_and_liggghts():
    """The mappings tests/test_scenarios_lammps.py and test_scenarios_liggghts.py run for real."""
    got = {(r["slot"], r["id"]): {e: m["fidelity"] for e, m in r["engines"].items()} for r in _beyond_rows()}
    assert got[("rolling", "constant_torque")]["lammps"] == "approximate"
    assert got[("rolling", "epsd")]["lammps"] == "exact"
    assert got[("twisting", "sds")]["lammps"] == "exact"
    assert got[("adhesion", "jkr")]["lammps"] == "approximate"
    assert got[("heat", "radius")]["lammps"] == "exact"
    assert got[("heat", "lens")]["liggghts"] == "exact"
    assert got[("heat", "radius")]["liggghts"] == "approximate"
    assert got[("twisting", "sds")]["liggghts"] == "none"
    # sjkr in the pull-off (LIGGGHTS cohesion sjkr on hertz/stiffness); no LAMMPS or LIGGGHTS viscous rolling
    assert got[("adhesion", "sjkr")]["liggghts"] == "exact" and got[("adhesion", "sjkr")]["lammps"] == "none"
    assert got[("rolling", "viscous")]["lammps"] == got[("rolling", "viscous")]["liggghts"] == "none"


def test_marshall_in_a_case_without_a_tangential_spring_is_refused_with_its_reason():
    """LAMMPS twisting marshall builds on the tangential spring: a twist case without one is none, not a crash."""
    rows = [r for r in _beyond_rows() if r["id"] == "marshall"]
    m = rows[0]["engines"]["lammps"]
    assert m["fidelity"] == "none" and "tangential" in m["reason"]


def test_models_command_shows_the_fidelities():
    out = CliRunner().invoke(cli, ["models"])
    assert out.exit_code == 0, out.output
    line = next(x for x in out.output.splitlines() if x.startswith("rolling") and " epsd " in x)
    assert line.split()[2:4] == ["—", "exact"] and "not wired" not in out.output
    js = json.loads(CliRunner().invoke(cli, ["models", "dmt", "--json"]).output)["models"]
    assert js[0]["engines"]["lammps"]["fidelity"] == "exact"


def test_lammps_scenario_mapping_of_marshall_without_a_tangential_spring():
    import tomllib

    from demcheck.case import from_dict

    raw = tomllib.loads(case_path("suite/beyond-twist.toml").read_text())
    raw["contact"] = {"normal": "hertz", "twisting": "marshall", "kt": 1e5}
    mp = scenario.mapping(from_dict(raw), "lammps")
    assert mp.fidelity == "none" and mp.native is None and "tangential spring" in mp.reasons[0]


def _no_slip_bound(c):
    """The largest Cr under which the case's sphere rolls on its level wall without slip, from the case's own numbers:
    rolling, v' = −v/T with T = 1.4 m R²/Cr, and the friction force m|v'| ≤ μ m g at the start: Cr ≤ 1.4 μ m g R²/v0."""
    import math

    p = c.particles[0]
    mat = c.materials[p.material]
    mass = mat.density * 4.0 / 3.0 * math.pi * p.radius ** 3
    g = math.hypot(*c.run.gravity)
    return 1.4 * mat.friction * mass * g * p.radius ** 2 / math.hypot(*p.velocity)


def test_the_viscous_rolling_example_rolls_without_slip():
    """`demcheck models` sets type B into the suite's rolling cases with an example Cr derived from the case: half the
    no-slip bound rounded down (1e-8 N·m·s for the suite's glass sphere, whose bound is 2.19e-8). Its Kratos twin runs
    and gives the closed form's time constant. (Before: Cr = 1e-7 for every case, 4.6× the bound: the sphere slid,
    and the rolling time constant came out NaN.)"""
    import math

    cases, _ = scenario.law_cases("rolling", "viscous")
    rolling = [c for c in cases if c.run.scenario == "rolling"]
    assert len(rolling) == 2
    for c in rolling:
        bound = _no_slip_bound(c)
        assert abs(bound / 2.192e-8 - 1) < 1e-3  # the suite's glass sphere at 0.02 m/s, μ 0.3
        assert 0.25 * bound < c.contact.params["c_r"] <= 0.5 * bound, (c.name, c.contact.params["c_r"], bound)
        assert abs(scenario.rolling_grip(c)[2] / bound - 1) < 1e-12
    linear = next(c for c in rolling if c.name.endswith("linear"))
    res = scenario.twin(linear, "kratos")
    assert res.ok, res.message
    p = linear.particles[0]
    mass = linear.materials[p.material].density * 4.0 / 3.0 * math.pi * p.radius ** 3
    tau = res.metrics()["rolling_time_constant"]
    assert abs(tau / (1.4 * mass * p.radius ** 2 / linear.contact.params["c_r"]) - 1) < 1e-3
