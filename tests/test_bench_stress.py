"""Run time against error, stability, the recommended time step, and results that are never garbage."""

import json
import math
import subprocess
import sys

import pytest

import demcheck
from demcheck.comparisons import bench as B, stress as S
from demcheck.errors import ConfigError
from demcheck.reference.collision import auto_dt, collide

from .conftest import CASES
from .helpers import glass_case


def _pts(order, c=1.0, steps=(10, 20, 50, 100, 200, 500)):
    t_c = 1e-5
    return [B.Point("x", s, t_c / s, None, 1.0 / s, None, {m: c * (t_c / s / t_c) ** order for m in B.METRICS})
            for s in steps]


def test_fit_order_recovers_a_known_slope():
    assert B.fit_order(_pts(2.0, c=1e-1)) == pytest.approx(2.0, abs=1e-12)
    assert B.fit_order(_pts(1.0, c=1e-1)) == pytest.approx(1.0, abs=1e-12)


def test_cheapest_takes_the_largest_dt_whose_finer_steps_all_meet_the_target():
    pts = _pts(2.0, c=1.0)  # error = (1/steps)²: 1e-2 at 10 steps, 1e-4 at 100
    assert B.cheapest(pts, 1.01e-2).steps_per_contact == 10
    assert B.cheapest(pts, 1.01e-4).steps_per_contact == 100
    assert B.cheapest(pts, 1e-9) is None
    # a lucky coarse point followed by a miss is not taken for convergence
    pts[0].errors = {m: 1e-12 for m in B.METRICS}
    assert B.cheapest(pts, 1e-3).steps_per_contact == 50


def test_reference_bench_measures_the_orders_of_the_scheme():
    """Elastic Hertz converges at second order in the engines' scheme, a damped law at first
    (docs/models.md, convergence); the adaptive method's error follows its tolerance."""
    hertz = B.bench_case(glass_case("hertz", {}, wall=True), engines=(), steps=(20, 50, 100, 200, 500),
                         rtols=(1e-6, 1e-9, 1e-12)).summary()
    assert hertz["sources"]["reference-verlet"]["order"] == pytest.approx(2.0, abs=0.15)
    lsd = B.bench_case(glass_case("lsd", {"stiffness_method": "energy"}, wall=True, restitution=0.5), engines=(),
                       steps=(100, 200, 500, 1000, 2000), rtols=()).summary()
    # contact time (the restitution's O(dt) term depends on where the steps fall: see test_convergence.py)
    assert lsd["sources"]["reference-verlet"]["order_per_metric"]["contact_time"] == pytest.approx(1.0, abs=0.05)
    errs = [p["error"] for p in hertz["points"] if p["source"] == "reference-adaptive"]
    assert errs[0] > errs[1] > errs[2] and errs[2] < 1e-10


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_engine_bench_matches_the_reference_scheme_and_batching_pays():
    """An exact mapping: each engine's error at each step is the reference verlet's (the twin is the seed
    law), and a batch of copies costs less per collision than a process per collision."""
    b = B.bench_case(glass_case("kk", {"eta_n": 20.0}, wall=True), steps=(20, 200), rtols=(), batch=8).summary()
    ref = {p["steps_per_contact"]: p["error"] for p in b["points"] if p["source"] == "reference-verlet"}
    for engine in ("lammps", "liggghts"):
        pts = [p for p in b["points"] if p["source"] == engine]
        assert len(pts) == 2
        for p in pts:
            assert p["error"] == pytest.approx(ref[p["steps_per_contact"]], rel=1e-6)
            assert p["batch_time"] < p["wall_time"]


def test_largest_stable_bisects_a_monotone_limit():
    calls = []

    def check(spc):
        calls.append(spc)
        return spc >= 7, "too coarse"

    assert S.largest_stable(check) == (8, "too coarse")
    assert len(calls) <= 6
    assert S.largest_stable(lambda spc: (False, "never"))[0] is None
    assert S.largest_stable(lambda spc: (True, ""))[0] == S.GRID[0]


def test_verlet_stability_limit_of_an_undamped_linear_spring():
    """Velocity Verlet is stable for a linear spring while dt < 2/ω = (2/π) t_c: the finest grid point
    below that bound, 2 steps per contact time (1.5 gives ω dt = 2.09 > 2), is the limit."""
    case = glass_case("lsd", {"kn": 2e6, "eta_n": 0.0}, wall=True, restitution=1.0)
    model_tc = auto_dt(case) * case.run.steps_per_contact
    spc, why = S.largest_stable(lambda s: S._stable_reference(case, model_tc / s, model_tc))
    assert spc == 2
    assert "energy" in why or "overlap" in why or "NaN" in why


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_engines_and_reference_agree_about_stability(tmp_path):
    raw = S.read_table(CASES / "suite" / "normal-lsd-wall.toml")
    s = S.stress_case(raw, demcheck.load(raw), only=["restitution"]).summary()
    assert {"reference-verlet", "lammps", "liggghts"} <= {l["source"] for l in s["limits"]}  # and the other engines
    assert s["disagreements"] == []
    assert all(l["dt_max_over_tc"] for l in s["limits"])


def test_the_reference_never_returns_garbage_silently():
    case = glass_case("hertz", {}, wall=True)
    t_c = auto_dt(case) * case.run.steps_per_contact
    assert collide(case, "verlet", dt=t_c / 3).status == "unresolved"
    r = collide(case, "verlet", dt=t_c / 5)
    assert r.status == "unstable" and "created" in r.message
    assert collide(case, "verlet", dt=t_c / 50).status == "ok"
    bad = collide(glass_case("lsd", {"kn": 2e6, "eta_n": 0.0}, wall=True, restitution=1.0), "verlet", dt=t_c / 1.2)
    assert bad.status in ("unstable", "unresolved")


def test_recommended_time_step_meets_its_target():
    rec = B.recommend(glass_case("tti", {}, wall=True, restitution=0.7), target=1e-3)
    assert rec["dt"] is not None and rec["expected_error"] <= 1e-3
    assert rec["dt"] == pytest.approx(rec["t_contact"] / rec["steps_per_contact"])
    # the Hertz time of the rules of thumb is the exact elastic contact time
    assert rec["hertz_time"] == pytest.approx(rec["t_contact"], rel=1e-12)
    coarser = [row for row in rec["table"] if row["steps_per_contact"] < rec["steps_per_contact"]]
    assert all(row["error"] > 1e-3 or row["status"] != "ok" for row in coarser[-1:])


def test_oblique_time_steps_answer_for_the_friction_law_too():
    """An oblique impact's error includes tangential restitution and rebound spin: for Walton's law at the
    Coulomb limit (its verlet plateau is false: docs/models.md) the rebound spin sets the step for 1e-3, and
    no step of the grid meets 1e-4 — where the normal metrics alone would have asked for 100 steps."""
    from demcheck import case as C

    case = C.load(CASES / "oblique-walton-spin-wall.toml")
    rec = B.recommend(case, target=1e-3)
    assert rec["metrics"][-2:] == ["tangential_restitution", "rebound_angular_velocity"]
    assert rec["dt"] is not None and rec["limited_by"] in B.OBLIQUE_METRICS
    tight = B.recommend(case, target=1e-4)
    assert tight["dt"] is None and "rebound_angular_velocity" in tight["message"]
    normal_only = [row for row in tight["table"] if row["status"] == "ok"]
    assert normal_only  # the grid ran; the normal metrics alone meet 1e-4 at 100 steps per contact:
    b = B.bench_case(case, engines=(), rtols=(), steps=(100,))
    assert max(b.points[0].errors[k] for k in B.METRICS) < 1e-4 < b.points[0].error


def test_cli_dt_and_bad_target():
    ok = subprocess.run([sys.executable, "-m", "demcheck", "dt", str(CASES / "kk-wall.toml"), "--json"],
                        capture_output=True, text=True, timeout=300)
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["expected_error"] <= 1e-3
    bad = subprocess.run([sys.executable, "-m", "demcheck", "dt", str(CASES / "kk-wall.toml"), "--target", "2"],
                         capture_output=True, text=True, timeout=300)
    # one line naming the option and its value (the rule's wording is the CLI's)
    lines = bad.stderr.strip().splitlines()
    assert bad.returncode == 2 and len(lines) == 1 and "--target = 2.0: must be" in lines[0]


def test_cli_bench_reference_only_writes_reports(tmp_path):
    p = subprocess.run([sys.executable, "-m", "demcheck", "bench", str(CASES / "hertz-wall.toml"), "--engines", "none",
                        "--steps", "10,50,200", "--report", str(tmp_path), "--json"], capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["cases"][0]["sources"]["reference-verlet"]["cheapest"]["0.01"]["steps_per_contact"] in (10, 50, 200)
    latest = tmp_path / "latest-bench"
    assert not (tmp_path / "latest").exists()  # <report>/latest is verify's: bench keeps a link of its own
    assert "## Work–precision" in (latest / "report.md").read_text()
    assert '<img class="plot"' in (latest / "report.html").read_text()
    bad = subprocess.run([sys.executable, "-m", "demcheck", "bench", str(CASES / "hertz-wall.toml"), "--steps", "0,5"],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "--steps" in bad.stderr


def test_cli_stress_reference_only_writes_reports(tmp_path):
    p = subprocess.run([sys.executable, "-m", "demcheck", "stress", str(CASES / "suite" / "normal-hertz-wall.toml"),
                        "--engines", "none", "--only", "restitution", "--report", str(tmp_path), "--json"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert len(out["cases"][0]["limits"]) == 4
    assert "## Stability" in (tmp_path / "latest-stress" / "report.md").read_text()


# ----------------------------------------------------------------------------- every case file read first

# demcheck as a user runs it, except that the work of a case (a stress bisection, a bench sweep) announces itself
# and stops: a bad file after a good one must be refused before any of that starts
_NO_WORK = """
import sys
from demcheck import cli
from demcheck.comparisons import bench, stress

def work(*args, **kwargs):
    print("WORK STARTED", file=sys.stderr)
    raise SystemExit(99)

stress.largest_stable = bench.bench_case = work
cli.main(sys.argv[1:])
"""


@pytest.mark.parametrize("command", [["stress", "--only", "speed"], ["bench", "--steps", "10"]])
@pytest.mark.parametrize("bad,needle", [
    ('name = "bad"\nkind = "collision"\nbogus = 1\n', "bogus = 1: unknown key"),
    ("name = [", "= '(file)': not valid TOML"),
])
def test_every_case_file_is_read_before_any_work_and_named_in_the_error(command, bad, needle, tmp_path):
    bad_file = tmp_path / "bad.toml"
    bad_file.write_text(bad)
    p = subprocess.run([sys.executable, "-c", _NO_WORK, command[0], str(CASES / "glass-pair.toml"), str(bad_file),
                        *command[1:], "--engines", "none", "--report", str(tmp_path / "reports")],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr[-2000:]
    assert lines[0].startswith(f"demcheck: error: {bad_file}") and needle in lines[0], lines
    assert not (tmp_path / "reports").exists()


# ----------------------------------------------------------------------------- metrics a scene does not produce


def test_a_metric_undefined_on_both_sides_is_left_out_and_one_side_only_is_an_error():
    """A head-on impact has no tangential restitution and no rebound spin, neither in the converged answer
    nor in a time-stepped run: those metrics are left out of the error, not poisoned into it. A metric that
    one side defines and the other does not is a real disagreement and stays an error (NaN)."""
    ref = {"restitution": 0.9, "tangential_restitution": float("nan"), "rebound_angular_velocity": None}
    run = {"restitution": 0.9009, "tangential_restitution": float("nan"), "rebound_angular_velocity": None}
    metrics = ("restitution", "tangential_restitution", "rebound_angular_velocity")
    e = B._errors(run, ref, metrics, scales={})
    assert list(e) == ["restitution"] and e["restitution"] == pytest.approx(1e-3)
    one_side = B._errors({**run, "tangential_restitution": 0.5}, ref, metrics, scales={})
    assert math.isnan(one_side["tangential_restitution"])
    p = B.Point("x", 10, 1e-6, None, 1.0, None, one_side)
    assert math.isnan(p.error)
    assert math.isnan(B.Point("x", 10, 1e-6, None, 1.0, None, {}).error)  # nothing measured: no error


def test_head_on_impact_with_a_friction_law_gets_a_time_step():
    """`demcheck dt` and `bench` on a head-on case with a tangential law: the error is the normal metrics'
    (the tangential ones are undefined on both sides), finite, and dt answers with a time step."""
    args = ["--set", "contact.normal=lsd", "--set", "contact.stiffness_method=energy",
            "--set", "contact.tangential=spring_sliding", "--set", "materials.glass.friction=0.3"]
    p = subprocess.run([sys.executable, "-m", "demcheck", "dt", str(CASES / "glass-pair.toml"), *args],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "recommended dt" in p.stdout
    assert "errors of restitution, contact_time, max_overlap, peak_force)" in p.stdout, p.stdout
    from demcheck import case as C

    case = C.load(CASES / "glass-pair.toml", [a for a in args if a != "--set"])
    b = B.bench_case(case, engines=(), rtols=(1e-6,), steps=(50, 500))
    assert all(list(pt.errors) == list(B.METRICS) for pt in b.points)
    assert all(math.isfinite(pt.error) for pt in b.points)
    rec = B.recommend(case)
    assert rec["dt"] is not None and rec["metrics"] == list(B.METRICS) and rec["limited_by"] in B.METRICS


@pytest.mark.engine("kratos")
@pytest.mark.engine("yade")
def test_bench_times_engines_that_hold_one_collision_per_deck(tmp_path):
    """Yade's and Kratos' decks hold one collision (no batched copies): bench times the single run and leaves the
    batched time empty, instead of failing the point (Yade) or crashing (Kratos)."""
    import json
    import subprocess
    import sys

    p = subprocess.run([sys.executable, "-m", "demcheck", "bench", str(CASES / "hertz-wall.toml"), "--engines",
                        "kratos,yade", "--steps", "50", "--report", str(tmp_path), "--json"], capture_output=True,
                       text=True, timeout=600)
    assert p.returncode in (0, 1), p.stderr
    rows = [r for c in json.loads(p.stdout)["cases"] for r in c["points"] if r["source"] in ("kratos", "yade")]
    assert {r["source"] for r in rows} == {"kratos", "yade"} and all(r["status"] == "ok" for r in rows)


@pytest.mark.parametrize("command, what", [(["stress", "--only", "speed"], "stress searches"),
                                           (["bench", "--steps", "10"], "bench times")])
def test_a_scenario_case_is_refused_as_it_is_loaded_before_any_work(command, what, tmp_path):
    """A scenario beyond sliding has no impact to time or to search a stable step of: one line naming the file,
    run.scenario, its value and the rule, exit 2 — as calibrate refuses it — before the work of any case."""
    scenario = CASES / "suite" / "beyond-incline.toml"
    p = subprocess.run([sys.executable, "-c", _NO_WORK, command[0], str(CASES / "glass-pair.toml"), str(scenario),
                        *command[1:], "--engines", "none", "--report", str(tmp_path / "reports")],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr[-2000:]
    assert lines[0].startswith(f"demcheck: error: {scenario}: run.scenario = 'incline': must be \"collision\": "
                               f"{what}"), lines
    assert not (tmp_path / "reports").exists()
    case = demcheck.load(scenario, base=True)  # and called as functions
    for run in (lambda: S.stress_case(S.read_table(scenario), case, engines=()),
                lambda: B.bench_case(case, engines=())):
        with pytest.raises(ConfigError, match="^run.scenario = 'incline': must be \"collision\""):
            run()
