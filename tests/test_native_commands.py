"""Native settings ([engine.NAME]) in bench, dt, stress and sweep, the LIGGGHTS reverse lookup, and the LAMMPS
mixing trap with unlike coefficients.

An engine with the case's own setting runs that native law, as its twin does; both are measured against the
twin's converged answer (the seed model of [contact] is another law). Golden values come from independent
paths: Hertz's elastic contact time by quadrature, the restitution of a Hertz spring with a δ^¼ dashpot from
an ODE solve (tests/test_native.py's for LAMMPS's tsuji; LIGGGHTS's √5 β(e) here, with and without the force
limit), the speed-independence of that restitution, and Hertz's scale invariance."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import pytest
from scipy.integrate import quad, solve_ivp

import demcheck
from demcheck.comparisons import audit as A, bench as B, stress as S
from demcheck.errors import ConfigError

from .test_native import TSUJI, _case, to_toml, tsuji_restitution

E, NU, RHO, R = 63e9, 0.24, 2500.0, 1e-3
MASS = RHO * 4.0 / 3.0 * math.pi * R ** 3


def demcheck_cli(*args, timeout=600):
    return subprocess.run([sys.executable, "-m", "demcheck", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout)


def _one_line_exit_2(p, *needles):
    assert p.returncode == 2, p.stdout[-2000:] + p.stderr
    assert p.stderr.strip().count("\n") == 0, p.stderr
    for n in needles:
        assert n in p.stderr, p.stderr


def hertz_contact_time(e_star: float, m: float, r: float, v: float) -> float:
    """The elastic Hertz contact time by quadrature: ½mv² = (2/5)Kδ_max^{5/2}, K = (4/3)E*√R,
    t_c = 2 (δ_max/v) ∫₀¹ dx/√(1 − x^{5/2})."""
    k = 4.0 / 3.0 * e_star * math.sqrt(r)
    d_max = (5.0 * m * v * v / (4.0 * k)) ** 0.4
    integral = quad(lambda x: 1.0 / math.sqrt(1.0 - x ** 2.5), 0.0, 1.0, limit=200)[0]
    return 2.0 * d_max / v * integral


def hertz_dashpot_restitution(alpha: float, limit: bool = False) -> float:
    """e of x'' = −f, f = x^{3/2} + α x^{1/4} x' (held ≥ 0 with ``limit``), x(0) = 0, x'(0) = 1: a Hertz spring
    with a δ^¼ dashpot in units that leave no mass, modulus or speed."""
    def rhs(t, y):
        x = max(y[0], 0.0)
        f = x ** 1.5 + alpha * x ** 0.25 * y[1]
        return [y[1], -(max(f, 0.0) if limit else f)]

    def out(t, y):
        return y[0]
    out.terminal, out.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 50.0), [1e-300, 1.0], events=out, rtol=1e-12, atol=1e-14, method="DOP853")
    return -float(sol.y_events[0][0][1])


def liggghts_alpha(e: float) -> float:
    """LIGGGHTS hertz: γn = −2√(5/6) β √(S_n m̄), S_n = 2E*√(R̄δ), β = ln e/√(ln²e + π²): α = −√5 β in the units
    of hertz_dashpot_restitution."""
    beta = math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi ** 2)
    return -math.sqrt(5.0) * beta


def _no_engine(monkeypatch, *names):
    """The engines ``names`` treated as not installed: their twins still run (no engine needed)."""
    from demcheck.engines import discovery

    real = discovery.find
    monkeypatch.setattr(discovery, "find", lambda e, *a, **k: None if e in names else real(e, *a, **k))


def _native_file(tmp_path, engine_table=None, angle=0.0, name="tsuji.toml"):
    f = tmp_path / name
    f.write_text(to_toml(_case(engine_table or {"lammps": {"pair_coeff": TSUJI}}, angle=angle)))
    return f


E_WALL_PAIR = E / (2.0 * (1.0 - NU * NU))  # LAMMPS reads a wall's hertz/material E and ν as a pair's


# ----------------------------------------------------------------------------- bench


def test_bench_measures_the_native_twin_against_its_own_converged_answer(monkeypatch):
    """lammps-twin's errors are against the tsuji law's converged contact (the ODE's e), on a grid of the native
    law's own contact time, and they shrink with the step; against the seed model they would be ≥ 0.16."""
    _no_engine(monkeypatch, "lammps")
    case = demcheck.load(_case({"lammps": {"pair_coeff": TSUJI}}))
    b = B.bench_case(case, engines=("lammps",), steps=(50, 200, 1000), rtols=()).summary()
    law = b["natives"]["lammps"]
    golden = tsuji_restitution(0.6)
    assert law["converged"]["restitution"] == pytest.approx(golden, abs=2e-6)
    t_c = hertz_contact_time(E_WALL_PAIR, MASS, R, 1.0)
    assert law["t_contact"] == pytest.approx(t_c, rel=1e-6)
    assert b["t_contact"] == pytest.approx(hertz_contact_time(E / (1 - NU * NU), MASS, R, 1.0), rel=1e-6)
    twin = [p for p in b["points"] if p["source"] == "lammps-twin"]
    assert [p["dt"] * p["steps_per_contact"] for p in twin] == pytest.approx([t_c] * 3, rel=1e-9)
    errors = [p["error"] for p in twin]
    assert errors[0] > errors[1] > errors[2] and errors[2] < 1e-3
    assert all(p["status"] == "ok" for p in twin)
    seed_e = b["reference"]["restitution"]
    assert law["seed_gap"]["restitution"] == pytest.approx(abs(golden - seed_e) / seed_e, rel=1e-4)
    assert law["seed_gap"]["restitution"] > 0.16
    assert "lammps-twin converged" in b["sources"]["lammps-twin"]["against"]
    assert "seed model" in b["sources"]["reference-verlet"]["against"]
    assert "lammps" in b["skipped"]  # not installed here: the twin ran without it


def test_a_force_history_converged_answer_understates_no_error_of_the_grid():
    """A twin with an incremental force history (Yade's Mindlin) has no adaptive solve: its converged answer is
    verlet at t_c/CONVERGED_STEPS, a first-order scheme there. The finest grid point's error against it must be
    its error against a twice finer run to within 10% (at 20 000 steps it was half of it)."""
    from demcheck.engines.base import Native
    from demcheck.engines.collide import twin_states
    from demcheck.engines.yade.mapping import MINDLIN
    from demcheck.reference.health import impact_scales

    case = demcheck.load(_case({}, angle=30.0))
    g = E / (2 * (1 + NU))
    nat = Native("yade", MINDLIN, tangential="mindlin", props={
        "kno": 4 / 3 * E / (1 - NU ** 2) * math.sqrt(R), "kso": 8 * g / (2 - NU) * math.sqrt(R), "betan": 0.2,
        "betas": 0.2, "mu": 0.5})
    law = B.native_law(case, "yade", nat)
    assert law.how.startswith(f"verlet at t_c/{B.CONVERGED_STEPS}")
    assert B.CONVERGED_STEPS >= 4 * max(B.DT_STEPS)
    finer = twin_states(case, "yade", law.t_contact / (2 * B.CONVERGED_STEPS), native=nat).metrics()
    point = twin_states(case, "yade", law.t_contact / max(B.DT_STEPS), native=nat).metrics()
    scales = impact_scales(case, law.model)
    against = B._native_errors(law, point, scales)
    truer = B._errors(point, finer, B.METRICS + B.OBLIQUE_METRICS, scales)
    for k in ("peak_force", "rebound_angular_velocity", "tangential_restitution"):
        assert against[k] == pytest.approx(truer[k], rel=0.1), k


@pytest.mark.engine("lammps")
def test_cli_bench_runs_the_native_law_in_lammps_as_its_twin(tmp_path):
    f = _native_file(tmp_path)
    p = demcheck_cli("bench", f, "--engines", "lammps", "--steps", "20,100", "--batch", "2", "--report",
                     tmp_path / "r", "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    (b,) = json.loads(p.stdout)["cases"]
    eng = {q["steps_per_contact"]: q for q in b["points"] if q["source"] == "lammps"}
    twin = {q["steps_per_contact"]: q for q in b["points"] if q["source"] == "lammps-twin"}
    assert set(eng) == set(twin) == {20, 100}
    for spc in eng:
        assert eng[spc]["status"] == "ok" and eng[spc]["batch_time"] > 0
        for k, v in twin[spc]["errors"].items():  # an exact twin: the same error against the same answer
            assert eng[spc]["errors"][k] == pytest.approx(v, abs=1e-9), k
    assert b["natives"]["lammps"]["native"].startswith("hertz/material damping tsuji")
    text = demcheck_cli("bench", f, "--engines", "lammps", "--steps", "20", "--batch", "2", "--report", tmp_path / "r")
    assert text.returncode == 0
    assert "measured against lammps-twin converged" in text.stdout and "restitution 0.6990 native" in text.stdout


# ----------------------------------------------------------------------------- dt


def test_dt_recommends_a_step_for_the_native_law_that_meets_the_target():
    """The recommended step for tsuji, checked on an independent path: the twin at that dt against the ODE's
    restitution, within the target; the seed model keeps its own recommendation."""
    case = demcheck.load(_case({"lammps": {"pair_coeff": TSUJI}}))
    rec = B.recommend(case, 1e-3)
    n = rec["natives"]["lammps"]
    assert rec["dt"] is not None and n["dt"] is not None and n["dt"] != rec["dt"]
    assert n["t_contact"] == pytest.approx(hertz_contact_time(E_WALL_PAIR, MASS, R, 1.0), rel=1e-6)
    assert n["dt"] == pytest.approx(n["t_contact"] / n["steps_per_contact"], rel=1e-12)
    assert n["expected_error"] <= 1e-3 and "lammps-twin converged" in n["against"]
    at = demcheck.collide(case, source="lammps-twin", dt=n["dt"]).metrics()["restitution"]
    golden = tsuji_restitution(0.6)
    assert abs(at - golden) / golden <= 1e-3
    coarser = [r for r in n["table"] if r["steps_per_contact"] < n["steps_per_contact"]]
    assert coarser and coarser[-1]["error"] > 1e-3  # the cheapest: the next coarser step misses


def test_cli_dt_names_the_native_law_and_says_when_no_step_converges(tmp_path):
    f = _native_file(tmp_path)
    p = demcheck_cli("dt", f)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "lammps (the case's own setting: hertz/material damping tsuji" in p.stdout
    assert "against lammps-twin converged" in p.stdout
    # at 30° LAMMPS's mindlin NULL under tsuji has no limit as dt → 0 (its Maw history at contact onset): no
    # step of the grid meets 1e-3 in the tangential metrics, and dt says so (exit 1)
    p = demcheck_cli("dt", f, "--set", "impact.angle=30.0", "--json")
    assert p.returncode == 1
    n = json.loads(p.stdout)["natives"]["lammps"]
    assert n["dt"] is None and ("tangential_restitution" in n["message"] or "rebound" in n["message"])


@pytest.mark.engine("lammps")
def test_lammps_at_the_recommended_native_dt_meets_the_target():
    case = demcheck.load(_case({"lammps": {"pair_coeff": TSUJI}}))
    n = B.recommend(case, 1e-3)["natives"]["lammps"]
    r = demcheck.collide(case, source="lammps", dt=n["dt"])
    golden = tsuji_restitution(0.6)
    assert r.ok and abs(r.metrics()["restitution"] - golden) / golden <= 1e-3


# ----------------------------------------------------------------------------- stress


def _raw(pair_coeff=TSUJI):
    return _case({"lammps": {"pair_coeff": pair_coeff}})


def test_stress_maps_the_native_law_in_its_own_contact_time(monkeypatch):
    """Hertz with a δ^¼ dashpot has no scale of its own: a 100× stiffer pair_coeff, with the free flight before
    the contact scaled as its contact time (100^(−2/5), so that the steps fall alike), gives the same stability
    limits in units of its own contact time; in the seed's they would be 4.8× apart."""
    from demcheck.case import from_dict

    _no_engine(monkeypatch, "lammps")
    out = {}
    for e_mod, gap in (("63e9", 1e-6), ("6.3e12", 1e-6 * 100 ** -0.4)):
        raw = _raw(TSUJI.replace("63e9", e_mod))
        raw["impact"]["gap"] = gap
        out[e_mod] = S.stress_case(raw, from_dict(raw), engines=("lammps",), only=["speed"]).summary()
    a, b = ({(l["value"]): l for l in out[k]["limits"] if l["source"] == "lammps-twin"} for k in out)
    assert set(a) == set(b) == {0.01, 1.0, 100.0}
    for v in a:
        assert a[v]["dt_max_over_tc"] == b[v]["dt_max_over_tc"] is not None
        assert b[v]["t_contact"] / a[v]["t_contact"] == pytest.approx(100 ** -0.4, rel=1e-9)
    # the seed model's contact time is another: E/(1−ν²) at a rigid wall against the pair_coeff's E/(2(1−ν²))
    seed = [l for l in out["6.3e12"]["limits"] if l["source"] == "reference-verlet"]
    assert seed and seed[0]["t_contact"] / b[seed[0]["value"]]["t_contact"] == pytest.approx(50 ** 0.4, rel=1e-9)
    assert out["63e9"]["natives"] == {"lammps": "hertz/material damping tsuji tangential mindlin"}


def test_stress_leaves_out_a_parameter_the_native_setting_does_not_read(monkeypatch):
    """LAMMPS's pair_coeff gives its own modulus: the stiffness parameter (the materials' E) does not move it and
    is left out for lammps and its twin, with the reason; LIGGGHTS reads the materials' E, and runs."""
    from demcheck.case import from_dict

    _no_engine(monkeypatch, "lammps", "liggghts")
    raw = _raw()
    s = S.stress_case(raw, from_dict(raw), engines=("lammps",), only=["stiffness"]).summary()
    assert {l["source"] for l in s["limits"]} == {"reference-verlet"}
    (why,) = [v for k, v in s["skipped"].items() if "lammps-twin" in k]
    assert "[engine.lammps]" in why and "stiffness" in why
    raw = _case({"liggghts": {"pair_style": "gran model hertz tangential history"}})
    s = S.stress_case(raw, from_dict(raw), engines=("liggghts",), only=["stiffness"]).summary()
    twin = [l for l in s["limits"] if l["source"] == "liggghts-twin"]
    assert [l["value"] for l in twin] == [0.01, 1.0, 100.0]
    assert twin[0]["t_contact"] / twin[2]["t_contact"] == pytest.approx(1e4 ** 0.4, rel=1e-6)  # E^(−2/5)


def test_stress_flags_an_engine_against_its_twin_not_the_seed():
    L = S.Limit
    res = S.StressResult("x", {}, [L("p", 1.0, "reference-verlet", 100, 0.01), L("p", 1.0, "lammps-twin", 1, 1.0),
                                   L("p", 1.0, "lammps", 1, 1.0), L("p", 1.0, "liggghts", 1, 1.0)])
    flags = res.flags()  # lammps agrees with its twin; liggghts (mapped) is judged against the reference
    assert [(f["source"], f["against"]) for f in flags] == [("liggghts", "reference-verlet")]
    res.limits[2] = L("p", 1.0, "lammps", 100, 0.01)
    assert ("lammps", "lammps-twin") in [(f["source"], f["against"]) for f in res.flags()]


@pytest.mark.engine("lammps")
def test_cli_stress_runs_the_native_law_in_lammps(tmp_path):
    f = _native_file(tmp_path)
    p = demcheck_cli("stress", f, "--engines", "lammps", "--only", "speed", "--report", tmp_path / "r", "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    (s,) = json.loads(p.stdout)["cases"]
    eng = {l["value"]: l["dt_max_over_tc"] for l in s["limits"] if l["source"] == "lammps"}
    twin = {l["value"]: l["dt_max_over_tc"] for l in s["limits"] if l["source"] == "lammps-twin"}
    assert eng == twin and len(eng) == 3 and s["disagreements"] == []


# ----------------------------------------------------------------------------- sweep


def test_api_sweep_of_the_native_twin_over_speed():
    """Tsuji's restitution on Hertz does not depend on the impact speed (the ODE has no speed): the twin gives
    the ODE's e at every speed, to its time-step error."""
    table = demcheck.sweep(_case({"lammps": {"pair_coeff": TSUJI}}), {"impact.speed": [0.3, 1.0, 3.0]},
                           source="lammps-twin")
    golden = tsuji_restitution(0.6)
    assert list(table["status"]) == ["ok"] * 3
    # at the native law's own step, t_c/200 (bench: 1.03e-3 at 200 steps in its worst metric; measured here
    # 1e-5 to 5.1e-4, with the phase of the contact's onset in the step)
    assert all(abs(e - golden) < 1e-3 for e in table["restitution"]), list(table["restitution"])


def test_a_native_law_runs_at_its_own_step():
    """The default step of a native source is the native law's elastic contact time (Hertz's by quadrature, at
    LAMMPS's wall E* = E/(2(1−ν²))) over run.steps_per_contact, not the seed model's; run.dt and dt still win."""
    case = demcheck.load(_case({"lammps": {"pair_coeff": TSUJI}}))
    t_c = hertz_contact_time(E_WALL_PAIR, MASS, R, 1.0)
    assert demcheck.collide(case, source="lammps-twin").dt == pytest.approx(t_c / 200, rel=1e-6)
    assert demcheck.collide(case, source="lammps-twin", dt=1e-8).dt == 1e-8
    assert demcheck.collide(case, source="lammps-twin", overrides=["run.dt=2e-8"]).dt == 2e-8
    # Hertz with a δ^¼ dashpot has no scale of its own: 10⁵× stiffer, the same e at the same steps per ITS
    # contact (at the seed model's step it would be 0.751, unresolved)
    stiff = TSUJI.replace("63e9", "63e14")
    table = demcheck.sweep(case, {"engine.lammps.pair_coeff": [TSUJI, stiff]}, source="lammps-twin")
    assert list(table["status"]) == ["ok", "ok"]
    assert all(abs(e - tsuji_restitution(0.6)) < 1e-3 for e in table["restitution"]), list(table["restitution"])


def test_a_contact_override_is_refused_for_a_native_source(tmp_path):
    """--set contact.* (the seed model's) changes no native run, as --vary contact.* does not: refused in one line
    before any work; the reference still takes it."""
    f = _native_file(tmp_path)
    _one_line_exit_2(demcheck_cli("sweep", f, "--engine", "lammps-twin", "--set", "contact.restitution=0.5",
                                  "--vary", "impact.speed=1,2"),
                     "--set contact.restitution = '0.5'", "[engine.lammps]", "does not change")
    case = _case({"lammps": {"pair_coeff": TSUJI}})
    with pytest.raises(ConfigError) as err:
        demcheck.sweep(case, {"impact.speed": [1.0]}, source="lammps-twin", contact__restitution=0.5)
    assert err.value.key == "overrides.contact.restitution" and "[engine.lammps]" in err.value.rule
    assert demcheck.sweep(case, {"impact.speed": [1.0]}, overrides={"contact.restitution": 0.5})["status"][0] == "ok"
    with pytest.raises(ConfigError) as err:  # the command's source and method checks, with the API's names
        demcheck.sweep(case, {"impact.speed": [1.0]}, source="lammps-twin", method="verlet")
    assert err.value.key == "method" and "at dt" in err.value.rule
    with pytest.raises(ConfigError) as err:
        demcheck.sweep(case, {"impact.speed": [1.0]}, source="lamps")
    assert err.value.key == "source" and "lammps-twin" in err.value.rule


@pytest.mark.engine("lammps")
def test_api_sweep_in_lammps_at_the_native_step_and_its_worker_ends_on_request():
    from demcheck.engines import run

    case = _case({"lammps": {"pair_coeff": TSUJI}})
    grid = {"engine.lammps.pair_coeff": [TSUJI, TSUJI.replace("63e9", "63e14")]}
    eng = demcheck.sweep(case, grid, source="lammps")
    twin = demcheck.sweep(case, grid, source="lammps-twin")
    assert list(eng["status"]) == ["ok", "ok"]
    assert list(eng["restitution"]) == pytest.approx(list(twin["restitution"]), abs=1e-9)
    assert run.workers()  # the idle worker stays for the next sweep…
    run.shutdown_workers()  # …until the API's user ends it
    assert run.workers() == []


def test_api_sweep_refuses_a_contact_key_for_the_native_source_only():
    case = _case({"lammps": {"pair_coeff": TSUJI}})
    with pytest.raises(ConfigError) as err:
        demcheck.sweep(case, {"contact.restitution": [0.5, 0.7]}, source="lammps-twin")
    assert err.value.key == "vary.contact.restitution" and "[engine.lammps]" in err.value.rule
    seed = demcheck.sweep(case, {"contact.restitution": [0.5, 0.7]})  # the reference: the seed model varies
    assert seed["restitution"].iloc[0] < seed["restitution"].iloc[1]


def test_cli_sweep_refusals_are_one_line_before_any_work(tmp_path):
    f = _native_file(tmp_path)
    out = tmp_path / "s.csv"
    p = demcheck_cli("sweep", f, "--engine", "lammps-twin", "--vary", "contact.restitution=0.5,0.7", "--csv", out)
    _one_line_exit_2(p, "--vary contact.restitution = [0.5, 0.7]", "[engine.lammps]", "does not change")
    p = demcheck_cli("sweep", f, "--engine", "lammps", "--vary", "materials.glass.youngs_modulus=6e10,7e10",
                     "--csv", out)
    _one_line_exit_2(p, "materials.glass.youngs_modulus", "changes neither that law nor the masses")
    p = demcheck_cli("sweep", f, "--engine", "lammps-twin", "--method", "verlet", "--vary", "impact.speed=1,2")
    _one_line_exit_2(p, "--method = 'verlet'")
    p = demcheck_cli("sweep", f, "--engine", "lamps-twin", "--vary", "impact.speed=1,2")
    _one_line_exit_2(p, "--engine = 'lamps-twin'", "lammps-twin")
    assert not out.exists()
    ok = demcheck_cli("sweep", f, "--engine", "lammps-twin", "--vary", "materials.glass.density=2000.0,3000.0",
                      "--json")  # the masses move: the native run does
    assert ok.returncode == 0, ok.stderr


def test_cli_sweep_of_a_liggghts_native_property():
    """Sweeping the native setting itself: LIGGGHTS hertz realises its coefficientRestitution (the ODE with
    α = −√5 β(e) gives it back to 1e-4), whatever it is."""
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        f = _native_file(Path(d), {"liggghts": {"pair_style": "gran model hertz tangential history"}})
        p = demcheck_cli("sweep", f, "--engine", "liggghts-twin", "--vary",
                         "engine.liggghts.coefficientRestitution=0.3,0.6,0.9", "--json")
    assert p.returncode == 0, p.stderr
    rows = json.loads(p.stdout)["rows"]
    for row in rows:
        e_in = row["engine.liggghts.coefficientRestitution"]
        assert hertz_dashpot_restitution(liggghts_alpha(e_in)) == pytest.approx(e_in, abs=1e-4)
        assert row["restitution"] == pytest.approx(e_in, abs=2e-3)  # the twin at the case's dt


STIFF = {"pair_style": "gran model hooke/stiffness tangential history", "kn": "1e5", "kt": "1e5", "gamman": "1",
         "gammat": "1"}


@pytest.mark.parametrize("table, key, words", [
    ({**STIFF, "kn": "0"}, "engine.liggghts.kn", "must be > 0"),
    ({**STIFF, "kn": "-1e5"}, "engine.liggghts.kn", "must be > 0"),
    ({**STIFF, "gamman": "-1"}, "engine.liggghts.gamman", "must be >= 0"),
    ({**STIFF, "coefficientFriction": "-0.5"}, "engine.liggghts.coefficientFriction", "must be >= 0"),
    ({k: v for k, v in STIFF.items() if k != "gammat"}, "engine.liggghts.gammat",
     "model hooke/stiffness needs kn, kt, gamman, gammat"),
    ({k: v for k, v in STIFF.items() if k not in ("kn", "kt")}, "engine.liggghts.kn", "needs kn, kt"),
    ({**STIFF, "pair_style": "gran model hertz/stiffness tangential history", "gamman": "0"}, "engine.liggghts",
     "no twin"),
])
def test_case_native_numbers_out_of_range_name_their_key(table, key, words):
    """A case's [engine.liggghts] property out of range, or a */stiffness model's missing (never a silent 0), is a
    ConfigError naming its key before any work."""
    with pytest.raises(ConfigError) as err:
        demcheck.load(_case({"liggghts": table}))
    assert err.value.key == key and words in err.value.rule, (err.value.key, err.value.rule)


def test_case_native_numbers_out_of_range_in_a_sweep_are_one_line(tmp_path):
    f = _native_file(tmp_path, {"liggghts": {**STIFF, "kn": "0"}})
    _one_line_exit_2(demcheck_cli("sweep", f, "--engine", "liggghts-twin", "--vary", "impact.speed=1,2"),
                     "engine.liggghts.kn = '0': must be > 0")
    f = _native_file(tmp_path, {"lammps": {"pair_coeff": TSUJI.replace("63e9", "0")}}, name="e0.toml")
    _one_line_exit_2(demcheck_cli("sweep", f, "--engine", "lammps-twin", "--vary", "impact.speed=1,2"),
                     "engine.lammps.pair_coeff", "hertz/material E = 0: must be > 0")


@pytest.mark.engine("lammps")
def test_cli_sweep_runs_the_native_law_in_lammps(tmp_path):
    f = _native_file(tmp_path)
    p = demcheck_cli("sweep", f, "--engine", "lammps", "--vary", "impact.angle=0,30", "--json")
    assert p.returncode == 0, p.stderr[-2000:]
    rows = json.loads(p.stdout)["rows"]
    twin = demcheck.sweep(_case({"lammps": {"pair_coeff": TSUJI}}), {"impact.angle": [0.0, 30.0]},
                          source="lammps-twin")
    for row, e_twin in zip(rows, twin["restitution"]):
        assert row["status"] == "ok" and row["restitution"] == pytest.approx(e_twin, abs=1e-9)


# ----------------------------------------------------------------------------- reverse lookups

LIGGGHTS_LINE = ("model hertz tangential history coefficientRestitution=0.6 coefficientFriction=0.5 "
                 f"youngsModulus={E:g} poissonsRatio={NU:g}")


def test_liggghts_reverse_lookup_names_the_seed_model_and_its_fidelity():
    p = demcheck_cli("models", "--engine", "liggghts", "--json", LIGGGHTS_LINE)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout)
    assert (r["seed"]["normal"], r["seed"]["tangential"]) == ("tti", "tti")
    # the normal law gives e back (the ODE); the tangential dashpot γn√(4G*/E*) is not TTIt's: approximate
    assert r["probes"][0]["twin"]["restitution"] == pytest.approx(
        hertz_dashpot_restitution(liggghts_alpha(0.6)), abs=1e-6)
    assert r["fidelity"] == "approximate" and 1e-3 < r["gap"] < 0.1
    assert r["implied"]["E*"] == pytest.approx(E / (2 * (1 - NU ** 2)), rel=1e-12)
    assert float(r["implied"]["kt"].split()[0]) == pytest.approx(8 * E / (4 * (2 - NU) * (1 + NU)), rel=1e-5)
    assert [f["code"] for f in r["findings"]] == ["hard-particles"]  # 63 GPa without hard_particles=yes
    again = demcheck_cli("models", "--engine", "liggghts", "--json", "pair_style gran " + LIGGGHTS_LINE
                         + " hard_particles=yes")
    assert again.returncode == 0 and json.loads(again.stdout)["findings"] == []
    text = demcheck_cli("models", "--engine", "liggghts", LIGGGHTS_LINE, "--radius", "2e-3")
    assert text.returncode == 0 and "nearest seed model: normal tti, tangential tti — approximate" in text.stdout
    assert "R = 0.002 m" in text.stdout


def test_liggghts_reverse_lookup_flags_limitforce_with_its_number():
    line = "gran " + LIGGGHTS_LINE.replace("history", "history limitForce on") + " hard_particles=yes"
    r = A.reverse("liggghts", line, radius=2e-3, speed=0.5)
    (f,) = r["findings"]
    assert f["code"] == "limit" and f["size"]["asked"] == 0.6
    assert f["size"]["realised"] == pytest.approx(hertz_dashpot_restitution(liggghts_alpha(0.6), limit=True),
                                                  abs=1e-5)
    assert f["size"]["realised"] > 0.62 and "0.6323 realised" in f["text"]


def test_liggghts_reverse_lookup_notes_rolling_friction_and_cohesion_once():
    r = A.reverse("liggghts", LIGGGHTS_LINE.replace("history", "history rolling_friction epsd2 cohesion sjkr"))
    assert [n.split()[0] for n in r["notes"]] == ["rolling_friction", "cohesion"], r["notes"]


@pytest.mark.parametrize("line, words", [
    ("model hertz tangential history coefficientRestitution=0.6 youngsModulus=63e9 poissonsRatio=0.24",
     "needs coefficientFriction"),
    ("model hertz tangential off coefficientRestitution=0.6", "needs youngsModulus=…, poissonsRatio=…"),
    ("model hooke/stiffness tangential history kn=1e5 coefficientFriction=0.5", "needs kt=…, gamman=…, gammat=…"),
    ("model hertz tangential off coefficientRestitution=x youngsModulus=63e9 poissonsRatio=0.24", "not a number"),
    ("model hertz tangential off colour=red", "colour: not a property read here"),
    ("model hertz tangential off coefficientRestitution=1.5 youngsModulus=63e9 poissonsRatio=0.24", "(0, 1]"),
    ("model hertzz", "not a LIGGGHTS 3.8.0 normal model"),
    # numbers out of range: one line naming the property and its value (never a traceback or an internal key)
    ("model hooke/stiffness tangential history kn=0 kt=1e5 gamman=1 gammat=1 coefficientFriction=0.5",
     "kn=0: must be > 0"),
    ("model hooke/stiffness tangential history kn=-1e5 kt=1e5 gamman=1 gammat=1 coefficientFriction=0.5",
     "kn=-100000: must be > 0"),
    ("model hertz/stiffness tangential history kn=1e5 kt=0 gamman=1 gammat=1 coefficientFriction=0.5",
     "kt=0: must be > 0"),
    ("model hooke/stiffness tangential history kn=1e5 kt=1e5 gamman=-1 gammat=1 coefficientFriction=0.5",
     "gamman=-1: must be >= 0"),
    ("model hooke/stiffness tangential history kn=1e5 kt=1e5 gamman=1 gammat=-1 coefficientFriction=0.5",
     "gammat=-1: must be >= 0"),
    (LIGGGHTS_LINE.replace("coefficientFriction=0.5", "coefficientFriction=-0.5"), "coefficientFriction=-0.5: must be"),
    ("model hertz/stiffness tangential history kn=1e5 kt=1e5 gamman=0 gammat=1 coefficientFriction=0.5", "no twin"),
])
def test_bad_liggghts_reverse_lookups_are_one_line(line, words):
    _one_line_exit_2(demcheck_cli("models", "--engine", "liggghts", line), "SETTING = ", words)


def test_reverse_lookups_of_other_engines_and_untwinned_laws():
    _one_line_exit_2(demcheck_cli("models", "--engine", "yade", "x"), "--engine = 'yade'", "has no reverse lookup",
                     "lammps:", "liggghts:")
    _one_line_exit_2(demcheck_cli("models", "--radius", "1e-3"), "--radius", "reverse lookup")
    _one_line_exit_2(demcheck_cli("models", "--engine", "lammps", "hooke 1e5 0.5 tangential mindlin NULL 1 0.5"),
                     "mindlin NULL: k_t from E and ν needs a material normal model")
    _one_line_exit_2(demcheck_cli("models", "--engine", "lammps", "hertz/material 0 0.6 0.24 tangential mindlin "
                                  "NULL 1.0 0.5"), "hertz/material E = 0: must be > 0")
    jkr = demcheck_cli("models", "--engine", "lammps", "--json", "jkr 1e9 0.5 0.3 0.1 tangential mindlin NULL 1 0.5")
    assert jkr.returncode == 0, jkr.stderr
    r = json.loads(jkr.stdout)
    assert r["seed"] is None and r["fidelity"] == "none"
    # the LAMMPS lookup's tsuji trap now carries the converged e (the ODE's)
    r = A.reverse("lammps", "* * " + TSUJI)
    (f,) = r["findings"]
    assert f["code"] == "tsuji" and f["size"]["realised"] == pytest.approx(tsuji_restitution(0.6), abs=1e-5)


# ----------------------------------------------------------------------------- the mixing trap, unlike types


def test_mixing_trap_of_unlike_hertz_material_types_carries_its_number(tmp_path):
    """Types 1 and 2 with different E and ν, auto-mixed with mindlin NULL: the trap's k_t ratio is LAMMPS's
    8E*/(4(2−ν̄)(1+ν̄)) over 8G* (closed forms of the mixing rules), and its measured size (the twin: no engine
    needed) is a real difference in the rebound."""
    deck = tmp_path / "in.mixed"
    deck.write_text(
        "units si\natom_style sphere\nboundary f f f\nregion box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box\n"
        "create_box 2 box\ncreate_atoms 1 single 0 0 0.005 units box\nset type 1 diameter 0.002 density 2500\n"
        "set type 2 diameter 0.004 density 7800\nvelocity all set 0 0 -1\ntimestep 2e-8\npair_style granular\n"
        "pair_coeff 1 1 hertz/material 63e9 0.6 0.24 damping coeff_restitution tangential mindlin NULL 1.0 0.5\n"
        "pair_coeff 2 2 hertz/material 200e9 0.8 0.3 damping coeff_restitution tangential mindlin NULL 1.0 0.4\n")
    r = A.audit(deck, run_engine=False)
    entry = next(p for p in r["pairs"] if p["pair"] == "1-2")
    (f,) = [f for f in entry["findings"] if f["code"] == "mixing"]
    e1, n1, e2, n2 = 63e9, 0.24, 200e9, 0.3
    e_star = 1 / ((1 - n1 ** 2) / e1 + (1 - n2 ** 2) / e2)
    nu = math.sqrt(n1 * n2)
    g_star = 1 / (2 * (2 - n1) * (1 + n1) / e1 + 2 * (2 - n2) * (1 + n2) / e2)
    assert f["size"]["kt_ratio"] == pytest.approx((8 * e_star / (4 * (2 - nu) * (1 + nu))) / (8 * g_star), rel=1e-12)
    worst = max(abs(v) for q in f["size"]["probes"] for v in q["difference"].values())
    assert worst > 0.01 and "measured at" in f["text"]
    # the pair asks for what LAMMPS's mixing gives it, √(e_I e_J) and √(μ_I μ_J): no restitution trap for the rule
    assert entry["asked"] == pytest.approx({"restitution": math.sqrt(0.6 * 0.8), "friction": math.sqrt(0.5 * 0.4)})
    assert "restitution" not in {f["code"] for f in entry["findings"]}
    assert not [f for p in r["pairs"] if p["pair"] in ("1-1", "2-2") for f in p["findings"] if f["code"] == "mixing"]
