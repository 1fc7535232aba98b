"""verify --baseline / --write-baseline: a clean rerun passes, a planted change fails with its size."""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from .conftest import CASES

CASE = CASES / "kk-wall.toml"


def verify(tmp, *args, engines="none"):
    env = dict(os.environ, DEMCHECK_CACHE=str(tmp / "cache"))
    return subprocess.run([sys.executable, "-m", "demcheck", "verify", str(CASE), "--engines", engines,
                           "--report", str(tmp / "r"), *map(str, args)], capture_output=True, text=True,
                          timeout=600, env=env)


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("baseline")
    p = verify(tmp, "--write-baseline", tmp / "base.json")
    assert p.returncode == 0, p.stderr
    return tmp, json.loads((tmp / "base.json").read_text())


def test_the_baseline_file_holds_values_verdicts_versions_and_tolerances(stored):
    _, base = stored
    assert base["format"] == "demcheck-baseline" and base["version"] == 1
    assert base["tolerances"] == {"default": 1e-9, "metrics": {}}  # data/tolerances.toml's implementation bar
    src = base["cases"]["kk-wall"]["sources"]["reference"]
    assert src["status"] == "ok" and 0 < src["metrics"]["restitution"] < 1
    assert base["cases"]["kk-wall"]["verdicts"]["reference-verlet"]["restitution"] == "agree"


def test_a_clean_rerun_passes(stored):
    tmp, _ = stored
    p = verify(tmp, "--baseline", tmp / "base.json", "--json")
    assert p.returncode == 0, p.stderr
    b = json.loads(p.stdout)["baseline"]
    assert b["regressions"] == 0 and b["checked"] >= 18 and b["unchanged"] == b["checked"]


def plant(tmp, base, name, **tolerances):
    b = json.loads(json.dumps(base))
    src = b["cases"]["kk-wall"]["sources"]["reference"]
    src["metrics"]["restitution"] -= 3e-3
    if tolerances:
        src["tolerances"] = tolerances
    (tmp / name).write_text(json.dumps(b))
    return tmp / name


def test_a_planted_change_fails_with_its_size(stored):
    tmp, base = stored
    p = verify(tmp, "--baseline", plant(tmp, base, "planted.json"), "--json")
    assert p.returncode == 1
    out = json.loads(p.stdout)
    (case,) = out["cases"]
    (comp,) = [k for k in case["comparisons"] if k["reason"].startswith("baseline:")]
    assert (comp["source"], comp["metric"], comp["verdict"]) == ("reference", "restitution", "differs unexpectedly")
    assert comp["rel_diff"] == pytest.approx(3e-3, rel=1e-9) and "moved 0.003 from the baseline's" in comp["reason"]
    assert out["failed"] == 1 and case["status"] == "unexpected" and out["baseline"]["regressions"] == 1
    latest = tmp / "r" / "latest"
    assert "**1 regression(s)**" in (latest / "report.md").read_text()
    suite = ET.parse(latest / "junit.xml").getroot().find("testsuite")
    assert suite.get("failures") == "1"


def test_a_per_quantity_tolerance_admits_the_change(stored):
    tmp, base = stored
    p = verify(tmp, "--baseline", plant(tmp, base, "loose.json", restitution=5e-3))
    assert p.returncode == 0, p.stderr
    p = verify(tmp, "--baseline", plant(tmp, base, "tight.json", restitution=1e-3))
    assert p.returncode == 1


def test_a_bad_baseline_is_one_line_before_any_work(stored, tmp_path):
    (tmp_path / "b.json").write_text('{"format": "demcheck-baseline", "version": 1, "cases": {}, '
                                     '"tolerances": {"default": -1}}')
    p = verify(tmp_path, "--baseline", tmp_path / "b.json")
    assert p.returncode == 2 and "at $.tolerances.default: -1 is less than the minimum of 0" in p.stderr
    assert not (tmp_path / "r").exists()  # nothing ran
    p = verify(tmp_path, "--baseline", tmp_path / "missing.json")
    assert p.returncode == 2 and "--baseline = " in p.stderr and "no such file" in p.stderr


@pytest.mark.engine("lammps")
def test_lammps_against_its_baseline(tmp_path):
    p = verify(tmp_path, "--write-baseline", tmp_path / "base.json", engines="lammps")
    assert p.returncode == 0, p.stderr
    base = json.loads((tmp_path / "base.json").read_text())
    assert base["engines"]["lammps"].startswith("22 Jul 2025")
    p = verify(tmp_path, "--baseline", tmp_path / "base.json", "--no-cache", "--json", engines="lammps")
    assert p.returncode == 0 and json.loads(p.stdout)["baseline"]["regressions"] == 0, p.stderr
    base["cases"]["kk-wall"]["sources"]["lammps"]["metrics"]["max_overlap"] *= 1.01
    (tmp_path / "p.json").write_text(json.dumps(base))
    p = verify(tmp_path, "--baseline", tmp_path / "p.json", "--json", engines="lammps")
    assert p.returncode == 1
    (comp,) = [k for c in json.loads(p.stdout)["cases"] for k in c["comparisons"] if k["reason"].startswith("baseline")]
    assert comp["source"] == "lammps" and comp["rel_diff"] == pytest.approx(0.01 / 1.01, rel=1e-9)
