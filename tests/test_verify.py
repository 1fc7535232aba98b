"""demcheck verify: verdict logic, expected differences by version, reports (md, json, JUnit, html in a
real headless browser), atomic writes, the engine-run cache and interruption."""

import json
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from demcheck.comparisons import report, suite, verdicts as V
from demcheck.engines.cache import Cache
from demcheck.errors import ConfigError
from demcheck.io import write_text

from .conftest import CASES

SCALES = {"impact_energy": 1e-5, "spin": 600.0}
TOL = V.Tolerances()
LAMMPS_RULE = V.ExpectedDifference(engine="lammps", versions=("22 Jul 2025*",), reason="kinematic rules",
                                   metrics=("tangential_restitution",))
MODEL = {"normal": "lsd", "tangential": "spring_sliding"}


def judge(metric="restitution", value=0.8, ref=0.8, twin=None, seed=None, fidelity="exact", version="22 Jul 2025 - Update 4",
          expected=(), engine="lammps"):
    twin = value if twin is None else twin
    seed = ref if seed is None else seed
    return V.judge_engine(engine, version, MODEL, metric, value, ref, twin, seed, fidelity, ["why"], SCALES, TOL,
                          list(expected))


# ----------------------------------------------------------------------------- verdict logic


def test_agree_within_the_time_steps_own_error():
    # the engine is as far from the converged answer as the seed law's verlet run at its dt
    c = judge(value=0.8012, ref=0.8, twin=0.8012, seed=0.8012)
    assert c.verdict == V.AGREE and c.parts["time_step"] == pytest.approx(0.0012)
    assert c.tolerance == pytest.approx(1e-6 + 1.01 * 0.0012)


@pytest.mark.parametrize("fidelity", ["exact", "approximate"])
@pytest.mark.parametrize("ref, seed, which", [(0.9, math.nan, "at the engine's step"), (math.nan, 0.9, "converged")])
def test_no_verdict_against_a_seed_run_that_is_not_finite(fidelity, ref, seed, which):
    # engine and twin agree and are finite, but one of the seed model's runs is not: failed, never agree or
    # "differs as expected" (before, a NaN step share counted as 0 and the engine "agreed")
    c = judge(value=0.9, ref=ref, twin=0.9, seed=seed, fidelity=fidelity)
    assert c.verdict == V.FAILED and which in c.reason and "not finite" in c.reason


def test_an_engine_off_its_twin_is_still_named_when_the_seed_run_is_not_finite():
    c = judge(value=0.9, ref=0.9, twin=0.95, seed=math.nan)
    assert c.verdict == V.UNEXPECTED and "documented formula" in c.reason


def test_beyond_the_time_step_error_is_unexpected_for_an_exact_mapping():
    c = judge(value=0.81, ref=0.8, twin=0.81, seed=0.8001)
    assert c.verdict == V.UNEXPECTED and "no documented difference" in c.reason


def test_an_engine_off_its_own_twin_is_unexpected_even_when_close_to_the_seed():
    c = judge(value=0.8000001, ref=0.8, twin=0.8000002, seed=0.8000001)
    assert c.verdict == V.UNEXPECTED and "documented formula" in c.reason
    assert c.parts["implementation"] == pytest.approx(1e-7)


def test_approximate_mapping_differs_as_expected_with_its_reason():
    c = judge(value=0.7, ref=0.8, twin=0.7, seed=0.8, fidelity="approximate")
    assert c.verdict == V.EXPECTED and c.reason == "approximate mapping: why"


def test_expected_differences_match_by_engine_version_and_metric():
    args = dict(metric="tangential_restitution", value=0.5, ref=0.6, twin=0.5, seed=0.6, expected=[LAMMPS_RULE])
    assert judge(**args).verdict == V.EXPECTED
    assert judge(**args).reason == "kinematic rules"
    # another version of the engine: not covered, so it shows up
    assert judge(**args, version="2 Apr 2026").verdict == V.UNEXPECTED
    # another engine, another metric: not covered either
    assert judge(**args, engine="liggghts", version="LIGGGHTS-PUBLIC 3.8.0").verdict == V.UNEXPECTED
    assert judge(**{**args, "metric": "restitution"}).verdict == V.UNEXPECTED


def test_a_metric_that_does_not_apply_agrees():
    c = judge(metric="tangential_restitution", value=math.nan, ref=math.nan, twin=math.nan, seed=math.nan)
    assert c.verdict == V.AGREE and c.rel_diff == 0.0


def test_a_metric_missing_on_the_engines_side_fails():
    # a broken run is never "agree" nor "differs as expected" (issue 12 item 5: judge_engine)
    assert judge(value=math.nan, twin=math.nan).verdict == V.FAILED


def test_scales_of_the_metrics():
    assert V.scale("energy_dissipated", 3.0, SCALES) == 1e-5
    assert V.scale("rebound_angular_velocity", 3.0, SCALES) == 600.0
    assert V.scale("peak_force", -4.0, SCALES) == 4.0
    assert V.scale("tangential_restitution", 0.01, SCALES) == 1.0


def test_verlet_and_closed_form_verdicts():
    assert V.judge_verlet("restitution", 0.805, 0.8, 200, SCALES, TOL).verdict == V.AGREE
    far = V.judge_verlet("restitution", 0.85, 0.8, 200, SCALES, TOL)
    assert far.verdict == V.EXPECTED and "200 steps per contact" in far.reason
    assert V.judge_closed_form("contact_time", 1.0 + 1e-9, 1.0, SCALES, TOL).verdict == V.AGREE
    assert V.judge_closed_form("contact_time", 1.0 + 1e-7, 1.0, SCALES, TOL).verdict == V.UNEXPECTED


def test_worst_verdict_order():
    assert V.worst([V.AGREE, V.EXPECTED, V.NOT_EXPRESSIBLE]) == V.EXPECTED
    assert V.worst([V.EXPECTED, V.UNEXPECTED]) == V.UNEXPECTED
    assert V.worst([V.UNEXPECTED, V.FAILED, V.AGREE]) == V.FAILED
    assert V.worst([]) == V.AGREE


def test_the_shipped_expected_differences_and_tolerances_load():
    entries = V.load_expected()
    assert entries and all(e.reason and e.versions for e in entries)
    assert V.Tolerances.load() == V.Tolerances()


@pytest.mark.parametrize("text,message", [
    ('[[difference]]\nengine = "lammps"\nreason = "x"\n', "versions = (missing): missing"),
    ('[[difference]]\nengine = "lammps"\nversions = []\nreason = "x"\n', "must be a non-empty list"),
    ('[[difference]]\nengine = "lammps"\nversions = ["*"]\nreason = "x"\ncolour = 1\n', "colour = 1: unknown key"),
    ("not toml [", "not valid TOML"),
])
def test_bad_expected_differences_file_is_one_clear_line(tmp_path, text, message):
    path = tmp_path / "expected.toml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message.replace("(", r"\(").replace(")", r"\)")):
        V.load_expected(path)


# ----------------------------------------------------------------------------- reports


def _run(tmp_path, files, engines=(), **kw):
    opts = suite.Options(engines=tuple(engines), jobs=2, cache=Cache(tmp_path / "cache"), **kw)
    return suite.run_suite([Path(f) for f in files], tmp_path / "reports", opts, quiet=True,
                           junit=tmp_path / "junit.xml", argv=["demcheck", "verify"]).to_json()


def test_reference_only_suite_writes_every_report(tmp_path):
    s = _run(tmp_path, [CASES / "glass-pair.toml", CASES / "suite" / "oblique-viscous.toml"])
    out = Path(s["report"])
    assert (tmp_path / "reports" / "latest").resolve() == out.resolve()
    data = json.loads((out / "results.json").read_text())
    assert data["partial"] is False and len(data["cases"]) == 1 + 8 and data["failed"] == 0
    assert data["cases"][0]["case_hash"] and data["command"] == ["demcheck", "verify"]
    md = (out / "report.md").read_text()
    assert "## Agreement matrix" in md and "## Disagreements and their reasons" in md
    # JUnit: valid XML, one testcase per case × source, counts that add up
    root = ET.parse(tmp_path / "junit.xml").getroot()
    ts = root.find("testsuite")
    cases = ts.findall("testcase")
    assert int(ts.get("tests")) == len(cases) == 9
    assert int(ts.get("failures")) == sum(c.find("failure") is not None for c in cases) == 0
    assert (out / "junit.xml").read_text() == (tmp_path / "junit.xml").read_text()
    html = (out / "report.html").read_text()
    assert html.count('<img class="plot"') >= 4  # two case panels, the angle plots


def test_seed_001_worked_example_is_in_the_default_suite():
    files = sorted(CASES.rglob("*.toml"))
    names = [c.name for _, c in suite.collect(files)]
    assert "glass-pair" in names
    assert len(names) > 150


def test_junit_marks_unexpected_differences_as_failures(tmp_path):
    summary = {"run_id": "x", "started": "2026-01-01T00:00:00", "wall_time": 1.0, "partial": False, "planned": 1,
               "engines": {}, "failed": 1, "demcheck": "0", "cases": [{
                   "case": "c", "file": "c.toml", "status": "unexpected", "model": MODEL, "sources": {},
                   "curves": {}, "comparisons": [
                       judge(value=0.81, ref=0.8, twin=0.81, seed=0.8).as_dict(),
                       V.status_comparison("liggghts", V.NOT_EXPRESSIBLE, "no law").as_dict()]}]}
    root = ET.fromstring(report.render_junit(summary))
    ts = root.find("testsuite")
    assert ts.get("tests") == "2" and ts.get("failures") == "1" and ts.get("skipped") == "1"
    fail = ts.find("testcase/failure")
    assert "restitution" in fail.text and "no documented difference" in fail.text
    md = report.render_markdown(summary)
    assert "**differs unexpectedly** — lammps" in md and "**not expressible** — liggghts: no law" in md


def test_atomic_write_keeps_the_old_report_when_writing_fails(tmp_path, monkeypatch):
    path = tmp_path / "report.md"
    write_text(path, "old\n")
    import demcheck.io as io_mod

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(io_mod.os, "replace", boom)
    with pytest.raises(OSError):
        write_text(path, "new\n")
    assert path.read_text() == "old\n"
    assert [p.name for p in tmp_path.iterdir()] == ["report.md"]  # no temporary left behind


def test_interrupted_run_keeps_finished_cases_and_says_partial(tmp_path, monkeypatch):
    real = suite.run_case
    calls = {"n": 0}

    def run_case(case, *a, **k):
        calls["n"] += 1
        if "hertz" in case.name:
            raise KeyboardInterrupt
        return real(case, *a, **k)

    monkeypatch.setattr(suite, "run_case", run_case)
    opts = suite.Options(engines=(), jobs=1, cache=None)
    with pytest.raises(KeyboardInterrupt):
        suite.run_suite([CASES / "glass-pair.toml", CASES / "hertz-wall.toml", CASES / "kk-wall.toml"],
                        tmp_path / "reports", opts, quiet=True)
    latest = tmp_path / "reports" / "latest"
    data = json.loads((latest / "results.json").read_text())
    assert data["partial"] is True
    names = [c["case"] for c in data["cases"]]
    assert "glass-pair" in names and "hertz-wall" not in names  # kk-wall may have finished meanwhile: kept
    assert data["planned"] == 3
    assert "PARTIAL REPORT" in (latest / "report.md").read_text()
    assert "PARTIAL REPORT" in (latest / "report.html").read_text()


def test_cli_verify_reference_only_exit_codes(tmp_path):
    def run(*args):
        return subprocess.run([sys.executable, "-m", "demcheck", "verify", *map(str, args)], capture_output=True,
                              text=True, cwd=tmp_path, timeout=600)

    p = run(CASES / "hertz-wall.toml", "--engines", "none", "--json", "--junit", tmp_path / "j.xml")
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["failed"] == 0 and out["engines"] == {} and (tmp_path / "j.xml").exists()
    p = run(CASES / "hertz-wall.toml", "--engines", "ansys")
    assert p.returncode == 2 and "--engines = 'ansys': must be lammps, liggghts" in p.stderr
    p = run(tmp_path / "nothing-here")
    assert p.returncode == 2 and "no such case file or directory" in p.stderr


def test_cli_verify_with_a_named_engine_missing_fails_before_any_work(tmp_path):
    """An engine named with --engines is required (docs/reliability.md): not found, the run fails with the reason,
    exit 1, no report. Only default discovery skips a missing engine (tests/test_run_reliability.py)."""
    env = dict(os.environ, DEMCHECK_LIGGGHTS="/nonexistent/liggghts", DEMCHECK_CACHE=str(tmp_path / "cache"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", str(CASES / "hertz-wall.toml"), "--engines",
                        "liggghts", "--report", str(tmp_path / "r")], capture_output=True, text=True, env=env,
                       timeout=600)
    assert p.returncode == 1, p.stderr
    assert "--engines names liggghts, which cannot run (discovery tried twice): liggghts is not usable: " \
           "/nonexistent/liggghts does not start" in p.stderr and "apt-get install liggghts" in p.stderr
    assert not (tmp_path / "r").exists()


# ----------------------------------------------------------------------------- with the engines


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_engine_suite_agrees_and_the_cache_skips_second_runs(tmp_path):
    files = [CASES / "suite" / "normal-kk-wall.toml", CASES / "suite" / "oblique-lsd-sliding-overlap.toml",
             CASES / "hls-constant-pair.toml"]
    first = _run(tmp_path, files, engines=("lammps", "liggghts"))
    assert first["failed"] == 0
    assert first["cache"]["hits"] == 0 and first["cache"]["misses"] > 0
    verdicts = {k["verdict"] for c in first["cases"] for k in c["comparisons"]}
    assert V.AGREE in verdicts and V.NOT_EXPRESSIBLE in verdicts  # HLS in LAMMPS
    kk = next(c for c in first["cases"] if c["case"].startswith("suite-kk-wall"))
    for engine in ("lammps", "liggghts"):
        assert kk["sources"][engine]["fidelity"] == "exact"
        assert all(k["verdict"] == V.AGREE for k in kk["comparisons"] if k["source"] == engine)
        assert kk["curves"][engine]["force_time_max"] < 1e-2
    # the overlap truncation is exact in LAMMPS, approximate in LIGGGHTS: explained, not failed
    obl = [c for c in first["cases"] if "overlap" in c["case"]]
    assert any(k["verdict"] == V.EXPECTED and k["source"] == "liggghts" for c in obl for k in c["comparisons"])
    second = _run(tmp_path, files, engines=("lammps", "liggghts"))
    assert second["cache"]["misses"] == 0 and second["cache"]["hits"] == first["cache"]["misses"]
    assert all(c["sources"].get("lammps", {}).get("cached") in (True, None) for c in second["cases"])


@pytest.mark.engine("lammps")
def test_an_unexpected_difference_fails_the_run(tmp_path):
    """With the implementation bar at zero, the engine's round-off from its twin is 'unexpected'."""
    s = _run(tmp_path, [CASES / "glass-pair.toml"], engines=("lammps",),
             tolerances=V.Tolerances(implementation=0.0, engine_rtol=0.0))
    lam = [k for c in s["cases"] for k in c["comparisons"] if k["source"] == "lammps"]
    assert s["failed"] == 1 and any(k["verdict"] == V.UNEXPECTED for k in lam)


def _chromium():
    return shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


@pytest.mark.browser
def test_report_html_renders_its_plots_in_a_headless_browser(tmp_path):
    s = _run(tmp_path, [CASES / "suite" / "normal-hertz-pair.toml", CASES / "suite" / "oblique-sliding.toml"])
    page = Path(s["report"]) / "report.html"
    browser = _chromium()
    assert browser, "chromium is not installed (scripts/install-browser.sh)"
    proc = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=5000",
                           "--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=120)
    dom = proc.stdout
    assert "<body" in dom, proc.stderr[-2000:]
    import re

    n = int(re.search(r'data-plots="(\d+)"', dom).group(1))
    ok = int(re.search(r'data-plots-ok="(\d+)"', dom).group(1))
    assert n >= 4 and ok == n  # every plot decoded and laid out with a size


# ----------------------------------------------------------------------------- the plot cache


def test_the_plot_cache_lives_under_the_cache_and_a_damaged_entry_is_drawn_again(tmp_path, caplog):
    files = [CASES / "glass-pair.toml"]
    _run(tmp_path, files)
    plots = sorted((tmp_path / "cache" / "plots").glob("*.b64"))
    assert len(plots) >= 2 and not (tmp_path / "plots").exists()  # under $DEMCHECK_CACHE, not beside it
    good = {p: p.read_text() for p in plots}
    damage = [lambda t: t[: len(t) // 2], lambda t: "", lambda t: t.replace(t[40:60], "#" * 20, 1)]
    for k, p in enumerate(plots):
        p.write_text(damage[k % len(damage)](good[p]))
    second = _run(tmp_path, files)
    out = Path(second["report"])
    assert (tmp_path / "reports" / "latest").resolve() == out.resolve()
    assert (out / "report.html").read_text().count('<img class="plot"') >= 2
    assert {p: p.read_text() for p in plots} == good  # each damaged entry replaced by a sound one
    logged = [r.getMessage() for r in caplog.records if r.name == "demcheck.cache"]
    assert len(logged) == len(plots) and all("plot cache: ignoring the damaged entry" in m for m in logged)


# ----------------------------------------------------------------------------- errors name their file


def test_a_bad_case_file_is_named_before_any_case_runs(tmp_path):
    good, bad = tmp_path / "good.toml", tmp_path / "bad.toml"
    good.write_text((CASES / "glass-pair.toml").read_text())
    bad.write_text((CASES / "glass-pair.toml").read_text().replace('normal = "hertz"', 'normal = "hertzz"'))
    with pytest.raises(ConfigError, match=rf"^{bad}: contact.normal = 'hertzz': unknown normal model"):
        _run(tmp_path, [good, bad])
    assert not (tmp_path / "reports").exists()


def test_a_bad_variant_is_named_with_its_file_and_label(tmp_path):
    bad = tmp_path / "bad.toml"
    text = (CASES / "glass-pair.toml").read_text().replace('normal = "hertz"', 'normal = "lsd"')
    bad.write_text(text + '\n[variants]\n"contact.stiffness_method" = ["energy", "bogus"]\n')
    with pytest.raises(ConfigError, match=rf"^{bad}\[stiffness_method=bogus\]: contact.stiffness_method = 'bogus'"):
        _run(tmp_path, [bad])
    bad.write_text((CASES / "glass-pair.toml").read_text() + '\n[variants]\n"impact.speed" = [1.0, -2.0]\n')
    with pytest.raises(ConfigError, match=rf"^{bad}\[speed=-2\]: impact.speed = -2.0: must be > 0"):
        _run(tmp_path, [bad])
    assert not (tmp_path / "reports").exists()


def test_cli_verify_names_the_file_at_fault_in_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((CASES / "glass-pair.toml").read_text().replace("[impact]", "[impact]\nsped = 1.0"))
    p = subprocess.run([sys.executable, "-m", "demcheck", "verify", str(CASES / "hertz-wall.toml"), str(bad),
                        "--engines", "none"], capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.strip().splitlines() == [f"demcheck: error: {bad}: impact.sped = 1.0: unknown key; did you "
                                             "mean 'speed'?"]
    assert not (tmp_path / "reports").exists()


# ----------------------------------------------------------------------------- engine runs the suite refuses


def test_an_engine_run_that_is_not_ok_fails_its_case_and_its_metrics_are_not_judged(monkeypatch):
    from demcheck.case import load
    from demcheck.engines import collide as engine_collide
    from demcheck.reference.collision import collide

    def unstable(case, engine, **kw):
        res = collide(case, "verlet")
        res.source, res.method, res.engine_version = engine, "engine", "fake 1.0"
        res.status, res.message = "unstable", "the overlap reached 3.2 radii"
        return res

    monkeypatch.setattr(engine_collide, "collide", unstable)
    found = {"lammps": {"found": True, "version": "fake 1.0", "executable": "lmp", "how_to_install": None}}
    opts = suite.Options(engines=("lammps",), jobs=1, cache=None)
    entry = suite.run_case(load(CASES / "glass-pair.toml"), CASES / "glass-pair.toml", opts, found).to_json()
    lam = [k for k in entry["comparisons"] if k["source"] == "lammps"]
    assert [(k["verdict"], k["reason"]) for k in lam] == [(V.FAILED, "unstable: the overlap reached 3.2 radii")]
    assert entry["status"] == "failed" and entry["sources"]["lammps"]["status"] == "unstable"


def test_a_case_whose_own_time_step_is_unhealthy_fails(tmp_path):
    """At the case's run.dt the reference's verlet method resolves nothing (one step inside the contact): the case
    fails — a run that is not ok is never "differs as expected" (docs/reliability.md)."""
    from demcheck.case import load

    opts = suite.Options(engines=(), jobs=1, cache=None)
    case = load(CASES / "glass-pair.toml", ["run.dt=3e-5"])
    entry = suite.run_case(case, CASES / "glass-pair.toml", opts, {}).to_json()
    ver = [k for k in entry["comparisons"] if k["source"] == "reference-verlet"]
    assert [k["verdict"] for k in ver] == [V.FAILED] and ver[0]["reason"].startswith("unresolved:")
    assert entry["status"] == "failed"


# ----------------------------------------------------------------------------- --timeout reaches every engine run

SLEEPER = """#!/bin/sh
case "$1" in -h) echo "Large-scale Atomic/Molecular Massively Parallel Simulator - 22 Jul 2025 - fake"; exit 0;; esac
exec sleep 300
"""


def test_the_timeout_applies_to_every_engine_run_collisions_and_packings(tmp_path, monkeypatch):
    from demcheck.engines import discovery

    fake = tmp_path / "lmp"
    fake.write_text(SLEEPER)
    fake.chmod(0o755)
    monkeypatch.setenv("DEMCHECK_LAMMPS", str(fake))
    discovery.find.cache_clear()
    try:
        s = _run(tmp_path, [CASES / "glass-pair.toml", CASES / "packing" / "layer-kk.toml"], engines=("lammps",),
                 timeout=1.0)
    finally:
        discovery.find.cache_clear()
    for c in s["cases"]:
        lam = [k for k in c["comparisons"] if k["source"] == "lammps"]
        assert [k["verdict"] for k in lam] == [V.FAILED], c["case"]
        assert lam[0]["reason"].startswith("lammps ran past its timeout of 1 s and was stopped"), lam[0]["reason"]


def test_no_cache_runs_afresh_and_replaces_the_cached_entries(tmp_path):
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp_path / "cache"))

    def verify(*extra):
        p = subprocess.run([sys.executable, "-m", "demcheck", "verify", str(CASES / "packing" / "layer-kk.toml"),
                            "--engines", "none", "--report", str(tmp_path / "r"), "--json", *extra],
                           capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
        assert p.returncode == 0, p.stderr
        return json.loads(p.stdout)

    first = verify()
    entries = sorted((tmp_path / "cache").rglob("*.npz"))
    assert entries and first["cache"]["misses"] > 0
    for e in entries:
        os.utime(e, (946684800, 946684800))  # 2000-01-01: an old entry
    fresh = verify("--no-cache")
    assert fresh["cache"]["hits"] == 0
    assert all(e.stat().st_mtime > 946684800 for e in entries)  # written over by the fresh run
