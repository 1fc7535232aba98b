"""demcheck validate: the published benchmarks' exact limits met by the reference, the verdict machinery's
ability to fail (a planted wrong paper value), and one benchmark end to end (engines by their markers)."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from demcheck.case import expand
from demcheck.comparisons import validate as VA
from demcheck.reference.collision import collide

ROOT = Path(__file__).resolve().parents[1] / "cases" / "benchmarks"


def _reference(path: Path, bench):
    """(Impact, {reference: metrics}) over the file's variants."""
    from demcheck.reference.model import resolve

    rows = []
    for case in expand(path):
        m = collide(case, "adaptive").metrics()
        m["_pair"] = resolve(case).pair
        rows.append((VA.impact_of(case), {"reference": m}))
    return {path.stem: rows}


def test_gross_sliding_limit_by_hand():
    # Chung & Ooi Test 4 at 60°: e_t = 1 − μ(1 + e)/tan θ, worked by hand: μ 0.092, e 0.98, tan 60° = √3
    imp = VA.Impact("al_oxide", 2.5e-3, 0.98, 0.092, 3.9 * math.cos(math.radians(60)), 3.9 * math.sin(math.radians(60)),
                    0.0, 60.0)
    assert VA.SLIDE_ET.value(imp, {"restitution": 0.98}) == pytest.approx(1 - 0.092 * 1.98 / math.sqrt(3), rel=1e-12)
    # ω' = 2.5 μ (1 + e) v cos θ / R in the rolling sense (the paper's sign: negative)
    assert VA.SLIDE_SPIN.value(imp, {"restitution": 0.98}) == pytest.approx(-2.5 * 0.092 * 1.98 * 1.95 / 2.5e-3)


@pytest.mark.parametrize("file,bench", [("chung-ooi-4-al-oxide-sliding.toml", "chung-ooi-4"),
                                        ("chung-ooi-4-al-oxide-tti.toml", "chung-ooi-4"),
                                        ("chung-ooi-2-al-alloy.toml", "chung-ooi-2"),
                                        ("chung-ooi-3-al-oxide-lsd.toml", "chung-ooi-3")])
def test_reference_meets_exact_limits(file, bench):
    b = VA.by_name(bench)[0]
    checks, _ = VA.judge(b, _reference(ROOT / file, b))
    limits = [c for c in checks if c["kind"] == "limit"]
    assert limits and all(c["points"] > 0 for c in limits)
    for c in limits:
        assert c["verdict"] == VA.MEETS, c


def test_a_planted_wrong_paper_value_fails(tmp_path):
    b = VA.by_name("chung-ooi-4")[0]
    rows = {"f": [(VA.Impact("al_oxide", 2.5e-3, 0.98, 0.092, 1.0, math.tan(math.radians(a)), 0.0, a),
                   {"reference": {"tangential_restitution": y, "rebound_angular_velocity": 0.0, "restitution": 0.98}})
                  for a, y in ((10.0, 0.70), (20.0, 0.62), (30.0, 0.68))]}
    good = "# block: al_oxide\n10 0.69\n20 0.61\n30 0.68\n"
    (tmp_path / "chung-ooi-4-et.dat").write_text(good)
    for name in ("chung-ooi-4-spin.dat", "chung-ooi-4-angle.dat"):
        (tmp_path / name).write_text("# nothing\n")
    checks, _ = VA.judge(b, rows, root=tmp_path)
    et = [c for c in checks if c["kind"] == "curve" and c["quantity"] == "et"][0]
    assert et["verdict"] == VA.MEETS and et["deviation"] == pytest.approx(0.01)
    (tmp_path / "chung-ooi-4-et.dat").write_text(good.replace("20 0.61", "20 0.71"))  # planted: 0.09 off
    checks, _ = VA.judge(b, rows, root=tmp_path)
    et = [c for c in checks if c["kind"] == "curve" and c["quantity"] == "et"][0]
    assert et["verdict"] == VA.MISSES and et["deviation"] == pytest.approx(0.09) and et["at"] == 20.0


def test_a_nan_is_never_a_match():
    b = VA.by_name("chung-ooi-4")[0]
    imp = VA.Impact("al_oxide", 2.5e-3, 0.98, 0.092, 1.0, 3.0, 0.0, 71.6)
    rows = {"f": [(imp, {"reference": {"tangential_restitution": math.nan, "rebound_angular_velocity": 0.0,
                                       "restitution": 0.98}})]}
    checks, _ = VA.judge(b, rows)
    assert all(c["verdict"] != VA.MEETS for c in checks if c["quantity"] == "et")


def test_every_data_file_names_its_source_and_reads():
    for f in VA.DATA.glob("*.dat"):
        text = f.read_text()
        assert "Digitised points as carried by" in text.splitlines()[1]
    for b in VA.BENCHMARKS:
        assert VA.files_of(b, ROOT), b.name
        for cur in b.curves:
            assert (VA.DATA / cur.file).is_file()
    assert VA.read_curve("chung-ooi-4-et.dat", "al_oxide")[1, 1] == pytest.approx(0.6869851729818782)


def test_verify_default_run_leaves_benchmarks_out():
    from demcheck.cli import _case_files

    assert not [f for f in _case_files(()) if "benchmarks" in f.parts]


def test_unknown_benchmark_is_one_line_exit_2():
    r = subprocess.run([sys.executable, "-m", "demcheck", "validate", "nope", "--engines", "none"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "NAME = 'nope'" in r.stderr and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
def test_validate_runs_end_to_end(tmp_path):
    """demcheck validate chung-ooi-7 with every installed engine: Test 7's exact ω' = ω0."""
    import json

    r = subprocess.run([sys.executable, "-m", "demcheck", "validate", "chung-ooi-7", "--report", str(tmp_path),
                        "--json"], capture_output=True, text=True, timeout=1200)
    assert r.returncode == 0, r.stderr[-2000:]
    out = json.loads(r.stdout)
    checks = out["validation"]["checks"]
    assert {c["source"] for c in checks} >= {"reference"}
    assert all(c["verdict"] == VA.MEETS for c in checks if c["source"] == "reference")
    assert (tmp_path / "latest" / "report.html").read_text().count("Validation against published benchmarks") == 1
    assert np.isfinite([c["deviation"] for c in checks]).all()
