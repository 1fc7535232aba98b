"""demcheck validate: the published benchmarks' exact limits met by the reference, the verdict machinery's
ability to fail (a planted wrong paper value), and one benchmark end to end (engines by their markers)."""

import math
import os
import subprocess
import sys
from pathlib import Path

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
                                        ("chung-ooi-3-al-oxide-lsd.toml", "chung-ooi-3"),
                                        ("chung-ooi-3-cast-iron-tti.toml", "chung-ooi-3"),
                                        # Ψ2 carries Ω, so the seed's torque arm R − δ/2 (Ψ2 3.009 against 3 at
                                        # Ψ1 = 10): met within Ω's arm allowance, missed without it
                                        ("thornton-e100-spring-sliding.toml", "thornton")])
def test_reference_meets_exact_limits(file, bench):
    b = VA.by_name(bench)[0]
    checks, _ = VA.judge(b, _reference(ROOT / file, b))
    limits = [c for c in checks if c["kind"] == "limit" and c["points"] > 0]  # the limits that apply here
    assert {c["quantity"] for c in limits} == set(b.quantities) & {lim.quantity for lim in b.limits}
    for c in limits:
        assert c["verdict"] == VA.MEETS, c


def test_ttin_returns_the_correlations_restitution_not_the_given_one():
    """Norouzi's ηn is a fit: TTIn at e = 0.2 rebounds at 0.1988, which the given-e limit would call a miss
    (1.2e-3 > 1e-6); the TTIn limit (the law's ODE solved by scipy) is met to 1e-6, and only it applies."""
    b = VA.by_name("chung-ooi-3")[0]
    rows = _reference(ROOT / "chung-ooi-3-al-oxide-tti.toml", b)
    (imp, ms), *_ = rows["chung-ooi-3-al-oxide-tti"]
    assert imp.e == 0.2 and imp.normal == "tti"
    e_out = ms["reference"]["restitution"]
    assert 1e-3 < imp.e - e_out < 1.5e-3
    assert abs(e_out - VA.tti_restitution(0.2)) < 1e-6
    assert not VA.GIVEN_E.applies(imp) and VA.TTI_E.applies(imp)
    assert VA.tti_restitution(0.999) == pytest.approx(0.999, abs=1e-6)  # c → 0: the correlation is exact


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


def test_an_engine_that_cannot_express_the_model_is_no_source_but_a_failed_run_misses():
    """Kratos without the law (not expressible) and a missing Yade are left out; a failed LAMMPS run misses every
    limit (a failed run is never agreement, nor 'no data')."""
    b = VA.by_name("chung-ooi-1")[0]
    path = ROOT / "chung-ooi-1-glass.toml"
    (case,) = expand(path)
    ok = {"status": "ok", "metrics": collide(case, "adaptive").metrics()}
    summary = {"cases": [{"case": case.name, "sources": {
        "reference": ok, "lammps": {"status": "failed", "message": "boom"},
        "kratos": {"status": "not expressible", "message": "no such law"},
        "yade": {"status": "engine missing", "message": "not installed"}}}]}
    val = VA.validate(summary, [b], {b.name: [path]}, opts=None)
    assert {c["source"] for c in val["checks"]} == {"reference", "lammps"}
    assert {(c["verdict"], c["deviation"]) for c in val["checks"] if c["source"] == "lammps"} == {(VA.MISSES, math.inf)}
    assert {c["verdict"] for c in val["checks"] if c["source"] == "reference"} == {VA.MEETS}


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


def test_validate_summary_and_report_are_titled_validate(tmp_path):
    r = subprocess.run([sys.executable, "-m", "demcheck", "validate", "chung-ooi-1", "--engines", "none", "--report",
                        str(tmp_path)], capture_output=True, text=True, timeout=600,
                       env={**os.environ, "DEMCHECK_CACHE": str(tmp_path / "cache"), "COLUMNS": "200"})
    assert r.returncode == 0, r.stderr[-2000:]
    assert "demcheck validate: 2 of 2" in r.stderr and "demcheck verify" not in r.stderr  # the title wraps
    assert "validation: limit meets: 6" in r.stderr
    html = (tmp_path / "latest-validate" / "report.html").read_text()
    assert "<title>demcheck validate " in html and "<title>demcheck verify" not in html


def test_validate_test7_reads_the_final_spin(tmp_path):
    """demcheck validate chung-ooi-7 in the reference (the engines' end-to-end run is the test below): Test 7's
    ω' = ω0 is read from each source's final spin (not a metric), for every file."""
    import json

    r = subprocess.run([sys.executable, "-m", "demcheck", "validate", "chung-ooi-7", "--engines", "none", "--report",
                        str(tmp_path), "--json"], capture_output=True, text=True, timeout=600,
                       env={**os.environ, "DEMCHECK_CACHE": str(tmp_path / "cache")})
    assert r.returncode == 0, r.stderr[-2000:]
    checks = json.loads(r.stdout)["validation"]["checks"]
    # four files (two materials × two laws), each with both spins as one zipped group of variants
    assert len(checks) == len(VA.files_of(VA.by_name("chung-ooi-7")[0], ROOT)) == 4
    for c in checks:
        assert c["source"] == "reference" and c["quantity"] == "spin_ratio" and c["points"] == 2
        assert c["verdict"] == VA.MEETS and c["deviation"] < 1e-9, c
    assert (tmp_path / "latest-validate" / "report.html").read_text().count("Validation against published benchmarks") == 1

# ----------------------------------------------------------------------------- end to end with the engines

ENGINES = ("lammps", "liggghts", "kratos", "yade")


def _hertz_by_hand(path: Path) -> dict:
    """Test 1's Hertz closed forms worked from the case file's numbers alone (not reference/analytic.py): δ_max
    from the energy balance ½ m̄ v² = (8/15) Ē √R̄ δ_max^{5/2}, F_max = (4/3) Ē √R̄ δ_max^{3/2}, and the contact
    time 2 ∫ dδ/δ̇ = 2 (δ_max/v) ∫₀¹ du/√(1 − u^{5/2}) by quadrature."""
    import tomllib

    from scipy.integrate import quad

    raw = tomllib.loads(path.read_text())
    (mat,) = raw["materials"].values()
    p0, p1 = raw["particles"]
    assert p0 == p1  # two identical spheres
    m = mat["density"] * 4 / 3 * math.pi * p0["radius"] ** 3
    m_eff, r_eff = m / 2, p0["radius"] / 2
    e_eff = mat["youngs_modulus"] / (2 * (1 - mat["poisson_ratio"] ** 2))
    v = raw["impact"]["speed"]  # the relative approach speed (10 m/s each)
    d = (15 * m_eff * v * v / (16 * e_eff * math.sqrt(r_eff))) ** 0.4
    integral = quad(lambda u: 1 / math.sqrt(1 - u**2.5), 0, 1, limit=200)[0]
    return {"contact_time": 2 * d / v * integral, "max_overlap": d,
            "peak_force": 4 / 3 * e_eff * math.sqrt(r_eff) * d**1.5}


@pytest.mark.engine("lammps")
@pytest.mark.engine("liggghts")
@pytest.mark.engine("kratos")
@pytest.mark.engine("yade")
def test_validate_end_to_end_with_the_installed_engines(tmp_path):
    """``demcheck validate chung-ooi-1`` (the cheapest benchmark: two single-case files, no variants) with every
    installed engine, from an empty run cache and again from the filled one: exit 0, the validation section in
    the JSON and the reports, every source against the three Hertz limits, and the numbers against the closed
    forms worked by hand here. (conftest skips on the closest engine marker only; the sources expected are the
    engines discovery finds, so a missing one is left out rather than failed.)"""
    import json

    from demcheck.engines import discovery

    installed = {e for e in ENGINES if discovery.find(e) is not None}
    env = {**os.environ, "DEMCHECK_CACHE": str(tmp_path / "cache")}
    cmd = [sys.executable, "-m", "demcheck", "validate", "chung-ooi-1", "--jobs", "1", "--json"]
    runs = []
    for k in (1, 2):  # cold cache, then warm
        r = subprocess.run([*cmd, "--report", str(tmp_path / f"r{k}")], capture_output=True, text=True, env=env,
                           timeout=600)
        assert r.returncode == 0, r.stderr[-3000:]
        runs.append(json.loads(r.stdout))
    out = runs[0]
    assert out["failed"] == 0
    assert {e for e, v in out["engines"].items() if v["found"]} == installed
    checks = out["validation"]["checks"]
    files = {"chung-ooi-1-glass", "chung-ooi-1-limestone"}
    assert {c["file"] for c in checks} == files
    assert {c["source"] for c in checks} == {"reference"} | installed
    assert len(checks) == len(files) * (1 + len(installed)) * 3  # file × source × (t_c, δ_max, F_max)
    for c in checks:
        assert c["kind"] == "limit" and c["points"] == 1 and c["verdict"] == VA.MEETS, c
        assert math.isfinite(c["deviation"])
        assert c["tolerance"] == (1e-6 if c["source"] == "reference" else 2e-3)
    assert out["validation"]["failed"] == []

    # the reported metrics against the closed forms worked by hand: the reference to 1e-6 (its events), each
    # engine to 2e-3 (its time step at the suite's steps per contact)
    summary = json.loads((tmp_path / "r1" / "latest-validate" / "results.json").read_text())
    for entry in summary["cases"]:
        exact = _hertz_by_hand(ROOT / f"{entry['case']}.toml")
        for src in {"reference"} | installed:
            m = entry["sources"][src]["metrics"]
            for q, v in exact.items():
                assert m[q] == pytest.approx(v, rel=1e-6 if src == "reference" else 2e-3), (entry["case"], src, q)
    md = (tmp_path / "r1" / "latest-validate" / "report.md").read_text()
    assert md.count("## Validation against published benchmarks") == 1
    assert sum(line.startswith("| chung-ooi-1-") for line in md.splitlines()) >= len(checks)
    assert (tmp_path / "r1" / "latest-validate" / "report.html").read_text().count("Validation against published benchmarks") == 1

    # the second run reads every engine run from the cache and judges the same numbers
    warm = json.loads((tmp_path / "r2" / "latest-validate" / "results.json").read_text())
    assert warm["cache"]["hits"] == len(files) * len(installed) and warm["cache"]["misses"] == 0
    assert [(c["source"], c["deviation"]) for c in runs[1]["validation"]["checks"]] == \
        [(c["source"], c["deviation"]) for c in checks]


def test_validate_exits_1_when_the_reference_misses_an_exact_limit(tmp_path, monkeypatch, capsys):
    """A planted wrong limit (Test 1's contact time 1% too long): the reference misses it, the command exits 1
    and names it (reference only: no engine needed)."""
    import dataclasses
    import json

    from demcheck import cli

    b = VA.by_name("chung-ooi-1")[0]
    wrong = [dataclasses.replace(lim, value=(lambda c, m, f=lim.value: 1.01 * f(c, m)))
             if lim.quantity == "contact_time" else lim for lim in b.limits]
    monkeypatch.setattr(VA, "BENCHMARKS", (dataclasses.replace(b, limits=tuple(wrong)),))
    monkeypatch.setenv("DEMCHECK_CACHE", str(tmp_path / "cache"))
    with pytest.raises(SystemExit) as exc:
        cli.main(["validate", "chung-ooi-1", "--engines", "none", "--report", str(tmp_path), "--json"])
    assert exc.value.code == 1
    out = json.loads(capsys.readouterr().out)
    failed = out["validation"]["failed"]
    assert {(c["file"], c["quantity"]) for c in failed} == {("chung-ooi-1-glass", "contact_time"),
                                                            ("chung-ooi-1-limestone", "contact_time")}
    assert all(c["deviation"] == pytest.approx(0.01 / 1.01, rel=1e-6) for c in failed)  # |t − 1.01 t|/(1.01 t)
    assert out["failed"] == 2
